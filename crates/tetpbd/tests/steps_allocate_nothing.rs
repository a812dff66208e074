//! A step allocates nothing once the scene has run its first frame.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use common::tearing::{pinned_bar, pull_ends};
use nalgebra::Vector3;
use tetpbd::generators::{ball, box_grid, CellSplit};
use tetpbd::{SoftBodyBuilder, Solver, SolverSettings};

/// Counts allocations made by the current thread (tests run on several threads).
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: forwards every call to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> u64 {
    ALLOCATIONS.with(|c| c.get())
}

#[test]
fn the_counter_counts() {
    let before = allocations();
    std::hint::black_box(vec![1u8; 16]);
    assert_eq!(allocations() - before, 1);
}

#[test]
fn steps_after_the_first_allocate_nothing() {
    let mut world = hecs::World::new();
    SoftBodyBuilder::new(box_grid(Vector3::new(1.0, 1.0, 1.0), [3, 3, 3], CellSplit::Six).unwrap())
        .edges(0.0)
        .volume(0.0)
        .build()
        .unwrap()
        .spawn(&mut world);
    let ball = SoftBodyBuilder::new(ball(0.5, 3, CellSplit::Five).unwrap())
        .vertex_face(1e-6)
        .translation(Vector3::new(3.0, 0.0, 0.0))
        .build()
        .unwrap();
    // Interaction components: a force at a point and a grab.
    let mut forces = tetpbd::UserForces::new(&ball.particles);
    let at = Vector3::new(3.0, 0.0, 0.0);
    forces
        .add_force_at_point(&ball.particles, &ball.tetrahedra, Vector3::x(), at)
        .unwrap();
    let grab = tetpbd::Grab::at(&ball.particles, &ball.tetrahedra, at, 1e-4, 100.0).unwrap();
    let e = ball.spawn(&mut world);
    world.insert(e, (forces, grab)).unwrap();
    for measure in [false, true] {
        let mut solver = Solver::new(SolverSettings {
            diagnostics: tetpbd::DiagnosticSettings {
                measure_error: measure,
                measure_before: measure,
            },
            safety: tetpbd::SafetySettings {
                max_correction_speed: Some(10.0),
                ..Default::default()
            },
            ..Default::default()
        })
        .unwrap();
        solver.step(&mut world).unwrap();
        let before = allocations();
        for _ in 0..10 {
            solver.step(&mut world).unwrap();
        }
        assert_eq!(allocations() - before, 0, "measure_error = {measure}");
    }
}

/// Plastic flow, in both modes and on every family, allocates nothing either: a bar held
/// twisted in a mould flows every frame.
#[test]
fn plastic_flow_allocates_nothing() {
    for volume_preserving in [false, true] {
        let mut world = hecs::World::new();
        let mesh = box_grid(Vector3::new(2.0, 0.4, 0.4), [8, 2, 2], CellSplit::Six).unwrap();
        let settings = tetpbd::PlasticitySettings {
            volume_preserving,
            ..Default::default()
        };
        let e = SoftBodyBuilder::new(mesh)
            .edges(1e-5)
            .volume(1e-7)
            .vertex_face(1e-5)
            .plasticity(settings)
            .build()
            .unwrap()
            .spawn(&mut world);
        {
            let mut p = world.get::<&mut tetpbd::Particles>(e).unwrap();
            for i in 0..p.len() {
                let x = p.rest_positions()[i];
                let (s, c) = (0.8 * x.x).sin_cos();
                let twisted = Vector3::new(x.x, c * x.y - s * x.z, s * x.y + c * x.z);
                p.set_position(i, twisted).unwrap();
                p.set_pinned(i, true).unwrap();
            }
        }
        let mut solver = Solver::new(SolverSettings::default()).unwrap();
        solver.step(&mut world).unwrap();
        let before = allocations();
        let mut flowed = 0;
        for _ in 0..10 {
            solver.step(&mut world).unwrap();
            flowed += tetpbd::systems::flow_plastically(&mut world, 1.0 / 60.0);
        }
        assert_eq!(allocations() - before, 0);
        assert!(flowed > 0, "the twist never flowed");
    }
}

