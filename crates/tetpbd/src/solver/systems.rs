//! Systems: plain functions over `&mut hecs::World`, each a loop over one query.
//!
//! [`crate::Solver`] calls them in this order every substep of length `h`:
//! [`predict`], the family projections (`iterations` times, in
//! [`crate::SolverSettings::order`], each iteration followed by [`project_grabs`]),
//! [`update_velocities`], [`damp_deformation`]; after the last substep of a frame,
//! [`roll_grab_targets`] and [`flow_plastically`]. They are public so that an integrator can build a different
//! schedule. Each skips the bodies that sleep ([`crate::Asleep`]); [`measure`] alone visits
//! them.

use hecs::World;
use nalgebra::Vector3;

use crate::body::activation::Asleep;
use crate::body::families::Family;
use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
pub use crate::body::forces::integrate_user_forces;
pub use crate::body::grab::{project_grabs, reset_grabs, roll_grab_targets};
use crate::body::mesh::Tetrahedra;
use crate::body::particles::{ExternalAcceleration, Particles};
use crate::constraints::{self, VERTEX_FACE_ORDER};
use crate::kernels::class_runs::{edge_run, vertex_face_run, volume_run};
pub use crate::kernels::compensated::add_compensated;
pub use crate::kernels::count::{Kernel, ProjectionCount};
pub use crate::kernels::particle_runs::VelocityUpdate;
use crate::kernels::particle_runs::{PredictRun, VelocityRun};
use crate::kernels::slots::WorkAccess;
use crate::kernels::working_copy::{self, CopyMode};
pub use crate::solver::material_systems::{
    project_neo_hookean, project_neo_hookean_with, reset_neo_hookean,
};
pub use crate::solver::plastic_flow::flow_plastically;
use crate::solver::stats::{ErrorAccumulator, ErrorStats};
pub use crate::solver::tearing_pass::tear_faces;
pub use crate::stabilisation::deformation_damping::damp_deformation;

/// Untangles the bodies a hook's contacts may touch ([`crate::Untangle`]; its module docs,
/// "Bodies a hook touches"): the step leaves them alone when its hook moves particles
/// ([`crate::SubstepHook::moves_particles`]), so an integrator with such a hook calls this
/// once per frame after the step, with the frame's length `dt` (s) and gravity (m/s²). A
/// calm body with an inverted tetrahedron is moved towards its rest shape's best fit,
/// lifted against gravity so that nothing of it ends lower than its lowest particle now, and
/// only as far as the elastic energy released pays for the lift. `held` (sorted) lists the
/// `(body, particle)` pairs the hook holds at points of its own (attachments): a held body's
/// goal is fitted to them, and a move that would carry one off is not made. Returns the
/// bodies moved.
pub fn untangle_touched_bodies(
    world: &mut World,
    dt: f32,
    gravity: Vector3<f32>,
    held: &[(hecs::Entity, u32)],
) -> usize {
    crate::stabilisation::untangle::untangle_touched_bodies(world, dt, gravity, held)
}

/// Saves `x` as the substep start, applies gravity plus each body's
/// [`ExternalAcceleration`] and [`crate::UserForces`] ([`integrate_user_forces`]) and the
/// linear damping `v ← v · max(0, 1 − damping·h)` to free
/// particles, then moves every particle to its prediction `x + h v`.
///
/// Pinned particles (inverse mass 0) keep their velocity: one set by the user moves them
/// kinematically.
///
/// A particle whose position or velocity is not finite when prediction reads it is restored
/// first (see [`crate::Restored`]) and reported in the result.
pub fn predict(
    world: &mut World,
    h: f32,
    gravity: Vector3<f32>,
    damping: f32,
) -> crate::solver::non_finite::Restored {
    let keep = (1.0 - damping * h).max(0.0);
    let mut restored = crate::solver::non_finite::Restored::default();
    integrate_user_forces(world, h);
    for (entity, p, extra) in world
        .query_mut::<(hecs::Entity, &mut Particles, Option<&ExternalAcceleration>)>()
        .without::<&Asleep>()
    {
        let a = gravity + extra.map_or(Vector3::zeros(), |e| e.0);
        let Particles {
            positions,
            prev_positions,
            velocities,
            inv_masses,
            residuals,
            rest_positions,
            ..
        } = p;
        let run = PredictRun {
            positions,
            prev_positions,
            velocities,
            inv_masses,
            residuals,
            rest_positions,
        };
        #[cfg(feature = "parallel")]
        let r = if crate::parallel::sweeps::particles_worth_it(run.positions.len()) {
            crate::parallel::sweeps::predict(run, a, h, keep)
        } else {
            run.predict(a, h, keep)
        };
        #[cfg(not(feature = "parallel"))]
        let r = run.predict(a, h, keep);
        restored.count += r.count;
        if let (None, Some((i, what, value))) = (restored.first, r.first) {
            restored.first = Some((entity, i, what, value));
        }
    }
    restored
}

