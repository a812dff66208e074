//! Parallel Gauss–Seidel (feature `parallel`): within a colour class no two constraints
//! share a particle, so a class's projections run concurrently and the result is
//! bit-identical to the serial sweep, for any number of threads. A family's sweep is one
//! parallel region whose phases are those of its [`ColourClasses`], run one after another
//! ([`crate::parallel::schedule::run_phases`]): a class alone in its phase is split among the threads
//! (the overflow class, see [`crate::ordering::colouring`], runs on one thread); the tasks of a
//! partitioned body ([`crate::ordering::partition`]) run each whole on one thread, on disjoint slabs. The passes over the particles of a large body (prediction, the copies into
//! and out of the working copy, the velocity update) run the same way as one phase of runs
//! of particles: each particle's update is independent, so they are bit-identical too. The
//! spin removal's copy back ([`crate::stabilisation::angular_momentum`]) sums per block of particles, one block per
//! unit, and the blocks are folded in order on one thread: bit-identical as well.
//! Every region enters the step's pool ([`crate::parallel::context`]) through rayon, or, when
//! the integrator keeps the helpers awake, is posted to the step's team
//! ([`crate::parallel::team`]) instead of waking the pool's threads.

use std::ops::Range;

use nalgebra::Vector3;

use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::kernels::class_runs::{edge_run, vertex_face_run, volume_run};
use crate::kernels::count::{Kernel, ProjectionCount};
use crate::kernels::neo_hookean::{self, MaterialStep, TetRun};
use crate::kernels::particle_runs::{PredictRun, VelocityRun, VelocityUpdate};
use crate::kernels::slots::{self, Slot, WorkAccess};
use crate::ordering::colouring::{ColourClasses, Phase};
use crate::parallel::schedule::{run_phases, Nothing, Split, PARTICLE_CHUNK};
use crate::parallel::shared::{for_runs, Shared, SharedAccess};
use crate::stabilisation::rigid_fit::{self, Moments, StoreRun, BLOCK};

/// Bodies with fewer constraints in a family than this take the serial path.
const MIN_PARALLEL: usize = 4096;

/// Bodies with fewer particles than this run the passes over the particles (prediction,
/// copies, velocity update) serially.
const MIN_PARALLEL_PARTICLES: usize = 4096;

/// Whether a family of `len` constraints runs on the pool: large enough, and the pool has
/// more than one thread (on one thread the serial sweep does the same work without the
/// region's claims and waits; the results are bit-identical either way).
pub(crate) fn worth_it(len: usize) -> bool {
    len >= MIN_PARALLEL && crate::parallel::context::threads() > 1
}

/// Whether some body of `world` takes a parallel path (so a step is worth a team).
pub(crate) fn any_parallel(world: &mut hecs::World) -> bool {
    use crate::{EdgeConstraints, Particles};
    let mut q = world.query::<(&Particles, Option<&EdgeConstraints>, Option<&Tetrahedra>)>();
    q.iter().any(|(p, e, t)| {
        particles_worth_it(p.len())
            || e.is_some_and(|e| worth_it(e.len()))
            || t.is_some_and(|t| worth_it(t.len()))
    })
}

/// Whether a pass over `len` particles runs on the pool.
pub(crate) fn particles_worth_it(len: usize) -> bool {
    len >= MIN_PARALLEL_PARTICLES && crate::parallel::context::threads() > 1
}

/// [`crate::systems::predict`] of one body, in runs of particles.
pub(crate) fn predict(
    run: PredictRun<'_>,
    a: Vector3<f32>,
    h: f32,
    keep: f32,
) -> crate::solver::non_finite::RestoredRun {
    let n = run.positions.len();
    let (w, rest) = (run.inv_masses, run.rest_positions);
    let shared = (
        Shared::new(run.positions),
        Shared::new(run.prev_positions),
        Shared::new(run.velocities),
        Shared::new(run.residuals),
    );
    for_runs(n, PARTICLE_CHUNK, &shared, |i, (x, xp, v, r)| {
        let run = PredictRun {
            positions: x,
            prev_positions: xp,
            velocities: v,
            inv_masses: &w[i.clone()],
            rest_positions: &rest[i.clone()],
            residuals: r,
        };
        run.predict(a, h, keep).offset(i.start)
    })
}

