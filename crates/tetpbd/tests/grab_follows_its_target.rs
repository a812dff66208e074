//! The grab ([`Grab`]) holds a material point to a moving target: a hard grab keeps it on
//! the target, a compliant one carrying the body's weight stretches by `M g α`, the maximum
//! force bounds how fast it can yank a body, releasing it leaves no trace, and bad input is
//! a typed error. Seeded sweeps over sizes, densities and substeps.

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    EdgeConstraints, Grab, MaterialPoint, Particles, SoftBody, SoftBodyBuilder, Solver,
    SolverSettings, StateError, Surface, Tetrahedra, VertexFaceConstraints, VolumeConstraints,
};

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }
}

/// The sweep's body `case`: an edge `size` m, density 10–10⁴ kg/m³, hard edges and volume.
fn body(rng: &mut Rng, case: usize) -> (SoftBody, f32) {
    let size = 0.2 + rng.next().abs() * 1.5;
    let split = if case.is_multiple_of(2) {
        CellSplit::Five
    } else {
        CellSplit::Six
    };
    let mesh = box_grid(Vector3::repeat(size), [2, 2 + case as u32 % 2, 2], split).unwrap();
    let b = SoftBodyBuilder::new(mesh)
        .density(10f32.powf(1.0 + 3.0 * rng.next().abs()))
        .edges(0.0)
        .volume(0.0)
        .build()
        .unwrap();
    (b, size)
}

fn grab_error(world: &hecs::World, e: hecs::Entity) -> f32 {
    let p = world.get::<&Particles>(e).unwrap();
    let t = world.get::<&Tetrahedra>(e).unwrap();
    let g = world.get::<&Grab>(e).unwrap();
    g.error(&p, &t).unwrap()
}

#[test]
fn hard_grab_keeps_the_point_on_a_moving_target() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for case in 0..12 {
        let substeps = [2, 5, 10, 20][case % 4];
        let (b, size) = body(&mut rng, case);
        // The top centre, dragged along a circle of the body's size at 1 revolution/s.
        let top = Vector3::new(0.0, size * 0.5, 0.0);
        let grab = Grab::at(&b.particles, &b.tetrahedra, top, 0.0, f32::INFINITY).unwrap();
        let mut world = hecs::World::new();
        let e = b.spawn(&mut world);
        world.insert_one(e, grab).unwrap();
        let mut solver = Solver::new(SolverSettings {
            substeps,
            ..SolverSettings::default()
        })
        .unwrap();
        let dt = solver.settings.dt;
        for frame in 1..=120 {
            let a = std::f32::consts::TAU * frame as f32 * dt;
            let target = top + Vector3::new(a.sin(), 1.0 - a.cos(), 0.0) * size;
            world
                .get::<&mut Grab>(e)
                .unwrap()
                .set_target(target)
                .unwrap();
            solver.step(&mut world).unwrap();
            let err = grab_error(&world, e);
            assert!(
                err <= 1e-4 * size,
                "case {case} ({substeps} substeps) frame {frame}: {err} m off the target"
            );
        }
    }
}

#[test]
fn compliant_grab_carrying_the_body_stretches_by_weight_times_compliance() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for case in 0..8 {
        let substeps = [5, 10, 20, 40][case % 4];
        let (b, size) = body(&mut rng, case);
        let mass = b.particles.total_mass();
        let g = 9.81;
        // A spring that stretches by a tenth of the body's size under its weight.
        let compliance = 0.1 * size / (mass * g);
        let top = Vector3::new(0.0, size * 0.5, 0.0);
        let grab = Grab::at(&b.particles, &b.tetrahedra, top, compliance, f32::INFINITY).unwrap();
        let mut world = hecs::World::new();
        let e = b.spawn(&mut world);
        world.insert_one(e, grab).unwrap();
        // Damping lets the bouncing settle within the run.
        let mut solver = Solver::new(SolverSettings {
            substeps,
            damping: 4.0,
            ..SolverSettings::default()
        })
        .unwrap();
        for _ in 0..240 {
            solver.step(&mut world).unwrap();
        }
        let stretch = grab_error(&world, e);
        let want = mass * g * compliance;
        assert!(
            (stretch - want).abs() <= 0.03 * want,
            "case {case} ({substeps} substeps): stretched {stretch} m, M g α = {want} m"
        );
        let force = world.get::<&Grab>(e).unwrap().force();
        assert!(
            (force - Vector3::new(0.0, mass * g, 0.0)).norm() <= 0.03 * mass * g,
            "case {case}: the grab carries {force:?} N, the weight is {} N",
            mass * g
        );
    }
}

