//! Frame-by-frame trace of one case of the stability matrix under one configuration: kinetic
//! energy over the case's reference, peak particle speed, inverted tetrahedra and the
//! vertex–face family's max |C| after each frame.
//!
//! ```text
//! cargo run --release -p tetpbd-stability --example diag_sliver -- [CASE] [CONFIG] [net]
//! ```
//!
//! `CASE` is a substring of the case name (default `slivers`), `CONFIG` one of the column
//! labels' prefixes (`vertex-face`, `vertex-face+edges`, `edges+volume`; default
//! `vertex-face`) optionally followed by `,soft`; `net` turns the 10 m/s safety net on.

use tetpbd::{Particles, SoftBodyBuilder, Solver};
use tetpbd_stability::{all_cases, Config, ConstraintSet, Start};

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
    let scene = &case.scene;
    if scene.start != Start::Rest {
        eprintln!("only cases started at rest are traced");
        return;
    }
    let builder = SoftBodyBuilder::new(scene.mesh.clone())
        .density(1000.0)
        .pinned(scene.pinned.iter().copied())
        .volume_epsilon(scene.epsilon);
    let body = match config.apply(builder, scene.compliance_scale).build() {
        Ok(b) => b,
        Err(e) => {
            eprintln!("rejected: {e}");
            return;
        }
    };
    let (lo, hi) = body.particles.aabb();
    let reference = body.particles.total_mass() * 9.81 * (hi - lo).norm();
    let mut world = hecs::World::new();
    let e = body.spawn(&mut world);
    let Ok(mut solver) = Solver::new(scene.settings.clone()) else {
        eprintln!("settings rejected");
        return;
    };
    solver.settings.measure_error = true;
    println!(
        "{} / {} under {} (net {net})",
        case.group,
        case.name,
        config.label()
    );
    println!("frame KE/ref  max|v| m/s  inverted  vf max|C| m  clamps");
    for frame in 1..=scene.frames {
        let Ok(stats) = solver.step(&mut world) else {
            eprintln!("step failed");
            return;
        };
        let Ok(p) = world.get::<&Particles>(e) else {
            return;
        };
        let vf = stats.vertex_face.after.map_or(0.0, |s| s.max);
        println!(
            "{frame:5} {:9.3e} {:11.3e} {:9} {:12.3e} {:7}",
            p.kinetic_energy() / reference,
            p.max_speed(),
            stats.inverted.unwrap_or(0),
            vf,
            stats.velocity_clamps
        );
    }
}
