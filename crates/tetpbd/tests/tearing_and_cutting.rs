//! Tearing and cutting: a bar pulled past its tearing strain tears and one pulled below it
//! never does; the strain's smoothing keeps a one-frame spike from tearing; torn bodies stay
//! finite, massive, upright at rest and gain no energy; a cut splits a cube into two pieces
//! with the right particle counts; the events list the pieces; everything repeats exactly.

mod common;

use common::tearing::{pinned_bar, pull_ends};
use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    cut, Blade, BuildError, Material, NeoHookeanMaterial, Particles, Pieces, SoftBodyBuilder,
    Solver, SolverSettings, TearEvent, Tearing, TearingError, TearingSettings, Tetrahedra,
};

const LENGTH: f32 = 2.0;

/// A bar along x with its end cross-sections pinned, tearing by `settings`.
fn spawn_bar(world: &mut World, settings: TearingSettings, cells: u32) -> Entity {
    let size = Vector3::new(LENGTH, 0.4, 0.4);
    pinned_bar(world, size, [cells, 2, 2], settings, |b| {
        b.edges(1e-6).volume(1e-8)
    })
}

fn solver() -> Solver {
    Solver::new(SolverSettings {
        gravity: Vector3::zeros(),
        ..Default::default()
    })
    .unwrap()
}

/// Pulls a bar to `stretch` (relative) over 1 s, holds it 0.5 s; returns every event.
fn pull(settings: TearingSettings, stretch: f32, world: &mut World) -> Vec<TearEvent> {
    spawn_bar(world, settings, 8);
    let mut solver = solver();
    let frames = 60;
    let mut events = Vec::new();
    for frame in 0..90 {
        if frame < frames {
            pull_ends(world, 0.5 * stretch * LENGTH / frames as f32);
        }
        solver.step(world).unwrap();
        events.extend_from_slice(solver.tear_events());
    }
    events
}

fn bodies(world: &World) -> usize {
    world.query::<&Particles>().iter().count()
}

#[test]
fn a_bar_pulled_past_its_strain_tears_in_two() {
    let settings = TearingSettings {
        strain: Some(0.3),
        ..Default::default()
    };
    let mut world = World::new();
    let events = pull(settings, 0.8, &mut world);
    assert!(!events.is_empty(), "the bar never tore");
    assert!(bodies(&world) >= 2, "{} bodies", bodies(&world));
    let added: usize = events.iter().map(|e| e.particles_added()).sum();
    let particles: usize = world.query::<&Particles>().iter().map(|p| p.len()).sum();
    assert_eq!(particles, 9 * 3 * 3 + added);
}

#[test]
fn a_bar_pulled_below_its_strain_never_tears() {
    let settings = TearingSettings {
        strain: Some(0.3),
        ..Default::default()
    };
    for stretch in [0.05, 0.1, 0.15] {
        let mut world = World::new();
        let events = pull(settings, stretch, &mut world);
        assert!(events.is_empty(), "tore at a stretch of {stretch}");
        let mut q = world.query::<&Tearing>();
        let t = q.iter().next().unwrap();
        assert_eq!(t.torn_faces(), 0);
        assert!(t.max_smoothed_strain() > 0.5 * stretch, "strain not read");
    }
}

/// One frame stretched to twice the tearing strain, then back: smoothed over 0.1 s the
/// spike tears nothing; unsmoothed it tears.
#[test]
fn smoothing_keeps_a_one_frame_spike_from_tearing() {
    for (smoothing_time, tears) in [(0.1, false), (0.0, true)] {
        let mut world = World::new();
        let settings = TearingSettings {
            strain: Some(0.3),
            force: None,
            smoothing_time,
            pieces: Pieces::KeepOne,
        };
        let e = spawn_bar(&mut world, settings, 4);
        let rest: Vec<Vector3<f32>> = world.get::<&Particles>(e).unwrap().positions().to_vec();
        let mut events = Vec::new();
        {
            let mut p = world.get::<&mut Particles>(e).unwrap();
            for (i, x) in rest.iter().enumerate() {
                p.set_position(i, Vector3::new(1.6 * x.x, x.y, x.z))
                    .unwrap();
            }
        }
        let torn = tetpbd::systems::tear_faces(&mut world, 1.0 / 60.0, 1.0 / 600.0, &mut events);
        {
            let mut p = world.get::<&mut Particles>(e).unwrap();
            for i in 0..p.len() {
                let x = p.rest_positions()[i];
                p.set_position(i, x).unwrap();
            }
        }
        let mut later = 0;
        for _ in 0..30 {
            later += tetpbd::systems::tear_faces(&mut world, 1.0 / 60.0, 1.0 / 600.0, &mut events);
        }
        assert_eq!(later, 0);
        assert_eq!(torn > 0, tears, "smoothing {smoothing_time} s");
    }
}

