//! Rest at default settings (soft–soft contacts on, sleeping off so the solver's own rest is
//! measured): stacks of soft cubes on rigid ground, and a soft cube held by static friction on
//! an incline. What is met is asserted; the stacks that do not come to rest are asserted as the
//! known limit they are (`docs/decisions/resting-contacts.md`): a fix makes those tests fail,
//! and they are then to be turned into rest assertions.

mod coupling_common;

use coupling_common::{particles, scene};
use hecs::Entity;
use nalgebra::{Rotation3, Vector3};
use rapier3d::math::{Pose, Rotation, Vector};
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Activation, Particles, SoftBodyBuilder};
use tetpbd_rapier::{CoupledWorld, SoftColliderBuilder};

/// Largest particle speed counted as rest, m/s.
const REST: f32 = 1e-3;

/// `n` cubes of side `size` (m, 4³ cells, 1000 kg/m³, hard edges and volumes), 2 cm apart,
/// above fixed ground at `substeps` substeps; bodies never sleep.
fn stack(n: usize, size: f32, substeps: u32) -> (CoupledWorld, Vec<Entity>) {
    let mut w = scene(substeps);
    w.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(20.0, 0.5, 20.0),
    );
    let bodies = (0..n)
        .map(|i| {
            let mesh = box_grid(Vector3::repeat(size), [4, 4, 4], CellSplit::Six).expect("mesh");
            let y = 0.01 + 0.5 * size + i as f32 * (size + 0.02);
            let e = SoftBodyBuilder::new(mesh)
                .density(1000.0)
                .edges(0.0)
                .volume(0.0)
                .translation(Vector3::new(0.0, y, 0.0))
                .build()
                .expect("body")
                .spawn(&mut w.soft);
            w.soft
                .insert_one(e, Activation::never_sleeps())
                .expect("entity");
            e
        })
        .collect();
    (w, bodies)
}

/// What a stack did over `seconds`: the time from which every particle stayed under
/// [`REST`] (`None`: it never did), and how far any particle of the top cube moved over the
/// last `watch` seconds (m).
struct Rest {
    at_rest_from: Option<f32>,
    top_moved: f32,
}

fn run_stack(n: usize, size: f32, substeps: u32, seconds: f32, watch: f32) -> Rest {
    let (mut w, bodies) = stack(n, size, substeps);
    let dt = w.physics.integration_parameters.dt;
    let frames = (seconds / dt).round() as usize;
    let from = frames - (watch / dt).round() as usize;
    let top = *bodies.last().expect("a cube");
    let (mut last_moving, mut top_moved) = (0usize, 0.0f32);
    let mut reference: Option<Vec<Vector3<f32>>> = None;
    for f in 1..=frames {
        w.step().expect("step");
        let max = bodies
            .iter()
            .map(|&e| w.soft.get::<&Particles>(e).expect("cube").max_speed())
            .fold(0.0f32, f32::max);
        assert!(max.is_finite(), "{n} cubes: non-finite speed");
        if max >= REST {
            last_moving = f;
        }
        let p = w.soft.get::<&Particles>(top).expect("top cube");
        if f == from {
            reference = Some(p.positions().to_vec());
        }
        if let Some(x0) = &reference {
            let d = p.positions().iter().zip(x0).map(|(a, b)| (a - b).norm());
            top_moved = d.fold(top_moved, f32::max);
        }
    }
    Rest {
        at_rest_from: (last_moving < frames).then_some(last_moving as f32 * dt),
        top_moved,
    }
}

/// Two cubes on the ground come to rest, for three cube sizes at 10, 20 and 40 substeps: every
/// particle under [`REST`] for good within 10 s (about 7 s at 10 substeps, 3.2 s at 20), and
/// the top cube moving less than 1 mm over the last 3 s. At 40 substeps a velocity `Δx/h` of a
/// few f32 roundings of a position about a metre up is already 1e-3 m/s (`h` = 0.4 ms), so
/// only the displacement is asserted there.
#[test]
fn two_cube_stacks_come_to_rest() {
    for size in [0.3, 0.5, 0.8] {
        for substeps in [10, 20, 40] {
            let r = run_stack(2, size, substeps, 13.0, 3.0);
            println!(
                "2 × {size} m, {substeps} substeps: below {REST} m/s from {:?} s, top moved {:.2} mm in the last 3 s",
                r.at_rest_from,
                r.top_moved * 1e3
            );
            assert!(
                substeps == 40 || r.at_rest_from.is_some_and(|t| t < 10.0),
                "2 × {size} m at {substeps} substeps still moving"
            );
            assert!(r.top_moved < 1e-3, "top moved {} m", r.top_moved);
        }
    }
}