/// [`crate::systems::update_velocities`] of one body, in runs of particles (the counts are
/// sums, whatever the split). The safety net's momentum restoration that may follow runs on
/// one thread, after this pass (its sums in particle order, so the result does not depend on
/// the thread count).
pub(crate) fn update_velocities(
    run: VelocityRun<'_>,
    h: f32,
    max_correction_speed: Option<f32>,
) -> VelocityUpdate {
    let n = run.positions.len();
    let (xp, r) = (run.prev_positions, run.residuals);
    let shared = (Shared::new(run.positions), Shared::new(run.velocities));
    for_runs(n, PARTICLE_CHUNK, &shared, |i, (x, v)| {
        let run = VelocityRun {
            positions: x,
            prev_positions: &xp[i.clone()],
            velocities: v,
            residuals: &r[i],
        };
        run.update(h, max_correction_speed)
    })
}

/// Fills `items` with `value`, in runs of [`PARTICLE_CHUNK`] items.
pub(crate) fn fill<T: Copy + Send + Sync>(items: &mut [T], value: T) {
    let n = items.len();
    for_runs(n, PARTICLE_CHUNK, &Shared::new(items), |_, run| {
        run.fill(value);
        Nothing
    });
}

/// [`crate::kernels::working_copy::load`] in runs of particles.
pub(crate) fn load(slots: &mut [Slot], x: &[Vector3<f32>], w: &[f32], r: &[Vector3<f32>]) {
    let n = slots.len().min(x.len()).min(w.len()).min(r.len());
    for_runs(n, PARTICLE_CHUNK, &Shared::new(slots), |i, run| {
        slots::load_run(run, &x[i.clone()], &w[i.clone()], &r[i]);
        Nothing
    });
}

/// [`crate::kernels::working_copy::store`] in runs of particles.
pub(crate) fn store(slots: &[Slot], x: &mut [Vector3<f32>], r: &mut [Vector3<f32>]) {
    let n = slots.len().min(x.len()).min(r.len());
    let shared = (Shared::new(x), Shared::new(r));
    for_runs(n, PARTICLE_CHUNK, &shared, |i, (x, r)| {
        slots::store_run(&slots[i], x, r);
        Nothing
    });
}

/// Runs `f` over every class, in one parallel region ([`crate::parallel::schedule::run_phases`]: the
/// phases of `classes` are its phases). A phase of one class is split among the threads in
/// chunks; a phase of tasks hands each task whole to one thread, which runs its classes in
/// order. `f` gets the access, the run's first item index, the run's multipliers and whether
/// the run is independent.
fn sweep<T: Send>(
    classes: &ColourClasses,
    items: &mut [T],
    acc: SharedAccess,
    f: impl Fn(&mut SharedAccess, usize, &mut [T], bool) -> ProjectionCount + Sync,
) -> ProjectionCount {
    let shared = Shared::new(items);
    let class_run = |k: usize, within: Range<usize>| {
        let (r, independent) = classes.class(k);
        let first = r.start + within.start;
        // SAFETY: `run_phases` hands each item of a class phase, and each task of a task
        // phase (whose classes are its own), to one call only.
        let run = unsafe { shared.run(first..r.start + within.end) };
        f(&mut { acc }, first, run, independent)
    };
    run_phases(
        classes.phase_count(),
        crate::parallel::schedule::CLASS_CHUNK,
        |j| match classes.phase(j) {
            Phase::Class(k) => {
                let (r, independent) = classes.class(k);
                let split = if independent {
                    Split::Lanes
                } else {
                    Split::Whole
                };
                (r.len(), split)
            }
            Phase::Tasks(tasks) => (tasks.len(), Split::Units),
        },
        |j, within| match classes.phase(j) {
            Phase::Class(k) => class_run(k, within),
            Phase::Tasks(tasks) => {
                let mut count = ProjectionCount::default();
                for t in tasks.start + within.start..tasks.start + within.end {
                    for k in classes.task(t) {
                        count += class_run(k, 0..classes.class(k).0.len());
                    }
                }
                count
            }
        },
    )
}

pub(crate) fn edges(
    p: &mut WorkAccess<'_>,
    e: &mut EdgeConstraints,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    let (edges, rest) = (&e.edges, &e.rest_lengths);
    sweep(&e.classes, &mut e.lambdas, acc, |a, s, lam, ind| {
        let r = s..s + lam.len();
        edge_run(
            a,
            &edges[r.clone()],
            &rest[r],
            lam,
            alpha_tilde,
            kernel,
            ind,
        )
    })
}

pub(crate) fn volume(
    p: &mut WorkAccess<'_>,
    tets: &Tetrahedra,
    vol: &mut VolumeConstraints,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    sweep(&tets.classes, &mut vol.lambdas, acc, |a, s, lam, ind| {
        let r = s..s + lam.len();
        let (t, rest) = (&tets.indices[r.clone()], &tets.rest_volumes[r]);
        volume_run(a, t, rest, lam, alpha_tilde, kernel, ind)
    })
}

