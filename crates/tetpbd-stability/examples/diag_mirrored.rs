//! Diagnosis of a tangle: soft edges + volume released from a mirrored start. Prints kinetic
//! energy, volume and momenta per frame, then the final state (per-tetrahedron volume ratios,
//! edge stretch, surface self-crossings, best rigid fit). `RESTART=1` then zeroes the
//! velocities and runs 600 more frames (`ITER`, `DAMP` override iterations and damping).
//! `SPIN=0` turns `SafetySettings::conserve_angular_momentum` off for the whole run,
//! `SPIN_RESTART=0|1` sets it for the restart only (e.g. `SPIN=0 SPIN_RESTART=1 RESTART=1
//! DAMP=0 … nonet long`: tangle without it, then restart with it).
//!
//! ```text
//! cargo run --release -p tetpbd-stability --example diag_mirrored -- [net|nonet] [short|long] [frames]
//! ```
//!
//! `-- --help` lists the arguments.

use clap::{Parser, ValueEnum};
use nalgebra::Vector3;
use tetpbd::{unique_edges, Particles, SoftBodyBuilder, Solver, Surface, Tetrahedra};
use tetpbd_stability::{all_cases, Config, ConstraintSet, Start};

fn seg_tri(
    p: Vector3<f32>,
    q: Vector3<f32>,
    a: Vector3<f32>,
    b: Vector3<f32>,
    c: Vector3<f32>,
) -> bool {
    let n = (b - a).cross(&(c - a));
    let dp = n.dot(&(p - a));
    let dq = n.dot(&(q - a));
    if dp * dq >= 0.0 {
        return false;
    }
    let t = dp / (dp - dq);
    let x = p + (q - p) * t;
    let s1 = (b - a).cross(&(x - a)).dot(&n);
    let s2 = (c - b).cross(&(x - b)).dot(&n);
    let s3 = (a - c).cross(&(x - c)).dot(&n);
    (s1 > 0.0 && s2 > 0.0 && s3 > 0.0) || (s1 < 0.0 && s2 < 0.0 && s3 < 0.0)
}

/// Diagnosis of a tangle: soft edges + volume released from a mirrored start. The
/// environment variables RESTART, ITER, DAMP, SPIN and SPIN_RESTART are described in the
/// example's source.
#[derive(Debug, Parser)]
#[command(name = "diag_mirrored")]
struct Cli {
    /// The 10 m/s safety net on (`net`) or off (`nonet`).
    #[arg(value_enum, default_value = "nonet")]
    net: Net,
    /// The case: `short` (mirrored) or `long` (mirrored, 1 min at 20 substeps).
    #[arg(value_enum, default_value = "short")]
    length: Length,
    /// Frames to run; 0 runs the case's own count.
    #[arg(default_value_t = 0)]
    frames: usize,
}

/// The safety-net switch.
#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
enum Net {
    /// On, at 10 m/s.
    Net,
    /// Off.
    Nonet,
}

/// Which mirrored case.
#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
enum Length {
    /// `mirrored`.
    Short,
    /// `mirrored, 1 min at 20 substeps`.
    Long,
}

