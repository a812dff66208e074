//! A heavy rigid box that rests on, or starts overlapping, a lighter dynamic box, with a heavy
//! soft body on top, stays put or leaves the overlap gently: neither box is thrown, whatever
//! the overlap, the mass ratio or the substep count.
//!
//! What it guards (`contacts::support` module docs): the box the soft body touches takes part
//! in the substeps with its rapier contacts kept as constraints against the box below, and
//! the reaction of those constraints goes to the box below. The constraints now follow
//! rapier's path out of an overlap instead of pushing the box out ahead of it, and the
//! reaction reaches the box below as a force for rapier's next step, not as a velocity.

mod robust_common;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use robust_common::{ground, scene_substeps, soft_box};
use tetpbd_rapier::CouplingSettings;

/// A `support` kg box (1.2 × 0.6 × 1.2 m) on the ground, a box of half extent `half` m and
/// `mass` kg placed `overlap` m into its top face, and an 0.8 m soft cube of 300 kg/m³ on
/// that. Runs 1 s; returns the largest speed either box reaches (m/s).
fn run(substeps: u32, overlap: f32, half: f32, mass: f32, support: f32) -> f32 {
    let mut s = scene_substeps(substeps);
    ground(&mut s);
    let (low, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.3, 0.0)),
        ColliderBuilder::cuboid(0.6, 0.3, 0.6).mass(support),
    );
    let y = 0.6 + half - overlap;
    let (high, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, y, 0.0)),
        ColliderBuilder::cuboid(half, half, half).mass(mass),
    );
    soft_box(
        &mut s,
        Vector3::repeat(0.8),
        [3, 3, 3],
        Vector3::new(0.0, y + half + 0.401, 0.0),
        Vector3::zeros(),
        300.0,
    );
    let mut fastest = 0.0f32;
    for _ in 0..60 {
        s.step().expect("step");
        let v = [low, high].map(|b| s.physics.bodies[b].linvel().length());
        fastest = fastest.max(v[0]).max(v[1]);
    }
    fastest
}

fn sweep(cases: &[(u32, f32, f32, f32, f32)]) {
    let limit = CouplingSettings::default().max_depenetration_speed;
    let mut thrown = Vec::new();
    for &(substeps, overlap, half, mass, support) in cases {
        let v = run(substeps, overlap, half, mass, support);
        let what = format!(
            "{substeps} substeps, overlap {overlap} m, box {half} m {mass} kg on {support} kg: \
             {v:.2} m/s (at most {limit:.2})"
        );
        println!("{what}");
        if v.is_nan() || v > limit {
            thrown.push(what);
        }
    }
    assert!(thrown.is_empty(), "thrown: {thrown:#?}");
}

/// A 50 kg box 4 cm into a 10 kg one at 10 and 40 substeps (the overlap was pushed out
/// ahead of rapier's own path and its reaction, summed over the substeps, threw the 10 kg
/// box at 24 and 64 m/s).
#[test]
fn heavy_box_overlapping_a_light_support_is_not_thrown() {
    sweep(&[(10, 0.04, 0.5, 50.0, 10.0), (40, 0.04, 0.5, 50.0, 10.0)]);
}

/// A 50 kg box resting on a 1 kg one at 20 substeps (the 1 kg box was thrown at 400 m/s;
/// with the reaction handed as a velocity it still got up to 9.6 m/s into the ground).
#[test]
fn heavy_box_on_a_light_support_is_not_thrown() {
    sweep(&[(20, 0.0, 0.5, 50.0, 1.0)]);
}

/// Overlaps of 0 to 4 cm, boxes of 0.1 to 500 kg on supports of 1 to 100 kg (mass ratios
/// 1:100 to 500:1), at 5 to 80 substeps.
#[test]
#[ignore = "96 runs, about 15 s in release"]
fn boxes_overlapping_light_supports_are_never_thrown() {
    let mut cases = Vec::new();
    for substeps in [5, 20, 80] {
        for overlap in [0.0, 0.005, 0.02, 0.04] {
            for (half, mass) in [(0.25, 1.0), (0.5, 50.0)] {
                for support in [1.0, 10.0, 100.0] {
                    cases.push((substeps, overlap, half, mass * support / 10.0, support));
                }
            }
            cases.push((substeps, overlap, 0.5, 500.0, 1.0));
            cases.push((substeps, overlap, 0.25, 1.0, 100.0));
        }
    }
    sweep(&cases);
}