/// Known limit: taller stacks keep swaying at the default 10 substeps (a stack of five 0.5 m
/// cubes at about 0.1 m/s, its top moving by centimetres; `resting-contacts.md`). The test
/// fails once they come to rest: turn it into a rest assertion then.
#[test]
#[ignore = "long: 9 stacks of 3 to 5 cubes for 13 s (CI runs it in release)"]
fn taller_stacks_keep_swaying_known_limit() {
    let mut still = Vec::new();
    for n in [3, 4, 5] {
        for size in [0.3, 0.5, 0.8] {
            let r = run_stack(n, size, 10, 13.0, 10.0);
            println!(
                "{n} × {size} m: below {REST} m/s from {:?} s, top moved {:.2} mm in the last 10 s",
                r.at_rest_from,
                r.top_moved * 1e3
            );
            if r.at_rest_from.is_some_and(|t| t <= 3.0) && r.top_moved < 1e-3 {
                still.push((n, size));
            }
        }
    }
    assert!(
        still.len() < 9,
        "every stack of 3–5 cubes came to rest within 3 s: the known limit is gone, assert rest instead"
    );
}

/// A 0.5 m soft cube on a fixed 20° incline with friction 0.5 (tan 20° = 0.36 < 0.5) holds
/// still: its centre creeps less than 1 mm in 10 s after it has settled, at 10 and 20 substeps.
#[test]
fn static_friction_holds_a_cube_on_a_20_degree_incline() {
    let theta = 20f32.to_radians();
    for substeps in [10, 20] {
        for size in [0.2, 0.5] {
            let creep = incline_creep(theta, 0.5, size, substeps);
            println!(
                "{size} m cube, {substeps} substeps: crept {:.3} mm in 10 s",
                creep * 1e3
            );
            assert!(
                creep < 1e-3,
                "{size} m cube at {substeps} substeps crept {creep} m"
            );
        }
    }
}

/// How far the centre of a `size` (m) soft cube on a fixed incline at `theta` (rad) with
/// friction `mu` (both sides) moves downhill over 10 s after 1 s of settling, m.
fn incline_creep(theta: f32, mu: f32, size: f32, substeps: u32) -> f32 {
    let mut w = scene(substeps);
    let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), theta);
    let normal = rot * Vector3::y();
    let downhill = -(rot * Vector3::x());
    let centre = rot * Vector3::new(0.0, -0.5, 0.0);
    w.physics.insert(
        RigidBodyBuilder::fixed().pose(Pose::from_parts(
            Vector::new(centre.x, centre.y, centre.z),
            Rotation::from_rotation_z(theta),
        )),
        ColliderBuilder::cuboid(4.0, 0.5, 2.0).friction(mu),
    );
    let mut mesh = box_grid(Vector3::repeat(size), [4, 4, 4], CellSplit::Six).expect("mesh");
    let start = normal * (size / 2.0 + 0.0025);
    for v in &mut mesh.vertices {
        *v = rot * *v + start;
    }
    let body = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .build()
        .expect("body");
    let e = body.spawn(&mut w.soft);
    let collider = SoftColliderBuilder::new()
        .friction(mu)
        .static_friction(mu)
        .build()
        .expect("collider");
    w.soft.insert_one(e, collider).expect("entity");
    w.soft
        .insert_one(e, Activation::never_sleeps())
        .expect("entity");
    for _ in 0..60 {
        w.step().expect("step");
    }
    let x0 = particles(&w, e).center_of_mass();
    for _ in 0..600 {
        w.step().expect("step");
    }
    (particles(&w, e).center_of_mass() - x0).dot(&downhill)
}
