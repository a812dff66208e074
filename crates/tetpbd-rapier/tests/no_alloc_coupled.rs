//! The coupled step allocates nothing of its own once a scene has run its first frames:
//! candidate gathering through rapier's broad phase, the projections, the write-back, the
//! contact reports and the soft–soft contacts all reuse their buffers.
//!
//! rapier's own work is excused, by the backtrace of each allocation:
//! * everything under `tetpbd_rapier::coupling::step_rapier`, the coupling's only call of
//!   `PhysicsPipeline::step` (the integrator's rapier step; `CoupledWorld` passes no hooks
//!   or event handler, so none of our code runs under it). It is never inlined and never a
//!   tail call, so its frame is in release backtraces too; `PhysicsPipeline::step` itself is
//!   a thin wrapper of `step_inner` that release builds can fold away (it did with the
//!   workspace's features unified, `cargo test --release --workspace --all-features`,
//!   leaving rapier's `StageSync::new` unexcused);
//! * the regrowth of rapier's list of modified rigid bodies under `RigidBodySet::get_mut`.
//!   The pipeline moves that list out of the set at every step (`mem::take` in
//!   `RigidBodySet::take_modified`), so the first body the write-back modifies after each
//!   step regrows it from zero capacity; no public rapier API writes a pose or velocity
//!   without it. Bounded below: about one allocation per frame and written body batch.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::{Cell, RefCell};

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{
    Attachments, CoupledWorld, CouplingSettings, SelfCollision, SoftColliderBuilder,
};

/// Counts the allocations of the current thread while enabled, sorted by who made them.
struct Counting;

#[derive(Default)]
struct Tally {
    ours: u64,
    pipeline: u64,
    modified_list: u64,
    /// Allocations counted as ours whose backtrace names none of this test's functions: it
    /// was not resolved (every frame `<unknown>`), so it could not be classified. Seen when
    /// the test binary is deleted or replaced on disk while it runs (another build relinking
    /// it in the same target directory): std resolves symbols from the file.
    unresolved: u64,
    /// Backtraces of the first few allocations counted as ours.
    traces: Vec<String>,
}

thread_local! {
    static ENABLED: Cell<bool> = const { Cell::new(false) };
    static INSIDE: Cell<bool> = const { Cell::new(false) };
    static TALLY: RefCell<Tally> = RefCell::new(Tally::default());
}

fn record() {
    if !ENABLED.with(Cell::get) || INSIDE.with(Cell::get) {
        return;
    }
    INSIDE.with(|i| i.set(true));
    // Capturing and resolving allocate: `INSIDE` keeps them out of the tally.
    let trace = std::backtrace::Backtrace::force_capture().to_string();
    TALLY.with(|t| {
        let mut t = t.borrow_mut();
        if trace.contains("tetpbd_rapier::coupling::step_rapier") {
            t.pipeline += 1;
        } else if trace.contains("RigidBodySet::get_mut") {
            t.modified_list += 1;
        } else {
            t.ours += 1;
            if !trace.contains("no_alloc_coupled::") {
                t.unresolved += 1;
            }
            if t.traces.len() < 3 {
                t.traces.push(trace);
            }
        }
    });
    INSIDE.with(|i| i.set(false));
}

// SAFETY: forwards every call to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        record();
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        record();
        // SAFETY: same contract as ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Runs `step` `frames` times with counting on; returns the tally.
fn counted(frames: usize, mut step: impl FnMut()) -> Tally {
    TALLY.with(|t| *t.borrow_mut() = Tally::default());
    ENABLED.with(|e| e.set(true));
    for _ in 0..frames {
        step();
    }
    ENABLED.with(|e| e.set(false));
    TALLY.with(|t| std::mem::take(&mut *t.borrow_mut()))
}

