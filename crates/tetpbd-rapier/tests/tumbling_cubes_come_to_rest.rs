//! Hard soft cubes thrown tumbling onto a fixed rapier ground come to rest, as rigid cubes
//! do, and never gain mechanical energy, at any size, speed, spin, mesh and substep count.
//!
//! What it guards: a rigid cube loses most of its energy at each face landing (the leading
//! edge's inelastic impact). A hard soft cube at a few substeps is numerically springy: the
//! face that slaps down is squashed and its recovery came back as rigid motion that rocked
//! and rolled the cube on like a ball; 10 of these 30 throws still moved after 5 s
//! (`response::passivity`, `docs/decisions/immovable-contacts-are-passive.md`).
//!
//! At rest means: no particle faster than 5 cm/s over the last second of 6 s (a cube thrown
//! flat at 20 m/s slides for about 4 s at the ground's friction). A cube at rest on the
//! ground moves at the rounding of its velocities (well under 1 mm/s); 5 cm/s is the
//! `random_scenes` report's threshold, the speed of a fall of 0.1 mm, far below the metres
//! per second of a cube that still rolls. Energy: growth above 10⁻³ `M g L` fails, as in
//! `tumbling_cubes_never_gain_energy`.

mod robust_common;

use nalgebra::{UnitQuaternion, Vector3};
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use robust_common::{mechanical_energy, scene_substeps, Draws};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder};

/// What one throw measured: the largest growth of the mechanical energy over its start and
/// `M g L` for scale (J), the fastest particle over the last second (m/s) and when the
/// cube last moved faster than the rest threshold (s).
struct Throw {
    growth: f32,
    scale: f32,
    end_speed: f32,
    settled_at: f32,
}

/// Speed below which a cube counts as at rest, m/s (module docs).
const REST: f32 = 0.05;

/// One seeded throw: a hard cube of 0.1–1 m, 2–4 cells, thrown at 2–20 m/s down at the
/// ground with a spin of up to 20 m/s at its corners, at `substeps`.
fn throw(draws: &mut Draws, substeps: u32) -> (String, Throw) {
    let size = 0.1 * 10f32.powf(draws.between(0.0, 1.0));
    let cells = [2u32, 3, 4][(draws.between(0.0, 3.0) as usize).min(2)];
    let split = if draws.between(0.0, 1.0) < 0.5 {
        CellSplit::Six
    } else {
        CellSplit::Five
    };
    let speed = draws.between(2.0, 20.0);
    let heading = draws.between(0.0, std::f32::consts::TAU);
    let dir = Vector3::new(heading.cos(), -draws.between(0.3, 1.0), heading.sin()).normalize();
    let spin_axis = Vector3::new(
        draws.between(-1.0, 1.0),
        draws.between(-1.0, 1.0),
        draws.between(-1.0, 1.0),
    )
    .normalize();
    let rate = draws.between(0.0, 20.0) / size;
    let tilt = UnitQuaternion::from_scaled_axis(Vector3::new(
        draws.between(-3.0, 3.0),
        draws.between(-3.0, 3.0),
        draws.between(-3.0, 3.0),
    ));
    let mut s = scene_substeps(substeps);
    // Wide enough that no throw leaves it.
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(200.0, 0.5, 200.0),
    );
    let mesh = box_grid(Vector3::repeat(size), [cells; 3], split).expect("mesh");
    let e = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .rotation(tilt)
        .translation(Vector3::new(0.0, size + 0.1, 0.0))
        .velocity(dir * speed)
        .angular_velocity(spin_axis * rate)
        .build()
        .expect("body")
        .spawn(&mut s.soft);
    let (start, scale) = {
        let p = s.soft.get::<&Particles>(e).expect("body");
        (mechanical_energy(&p), p.total_mass() * 9.81 * size)
    };
    let mut r = Throw {
        growth: 0.0,
        scale,
        end_speed: 0.0,
        settled_at: 0.0,
    };
    let frames = 360;
    for f in 0..frames {
        s.step().expect("step");
        let p = s.soft.get::<&Particles>(e).expect("body");
        r.growth = r.growth.max(mechanical_energy(&p) - start);
        let speed = p.max_speed();
        if f >= frames - 60 {
            r.end_speed = r.end_speed.max(speed);
        }
        if speed > REST {
            r.settled_at = (f + 1) as f32 / 60.0;
        }
    }
    let what = format!(
        "{size:.2} m cube, {cells}³ {split:?}, {substeps} substeps, {speed:.1} m/s, \
         spin {rate:.1} rad/s"
    );
    (what, r)
}

#[test]
fn tumbling_cubes_come_to_rest_on_the_ground() {
    let mut failures = Vec::new();
    for seed in 0..6u64 {
        let mut draws = Draws(0x9e37_79b9_7f4a_7c15_u64.wrapping_mul(seed + 1));
        for substeps in [2u32, 5, 10, 20, 40] {
            let (what, r) = throw(&mut draws, substeps);
            println!(
                "seed {seed}: {what}: energy growth {:.1e} of M g L, end speed {:.3} m/s, \
                 last moving at {:.2} s",
                r.growth / r.scale,
                r.end_speed,
                r.settled_at
            );
            if r.growth > 1e-3 * r.scale || r.end_speed > REST {
                failures.push(what);
            }
        }
    }
    println!("{} of 30 throws failed", failures.len());
    assert!(
        failures.is_empty(),
        "still moving or gained energy: {failures:#?}"
    );
}
