//! Sleeping in the core solver: a still body falls asleep and costs no projections; writes,
//! impulses and `wake` wake it where it lay; `can_sleep = false` never sleeps; a snapshot of
//! a sleeping body restores asleep.

use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{is_sleeping, wake, Activation, Particles, SoftBodyBuilder, Solver, SolverSettings};

/// A cube of `cells`³ cells floating without gravity, at rest.
fn still_cube(world: &mut World, size: f32, cells: u32, density: f32) -> Entity {
    let mesh = box_grid(Vector3::repeat(size), [cells; 3], CellSplit::Six).unwrap();
    SoftBodyBuilder::new(mesh)
        .density(density)
        .edges(1e-6)
        .volume(0.0)
        .build()
        .unwrap()
        .spawn(world)
}

fn solver(substeps: u32) -> Solver {
    Solver::new(SolverSettings {
        gravity: Vector3::zeros(),
        substeps,
        ..Default::default()
    })
    .unwrap()
}

/// Steps until the body sleeps; returns the frames it took.
fn frames_to_sleep(solver: &mut Solver, world: &mut World, e: Entity, max: usize) -> Option<usize> {
    (1..=max).find(|_| {
        solver.step(world).unwrap();
        is_sleeping(world, e)
    })
}

#[test]
fn still_bodies_of_any_size_mass_and_substeps_fall_asleep_after_the_time_until_sleep() {
    let mut seed = 0x9e37_79b9_u32;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f32 / u32::MAX as f32
    };
    for case in 0..6 {
        let size = 0.1 + 1.9 * next();
        let density = 10.0 + 5000.0 * next();
        let substeps = 1 + (next() * 20.0) as u32;
        let mut world = World::new();
        let e = still_cube(&mut world, size, 2, density);
        let mut s = solver(substeps);
        let dt = s.settings.dt;
        let frames = frames_to_sleep(&mut s, &mut world, e, 200).unwrap_or_else(|| {
            panic!("case {case}: size {size} m, density {density}, {substeps} substeps never slept")
        });
        let expected = (Activation::DEFAULT_TIME_UNTIL_SLEEP / dt).ceil() as usize;
        assert!(
            frames.abs_diff(expected) <= 1,
            "case {case}: slept after {frames} frames, the rule says {expected}"
        );
    }
}

#[test]
fn a_sleeping_body_costs_no_projections_and_keeps_its_state() {
    let mut world = World::new();
    let e = still_cube(&mut world, 1.0, 3, 1000.0);
    let mut s = solver(5);
    frames_to_sleep(&mut s, &mut world, e, 100).expect("falls asleep");
    let before = (*world.get::<&Particles>(e).unwrap()).clone();
    for _ in 0..10 {
        let stats = s.step(&mut world).unwrap();
        assert_eq!(stats.bodies, 1);
        assert_eq!(stats.bodies_asleep, 1);
        assert_eq!(
            stats.particles, 0,
            "a sleeping body's particles are not stepped"
        );
        assert_eq!(stats.edge.projections + stats.volume.projections, 0);
        assert_eq!(stats.edge.count + stats.volume.count, 0);
    }
    assert_eq!(*world.get::<&Particles>(e).unwrap(), before);
}

#[test]
fn a_moving_or_falling_body_stays_awake() {
    let mut world = World::new();
    let e = still_cube(&mut world, 0.5, 2, 1000.0);
    let mut s = solver(5);
    world
        .get::<&mut Particles>(e)
        .unwrap()
        .apply_impulse(Vector3::new(0.0, 0.0, 10.0))
        .unwrap();
    assert_eq!(
        frames_to_sleep(&mut s, &mut world, e, 120),
        None,
        "drifting at constant speed"
    );
    let mut world = World::new();
    let e = still_cube(&mut world, 0.5, 2, 1000.0);
    let mut s = Solver::new(SolverSettings::default()).unwrap();
    assert_eq!(frames_to_sleep(&mut s, &mut world, e, 120), None, "falling");
}