pub(crate) fn vertex_face(
    p: &mut WorkAccess<'_>,
    tets: &Tetrahedra,
    vf: &mut VertexFaceConstraints,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    let heights = &vf.rest_heights;
    sweep(&tets.classes, &mut vf.lambdas, acc, |a, s, lam, ind| {
        let r = s..s + lam.len();
        vertex_face_run(
            a,
            &tets.indices[r.clone()],
            &heights[r],
            &[],
            lam,
            alpha_tilde,
            kernel,
            ind,
        )
    })
}

/// The material's sweep of one body ([`crate::kernels::neo_hookean::sweep`]), each colour
/// class split among the threads like the families'; each projection writes its own entry of
/// `run.released`, summed afterwards in tetrahedron order.
pub(crate) fn material(
    p: &mut WorkAccess<'_>,
    prev: &[Vector3<f32>],
    tets: &Tetrahedra,
    run: &mut TetRun<'_>,
    k: &MaterialStep,
    kernel: Kernel,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    let (rest_inverse, rest_volumes) = (run.rest_inverse, run.rest_volumes);
    let released = Shared::new(&mut *run.released);
    sweep(&tets.classes, run.lambdas, acc, |a, s, lam, ind| {
        let r = s..s + lam.len();
        let mut part = TetRun {
            rest_inverse: &rest_inverse[r.clone()],
            rest_volumes: &rest_volumes[r.clone()],
            lambdas: lam,
            // SAFETY: `sweep` hands each range of tetrahedra to one call only (the ranges of
            // the multipliers it hands out), and `released` is indexed like them.
            released: unsafe { released.run(r.clone()) },
        };
        neo_hookean::run(a, prev, &tets.indices[r], &mut part, k, kernel, ind)
    })
}

/// The spin removal's measuring copy back ([`crate::stabilisation::angular_momentum`]) of one body: one unit per
/// block of [`crate::stabilisation::rigid_fit::BLOCK`] particles, each block's f32 sums written to its entry of
/// `blocks` (the caller folds them in block order, as the serial path does, so the result
/// does not depend on the thread count).
pub(crate) fn store_measuring(
    run: StoreRun<'_>,
    origins: [Vector3<f32>; 2],
    blocks: &mut [Moments<f32>],
    spin: bool,
) {
    let n = run.slots.len();
    let (x, r) = (Shared::new(run.positions), Shared::new(run.residuals));
    let (out, s) = (Shared::new(blocks), Shared::new(run.slots));
    let (xp, v, m) = (run.prev_positions, run.velocities, run.masses);
    run_phases(
        1,
        1,
        |_| (n.div_ceil(BLOCK), Split::Units),
        |_, units| {
            for b in units {
                let i = b * BLOCK..((b + 1) * BLOCK).min(n);
                // SAFETY: `run_phases` hands each unit, so each block of particles and its
                // entry of `blocks`, to one call only.
                let (x, r, s, out) = unsafe {
                    (
                        x.run(i.clone()),
                        r.run(i.clone()),
                        s.run(i.clone()),
                        out.run(b..b + 1),
                    )
                };
                let block = StoreRun {
                    slots: s,
                    positions: x,
                    residuals: r,
                    prev_positions: &xp[i.clone()],
                    velocities: &v[i.clone()],
                    masses: &m[i],
                };
                out[0] = if spin {
                    block.store_measuring::<true>(origins)
                } else {
                    block.store_measuring::<false>(origins)
                };
            }
            Nothing
        },
    );
}

/// [`crate::stabilisation::rigid_fit::FixUp::apply`] in runs of particles.
pub(crate) fn fix_up(
    fix: rigid_fit::FixUp<'_>,
    origin_centre: [Vector3<f32>; 2],
    theta: Vector3<f32>,
    limit: crate::stabilisation::correction_energy::Limit,
) {
    let n = fix.positions.len();
    let xp = fix.prev_positions;
    let shared = (
        (Shared::new(fix.positions), Shared::new(fix.residuals)),
        Shared::new(fix.before),
    );
    for_runs(n, PARTICLE_CHUNK, &shared, |i, ((x, r), before)| {
        rigid_fit::FixUp {
            positions: x,
            residuals: r,
            prev_positions: &xp[i],
            before,
        }
        .apply(origin_centre, theta, limit);
        Nothing
    });
}