/// Every body of `world`: finite state, every particle with mass, every rest shape upright
/// (its rest volume has the sign of the rest positions' volume and is not zero).
fn assert_sound(world: &World) {
    for (p, t, m) in world
        .query::<(&Particles, &Tetrahedra, Option<&NeoHookeanMaterial>)>()
        .iter()
    {
        assert!(p
            .positions()
            .iter()
            .all(|x| x.iter().all(|c| c.is_finite())));
        assert!(p
            .velocities()
            .iter()
            .all(|x| x.iter().all(|c| c.is_finite())));
        assert!(p.masses().iter().all(|&m| m > 0.0 && m.is_finite()));
        assert!(p.inv_masses().iter().all(|&w| w.is_finite() && w >= 0.0));
        let rest = Tetrahedra::volume_at;
        for k in 0..t.len() {
            let v = rest(t, k, p.rest_positions());
            assert!(
                v * t.rest_volumes()[k] > 0.0,
                "tetrahedron {k} inverted at rest"
            );
        }
        assert_eq!(t.count_inverted(p.rest_positions()), 0);
        if let Some(m) = m {
            assert!(m
                .rest_inverse()
                .iter()
                .all(|d| d.iter().all(|c| c.is_finite())));
        }
    }
}

/// Energy of every body: kinetic plus the material's elastic energy, J.
fn energy(world: &World) -> f64 {
    world
        .query::<(&Particles, &Tetrahedra, &NeoHookeanMaterial)>()
        .iter()
        .map(|(p, t, m)| f64::from(p.kinetic_energy()) + m.elastic_energy(t, p.positions()))
        .sum()
}

/// A Neo-Hookean bar whose halves fly apart at `speed` (m/s each) in zero gravity tears into
/// sound pieces, and the total energy never exceeds the kinetic energy it started with.
#[test]
fn torn_bodies_stay_sound_and_gain_no_energy() {
    for (speed, pieces) in [
        (5.0, Pieces::Split),
        (10.0, Pieces::KeepOne),
        (20.0, Pieces::Split),
    ] {
        let mut world = World::new();
        let mesh = box_grid(Vector3::new(LENGTH, 0.4, 0.4), [8, 2, 2], CellSplit::Six).unwrap();
        let body = SoftBodyBuilder::new(mesh)
            .material(Material::new(2e5, 0.3).unwrap())
            .tearing(TearingSettings {
                strain: Some(0.2),
                force: None,
                smoothing_time: 0.02,
                pieces,
            })
            .build()
            .unwrap();
        let mass = body.particles.total_mass();
        let e = body.spawn(&mut world);
        {
            let mut p = world.get::<&mut Particles>(e).unwrap();
            for i in 0..p.len() {
                let x = p.rest_positions()[i].x;
                p.set_velocity(i, Vector3::new(speed * x.signum(), 0.0, 0.0))
                    .unwrap();
            }
        }
        let start = energy(&world);
        let mut solver = Solver::new(SolverSettings {
            gravity: Vector3::zeros(),
            substeps: 20,
            ..Default::default()
        })
        .unwrap();
        let mut tore = false;
        for _ in 0..60 {
            solver.step(&mut world).unwrap();
            tore |= !solver.tear_events().is_empty();
            assert_sound(&world);
            let now = energy(&world);
            assert!(
                now <= start * 1.001,
                "speed {speed}: energy {now} > {start}"
            );
        }
        assert!(tore, "speed {speed}: never tore");
        let total: f32 = world
            .query::<&Particles>()
            .iter()
            .map(|p| p.total_mass())
            .sum();
        assert!((total - mass).abs() < 1e-4 * mass, "mass {total} vs {mass}");
    }
}

fn cube(world: &mut World, pieces: Pieces) -> Entity {
    let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [2, 2, 2], CellSplit::Six).unwrap();
    SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .volume(0.0)
        .vertex_face(1e-6)
        .tearing(TearingSettings {
            pieces,
            ..Default::default()
        })
        .build()
        .unwrap()
        .spawn(world)
}