#[test]
fn can_sleep_false_never_sleeps() {
    let mut world = World::new();
    let e = still_cube(&mut world, 0.5, 2, 1000.0);
    *world.get::<&mut Activation>(e).unwrap() = Activation::never_sleeps();
    let mut s = solver(5);
    assert_eq!(frames_to_sleep(&mut s, &mut world, e, 300), None);
    assert_eq!(world.get::<&Activation>(e).unwrap().time_below(), 0.0);
}

/// Each way of writing a sleeping body wakes it, and it moves on from where it lay.
#[test]
fn writes_impulses_and_wake_wake_a_sleeping_body_where_it_lay() {
    type Write = fn(&mut World, Entity);
    let writes: [(&str, Write); 6] = [
        ("wake", |w, e| assert!(wake(w, e))),
        ("positions_mut", |w, e| {
            w.get::<&mut Particles>(e).unwrap().positions_mut()[0].y += 0.01;
        }),
        ("velocities_mut", |w, e| {
            w.get::<&mut Particles>(e).unwrap().velocities_mut()[0].y = 1.0;
        }),
        ("set_velocity", |w, e| {
            let v = Vector3::new(0.0, 1.0, 0.0);
            w.get::<&mut Particles>(e)
                .unwrap()
                .set_velocity(1, v)
                .unwrap();
        }),
        ("set_pinned", |w, e| {
            w.get::<&mut Particles>(e)
                .unwrap()
                .set_pinned(0, true)
                .unwrap();
        }),
        ("apply_impulse", |w, e| {
            let j = Vector3::new(1.0, 0.0, 0.0);
            w.get::<&mut Particles>(e)
                .unwrap()
                .apply_impulse(j)
                .unwrap();
        }),
    ];
    for (name, write) in writes {
        let mut world = World::new();
        let e = still_cube(&mut world, 0.5, 2, 1000.0);
        let mut s = solver(5);
        frames_to_sleep(&mut s, &mut world, e, 100).expect("falls asleep");
        let slept_at = world.get::<&Particles>(e).unwrap().positions().to_vec();
        write(&mut world, e);
        let stats = s.step(&mut world).unwrap();
        assert!(!is_sleeping(&world, e), "{name} wakes the body");
        // `wake` acts before the step; the step counts the bodies it woke itself.
        let woken_by_step = usize::from(name != "wake");
        assert_eq!(stats.bodies_woken, woken_by_step, "{name}");
        assert!(
            stats.edge.projections > 0,
            "{name}: the woken body is stepped"
        );
        if name == "wake" {
            let p = world.get::<&Particles>(e).unwrap();
            assert_eq!(
                p.positions(),
                &slept_at[..],
                "woken by wake: no pop, no drift"
            );
            assert_eq!(p.max_speed(), 0.0);
        }
    }
    let mut world = World::new();
    let e = still_cube(&mut world, 0.5, 2, 1000.0);
    assert!(!wake(&mut world, e), "an awake body is not woken");
}

#[cfg(feature = "serde")]
#[test]
fn a_snapshot_of_a_sleeping_body_restores_asleep() {
    let mut world = World::new();
    let e = still_cube(&mut world, 0.5, 2, 1000.0);
    let mut s = solver(5);
    frames_to_sleep(&mut s, &mut world, e, 100).expect("falls asleep");
    let json = serde_json::to_string(&*world.get::<&Activation>(e).unwrap()).unwrap();
    let a: Activation = serde_json::from_str(&json).unwrap();
    assert!(a.sleeping());
    let mut fresh = World::new();
    let e2 = still_cube(&mut fresh, 0.5, 2, 1000.0);
    *fresh.get::<&mut Activation>(e2).unwrap() = a;
    let stats = s.step(&mut fresh).unwrap();
    assert_eq!(
        stats.bodies_asleep, 1,
        "the marker follows the restored state"
    );
    assert!(is_sleeping(&fresh, e2));
}