fn check(name: &str, tally: &Tally, frames: u64) {
    println!(
        "{name}: {} of ours ({} with unresolved backtraces), {} in rapier's step, {} in rapier's modified-body list over {frames} frames",
        tally.ours, tally.unresolved, tally.pipeline, tally.modified_list
    );
    assert_eq!(
        tally.ours,
        0,
        "{name}: allocations inside the coupled step ({} with unresolved backtraces, \
         which cannot be classified: was the test binary replaced while it ran?); \
         first ones:\n{}",
        tally.unresolved,
        tally.traces.join("\n----\n")
    );
    assert!(
        tally.modified_list <= frames,
        "{name}: {} allocations in rapier's modified-body list",
        tally.modified_list
    );
}

fn scene() -> CoupledWorld {
    scene_with(CouplingSettings::default())
}

/// Rigid ground, 10 substeps, the given coupling settings.
fn scene_with(coupling: CouplingSettings) -> CoupledWorld {
    let solver = SolverSettings {
        substeps: 10,
        ..SolverSettings::default()
    };
    let mut scene = CoupledWorld::new(solver, coupling).expect("settings");
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(5.0, 0.5, 5.0),
    );
    scene
}

fn soft_cube(scene: &mut CoupledWorld, cells: u32, at: Vector3<f32>) -> hecs::Entity {
    soft_cube_with_density(scene, cells, at, 1000.0)
}

fn soft_cube_with_density(
    scene: &mut CoupledWorld,
    cells: u32,
    at: Vector3<f32>,
    density: f32,
) -> hecs::Entity {
    let mesh =
        generators::box_grid(Vector3::repeat(1.0), [cells; 3], CellSplit::Six).expect("mesh");
    let e = SoftBodyBuilder::new(mesh)
        .density(density)
        .edges(0.0)
        .volume(0.0)
        .translation(at)
        .build()
        .expect("body")
        .spawn(&mut scene.soft);
    // Falling asleep and waking move a body between two hecs archetypes, which allocates the
    // first time and whenever the sleeping archetype grows (`docs/decisions/sleeping.md`);
    // these scenes count the steady step, awake.
    scene
        .soft
        .insert_one(e, tetpbd::Activation::never_sleeps())
        .expect("entity");
    e
}

#[test]
fn the_counter_sees_our_allocations() {
    let tally = counted(1, || {
        std::hint::black_box(vec![1u8; 16]);
    });
    assert_eq!(tally.ours, 1);
}

/// A soft cube on rigid ground with a rigid ball resting on it; a second soft cube hanging
/// from a fixed rigid bar by a body attachment and from a soft point target, with a dynamic
/// rigid box resting on the ground beside it.
#[test]
fn coupled_scene_steps_without_allocating() {
    let mut scene = scene();
    soft_cube(&mut scene, 3, Vector3::new(0.0, 0.5, 0.0));
    scene.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 1.16, 0.0)),
        ColliderBuilder::ball(0.15),
    );
    scene.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(-2.0, 0.25, 0.0)),
        ColliderBuilder::cuboid(0.25, 0.25, 0.25),
    );
    let (bar, _) = scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(2.0, 2.6, 0.0)),
        ColliderBuilder::cuboid(0.5, 0.1, 0.1),
    );
    let hanging = soft_cube_with_density(&mut scene, 2, Vector3::new(2.0, 1.5, 0.0), 100.0);
    let mut att = Attachments::new();
    {
        let p = scene.soft.get::<&Particles>(hanging).expect("body");
        let nearest = |target: Vector3<f32>| {
            (0..p.len() as u32)
                .min_by(|&a, &b| {
                    let d = |i: u32| (p.positions()[i as usize] - target).norm();
                    d(a).total_cmp(&d(b))
                })
                .expect("particles")
        };
        let top = nearest(Vector3::new(2.0, 2.5, 0.0));
        let corner = nearest(Vector3::new(1.5, 2.5, -0.5));
        att.attach_to_body(&p, top, &scene.physics.bodies, bar, 0.0)
            .expect("attachment");
        att.attach_to_point(&p, corner, p.positions()[corner as usize], 1e-4)
            .expect("attachment");
    }
    scene.soft.insert_one(hanging, att).expect("entity");
    for _ in 0..20 {
        scene.step().expect("step");
    }
    let frames = 30;
    let mut contacts = 0;
    let tally = counted(frames, || {
        let stats = scene.step().expect("step");
        contacts = contacts.max(stats.contacts);
    });
    assert!(contacts > 0, "the scene has soft–rigid contacts");
    // The counted frames are a sane scene, not an exploded one.
    let p = scene.soft.get::<&Particles>(hanging).expect("body");
    let (lo, hi) = p.aabb();
    assert!(
        lo.y > 0.5 && hi.norm() < 10.0 && p.max_speed() < 1.0,
        "hanging cube bounds {lo:?}..{hi:?}, max speed {}",
        p.max_speed()
    );
    drop(p);
    check("coupled", &tally, frames as u64);
}