#[test]
fn max_force_bounds_how_fast_a_grab_yanks_a_body() {
    let mut rng = Rng(0x0bad_cafe_dead_beef);
    for case in 0..12 {
        let substeps = [1, 5, 10, 30][case % 4];
        let (b, size) = body(&mut rng, case);
        let mass = b.particles.total_mass();
        // At most 2 m/s² for the whole body, towards a target 100 body sizes away.
        let max_force = 2.0 * mass;
        let mut grab = Grab::at(
            &b.particles,
            &b.tetrahedra,
            Vector3::zeros(),
            0.0,
            max_force,
        )
        .unwrap();
        grab.set_target(Vector3::new(100.0 * size, 0.0, 0.0))
            .unwrap();
        let mut world = hecs::World::new();
        let e = b.spawn(&mut world);
        world.insert_one(e, grab).unwrap();
        let mut solver = Solver::new(SolverSettings {
            substeps,
            gravity: Vector3::zeros(),
            ..SolverSettings::default()
        })
        .unwrap();
        let frames = 30;
        for _ in 0..frames {
            solver.step(&mut world).unwrap();
            let f = world.get::<&Grab>(e).unwrap().force().norm();
            assert!(
                f <= max_force * 1.0001,
                "case {case}: {f} N > {max_force} N"
            );
        }
        let t = frames as f32 * solver.settings.dt;
        let p = world.get::<&Particles>(e).unwrap().linear_momentum();
        assert!(
            p.norm() <= max_force * t * 1.001,
            "case {case} ({substeps} substeps): momentum {} > F_max t = {}",
            p.norm(),
            max_force * t
        );
        assert!(
            p.x >= 0.98 * max_force * t,
            "case {case} ({substeps} substeps): a far target pulls at the bound: {p:?}, F_max t = {}",
            max_force * t
        );
    }
}

/// A world holding a copy of `e`'s components, without any grab.
fn copy_without_grab(world: &hecs::World, e: hecs::Entity) -> (hecs::World, hecs::Entity) {
    let mut b = hecs::EntityBuilder::new();
    b.add(Clone::clone(&*world.get::<&Particles>(e).unwrap()));
    b.add(Clone::clone(&*world.get::<&Tetrahedra>(e).unwrap()));
    b.add(Clone::clone(&*world.get::<&Surface>(e).unwrap()));
    if let Ok(c) = world.get::<&EdgeConstraints>(e) {
        b.add(Clone::clone(&*c));
    }
    if let Ok(c) = world.get::<&VertexFaceConstraints>(e) {
        b.add(Clone::clone(&*c));
    }
    if let Ok(c) = world.get::<&VolumeConstraints>(e) {
        b.add(Clone::clone(&*c));
    }
    let mut w = hecs::World::new();
    let copy = w.spawn(b.build());
    (w, copy)
}

#[test]
fn released_body_moves_as_one_never_grabbed() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for case in 0..6 {
        let (b, size) = body(&mut rng, case);
        let mut grab = Grab::at(&b.particles, &b.tetrahedra, Vector3::zeros(), 1e-4, 1e3).unwrap();
        grab.set_target(Vector3::new(size, size, 0.0)).unwrap();
        let mut world = hecs::World::new();
        let e = b.spawn(&mut world);
        world.insert_one(e, grab).unwrap();
        let mut solver = Solver::new(SolverSettings::default()).unwrap();
        for _ in 0..10 {
            solver.step(&mut world).unwrap();
        }
        world.remove_one::<Grab>(e).unwrap();
        let (mut never, copy) = copy_without_grab(&world, e);
        for _ in 0..20 {
            solver.step(&mut world).unwrap();
            solver.step(&mut never).unwrap();
        }
        let a = world.get::<&Particles>(e).unwrap();
        let b = never.get::<&Particles>(copy).unwrap();
        assert_eq!(a.positions(), b.positions(), "case {case}");
        assert_eq!(a.velocities(), b.velocities(), "case {case}");
    }
}

#[test]
fn bad_grabs_are_typed_errors() {
    let mut rng = Rng(7);
    let (b, _) = body(&mut rng, 0);
    let (p, t) = (&b.particles, &b.tetrahedra);
    let nan = Vector3::new(0.0, f32::NAN, 0.0);
    assert!(matches!(
        Grab::at(p, t, nan, 0.0, 1.0),
        Err(StateError::NonFinite { what: "point", .. })
    ));
    assert!(matches!(
        Grab::at(p, t, Vector3::zeros(), -1.0, 1.0),
        Err(StateError::BadCompliance { value }) if value == -1.0
    ));
    for bad in [0.0, -3.0, f32::NAN] {
        assert!(matches!(
            Grab::at(p, t, Vector3::zeros(), 0.0, bad),
            Err(StateError::BadParameter {
                what: "max force (N)",
                ..
            })
        ));
    }
    let mut g = Grab::at(p, t, Vector3::zeros(), 0.0, 1.0).unwrap();
    assert!(matches!(
        g.set_target(nan),
        Err(StateError::NonFinite {
            what: "grab target",
            ..
        })
    ));
    assert!(matches!(
        MaterialPoint::new(t, 10_000, [0.25; 4]),
        Err(StateError::TetrahedronOutOfRange { index: 10_000, .. })
    ));
    let mp = MaterialPoint::new(t, 0, [0.1, 0.2, 0.3, 0.4]).unwrap();
    assert!(Grab::new(mp, Vector3::zeros(), 0.0, f32::INFINITY).is_ok());
}