/// Sets every multiplier λ to zero (start of a substep), the [`crate::Grab`]s' and the
/// [`crate::NeoHookeanMaterial`]s' too.
pub fn reset_lambdas(world: &mut World) {
    reset_grabs(world);
    reset_neo_hookean(world);
    for e in world
        .query_mut::<&mut EdgeConstraints>()
        .without::<&Asleep>()
    {
        zero(&mut e.lambdas);
    }
    for v in world
        .query_mut::<&mut VertexFaceConstraints>()
        .without::<&Asleep>()
    {
        zero(&mut v.lambdas);
    }
    for v in world
        .query_mut::<&mut VolumeConstraints>()
        .without::<&Asleep>()
    {
        zero(&mut v.lambdas);
    }
}

/// Sets every multiplier of a family to zero (in parallel on a large family).
fn zero<T: Default + Copy + Send + Sync>(lambdas: &mut [T]) {
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::worth_it(lambdas.len()) {
        crate::parallel::sweeps::fill(lambdas, T::default());
        return;
    }
    lambdas.fill(T::default());
}

/// One Gauss–Seidel sweep over every body's [`EdgeConstraints`] with the default kernel.
pub fn project_edges(world: &mut World, h: f32) -> ProjectionCount {
    project_edges_with(world, h, Kernel::default())
}

/// One Gauss–Seidel sweep over every body's [`EdgeConstraints`], in solver (colour) order.
///
/// A zero-length edge (`|p0 − p1| < 1e-6 d`) is pushed apart along its rest-pose direction
/// and counted as degenerate. With the `parallel` feature, the edges of one colour class
/// (which share no particle) are projected concurrently; the result is bit-identical to the
/// serial sweep.
pub fn project_edges_with(world: &mut World, h: f32, kernel: Kernel) -> ProjectionCount {
    project_family(world, Family::Edge, h, kernel, CopyMode::PerSweep)
}

/// One sweep over every body's [`VertexFaceConstraints`] with the default kernel.
pub fn project_vertex_face(world: &mut World, h: f32) -> ProjectionCount {
    project_vertex_face_with(world, h, Kernel::default())
}

/// One Gauss–Seidel sweep over every body's [`VertexFaceConstraints`]: the four constraints
/// of a tetrahedron one after another, tetrahedra in solver (colour) order.
///
/// Each constraint is the degeneracy-aware form [`crate::constraints::vertex_face_bounded`]:
/// the height where the face is healthy, the signed volume over a bounded area where the face
/// is thin (near collinear), so the gradients stay bounded. A face collapsed to a point (no
/// plane, no direction) is counted and given a fallback: `p1` is held at its rest value above
/// `p0` along the face's rest-pose normal. That constraint is linear in `p0` and `p1`, always
/// defined, and re-expands a tetrahedron collapsed to a point.
pub fn project_vertex_face_with(world: &mut World, h: f32, kernel: Kernel) -> ProjectionCount {
    project_family(world, Family::VertexFace, h, kernel, CopyMode::PerSweep)
}

/// One sweep over every body's [`VolumeConstraints`] with the default kernel.
pub fn project_volume(world: &mut World, h: f32) -> ProjectionCount {
    project_volume_with(world, h, Kernel::default())
}

/// One Gauss–Seidel sweep over every body's [`VolumeConstraints`], in solver (colour)
/// order. A tetrahedron whose gradients vanish (all four points collinear) is skipped and
/// counted.
pub fn project_volume_with(world: &mut World, h: f32, kernel: Kernel) -> ProjectionCount {
    project_family(world, Family::Volume, h, kernel, CopyMode::PerSweep)
}