/// Three soft cubes stacked on rigid ground with soft–soft contacts, and a self-colliding
/// cube beside them.
#[test]
fn soft_pile_steps_without_allocating() {
    let mut scene = scene();
    for i in 0..3 {
        soft_cube(
            &mut scene,
            3,
            Vector3::new(0.1 * i as f32, 0.5 + 1.01 * i as f32, 0.0),
        );
    }
    let folded = soft_cube(&mut scene, 2, Vector3::new(2.0, 0.5, 0.0));
    scene
        .soft
        .insert_one(folded, SelfCollision)
        .expect("entity");
    for _ in 0..20 {
        scene.step().expect("step");
    }
    let frames = 30;
    let mut candidates = 0;
    let tally = counted(frames, || {
        let stats = scene.step().expect("step");
        candidates = candidates.max(stats.soft_contacts.candidates);
    });
    assert!(candidates > 0, "the pile has soft–soft contact candidates");
    check("pile", &tally, frames as u64);
}

/// Three soft cubes stacked on rigid ground with the self-weight sweep on
/// (`StackingSettings::self_weight`): the ground-up sweep runs on the bottom cube
/// in every substep, its levels rebuilt as its ground contacts change.
#[test]
fn self_weight_sweep_steps_without_allocating() {
    let mut scene = scene_with(CouplingSettings {
        stacking: Some(tetpbd_rapier::StackingSettings {
            self_weight: true,
            ..Default::default()
        }),
        ..CouplingSettings::default()
    });
    for i in 0..3 {
        soft_cube(
            &mut scene,
            3,
            Vector3::new(0.1 * i as f32, 0.55 + 1.01 * i as f32, 0.0),
        );
    }
    for _ in 0..20 {
        scene.step().expect("step");
    }
    let frames = 30;
    let mut passes = 0;
    let tally = counted(frames, || {
        passes += scene.step().expect("step").stacking_passes;
    });
    assert!(passes > 0, "the self-weight sweep ran");
    check("self-weight", &tally, frames as u64);
}

/// A soft cube rolling over rigid ground with rolling resistance on (off by default, so the
/// scenes above never run its pass).
#[test]
fn rolling_resistance_steps_without_allocating() {
    let mut scene = scene();
    let cube = soft_cube(&mut scene, 3, Vector3::new(0.0, 0.5, 0.0));
    let collider = SoftColliderBuilder::new()
        .friction(0.8)
        .rolling_resistance(0.05)
        .build()
        .expect("collider");
    scene.soft.insert_one(cube, collider).expect("entity");
    {
        // Spin about z so the cube tips and rolls against the resistance.
        let mut p = scene.soft.get::<&mut Particles>(cube).expect("body");
        let centre = p.center_of_mass();
        for i in 0..p.len() {
            let r = p.positions()[i] - centre;
            let v = Vector3::new(0.0, 0.0, -6.0).cross(&r);
            p.set_velocity(i, v).expect("velocity");
        }
    }
    // A few frames only: the face it tips onto stops it soon (`response::passivity`).
    for _ in 0..2 {
        scene.step().expect("step");
    }
    let spin = |scene: &CoupledWorld| {
        let p = scene.soft.get::<&Particles>(cube).expect("body");
        p.angular_momentum().norm()
    };
    let spin_before = spin(&scene);
    let frames = 30;
    let mut contacts = 0;
    let tally = counted(frames, || {
        let stats = scene.step().expect("step");
        contacts = contacts.max(stats.contacts);
    });
    println!(
        "angular momentum {spin_before:.3} -> {:.3} kg m²/s",
        spin(&scene)
    );
    assert!(contacts > 0, "the cube touches the ground");
    assert!(spin_before > 0.1, "the cube still rolls: {spin_before}");
    check("rolling", &tally, frames as u64);
}

