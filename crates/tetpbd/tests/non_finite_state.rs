//! A non-finite position or velocity written by the caller is reported by the step, naming
//! the body, particle and value, and the body is restored, never frozen.

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{hecs, Particles, SoftBodyBuilder, Solver, SolverSettings, StepError, Tetrahedra};

fn cube(world: &mut hecs::World, x: f32) -> hecs::Entity {
    let mesh = box_grid(Vector3::new(0.5, 0.5, 0.5), [2, 2, 2], CellSplit::Six).unwrap();
    SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .volume(0.0)
        .translation(Vector3::new(x, 2.0, 0.0))
        .build()
        .unwrap()
        .spawn(world)
}

fn solver(substeps: u32) -> Solver {
    Solver::new(SolverSettings {
        substeps,
        diagnostics: tetpbd::DiagnosticSettings {
            measure_error: true,
            ..Default::default()
        },
        ..Default::default()
    })
    .unwrap()
}

#[test]
fn nan_or_inf_written_by_the_caller_is_reported_and_the_body_keeps_falling() {
    let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    for (case, &value) in bad.iter().enumerate() {
        for velocity in [false, true] {
            for substeps in [1, 10] {
                let mut world = hecs::World::new();
                let _healthy = cube(&mut world, -2.0);
                let body = cube(&mut world, 2.0);
                let mut solver = solver(substeps);
                for _ in 0..5 {
                    solver.step(&mut world).unwrap();
                }
                let victim = 7 + 3 * case;
                {
                    let mut p = world.get::<&mut Particles>(body).unwrap();
                    if velocity {
                        p.velocities_mut()[victim].y = value;
                    } else {
                        p.positions_mut()[victim].x = value;
                    }
                }
                let err = solver.step(&mut world).unwrap_err();
                let StepError::NonFiniteState {
                    entity,
                    particle,
                    what,
                    value: found,
                    restored,
                } = &err
                else {
                    panic!("expected NonFiniteState, got {err:?}");
                };
                assert_eq!(*entity, body);
                assert_eq!(*particle, victim);
                assert_eq!(*what, if velocity { "velocity" } else { "position" });
                let component = if velocity { found[1] } else { found[0] };
                assert!(component.is_nan() == value.is_nan() && !component.is_finite());
                assert_eq!(*restored, 1, "one restoration, in the first substep");
                let message = err.to_string();
                assert!(message.contains(&format!("particle {victim}")), "{message}");
                // The next frames are healthy and the body keeps falling, whole.
                let y0 = world.get::<&Particles>(body).unwrap().center_of_mass().y;
                for _ in 0..10 {
                    let stats = solver.step(&mut world).unwrap();
                    assert_eq!(stats.non_finite_resets, 0);
                    assert_eq!(stats.non_finite_restored, 0);
                    assert_eq!(stats.inverted, Some(0));
                }
                let p = world.get::<&Particles>(body).unwrap();
                assert!(p
                    .positions()
                    .iter()
                    .all(|x| x.iter().all(|c| c.is_finite())));
                assert!(p
                    .velocities()
                    .iter()
                    .all(|x| x.iter().all(|c| c.is_finite())));
                let y1 = p.center_of_mass().y;
                assert!(y1 < y0 - 0.01, "still falling: {y0} -> {y1}");
            }
        }
    }
}

#[test]
fn a_whole_body_of_nan_is_restored_and_counted_once_per_particle() {
    let mut world = hecs::World::new();
    let body = cube(&mut world, 0.0);
    let mut solver = solver(10);
    solver.step(&mut world).unwrap();
    let n = {
        let mut p = world.get::<&mut Particles>(body).unwrap();
        p.positions_mut().fill(Vector3::repeat(f32::NAN));
        p.len()
    };
    match solver.step(&mut world) {
        Err(StepError::NonFiniteState {
            particle, restored, ..
        }) => {
            assert_eq!(particle, 0);
            assert_eq!(restored, n as u64);
        }
        other => panic!("expected NonFiniteState, got {other:?}"),
    }
    let stats = solver.step(&mut world).unwrap();
    assert_eq!(stats.inverted, Some(0));
}

#[test]
fn a_nan_body_counts_as_inverted_not_healthy() {
    let mut world = hecs::World::new();
    let body = cube(&mut world, 0.0);
    let (p, t) = world
        .query_one_mut::<(&mut Particles, &Tetrahedra)>(body)
        .unwrap();
    assert_eq!(t.count_inverted(p.positions()), 0);
    p.positions_mut()[0] = Vector3::repeat(f32::NAN);
    assert!(t.count_inverted(p.positions()) > 0);
}
