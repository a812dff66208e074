//! Sleeping in coupled scenes at default settings (soft–soft contacts on): resting soft
//! bodies fall asleep, a stack sleeps and wakes as one island, a thrown rigid ball wakes a
//! sleeping pile, sleeping bodies gather no contacts and cost no projections, a rigid box on
//! a sleeping cube is left to rapier's sleep rule, and two runs agree bit for bit.

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{is_sleeping, Activation, Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings};

/// Rigid ground (top face at y = 0), `substeps` substeps at 60 Hz.
fn ground(substeps: u32) -> CoupledWorld {
    let solver = SolverSettings {
        substeps,
        ..SolverSettings::default()
    };
    let mut w = CoupledWorld::new(solver, CouplingSettings::default()).expect("settings");
    w.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(20.0, 0.5, 20.0),
    );
    w
}

/// A cube of edge `size` (m) and 4³ cells with its lowest face at height `y` (m).
fn cube(w: &mut CoupledWorld, size: f32, density: f32, at: Vector3<f32>) -> Entity {
    let mesh = box_grid(Vector3::repeat(size), [4, 4, 4], CellSplit::Six).expect("mesh");
    SoftBodyBuilder::new(mesh)
        .density(density)
        .edges(0.0)
        .volume(0.0)
        .translation(at + Vector3::new(0.0, 0.5 * size, 0.0))
        .build()
        .expect("body")
        .spawn(&mut w.soft)
}

fn asleep(w: &CoupledWorld, bodies: &[Entity]) -> usize {
    bodies.iter().filter(|&&e| is_sleeping(&w.soft, e)).count()
}

/// Steps until every body sleeps; the frame that happened in.
fn frames_until_all_asleep(w: &mut CoupledWorld, bodies: &[Entity], max: usize) -> Option<usize> {
    (1..=max).find(|_| {
        w.step().expect("step");
        asleep(w, bodies) == bodies.len()
    })
}

fn stack(substeps: u32, size: f32, density: f32, n: usize) -> (CoupledWorld, Vec<Entity>) {
    let mut w = ground(substeps);
    let bodies = (0..n)
        .map(|i| {
            let y = 0.01 + i as f32 * (size + 0.02);
            cube(&mut w, size, density, Vector3::new(0.0, y, 0.0))
        })
        .collect();
    (w, bodies)
}

#[test]
fn resting_cubes_of_any_size_mass_and_substeps_fall_asleep_within_two_seconds() {
    let mut seed = 0x2545_f491_u32;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f32 / u32::MAX as f32
    };
    for case in 0..4 {
        let size = 0.2 + 0.8 * next();
        let density = 100.0 + 2000.0 * next();
        let substeps = 5 + (next() * 10.0) as u32;
        let (mut w, bodies) = stack(substeps, size, density, 1);
        let at = frames_until_all_asleep(&mut w, &bodies, 120);
        assert!(
            at.is_some(),
            "case {case}: {size} m, {density} kg/m³, {substeps} substeps still awake after 2 s"
        );
        let p = w.soft.get::<&Particles>(bodies[0]).expect("body");
        let lowest = p
            .positions()
            .iter()
            .map(|x| x.y)
            .fold(f32::INFINITY, f32::min);
        assert!(
            lowest > -0.01,
            "case {case}: asleep on the ground, not in it ({lowest} m)"
        );
    }
}

#[test]
fn sleeping_bodies_gather_no_contacts_and_cost_no_projections() {
    let (mut w, bodies) = stack(10, 0.5, 1000.0, 1);
    frames_until_all_asleep(&mut w, &bodies, 120).expect("falls asleep");
    let before = (*w.soft.get::<&Particles>(bodies[0]).expect("body")).clone();
    for _ in 0..30 {
        let s = w.step().expect("step");
        assert_eq!(s.soft.bodies_asleep, 1);
        assert_eq!(s.soft.particles, 0);
        assert_eq!(s.soft.edge.projections + s.soft.volume.projections, 0);
        assert_eq!(
            s.candidates + s.corner_candidates,
            0,
            "no contacts gathered"
        );
        assert_eq!(s.soft_contacts.candidates, 0);
    }
    assert_eq!(*w.soft.get::<&Particles>(bodies[0]).expect("body"), before);
}