/// One sweep of `family` over every body that has it, reaching the particles as `mode` says.
pub(crate) fn project_family(
    world: &mut World,
    family: Family,
    h: f32,
    kernel: Kernel,
    mode: CopyMode,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    match family {
        Family::Edge => {
            let q = world.query_mut::<(&mut Particles, &mut EdgeConstraints)>();
            for (p, e) in q.without::<&Asleep>() {
                let alpha_tilde = e.compliance / (h * h);
                count +=
                    working_copy::with_access(p, mode, |acc| edges_of(acc, e, alpha_tilde, kernel));
            }
        }
        Family::VertexFace => {
            let q = world.query_mut::<(&mut Particles, &Tetrahedra, &mut VertexFaceConstraints)>();
            for (p, tets, vf) in q.without::<&Asleep>() {
                let alpha_tilde = vf.compliance / (h * h);
                count += working_copy::with_access(p, mode, |acc| {
                    vertex_faces_of(acc, tets, vf, alpha_tilde, kernel)
                });
            }
        }
        Family::Volume => {
            let q = world.query_mut::<(&mut Particles, &Tetrahedra, &mut VolumeConstraints)>();
            for (p, tets, vol) in q.without::<&Asleep>() {
                let alpha_tilde = vol.compliance / (h * h);
                count += working_copy::with_access(p, mode, |acc| {
                    volumes_of(acc, tets, vol, alpha_tilde, kernel)
                });
            }
        }
    }
    count
}

/// One sweep of one body's edges on its working copy.
fn edges_of(
    acc: &mut WorkAccess<'_>,
    e: &mut EdgeConstraints,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::worth_it(e.edges.len()) {
        return crate::parallel::sweeps::edges(acc, e, alpha_tilde, kernel);
    }
    let mut count = ProjectionCount::default();
    for (r, independent) in e.classes.ranges() {
        let (edges, rest, lambdas) = (
            &e.edges[r.clone()],
            &e.rest_lengths[r.clone()],
            &mut e.lambdas[r],
        );
        count += edge_run(acc, edges, rest, lambdas, alpha_tilde, kernel, independent);
    }
    count
}

/// One sweep of one body's vertex–face constraints on its working copy.
fn vertex_faces_of(
    acc: &mut WorkAccess<'_>,
    tets: &Tetrahedra,
    vf: &mut VertexFaceConstraints,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::worth_it(tets.len()) {
        return crate::parallel::sweeps::vertex_face(acc, tets, vf, alpha_tilde, kernel);
    }
    let mut count = ProjectionCount::default();
    for (r, independent) in tets.classes.ranges() {
        let (t, hgt, lam) = (
            &tets.indices[r.clone()],
            &vf.rest_heights[r.clone()],
            &mut vf.lambdas[r],
        );
        count += vertex_face_run(acc, t, hgt, &[], lam, alpha_tilde, kernel, independent);
    }
    count
}

/// One sweep of one body's volume constraints on its working copy.
fn volumes_of(
    acc: &mut WorkAccess<'_>,
    tets: &Tetrahedra,
    vol: &mut VolumeConstraints,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::worth_it(tets.len()) {
        return crate::parallel::sweeps::volume(acc, tets, vol, alpha_tilde, kernel);
    }
    let mut count = ProjectionCount::default();
    for (r, independent) in tets.classes.ranges() {
        let (t, rest, lam) = (
            &tets.indices[r.clone()],
            &tets.rest_volumes[r.clone()],
            &mut vol.lambdas[r],
        );
        count += volume_run(acc, t, rest, lam, alpha_tilde, kernel, independent);
    }
    count
}