/// A 1000 kg rigid box landing on a 1 kg soft slab on the ground: the stacking pass runs
/// (its levels rebuilt whenever the slab's ground contacts change, as during the landing).
#[test]
fn stacking_pass_steps_without_allocating() {
    let mut scene = scene();
    let size = Vector3::new(0.6, 0.1, 0.6);
    let mesh = generators::box_grid(size, [3, 1, 3], CellSplit::Six).expect("mesh");
    SoftBodyBuilder::new(mesh)
        .density(1.0 / (size.x * size.y * size.z))
        .edges(0.0)
        .volume(0.0)
        .translation(Vector3::new(0.0, 0.053, 0.0))
        .build()
        .expect("body")
        .spawn(&mut scene.soft);
    // The box lands on the slab, is lifted 0.3 m and dropped; the landing jolts the slab off
    // and back onto the ground, so the stacking levels are rebuilt as its ground contacts
    // change. A first drop grows every buffer to its high-water mark (as for the contact
    // lists); the second one is counted.
    let (boxh, _) = scene.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(-0.1, 0.223, -0.1)),
        ColliderBuilder::cuboid(0.1, 0.1, 0.1).mass(1000.0),
    );
    for _ in 0..10 {
        scene.step().expect("step");
    }
    let drop_box = |scene: &mut CoupledWorld| {
        if let Some(b) = scene.physics.bodies.get_mut(boxh) {
            b.set_translation(Vector::new(-0.1, 0.5, -0.1), true);
            b.set_linvel(Vector::ZERO, true);
        }
    };
    drop_box(&mut scene);
    for _ in 0..30 {
        scene.step().expect("step");
    }
    drop_box(&mut scene);
    let frames = 30;
    let mut passes = 0;
    let tally = counted(frames, || {
        passes += scene.step().expect("step").stacking_passes;
    });
    assert!(passes > 0, "the stacking pass ran");
    check("stacking", &tally, frames as u64);
}

/// A soft cube resting on a box hinged below a fixed bar (a pivoting impulse-jointed body),
/// and a soft cube attached to a box on a spherical multibody joint (its soft reaction goes
/// through the multibody).
#[test]
fn jointed_bodies_step_without_allocating() {
    use rapier3d::prelude::{RevoluteJointBuilder, SphericalJointBuilder};
    let mut scene = scene();
    let bar = |scene: &mut CoupledWorld, x: f32| {
        scene
            .physics
            .bodies
            .insert(RigidBodyBuilder::fixed().translation(Vector::new(x, 3.0, 0.0)))
    };
    let hinge = bar(&mut scene, 0.0);
    let (hinged, _) = scene.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 2.0, 0.0)),
        ColliderBuilder::cuboid(0.6, 0.1, 0.6).mass(20.0),
    );
    let joint = RevoluteJointBuilder::new(Vector::Z)
        .local_anchor2(Vector::new(0.0, 1.0, 0.0))
        .build();
    scene
        .physics
        .impulse_joints
        .insert(hinge, hinged, joint, true);
    soft_cube_with_density(&mut scene, 2, Vector3::new(0.0, 2.601, 0.0), 10.0);
    let ball = bar(&mut scene, 3.0);
    let (link, _) = scene.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(3.0, 2.0, 0.0)),
        ColliderBuilder::cuboid(0.1, 0.1, 0.1).mass(2.0),
    );
    let joint = SphericalJointBuilder::new()
        .local_anchor2(Vector::new(0.0, 1.0, 0.0))
        .build();
    scene
        .physics
        .multibody_joints
        .insert(ball, link, joint, true)
        .expect("multibody joint");
    let hanging = soft_cube_with_density(&mut scene, 2, Vector3::new(3.0, 1.4, 0.0), 2.0);
    let mut att = Attachments::new();
    {
        let p = scene.soft.get::<&Particles>(hanging).expect("body");
        let top = (0..p.len() as u32)
            .max_by(|&a, &b| {
                p.positions()[a as usize]
                    .y
                    .total_cmp(&p.positions()[b as usize].y)
            })
            .expect("particles");
        att.attach_to_body(&p, top, &scene.physics.bodies, link, 0.0)
            .expect("attachment");
    }
    scene.soft.insert_one(hanging, att).expect("entity");
    // The swinging bodies pass through the fast-collider list's high-water mark first.
    for _ in 0..120 {
        scene.step().expect("step");
    }
    let frames = 30;
    let mut written = 0;
    let tally = counted(frames, || {
        written += scene.step().expect("step").bodies_written;
    });
    assert!(written > 0, "the jointed bodies get the soft reaction");
    check("jointed", &tally, frames as u64);
}

