//! Single projections and the XPBD update, through the solver's systems.

mod common;

use common::{unit_tet, Rng};
use hecs::World;
use nalgebra::Vector3;
use tetpbd::constraints::{apply, edge, vertex_face, volume};
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings, TetMesh};

fn perturbed(rng: &mut Rng, p: [Vector3<f32>; 4], amount: f64) -> [Vector3<f32>; 4] {
    p.map(|v| v + rng.vec(amount).cast::<f32>())
}

#[test]
fn hard_projection_removes_c_to_first_order() {
    let mut rng = Rng::new(10);
    let rest = unit_tet().vertices;
    let rest: [Vector3<f32>; 4] = [rest[0], rest[1], rest[2], rest[3]];
    // Above f32 rounding (~1e-7 m here), |C| after one hard projection is O(|C|²).
    for amount in [3e-2, 1e-2] {
        let mut worst_ratio = 0.0f32;
        for _ in 0..100 {
            let mut x = perturbed(&mut rng, rest, amount).to_vec();
            let w = [1.0, 0.5, 2.0, 1.0];
            // Volume.
            let e = volume(&x[0], &x[1], &x[2], &x[3], 1.0 / 6.0);
            let before = e.c.abs();
            let mut lambda = 0.0;
            assert!(apply(&mut x, [0, 1, 2, 3], w, &e, &mut lambda, 0.0));
            let after = volume(&x[0], &x[1], &x[2], &x[3], 1.0 / 6.0).c.abs();
            assert!(
                after <= 10.0 * before * before + 1e-6,
                "volume {before} -> {after}"
            );
            worst_ratio = worst_ratio.max(after / before.max(1e-12));
            // Vertex–face.
            let e = vertex_face(&x[0], &x[1], &x[2], &x[3], 1.0).unwrap();
            let before = e.c.abs();
            let mut lambda = 0.0;
            assert!(apply(&mut x, [0, 1, 2, 3], w, &e, &mut lambda, 0.0));
            let after = vertex_face(&x[0], &x[1], &x[2], &x[3], 1.0)
                .unwrap()
                .c
                .abs();
            assert!(
                after <= 10.0 * before * before + 1e-6,
                "vertex-face {before} -> {after}"
            );
        }
        assert!(
            worst_ratio < 0.1,
            "perturbation {amount}: |C| after / before = {worst_ratio}"
        );
    }
}

#[test]
fn lighter_particle_moves_more_and_pinned_never_moves() {
    let mut x = vec![Vector3::new(0.0f32, 0.0, 0.0), Vector3::new(2.0, 0.0, 0.0)];
    let e = edge(&x[0], &x[1], 1.0, None).unwrap();
    let mut lambda = 0.0;
    // Particle 1 is three times lighter (w three times larger).
    apply(&mut x, [0, 1], [1.0, 3.0], &e, &mut lambda, 0.0);
    let d0 = x[0].norm();
    let d1 = (x[1] - Vector3::new(2.0, 0.0, 0.0)).norm();
    assert!((d1 / d0 - 3.0).abs() < 1e-4, "moves {d0} and {d1}");
    assert!(((x[0] - x[1]).norm() - 1.0).abs() < 1e-6);

    let mut x = vec![Vector3::new(0.0f32, 0.0, 0.0), Vector3::new(2.0, 0.0, 0.0)];
    let mut lambda = 0.0;
    apply(&mut x, [0, 1], [0.0, 1.0], &e, &mut lambda, 0.0);
    assert_eq!(x[0], Vector3::zeros());
    assert!((x[1].x - 1.0).abs() < 1e-6);
}

#[test]
fn pinned_particles_never_move_in_the_solver() {
    let mut world = World::new();
    let mesh =
        tetpbd::generators::beam(2.0, 0.5, 4, 1, tetpbd::generators::CellSplit::Six).unwrap();
    let root = tetpbd::generators::beam_root(&mesh);
    let e = SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .volume(0.0)
        .vertex_face(0.0)
        .pinned(root.iter().copied())
        .build()
        .unwrap()
        .spawn(&mut world);
    let before: Vec<_> = root
        .iter()
        .map(|&i| world.get::<&Particles>(e).unwrap().positions()[i as usize])
        .collect();
    let mut solver = Solver::default();
    for _ in 0..60 {
        solver.step(&mut world).unwrap();
    }
    let p = world.get::<&Particles>(e).unwrap();
    for (k, &i) in root.iter().enumerate() {
        assert_eq!(p.positions()[i as usize], before[k]);
    }
    // And the free end sagged.
    assert!(p.positions().iter().any(|x| x.y < -0.01));
}

/// A single tetrahedron with its base pinned and the apex free on three compliant edges:
/// a vertical spring of stiffness `3 cos²θ / α` for small oscillations.
fn apex_period(substeps: u32, alpha: f32) -> (f32, f32) {
    let h = 1.0f32;
    let r = 0.5f32;
    let mut vertices: Vec<Vector3<f32>> = (0..3)
        .map(|k| {
            let a = k as f32 * std::f32::consts::TAU / 3.0;
            Vector3::new(r * a.cos(), 0.0, r * a.sin())
        })
        .collect();
    vertices.push(Vector3::new(0.0, h, 0.0));
    let mesh = TetMesh {
        vertices,
        tets: vec![[0, 1, 2, 3]],
    };
    let mut world = World::new();
    let body = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(alpha)
        .pinned([0, 1, 2])
        .build()
        .unwrap();
    let m = body.particles.masses()[3];
    let e = body.spawn(&mut world);
    let cos2 = h * h / (h * h + r * r);
    let omega = (3.0 * cos2 / (alpha * m)).sqrt();
    let analytic = std::f32::consts::TAU / omega;
    world
        .get::<&mut Particles>(e)
        .unwrap()
        .set_velocity(3, Vector3::new(0.0, 0.2, 0.0))
        .unwrap();
    let mut solver = Solver::new(SolverSettings {
        dt: 1.0 / 60.0,
        substeps,
        gravity: Vector3::zeros(),
        ..Default::default()
    })
    .unwrap();
    // Upward zero crossings of the apex's height over 4 analytic periods.
    let mut crossings = Vec::new();
    let mut prev = 0.0;
    let mut t = 0.0;
    while t < 4.0 * analytic {
        solver.step(&mut world).unwrap();
        t += solver.settings.dt;
        let y = world.get::<&Particles>(e).unwrap().positions()[3].y - h;
        if prev < 0.0 && y >= 0.0 {
            crossings.push(t - solver.settings.dt * y / (y - prev));
        }
        prev = y;
    }
    let measured = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f32;
    (measured, analytic)
}

#[test]
fn xpbd_spring_period_is_independent_of_substeps() {
    // α chosen so the period is about 0.6 s (ωh ≈ 0.17 at one substep per 1/60 s frame).
    // The amplitude is a few cm: XPBD's per-substep correction of a soft constraint,
    // w h² k C, must stay well above f32 rounding of the positions.
    let alpha = 9e-4;
    let mut periods = Vec::new();
    for substeps in [1, 4, 16] {
        let (measured, analytic) = apex_period(substeps, alpha);
        let err = (measured - analytic).abs() / analytic;
        assert!(
            err < 0.03,
            "{substeps} substeps: period {measured} s vs analytic {analytic} s ({:.2} %)",
            err * 100.0
        );
        periods.push(measured);
    }
    let spread = (periods[0] - periods[2]).abs() / periods[2];
    assert!(spread < 0.03, "periods {periods:?}");
}