/// The tearing pass of a frame that tears nothing allocates nothing: a bar held stretched
/// below its tearing strain has its faces' strains smoothed every frame, and bars of every
/// family hung from their tops below their tearing force have their faces' forces smoothed.
#[test]
fn a_frame_without_tearing_allocates_nothing() {
    let mut world = hecs::World::new();
    let by_force = tetpbd::TearingSettings {
        strain: None,
        force: Some(1e6),
        ..Default::default()
    };
    let mut hung = Vec::new();
    for family in 0..3 {
        let mesh = box_grid(Vector3::new(0.2, 0.6, 0.2), [2, 6, 2], CellSplit::Six).unwrap();
        let top: Vec<u32> = (0..mesh.vertices.len() as u32)
            .filter(|&i| mesh.vertices[i as usize].y > 0.299)
            .collect();
        let b = SoftBodyBuilder::new(mesh).tearing(by_force).pinned(top);
        let b = match family {
            0 => b.material(tetpbd::Material::new(1e6, 0.3).unwrap()),
            1 => b.edges(1e-6).vertex_face(1e-6),
            _ => b.edges(0.0).volume(0.0),
        };
        hung.push(b.build().unwrap().spawn(&mut world));
    }
    let mesh = box_grid(Vector3::new(2.0, 0.4, 0.4), [8, 2, 2], CellSplit::Six).unwrap();
    let e = SoftBodyBuilder::new(mesh)
        .edges(1e-5)
        .volume(1e-7)
        .tearing(tetpbd::TearingSettings::default())
        .build()
        .unwrap()
        .spawn(&mut world);
    {
        let mut p = world.get::<&mut tetpbd::Particles>(e).unwrap();
        for i in 0..p.len() {
            let x = p.rest_positions()[i];
            p.set_position(i, Vector3::new(1.2 * x.x, x.y, x.z))
                .unwrap();
            p.set_pinned(i, true).unwrap();
        }
    }
    let mut solver = Solver::new(SolverSettings {
        substeps: 30,
        ..Default::default()
    })
    .unwrap();
    solver.step(&mut world).unwrap();
    let before = allocations();
    for _ in 0..10 {
        let stats = solver.step(&mut world).unwrap();
        assert_eq!(stats.faces_torn, 0);
    }
    assert_eq!(allocations() - before, 0);
    let strain = world
        .get::<&tetpbd::Tearing>(e)
        .unwrap()
        .max_smoothed_strain();
    assert!(strain > 0.1, "the strain was not read: {strain}");
    for e in hung {
        let force = world
            .get::<&tetpbd::Tearing>(e)
            .unwrap()
            .max_smoothed_force();
        assert!(force > 0.1, "the force was not read: {force} N");
    }
}

/// Counts the allocations of the substep loop (from the frame's start to its end, before
/// the tearing pass).
#[derive(Default)]
struct SubstepAllocations {
    start: u64,
    inside: u64,
}

impl tetpbd::SubstepHook for SubstepAllocations {
    fn begin_frame(&mut self, _: &mut hecs::World, _: tetpbd::FrameContext) {
        self.start = allocations();
    }
    fn end_frame(&mut self, _: &mut hecs::World, _: tetpbd::FrameContext) {
        self.inside += allocations() - self.start;
    }
    fn moves_particles(&self) -> bool {
        false
    }
}

/// A frame that tears allocates only in its tearing pass, and the frames after a split
/// (the new pieces' first frames included) allocate nothing: bars of each family pulled
/// apart until they fall into pieces.
#[test]
fn a_frame_that_tears_allocates_only_in_the_tearing_pass() {
    for family in 0..3 {
        let mut world = hecs::World::new();
        let settings = tetpbd::TearingSettings {
            strain: Some(0.2),
            smoothing_time: 0.02,
            ..Default::default()
        };
        let size = Vector3::new(2.0, 0.3, 0.3);
        pinned_bar(&mut world, size, [8, 1, 1], settings, |b| match family {
            0 => b.material(tetpbd::Material::new(1e6, 0.3).unwrap()),
            1 => b.edges(1e-6).vertex_face(1e-6),
            _ => b.edges(0.0).volume(0.0),
        });
        let mut solver = Solver::new(SolverSettings::default()).unwrap();
        let mut hook = SubstepAllocations::default();
        let (mut tearing_frames, mut quiet_after_split) = (0, 0);
        for frame in 0..90 {
            pull_ends(&mut world, 2.0 / 60.0);
            let split = world.len() > 1;
            let before = allocations();
            let stats = solver.step_with(&mut world, &mut hook).unwrap();
            let all = allocations() - before;
            if frame == 0 {
                hook.inside = 0;
                continue;
            }
            if stats.faces_torn > 0 {
                tearing_frames += 1;
            } else if split {
                quiet_after_split += 1;
                assert_eq!(all, 0, "family {family}, frame {frame} after a split");
            }
        }
        assert_eq!(hook.inside, 0, "family {family}: the substeps allocated");
        assert!(tearing_frames > 0, "family {family}: nothing tore");
        assert!(
            quiet_after_split > 10 && world.len() > 1,
            "family {family}: the bar never split ({quiet_after_split} frames after)"
        );
    }
}