fn main() {
    let cli = Cli::parse();
    let net = cli.net == Net::Net;
    let long = cli.length == Length::Long;
    let frames = cli.frames;
    let cases = all_cases(if net { Some(10.0) } else { None });
    let name = if long {
        "mirrored, 1 min at 20 substeps"
    } else {
        "mirrored"
    };
    let case = cases.iter().find(|c| c.name == name).unwrap();
    let scene = &case.scene;
    let cfg = Config {
        set: ConstraintSet::EdgesVolume,
        soft: true,
    };
    let b = SoftBodyBuilder::new(scene.mesh.clone()).density(1000.0);
    let body = cfg.apply(b, 1.0).build().unwrap();
    let mut settings = scene.settings.clone();
    settings.diagnostics.measure_error = true;
    settings.safety.conserve_angular_momentum = std::env::var("SPIN").map_or(true, |v| v != "0");
    let mut solver = Solver::new(settings).unwrap();
    let (lo, hi) = body.particles.aabb();
    let centre = (lo + hi) / 2.0;
    let mut world = tetpbd::hecs::World::new();
    let e = body.spawn(&mut world);
    {
        let mut p = world.get::<&mut Particles>(e).unwrap();
        Start::Mirrored.apply(&mut p, centre).unwrap();
    }
    let n = if frames > 0 { frames } else { scene.frames };
    let mut clamps = 0;
    for f in 1..=n {
        let st = solver.step(&mut world).unwrap();
        clamps += st.velocity_clamps;
        let p = world.get::<&Particles>(e).unwrap();
        let t = world.get::<&Tetrahedra>(e).unwrap();
        if f <= 10 || f % (n / 20).max(1) == 0 {
            println!(
                "f {f:5} KE {:10.3} vol {:.4} inv {} maxspeed {:.3} clamps {} L {:.1} P {:.2}",
                p.kinetic_energy(),
                t.volume_ratio(p.positions()),
                t.count_inverted(p.positions()),
                p.max_speed(),
                clamps,
                p.angular_momentum().norm(),
                p.linear_momentum().norm()
            );
        }
    }
    if std::env::var("RESTART").is_ok() {
        {
            let mut p = world.get::<&mut Particles>(e).unwrap();
            for v in p.velocities_mut() {
                *v = Vector3::zeros();
            }
        }
        solver.settings.safety.max_correction_speed = None;
        if let Ok(v) = std::env::var("SPIN_RESTART") {
            solver.settings.safety.conserve_angular_momentum = v != "0";
        }
        if let Ok(n) = std::env::var("ITER") {
            solver.settings.iterations = n.parse().unwrap();
        }
        if let Ok(d) = std::env::var("DAMP") {
            solver.settings.damping = d.parse().unwrap();
        }
        for f in 1..=600 {
            solver.step(&mut world).unwrap();
            let p = world.get::<&Particles>(e).unwrap();
            let t = world.get::<&Tetrahedra>(e).unwrap();
            if f <= 3 || f % 60 == 0 {
                println!(
                    "restart f {f:4} KE {:9.3} vol {:.4} L {:7.2} P {:.3}",
                    p.kinetic_energy(),
                    t.volume_ratio(p.positions()),
                    p.angular_momentum().norm(),
                    p.linear_momentum().norm()
                );
            }
        }
    }
    let p = world.get::<&Particles>(e).unwrap();
    let t = world.get::<&Tetrahedra>(e).unwrap();
    let s = world.get::<&Surface>(e).unwrap();
    let x = p.positions();
    let r = p.rest_positions();
    let mut ratios: Vec<(f32, usize)> = (0..t.len())
        .map(|i| (t.volume_at(i, x) / t.rest_volumes()[i], i))
        .collect();
    ratios.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    println!(
        "tets {} ratio min {:.3} p10 {:.3} median {:.3} p90 {:.3} max {:.3}",
        ratios.len(),
        ratios[0].0,
        ratios[ratios.len() / 10].0,
        ratios[ratios.len() / 2].0,
        ratios[ratios.len() * 9 / 10].0,
        ratios[ratios.len() - 1].0
    );
    let bins = [0.0, 0.25, 0.5, 0.75, 0.9, 0.99, 1.01, 1.1, 1.5, 100.0];
    for w in bins.windows(2) {
        let c = ratios.iter().filter(|r| r.0 >= w[0] && r.0 < w[1]).count();
        println!("  ratio [{:.2},{:.2}): {c}", w[0], w[1]);
    }
    let cm: Vector3<f32> = p.center_of_mass();
    for &(rt, i) in ratios.iter().take(8) {
        let idx = t.indices()[i];
        let c: Vector3<f32> = idx.iter().map(|&k| r[k as usize]).sum::<Vector3<f32>>() / 4.0;
        let cn: Vector3<f32> = idx.iter().map(|&k| x[k as usize]).sum::<Vector3<f32>>() / 4.0 - cm;
        println!(
            "  tet {i} ratio {rt:.3} rest centre {:.2} {:.2} {:.2} now rel {:.2} {:.2} {:.2}",
            c.x, c.y, c.z, cn.x, cn.y, cn.z
        );
    }
    let edges = unique_edges(t.indices());
    let mut st: Vec<f32> = edges
        .iter()
        .map(|&[a, b]| {
            (x[a as usize] - x[b as usize]).norm() / (r[a as usize] - r[b as usize]).norm()
        })
        .collect();
    st.sort_by(|a, b| a.partial_cmp(b).unwrap());
    println!(
        "edges {} stretch min {:.3} p10 {:.3} med {:.3} p90 {:.3} max {:.3}",
        st.len(),
        st[0],
        st[st.len() / 10],
        st[st.len() / 2],
        st[st.len() * 9 / 10],
        st[st.len() - 1]
    );
    // surface self-intersection: surface edges vs non-adjacent surface triangles
    let tris = s.triangles();
    let mut sedges = std::collections::BTreeSet::new();
    for tr in tris {
        for k in 0..3 {
            let (a, b) = (tr[k], tr[(k + 1) % 3]);
            sedges.insert((a.min(b), a.max(b)));
        }
    }
    let mut hits = 0;
    for &(a, b) in &sedges {
        for tr in tris {
            if tr.contains(&a) || tr.contains(&b) {
                continue;
            }
            if seg_tri(
                x[a as usize],
                x[b as usize],
                x[tr[0] as usize],
                x[tr[1] as usize],
                x[tr[2] as usize],
            ) {
                hits += 1;
            }
        }
    }
    println!(
        "surface edge-triangle crossings {hits} (surface tris {})",
        tris.len()
    );
    // all-edges vs all tet faces crossing (interior overlap)
    // rigid fit check: mirrored? compare against rest and mirrored rest via aligned distance
    let rc: Vector3<f32> = r.iter().sum::<Vector3<f32>>() / r.len() as f32;
    let mut a = nalgebra::Matrix3::<f32>::zeros();
    for i in 0..x.len() {
        a += (x[i] - cm) * (r[i] - rc).transpose();
    }
    println!(
        "det of cross-covariance (sign: + rotation-like, - reflection-like) {:.4}",
        a.determinant()
    );
    let svd = a.svd(true, true);
    let rot = svd.u.unwrap() * svd.v_t.unwrap();
    let mut err = 0.0f32;
    for i in 0..x.len() {
        err = err.max(((x[i] - cm) - rot * (r[i] - rc)).norm());
    }
    println!(
        "best orthogonal fit det {:.2} max residual {:.3} m",
        rot.determinant(),
        err
    );
    let mut bb = (Vector3::repeat(f32::MAX), Vector3::repeat(f32::MIN));
    for v in x {
        bb.0 = bb.0.inf(v);
        bb.1 = bb.1.sup(v);
    }
    println!("aabb size {:?}", (bb.1 - bb.0).as_slice());
}
