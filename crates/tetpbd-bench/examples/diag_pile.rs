//! Diagnosis of the pile scene (`ContactScene::pile`, tetpbd with the self-weight sweep): per
//! frame, for every body moving faster than 1 m/s or with an inverted tetrahedron, its
//! largest particle speed, inverted tetrahedra, `Σ rᵢ × vᵢ` about its centre (`L/m`,
//! unweighted, velocities from positions), lowest particle and centre.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --example diag_pile -- [SUBSTEPS [DAMPING [FROM [TO [sw|nosw]]]]]
//! ```
//!
//! Defaults `80 5 50 80 sw`: the run in which, at frames 56–58, a cube falling at 9 m/s
//! onto one resting on the ground drives it 15 cm into the ground and the push-out launches
//! both at 60–160 m/s (docs/performance.md, "The spin removal").

use nalgebra::Vector3;
use tetpbd_bench::{build_contact, ContactEngine, ContactScene, DT};

fn signed_volume(p: &[Vector3<f32>], t: &[u32; 4]) -> f32 {
    let [a, b, c, d] = t.map(|i| p[i as usize]);
    (b - a).dot(&(c - a).cross(&(d - a))) / 6.0
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let num = |i: usize, d: f32| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (substeps, damping) = (num(1, 80.0) as u32, num(2, 5.0));
    let (from, to) = (num(3, 50.0) as usize, num(4, 80.0) as usize);
    let self_weight = args.get(5).is_none_or(|s| s != "nosw");
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