/// Sets `v = (x − x_prev + r) / h`, with `r` the rounding residual of the substep's
/// position updates (see [`add_compensated`]).
///
/// With `max_correction_speed = Some(s)`, the part of the new velocity that the constraint
/// projections added, `(x − x_prev)/h − v_pred` (with `v_pred` the predicted velocity, still
/// in the velocity array during the projections), is clamped to length `s` (m/s) per
/// particle. The positions keep their full correction; only the velocity it would have
/// created is limited. This is a safety net for large errors corrected in one substep (an
/// inverted body snapping back), which otherwise turn into a velocity of `Δx/h`; each clamp
/// is counted.
///
/// Clamping particles one by one removes linear and angular momentum (an asymmetric
/// snap-back would push and turn the body). So when at least one particle of a body was
/// clamped and the body has no pinned particle, the momentum the clamp removed is given back
/// as a rigid velocity change of the whole body, a uniform velocity plus a rotation about its
/// centre of mass (the momentum restoration of the `stabilisation` folder): the net never changes a free body's linear or
/// angular momentum. That costs two more serial passes over the body's particles, only in
/// substeps where the net clamped one of them; bodies it leaves alone are bit-identical to
/// running without it. A body with pinned particles (inverse mass 0) gets the per-particle
/// clamp alone: its pins exchange momentum with the outside anyway. A
/// [`crate::SubstepHook`]'s corrections (e.g. collision push-out) are clamped and given back
/// like the projections'.
///
/// A particle whose position became non-finite is put back to its substep start with zero
/// velocity and counted (a safety net that never acts in a healthy run).
pub fn update_velocities(
    world: &mut World,
    h: f32,
    max_correction_speed: Option<f32>,
) -> VelocityUpdate {
    let mut out = VelocityUpdate::default();
    for p in world.query_mut::<&mut Particles>().without::<&Asleep>() {
        let Particles {
            positions,
            prev_positions,
            velocities,
            residuals,
            inv_masses,
            masses,
            ..
        } = p;
        let run = VelocityRun {
            positions,
            prev_positions,
            velocities,
            residuals,
        };
        #[cfg(feature = "parallel")]
        let u = if crate::parallel::sweeps::particles_worth_it(run.positions.len()) {
            crate::parallel::sweeps::update_velocities(run, h, max_correction_speed)
        } else {
            run.update(h, max_correction_speed)
        };
        #[cfg(not(feature = "parallel"))]
        let u = run.update(h, max_correction_speed);
        if u.clamped > 0 && !inv_masses.contains(&0.0) {
            let run = crate::stabilisation::momentum_restoration::RestoreRun {
                positions,
                prev_positions,
                residuals,
                velocities,
                masses,
            };
            crate::stabilisation::momentum_restoration::restore(run, h);
        }
        out += u;
    }
    out
}

/// `|C|` of every constraint at the current positions, per family, over all bodies.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measured {
    /// Edge family.
    pub edge: ErrorStats,
    /// Vertex–face family.
    pub vertex_face: ErrorStats,
    /// Volume family.
    pub volume: ErrorStats,
    /// Tetrahedra whose signed volume has the wrong sign (over all bodies with tetrahedra).
    pub inverted: usize,
}

/// Evaluates every constraint at the current positions without moving anything.
pub fn measure(world: &mut World) -> Measured {
    let mut edge = ErrorAccumulator::default();
    let mut vface = ErrorAccumulator::default();
    let mut vol = ErrorAccumulator::default();
    let mut inverted = 0;
    for (p, e) in world.query_mut::<(&Particles, &EdgeConstraints)>() {
        for (k, &[a, b]) in e.edges.iter().enumerate() {
            edge.add(
                (p.positions[a as usize] - p.positions[b as usize]).norm() - e.rest_lengths[k],
            );
        }
    }
    for (p, tets, vf) in world.query_mut::<(&Particles, &Tetrahedra, &VertexFaceConstraints)>() {
        for (t, tet) in tets.indices.iter().enumerate() {
            for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
                let [a, b, c, d] = order.map(|o| p.positions[tet[o] as usize]);
                // A face collapsed to a point has no height; its violation is the full
                // rest value.
                let rest = vf.rest_heights[t][k];
                let hgt = constraints::bounded_height(
                    &a,
                    &b,
                    &c,
                    &d,
                    constraints::VERTEX_FACE_KAPPA,
                    rest,
                )
                .unwrap_or(0.0);
                vface.add(hgt - rest);
            }
        }
    }
    for (p, tets, _) in world.query_mut::<(&Particles, &Tetrahedra, &VolumeConstraints)>() {
        for t in 0..tets.len() {
            vol.add(tets.volume_at(t, &p.positions) - tets.rest_volumes[t]);
        }
    }
    for (p, tets) in world.query_mut::<(&Particles, &Tetrahedra)>() {
        inverted += tets.count_inverted(&p.positions);
    }
    Measured {
        edge: edge.finish(),
        vertex_face: vface.finish(),
        volume: vol.finish(),
        inverted,
    }
}
