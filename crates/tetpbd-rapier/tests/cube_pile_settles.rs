//! The pile of nine soft cubes (rapier's `fem_bench` "jelly pile" on
//! rigid ground, as `tetpbd-bench` builds it) comes to rest at 10 substeps, undamped and with
//! `DeformationDamping` 5/s: every particle slower than 0.02 m/s over the last 30 frames of
//! 8 s. The last cube lands at about 2.5 s; a cube that lands perched on a neighbour's edge
//! rocks on it with a period of about 0.3 s, its speed halving every half second (0.8 m/s at
//! 3 s, 0.02 m/s at 6 s): a weakly damped mode, but one that dies out. A rocking that does not
//! decay fails here.
//!
//! What it guards: the cubes are placed face to face, so a falling cube's bottom edge passes
//! a landed neighbour's top edge flush with it. A landed cube bulges by a few millimetres, so the
//! neighbour's top-edge particles lie just inside the falling cube's bottom face (and its
//! bottom-edge particles just inside the neighbour's top face). If the vertex–triangle
//! contact of that face caught them, it would stop the falling cube on the edge and kick it
//! sideways; displaced cubes would land partly on their neighbours' edges, crush them into
//! ramps and be thrown off. A particle behind a face it has not been touching is left alone
//! when it is less deep behind a side face of the same body across a crease, whose prism it
//! is in (it is grazing that side face; `SoftContacts` docs).

mod soft_soft_common;

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use soft_soft_common::penetration;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Activation, Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, DeformationDamping};

const DT: f32 = 1.0 / 60.0;

/// The bench's pile scene: rigid ground (top face at y = 0), 1 m cubes of 4³ cells at `at`.
fn scene(substeps: u32, damping: f32, at: &[Vector3<f32>]) -> (CoupledWorld, Vec<Entity>) {
    let solver = SolverSettings {
        dt: DT,
        substeps,
        iterations: 1,
        ..SolverSettings::default()
    };
    let mut w = CoupledWorld::new(solver, CouplingSettings::default()).expect("settings");
    w.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(12.0, 0.5, 12.0),
    );
    let cube = box_grid(Vector3::repeat(1.0), [4, 4, 4], CellSplit::Six).expect("mesh");
    let bodies = at
        .iter()
        .map(|p| {
            let e = SoftBodyBuilder::new(cube.clone())
                .density(1000.0)
                .edges(0.0)
                .volume(0.0)
                .translation(*p)
                .build()
                .expect("body")
                .spawn(&mut w.soft);
            // Watched awake: the rest measured is the solver's, not sleeping's.
            *w.soft.get::<&mut Activation>(e).expect("body") = Activation::never_sleeps();
            if damping > 0.0 {
                let d = DeformationDamping::new(damping).expect("rate");
                w.soft.insert_one(e, d).expect("entity");
            }
            e
        })
        .collect();
    (w, bodies)
}

/// `fem_bench` layout: a 3 × 3 grid of 1 m pitch, cube `i` centred at 0.55 + 1.05 i m,
/// each moved by up to `jitter` m in x and z (a fixed pseudo-random sequence of `seed`).
fn pile_layout(seed: u64, jitter: f32) -> Vec<Vector3<f32>> {
    let mut h = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    let mut r = move || {
        h ^= h << 13;
        h ^= h >> 7;
        h ^= h << 17;
        (h % 2001) as f32 / 1000.0 - 1.0
    };
    (0..9)
        .map(|i| {
            let x = (i % 3) as f32 - 1.0 + jitter * r();
            let z = (i / 3) as f32 - 1.0 + jitter * r();
            Vector3::new(x, 0.55 + i as f32 * 1.05, z)
        })
        .collect()
}

fn com_velocity(w: &CoupledWorld, e: Entity) -> Vector3<f32> {
    let p = w.soft.get::<&Particles>(e).expect("body");
    p.linear_momentum() / p.total_mass()
}

/// What a pile run gave: largest particle speed over the last 30 frames (m/s, from positions
/// as the bench measures it), deepest particle below the ground from 3 s on (m), largest
/// interpenetration of two cubes at the end (m).
struct Rest {
    settled: f32,
    ground: f32,
    inter: f32,
}

fn run_pile(substeps: u32, damping: f32, at: &[Vector3<f32>]) -> Rest {
    let (mut w, bodies) = scene(substeps, damping, at);
    let positions = |w: &CoupledWorld| -> Vec<Vec<Vector3<f32>>> {
        let get = |&e: &Entity| w.soft.get::<&Particles>(e).map(|p| p.positions().to_vec());
        bodies.iter().map(|e| get(e).expect("body")).collect()
    };
    let mut prev = positions(&w);
    let (frames, rest_from) = (480, 180);
    let mut r = Rest {
        settled: 0.0,
        ground: 0.0,
        inter: 0.0,
    };
    for f in 0..frames {
        w.step().expect("step");
        let x = positions(&w);
        let all = x.iter().flatten();
        assert!(all.clone().all(|p| p.iter().all(|c| c.is_finite())));
        if f >= rest_from {
            r.ground = all.fold(r.ground, |g, p| g.max(-p.y));
        }
        if f + 30 >= frames {
            for (xb, pb) in x.iter().zip(&prev) {
                for (p, q) in xb.iter().zip(pb) {
                    r.settled = r.settled.max((p - q).norm() / DT);
                }
            }
        }
        prev = x;
    }
    for &a in &bodies {
        for &b in &bodies {
            if a != b {
                r.inter = r.inter.max(penetration(&w.soft, a, b).1);
            }
        }
    }
    r
}

