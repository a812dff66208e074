//! Frame-by-frame trace of one case of the stability matrix under one configuration: kinetic
//! energy over the case's reference, peak particle speed, inverted tetrahedra and the
//! vertex–face family's max |C| after each frame. The run is the suite's own
//! ([`tetpbd_stability::run_scene_observed`]), from the case's start.
//!
//! ```text
//! cargo run --release -p tetpbd-stability --example diag_sliver -- [CASE] [CONFIG] [net]
//! ```
//!
//! `CASE` is a substring of the case name (default `slivers`), `CONFIG` one of the column
//! labels' prefixes (`vertex-face`, `vertex-face+edges`, `edges+volume`; default
//! `vertex-face`) optionally followed by `,soft`; `net` turns the 10 m/s safety net on.

use tetpbd_stability::{all_cases, run_scene_observed, Config, ConstraintSet};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let case_name = args.first().map_or("slivers", String::as_str);
    let config_name = args.get(1).map_or("vertex-face", String::as_str);
    let net = args.iter().any(|a| a == "net");
    let (set_name, soft) = match config_name.split_once(',') {
        Some((s, rest)) => (s, rest == "soft"),
        None => (config_name, false),
    };
    let set = match set_name {
        "edges+volume" => ConstraintSet::EdgesVolume,
        "vertex-face+edges" => ConstraintSet::VertexFaceEdges,
        _ => ConstraintSet::VertexFace,
    };
    let config = Config { set, soft };
    let cases = all_cases(net.then_some(10.0));
    let Some(case) = cases.iter().find(|c| c.name.contains(case_name)) else {
        eprintln!("no case matches {case_name:?}");
        return;
    };
    println!(
        "{} / {} under {} (net {net})",
        case.group,
        case.name,
        config.label()
    );
    println!("frame KE/ref  max|v| m/s  inverted  vf max|C| m  clamps");
    let out = run_scene_observed(&case.scene, &config, |f| {
        let vf = f.stats.vertex_face.after.map_or(0.0, |s| s.max);
        println!(
            "{:5} {:9.3e} {:11.3e} {:9} {:12.3e} {:7}",
            f.frame,
            f.particles.kinetic_energy() / f.reference,
            f.particles.max_speed(),
            f.stats.inverted.unwrap_or(0),
            vf,
            f.stats.velocity_clamps
        );
    });
    if let Some(e) = out.build_error {
        eprintln!("rejected: {e}");
    }
    if let Some(e) = out.settings_error {
        eprintln!("settings or step rejected: {e}");
    }
}
