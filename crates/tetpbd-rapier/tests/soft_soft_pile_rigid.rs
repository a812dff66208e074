//! A pile of nine soft cubes (4×4×4 cells) dropped in the layout of rapier's
//! `fem_bench` "jelly pile" onto *rigid* ground, through the rigid coupling with
//! its soft–soft contacts (`CouplingSettings::soft_contacts`, on by default). 60 Hz, 20
//! substeps, deformation damping 5/s on the cubes (applied by the solver).

mod soft_soft_common;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use soft_soft_common::penetration;
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Activation, Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, DeformationDamping};

#[test]
fn nine_cubes_settle_on_rigid_ground() {
    let damping: f32 = std::env::var("PILE_DAMP")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1.0);
    let solver = SolverSettings {
        substeps: 20,
        damping,
        ..SolverSettings::default()
    };
    let mut s = CoupledWorld::new(solver, CouplingSettings::default()).expect("settings");
    // fem_bench: ground cuboid 24 × 0.2 × 24 m with its top at y = 0.
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.1, 0.0)),
        ColliderBuilder::cuboid(12.0, 0.1, 12.0),
    );
    let mesh = generators::box_grid(Vector3::repeat(1.0), [4, 4, 4], CellSplit::Six).expect("mesh");
    let mut cubes = Vec::new();
    for i in 0..9 {
        let at = Vector3::new(
            (i % 3) as f32 - 1.0,
            0.55 + i as f32 * 1.05,
            (i / 3) as f32 - 1.0,
        );
        let body = SoftBodyBuilder::new(mesh.clone())
            .density(1000.0)
            .edges(0.0)
            .volume(0.0)
            .translation(at)
            .build()
            .expect("cube");
        let e = body.spawn(&mut s.soft);
        // Watched awake: the rest measured is the solver's, not sleeping's.
        *s.soft.get::<&mut Activation>(e).expect("body") = Activation::never_sleeps();
        // Material damping, as rapier's jelly has (elastic_damping_ratio 0.5).
        let damping = DeformationDamping::new(5.0).expect("rate");
        s.soft.insert_one(e, damping).expect("entity");
        cubes.push(e);
    }
    let max_speed = |s: &CoupledWorld| {
        let mut v = 0.0f32;
        for p in s.soft.query::<&Particles>().iter() {
            v = v.max(p.max_speed());
        }
        v
    };
    let max_centre_speed = |s: &CoupledWorld| {
        let mut v = 0.0f32;
        for p in s.soft.query::<&Particles>().iter() {
            v = v.max((p.linear_momentum() / p.total_mass()).norm());
        }
        v
    };
    let mut tail = 0.0f32;
    let mut peak = 0.0f32;
    let mut worst_pen = 0.0f32;
    for f in 0..300 {
        let stats = s.step().expect("step");
        assert_eq!(stats.soft.non_finite_resets, 0);
        let v = max_speed(&s);
        if f >= 270 {
            tail = tail.max(v);
        }
        peak = peak.max(max_centre_speed(&s));
        if f % 30 == 29 {
            for &a in &cubes {
                for &b in &cubes {
                    if a != b {
                        worst_pen = worst_pen.max(penetration(&s.soft, a, b).1);
                    }
                }
            }
        }
        if f % 60 == 59 {
            let c = stats.soft_contacts;
            println!(
                "t {} s: max|v| {v:.4} m/s, soft contacts {}, rigid contacts {}, ground penetration {:.5} m, soft penetration {:.5} m",
                (f + 1) / 60,
                c.contacts,
                stats.contacts,
                stats.max_penetration,
                c.max_penetration
            );
        }
    }
    let mut pen = 0.0f32;
    for &a in &cubes {
        for &b in &cubes {
            if a != b {
                pen = pen.max(penetration(&s.soft, a, b).1);
            }
        }
    }
    println!(
        "after 5 s: max|v| over the last 0.5 s {tail:.4} m/s, peak centre speed {peak:.3} m/s, \
         interpenetration {pen:.5} m (worst sampled {worst_pen:.5} m)"
    );
    assert!(tail < 0.05, "still moving at {tail} m/s");
    // The highest cube hits at √(2 g 9 m) ≈ 13.3 m/s; no cube may move faster than that.
    assert!(peak < 13.5, "a cube was flung at {peak} m/s");
    assert!(pen < 0.002, "interpenetration {pen} m");
    for &e in &cubes {
        let p = s.soft.get::<&Particles>(e).expect("cube");
        let c = p.center_of_mass();
        assert!(c.y > 0.4 && c.y < 1.7, "cube off the pile: centre {c:?}");
    }
}
