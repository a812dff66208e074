//! Frame-by-frame trace of one case of the stability matrix under one configuration: kinetic
//! energy over the case's reference, peak particle speed, inverted tetrahedra and the
//! vertex–face family's max |C| after each frame. The run is the suite's own
//! ([`tetpbd_stability::run_scene_observed`]), from the case's start.
//!
//! ```text
//! cargo run --release -p tetpbd-stability --example diag_sliver -- [CASE] [CONFIG] [net]
//! ```
//!
//! `-- --help` lists the arguments.

use clap::{Parser, ValueEnum};
use tetpbd_stability::{all_cases, run_scene_observed, Config, ConstraintSet};

/// Frame-by-frame trace of one case of the stability matrix under one configuration.
#[derive(Debug, Parser)]
#[command(name = "diag_sliver")]
struct Cli {
    /// A substring of the case's name.
    #[arg(default_value = "slivers")]
    case: String,
    /// The configuration: a column label's prefix (`vertex-face`, `vertex-face+edges`,
    /// `edges+volume`), or `material` (rubber), optionally followed by `,soft` (for the
    /// material: soft tissue).
    #[arg(default_value = "vertex-face", value_parser = parse_config)]
    config: Config,
    /// `net` turns the 10 m/s safety net on (default: off).
    #[arg(value_enum)]
    net: Option<Net>,
}

/// The safety-net switch.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum Net {
    /// The 10 m/s safety net.
    Net,
}

fn parse_config(text: &str) -> Result<Config, String> {
    let (set_name, soft) = match text.split_once(',') {
        Some((s, "soft")) => (s, true),
        Some((_, other)) => return Err(format!("`{other}` after the comma: only `soft`")),
        None => (text, false),
    };
    let set = match set_name {
        "edges+volume" => ConstraintSet::EdgesVolume,
        "vertex-face+edges" => ConstraintSet::VertexFaceEdges,
        "vertex-face" => ConstraintSet::VertexFace,
        "material" => ConstraintSet::Material,
        other => {
            return Err(format!(
                "`{other}`: one of vertex-face, vertex-face+edges, edges+volume, material"
            ))
        }
    };
    Ok(Config { set, soft })
}

fn main() {
    let cli = Cli::parse();
    let (case_name, config, net) = (cli.case.as_str(), cli.config, cli.net.is_some());
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