#[test]
fn a_stack_of_three_sleeps_and_wakes_as_one_island() {
    let (mut w, bodies) = stack(10, 0.5, 1000.0, 3);
    let mut first = None;
    for f in 0..600 {
        w.step().expect("step");
        let n = asleep(&w, &bodies);
        if n > 0 && first.is_none() {
            first = Some(f);
            assert_eq!(n, 3, "frame {f}: the stack falls asleep as one ({n} of 3)");
        }
        if first.is_some() {
            assert_eq!(n, 3, "frame {f}: one island stays asleep together");
        }
        if first.is_some_and(|s| f > s + 10) {
            break;
        }
    }
    let slept = first.expect("the stack falls asleep within 10 s");
    // A write to the bottom cube wakes the whole stack in the next frame.
    w.soft
        .get::<&mut Particles>(bodies[0])
        .expect("body")
        .velocities_mut()[0]
        .x = 0.0;
    let s = w.step().expect("step");
    assert_eq!(asleep(&w, &bodies), 0, "woken as one island");
    assert_eq!(s.soft.bodies_woken, 3);
    eprintln!("stack of 3 asleep after {:.2} s", (slept + 1) as f32 / 60.0);
}

/// A rigid ball thrown at a sleeping pile wakes it and is stopped by it.
#[test]
fn a_thrown_ball_wakes_a_sleeping_pile() {
    let mut w = ground(10);
    let mut bodies = Vec::new();
    for i in 0..3 {
        for j in 0..2 {
            let at = Vector3::new(i as f32 * 0.52 - 0.52, 0.01 + j as f32 * 0.52, 0.0);
            bodies.push(cube(&mut w, 0.5, 500.0, at));
        }
    }
    frames_until_all_asleep(&mut w, &bodies, 600).expect("the pile falls asleep");
    let (ball, _) = w.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(-2.0, 0.75, 0.0))
            .linvel(Vector::new(8.0, 0.0, 0.0)),
        ColliderBuilder::ball(0.15).density(2000.0),
    );
    let mut woke = None;
    for f in 0..60 {
        w.step().expect("step");
        if woke.is_none() && asleep(&w, &bodies) < bodies.len() {
            woke = Some(f);
        }
    }
    let woke = woke.expect("the ball wakes the pile");
    let x = ball_x(&w, ball);
    assert!(
        x < 0.3,
        "the ball is stopped by the pile, not through it (x = {x} m)"
    );
    eprintln!("pile woke {woke} frames after the throw; ball at x = {x:.3} m after 1 s");
}

fn ball_x(w: &CoupledWorld, ball: RigidBodyHandle) -> f32 {
    w.physics.bodies[ball].translation().x
}

/// A dynamic box resting on a soft cube falls asleep in rapier, then the cube does; neither
/// keeps the other awake, and the box does not sink into the sleeping cube.
#[test]
fn a_rigid_box_on_a_soft_cube_sleeps_and_stays_on_top() {
    let mut w = ground(10);
    let e = cube(&mut w, 0.5, 1000.0, Vector3::new(0.0, 0.01, 0.0));
    let (boxh, _) = w.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.62, 0.0)),
        ColliderBuilder::cuboid(0.1, 0.1, 0.1).density(500.0),
    );
    let mut both = None;
    for f in 0..600 {
        w.step().expect("step");
        if is_sleeping(&w.soft, e) && w.physics.bodies[boxh].is_sleeping() {
            both = Some(f);
            break;
        }
    }
    let both = both.expect("box and cube both asleep within 10 s");
    let y0 = w.physics.bodies[boxh].translation().y;
    for _ in 0..120 {
        w.step().expect("step");
    }
    let y1 = w.physics.bodies[boxh].translation().y;
    assert!(is_sleeping(&w.soft, e) && w.physics.bodies[boxh].is_sleeping());
    assert!((y1 - y0).abs() < 1e-4, "the box stays put ({y0} → {y1} m)");
    eprintln!(
        "box and cube asleep after {:.2} s",
        (both + 1) as f32 / 60.0
    );
}

#[test]
fn can_sleep_false_keeps_a_resting_cube_awake() {
    let (mut w, bodies) = stack(10, 0.5, 1000.0, 1);
    *w.soft.get::<&mut Activation>(bodies[0]).expect("body") = Activation::never_sleeps();
    assert_eq!(frames_until_all_asleep(&mut w, &bodies, 240), None);
}

/// Two runs of a stack that falls asleep give bit-identical particles and sleep frames.
#[test]
fn sleeping_runs_are_bit_identical() {
    let run = || {
        let (mut w, bodies) = stack(10, 0.5, 1000.0, 3);
        let mut frames = Vec::new();
        for f in 0..240 {
            let s = w.step().expect("step");
            if s.soft.bodies_fell_asleep > 0 {
                frames.push(f);
            }
        }
        let bits: Vec<u32> = bodies
            .iter()
            .flat_map(|&e| {
                let p = w.soft.get::<&Particles>(e).expect("body");
                p.positions()
                    .iter()
                    .flat_map(|x| x.map(f32::to_bits).data.0[0])
                    .collect::<Vec<_>>()
            })
            .collect();
        (frames, bits)
    };
    let (a, b) = (run(), run());
    assert!(!a.0.is_empty(), "the stack falls asleep in 4 s");
    assert_eq!(a, b);
}