/// A slab on the ground torn apart by two kinematic boxes holding its ends, then left to
/// settle: once the pieces have had their first frames, the coupled step allocates nothing of
/// ours. (A frame that tears allocates — the split, the attachments following the pieces —
/// and so does the pieces' first frame, in which the coupling builds their contact caches
/// (soft–soft bounding volumes, corner and candidate buffers grown for the new bodies) as for
/// any body spawned into the scene; while the fragments fly, a buffer may still grow to a new
/// largest contact count.)
#[test]
fn a_torn_coupled_slab_settles_without_allocating() {
    let mut scene = scene();
    let mesh = generators::box_grid(Vector3::new(1.0, 0.1, 0.4), [10, 1, 4], CellSplit::Six)
        .expect("mesh");
    let body = SoftBodyBuilder::new(mesh)
        .edges(1e-6)
        .volume(1e-8)
        .tearing(tetpbd::TearingSettings {
            strain: Some(0.3),
            ..Default::default()
        })
        .translation(Vector3::new(0.0, 0.06, 0.0))
        .build()
        .expect("body");
    let mut att = tetpbd_rapier::Attachments::new();
    let mut boxes = Vec::new();
    for side in [-1.0f32, 1.0] {
        let (h, _) = scene.physics.insert(
            RigidBodyBuilder::kinematic_velocity_based()
                .translation(Vector::new(side * 0.55, 0.3, 0.0))
                .linvel(Vector::new(side * 2.0, 0.0, 0.0)),
            ColliderBuilder::cuboid(0.05, 0.05, 0.05),
        );
        boxes.push(h);
        for i in 0..body.particles.len() {
            if (body.particles.positions()[i].x - side * 0.5).abs() < 1e-4 {
                att.attach_to_body(&body.particles, i as u32, &scene.physics.bodies, h, 0.0)
                    .expect("attachment");
            }
        }
    }
    let e = body.spawn(&mut scene.soft);
    scene
        .soft
        .insert(
            e,
            (
                att,
                tetpbd_rapier::SoftCollider::default(),
                tetpbd::Activation::never_sleeps(),
            ),
        )
        .expect("entity");
    for _ in 0..3 {
        scene.step().expect("step");
    }
    let mut tearing = 0;
    for frame in 0..60 {
        if frame == 30 {
            for &h in &boxes {
                scene.physics.bodies[h].set_linvel(Vector::ZERO, true);
            }
        }
        scene.step().expect("step");
        tearing += scene.coupling.tear_events().len();
    }
    assert!(tearing > 0, "the slab never tore");
    assert!(scene.soft.len() > 1, "the slab never split");
    let mut torn = 0;
    let tally = counted(60, || {
        scene.step().expect("step");
        torn += scene.coupling.tear_events().len();
    });
    assert_eq!(torn, 0, "it tore again while settling");
    check("the torn slab settling", &tally, 60);
}