/// A cube released 10 cm above the top of a landed neighbour, face to face with it, falls
/// past it until it reaches the ground, neither stopped on the neighbour's top edge nor pushed
/// off sideways.
#[test]
fn cube_falls_past_a_flush_neighbour_without_snagging() {
    let at = [Vector3::new(0.0, 0.502, 0.0), Vector3::new(1.0, 1.6, 0.0)];
    let (mut w, bodies) = scene(10, 0.0, &at);
    let (mut sideways, mut worst_lag) = (0.0f32, 0.0f32);
    // The falling cube's bottom (1.1 m up) reaches the ground after √(2·1.1/g) = 0.47 s,
    // 28 frames; stop a few frames before.
    for f in 1..=24 {
        w.step().expect("step");
        let v = com_velocity(&w, bodies[1]);
        sideways = sideways.max((v.x * v.x + v.z * v.z).sqrt());
        // Free fall from rest: v_y = −g t (the substep integrator lags by well under 1 %).
        let free = -9.81 * f as f32 * DT;
        worst_lag = worst_lag.max((v.y - free).abs());
    }
    println!("sideways {sideways:.3} m/s, largest lag behind free fall {worst_lag:.3} m/s");
    assert!(sideways < 0.1, "pushed sideways at {sideways} m/s");
    // Friction against the neighbour's side face (pressed by its landing bulge) drags it a
    // little; a cube stopped on the edge would fall far behind.
    assert!(worst_lag < 0.5, "held up: {worst_lag} m/s behind free fall");
}

fn assert_rest(what: &str, r: &Rest) {
    println!(
        "{what}: settled max|v| {:.4} m/s, ground penetration at rest {:.4} m, interpenetration {:.4} m",
        r.settled, r.ground, r.inter
    );
    assert!(
        r.settled < 0.02,
        "{what}: still moving at {} m/s",
        r.settled
    );
    assert!(r.ground <= 0.0, "{what}: {} m below the ground", r.ground);
    assert!(r.inter < 0.01, "{what}: interpenetration {} m", r.inter);
}

/// The bench's pile at 10 substeps comes to rest, undamped and damped.
#[test]
fn pile_comes_to_rest_at_10_substeps() {
    for damping in [0.0, 5.0] {
        let r = run_pile(10, damping, &pile_layout(0, 0.0));
        assert_rest(&format!("10 substeps, damping {damping}/s"), &r);
    }
}

/// Which pile comes to rest is chaotic (a millimetre moves where the cubes end up), so one
/// run proves little: eight layouts with every cube moved by up to 2 mm, undamped and damped,
/// at 10 and 5 substeps (the thresholds are in the test). A pile that does not settle is
/// mostly a cube perched off-centre on another, still rocking on its edge (the weakly damped
/// mode above; how slowly it dies out is open work). At 5 substeps a particle of a loaded cube
/// also ends up to 2.4 mm below the rigid ground (the coupling's ground contact, not the
/// soft–soft contacts), so only the speed and the interpenetration are asserted there.
#[test]
#[ignore = "32 pile runs, about 50 s in release"]
fn jittered_piles_come_to_rest() {
    let mut counts = Vec::new();
    // By 8 s all 16 piles settle at 10 and at 5 substeps; by 5 s, 16 and 14 (at 5 substeps
    // 8 of 16 before contacts that are no impact were capped:
    // `docs/decisions/contacts-that-are-no-impact-are-capped.md`). The margin is for chaos.
    for (substeps, needed) in [(10, 14), (5, 13)] {
        let mut rested = 0;
        for seed in 1..=8 {
            for damping in [0.0, 5.0] {
                let r = run_pile(substeps, damping, &pile_layout(seed, 0.002));
                let ok = r.settled < 0.02 && r.inter < 0.01 && (substeps == 5 || r.ground <= 0.0);
                println!(
                    "{substeps} substeps, seed {seed}, damping {damping}: {:.4} m/s, {:.4} m, {:.4} m{}",
                    r.settled,
                    r.ground,
                    r.inter,
                    if ok { "" } else { "  not at rest" }
                );
                rested += usize::from(ok);
            }
        }
        counts.push((substeps, rested, needed));
    }
    for (substeps, rested, needed) in counts {
        assert!(
            rested >= needed,
            "{substeps} substeps: {rested} of 16 came to rest (at least {needed} expected)"
        );
    }
}
