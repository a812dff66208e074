//! A hard soft cube released at rest, tilted, with its lowest corner or edge on a fixed
//! rapier ground topples onto a face and stays on the ground: it never hops, and its
//! mechanical energy never grows, at any size, tilt, grid, split and substep count.
//!
//! What it guards: the cube sets its corner down at rest, so its contact with the ground
//! is not an impact; when it lands on its face the face is squashed (a hard body at a few
//! substeps is numerically springy) and, recovering its shape while its other corners
//! still touch, it would throw itself back up — in a pile, a cube rocking on its edge hopped
//! and slid away at 1–3 m/s this way. The coupling caps the body's separating velocity at
//! every contact that is not an impact (`response::restitution` module docs).

mod robust_common;

use nalgebra::{UnitQuaternion, Vector3};
use robust_common::{cube_sweep_case, ground, mechanical_energy, scene_substeps, Draws};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder};

/// What one release measured: the highest the lowest particle rose above the ground (m)
/// after the first frame, and the largest growth of the mechanical energy over its start
/// (J), with `M g L` (J) for scale.
struct Release {
    lift: f32,
    growth: f32,
    scale: f32,
}

fn release(
    size: f32,
    cells: u32,
    split: CellSplit,
    substeps: u32,
    tilt: UnitQuaternion<f32>,
) -> Release {
    let mut s = scene_substeps(substeps);
    ground(&mut s);
    // The lowest corner of the tilted cube 1 mm above the ground.
    let lowest = (0..8)
        .map(|k| {
            let corner = Vector3::new(
                if k & 1 == 0 { -0.5 } else { 0.5 },
                if k & 2 == 0 { -0.5 } else { 0.5 },
                if k & 4 == 0 { -0.5 } else { 0.5 },
            ) * size;
            (tilt * corner).y
        })
        .fold(f32::INFINITY, f32::min);
    let mesh = box_grid(Vector3::repeat(size), [cells; 3], split).expect("mesh");
    let e = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .rotation(tilt)
        .translation(Vector3::new(0.0, 0.001 - lowest, 0.0))
        .build()
        .expect("body")
        .spawn(&mut s.soft);
    let (start, mass) = {
        let p = s.soft.get::<&Particles>(e).expect("body");
        (mechanical_energy(&p), p.total_mass())
    };
    let mut r = Release {
        lift: 0.0,
        growth: 0.0,
        scale: mass * 9.81 * size,
    };
    for frame in 0..150 {
        s.step().expect("step");
        let p = s.soft.get::<&Particles>(e).expect("body");
        assert!(p
            .positions()
            .iter()
            .all(|x| x.iter().all(|c| c.is_finite())));
        r.growth = r.growth.max(mechanical_energy(&p) - start);
        if frame > 0 {
            let bottom = p
                .positions()
                .iter()
                .map(|x| x.y)
                .fold(f32::INFINITY, f32::min);
            r.lift = r.lift.max(bottom);
        }
    }
    r
}

#[test]
fn tilted_cubes_topple_onto_a_face_without_hopping() {
    let mut draws = Draws(0x5eed_7117);
    let mut failures = Vec::new();
    for case in 0..12 {
        let (size, substeps, cells, split) = cube_sweep_case(case);
        let heading = draws.between(0.0, std::f32::consts::TAU);
        let axis = Vector3::new(heading.cos(), 0.0, heading.sin());
        let roll = draws.between(10f32.to_radians(), 40f32.to_radians());
        let pitch = draws.between(0.0, 30f32.to_radians());
        let tilt = UnitQuaternion::from_scaled_axis(axis * roll)
            * UnitQuaternion::from_scaled_axis(Vector3::z() * pitch);
        let r = release(size, cells, split, substeps, tilt);
        let what = format!(
            "{size} m cube, {cells}³ cells {split:?}, {substeps} substeps, tilt {:.0}°/{:.0}°",
            roll.to_degrees(),
            pitch.to_degrees()
        );
        println!(
            "{what}: lift {:.4} m, energy growth {:.2e} of M g L",
            r.lift,
            r.growth / r.scale
        );
        // Toppling, the cube keeps an edge on the ground; 2 % of its size above the contact
        // margin is a hop (without the cap on contacts that are not impacts: up to 5.5 %).
        // Left: a rebound of up to 1.4 % of its size from the cube's rotation when its face
        // slaps down (the cap is on the centre of mass's velocity, which does not see it).
        if r.lift > 0.02 * size + 0.002 || r.growth > 1e-3 * r.scale {
            failures.push(what);
        }
    }
    assert!(
        failures.is_empty(),
        "hopped or gained energy: {failures:#?}"
    );
}
