//! Diagnosis of the pile scene (`ContactScene::pile`, tetpbd with the self-weight sweep): per
//! frame, for every body moving faster than 1 m/s or with an inverted tetrahedron, its
//! largest particle speed, inverted tetrahedra, `Σ rᵢ × vᵢ` about its centre (`L/m`,
//! unweighted, velocities from positions), lowest particle and centre.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --example diag_pile -- [SUBSTEPS [DAMPING [FROM [TO [sw|nosw]]]]]
//! ```
//!
//! `-- --help` lists the arguments. Defaults `80 5 50 80 sw`: the run in which, at frames 56–58, a cube falling at 9 m/s
//! onto one resting on the ground drives it 15 cm into the ground and the push-out launches
//! both at 60–160 m/s (docs/performance.md, "The spin removal").

use clap::{Parser, ValueEnum};
use nalgebra::Vector3;
use tetpbd_bench::{build_contact, ContactEngine, ContactScene, DT};

fn signed_volume(p: &[Vector3<f32>], t: &[u32; 4]) -> f32 {
    let [a, b, c, d] = t.map(|i| p[i as usize]);
    (b - a).dot(&(c - a).cross(&(d - a))) / 6.0
}

/// Diagnosis of the pile scene: per frame, the bodies moving faster than 1 m/s or with an
/// inverted tetrahedron.
#[derive(Debug, Parser)]
#[command(name = "diag_pile")]
struct Cli {
    /// Substeps per frame.
    #[arg(default_value_t = 80)]
    substeps: u32,
    /// Deformation damping, 1/s.
    #[arg(default_value_t = 5.0)]
    damping: f32,
    /// First frame printed.
    #[arg(default_value_t = 50)]
    from: usize,
    /// Last frame run.
    #[arg(default_value_t = 80)]
    to: usize,
    /// The self-weight sweep on (`sw`) or off (`nosw`).
    #[arg(value_enum, default_value = "sw")]
    self_weight: SelfWeight,
}

/// The self-weight sweep switch.
#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
enum SelfWeight {
    /// On.
    Sw,
    /// Off.
    Nosw,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cli = Cli::parse();
    let (substeps, damping) = (cli.substeps, cli.damping);
    let (from, to) = (cli.from, cli.to);
    let self_weight = cli.self_weight == SelfWeight::Sw;
    let scene = ContactScene::pile(to)?;
    let rest: Vec<f32> = scene
        .cube
        .tets
        .iter()
        .map(|t| signed_volume(&scene.cube.vertices, t))
        .collect();
    let engine = ContactEngine::Tetpbd {
        damping,
        self_weight,
    };
    let mut sim = build_contact(engine, &scene, substeps, 1)?;
    let mut prev = sim.bodies();
    for f in 0..to {
        sim.step()?;
        let x = sim.bodies();
        if f >= from {
            let mut line = format!("f {f}:");
            for (b, (xb, pb)) in x.iter().zip(&prev).enumerate() {
                let speed = |(a, p): (&Vector3<f32>, &Vector3<f32>)| (a - p).norm() / DT;
                let v = xb.iter().zip(pb).map(speed).fold(0.0f32, f32::max);
                let inv = scene
                    .cube
                    .tets
                    .iter()
                    .zip(&rest)
                    .filter(|(t, r)| signed_volume(xb, t) * r.signum() < 0.0)
                    .count();
                let c: Vector3<f32> = xb.iter().sum::<Vector3<f32>>() / xb.len() as f32;
                let l: Vector3<f32> = xb
                    .iter()
                    .zip(pb)
                    .map(|(a, p)| (a - c).cross(&((a - p) / DT)))
                    .sum();
                let low = xb.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
                if v > 1.0 || inv > 0 {
                    line += &format!(
                        " b{b} v {v:.1} inv {inv} L/m {:.0} low {low:.2} c {:.2},{:.2},{:.2}",
                        l.norm(),
                        c.x,
                        c.y,
                        c.z
                    );
                }
            }
            println!("{line}");
        }
        prev = x;
    }
    Ok(())
}