#[test]
fn a_cut_splits_a_cube_into_two_pieces() {
    let mut world = World::new();
    let e = cube(&mut world, Pieces::Split);
    let blade = Blade::Plane {
        point: Vector3::new(0.0, 0.0, 0.0),
        normal: Vector3::new(1.0, 0.0, 0.0),
    };
    let event = cut(&mut world, e, &blade)
        .unwrap()
        .expect("the blade crosses the cube");
    // The middle plane: 4 squares of 2 triangles; its 9 particles are duplicated.
    assert_eq!(event.faces_torn, 8);
    assert_eq!(event.particles_added(), 9);
    assert_eq!(event.pieces.len(), 2);
    assert_eq!(event.pieces[0].entity, e);
    let new: Vec<Entity> = event.new_entities().collect();
    assert_eq!(new.len(), 1);
    for piece in &event.pieces {
        let p = world.get::<&Particles>(piece.entity).unwrap();
        let t = world.get::<&Tetrahedra>(piece.entity).unwrap();
        assert_eq!(p.len(), 18);
        assert_eq!(piece.particles.len(), 18);
        assert_eq!(t.len(), 24);
        // Each piece lies on one side of the blade.
        let x = p.positions().iter().map(|x| x.x);
        let (lo, hi) = x.fold((f32::MAX, f32::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
        assert!(lo > -1e-6 || hi < 1e-6, "a piece spans x = {lo}..{hi}");
    }
    assert_sound(&world);
    // Every original particle went to exactly one piece.
    for i in 0..27 {
        assert!(event.moved(i).is_some(), "particle {i}");
    }
    // Cutting again along the same plane finds no shared face.
    assert!(cut(&mut world, e, &blade).unwrap().is_none());
}

#[test]
fn a_cut_kept_as_one_entity_lists_one_piece() {
    let mut world = World::new();
    let e = cube(&mut world, Pieces::KeepOne);
    let blade = Blade::Triangle([
        Vector3::new(-5.0, 0.0, -5.0),
        Vector3::new(5.0, 0.0, -5.0),
        Vector3::new(0.0, 0.0, 10.0),
    ]);
    let event = cut(&mut world, e, &blade).unwrap().unwrap();
    assert_eq!(event.pieces.len(), 1);
    assert_eq!(world.get::<&Particles>(e).unwrap().len(), 36);
    assert_eq!(bodies(&world), 1);
    // A blade beside the body cuts nothing.
    let beside = Blade::Plane {
        point: Vector3::new(3.0, 0.0, 0.0),
        normal: Vector3::x(),
    };
    assert_eq!(cut(&mut world, e, &beside), Ok(None));
}

#[test]
fn bad_tearing_settings_and_blades_are_named() {
    let mesh = || box_grid(Vector3::new(1.0, 1.0, 1.0), [1, 1, 1], CellSplit::Six).unwrap();
    for (strain, tau, expected) in [
        (0.0, 0.1, TearingError::BadStrain { value: 0.0 }),
        (-1.0, 0.1, TearingError::BadStrain { value: -1.0 }),
        (0.3, -0.5, TearingError::BadSmoothingTime { value: -0.5 }),
        (
            0.3,
            f32::INFINITY,
            TearingError::BadSmoothingTime {
                value: f32::INFINITY,
            },
        ),
    ] {
        let s = TearingSettings {
            strain: Some(strain),
            smoothing_time: tau,
            ..Default::default()
        };
        let err = SoftBodyBuilder::new(mesh()).tearing(s).build().unwrap_err();
        assert_eq!(err, BuildError::Tearing(expected));
    }
    let mut world = World::new();
    let e = cube(&mut world, Pieces::Split);
    let flat = Blade::Triangle([Vector3::zeros(); 3]);
    assert!(matches!(
        cut(&mut world, e, &flat),
        Err(tetpbd::CutError::BadBlade { .. })
    ));
    let nan = Blade::Plane {
        point: Vector3::new(f32::NAN, 0.0, 0.0),
        normal: Vector3::x(),
    };
    assert!(cut(&mut world, e, &nan).is_err());
    world.despawn(e).unwrap();
    assert_eq!(
        cut(
            &mut world,
            e,
            &Blade::Plane {
                point: Vector3::zeros(),
                normal: Vector3::y()
            }
        ),
        Err(tetpbd::CutError::NoSuchBody { entity: e })
    );
}

/// The same pull twice: the same events, the same particles, bit for bit.
#[test]
fn tearing_repeats_exactly() {
    let settings = TearingSettings {
        strain: Some(0.3),
        ..Default::default()
    };
    let run = || {
        let mut world = World::new();
        let events = pull(settings, 0.8, &mut world);
        let particles: Vec<Particles> = world.query::<&Particles>().iter().cloned().collect();
        (events, particles)
    };
    let (a, b) = (run(), run());
    assert!(!a.0.is_empty());
    assert_eq!(a.0, b.0);
    assert_eq!(a.1, b.1);
}

#[cfg(feature = "serde")]
#[test]
fn tearing_state_round_trips_through_serde() {
    let mut world = World::new();
    let e = cube(&mut world, Pieces::KeepOne);
    let t = (*world.get::<&Tearing>(e).unwrap()).clone();
    let json = serde_json::to_string(&t).unwrap();
    let back: Tearing = serde_json::from_str(&json).unwrap();
    assert_eq!(t, back);
}
