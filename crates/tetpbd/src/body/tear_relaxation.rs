//! The energy bound on the pieces of a split: a tear releases at most what the pieces'
//! constraints store.
//!
//! A split duplicates particles where they are, with their velocities: it moves nothing and
//! changes no energy. What follows does: each piece's constraints still carry the strain the
//! body had, and its substeps relax it. A compliant constraint `C` of compliance `α` stores
//! `C²/(2α)` (J) and may give that back as motion. A hard one (`α = 0`) stores nothing: its
//! strain at the tear is what the solver had not yet corrected (a stiff body pulled faster
//! than its iterations converge), and closing it turns `C/h` into velocity from nothing. A
//! stiff slab held at both ends and stretched by a third, torn free at one end, contracts
//! towards the other in a few substeps and moves as a whole at several times the speed of
//! whatever pulled it.
//!
//! The bound: from the split on, for [`RELAXATION_TIME`], each piece's kinetic energy may
//! not exceed what it had at the split plus the elastic energy its constraints have released
//! since and the work gravity did on it:
//!
//! ```text
//! K ≤ K₀ + max(U₀ − U, 0) + M (g + a)·(c − c₀)      (J)
//! ```
//!
//! with `K = Σ ½ mᵢ|vᵢ|²` over its free particles, `U` the elastic energy its compliant
//! families hold ([`held_energy`]: the work of the forces the solver applied, not `C²/(2α)`
//! of a strain it has not converged on), `M` and `c` its mass and centre of mass, `g` gravity
//! and `a` its [`crate::ExternalAcceleration`]; subscript 0 at the split. Elastic energy a
//! piece gains afterwards (something still pulling it) buys no kinetic energy. Each frame,
//! once the frame is stepped, a piece above the bound loses the excess from its velocities:
//! first from their part relative to their rigid fit (its deformation), then, if that is not
//! enough, from the rigid fit itself, scaled down as a whole. Below the bound nothing is
//! touched: a piece falls, bounces, is dragged and swings freely within the energy it had.
//! Pinned particles are left alone (the fit and the energies are over the free particles).
//! What a kinematic body holding a piece does to it in that time is not told apart from
//! what the piece does by itself: a holder that speeds up within [`RELAXATION_TIME`] of a
//! tear drags the piece at most at the kinetic energy it had. A cut
//! ([`crate::cut`]) starts no bound (it is made between frames, with no substep to read
//! the multipliers of).
//!
//! Cost: nothing in a frame on a body not split in the last [`RELAXATION_TIME`]; otherwise,
//! per piece and frame, one pass over its particles (the fit and the kinetic energy) and one
//! over its constraints (the elastic energy), and one more over the particles in a frame
//! where the bound acts. The component stays on the piece once the time is out (removing it
//! would allocate in a frame without tearing).

use hecs::{Entity, World};

use crate::body::activation::Asleep;
use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::particles::ExternalAcceleration;
use crate::body::particles::Particles;
use crate::constraints::{bounded_height, VERTEX_FACE_KAPPA, VERTEX_FACE_ORDER};
use nalgebra::Vector3;

/// How long after a split a piece's mechanical energy is held to its value at the split, s.
pub const RELAXATION_TIME: f32 = 0.25;

/// A piece of a recent split (a hecs component the tearing pass adds): its kinetic plus
/// elastic energy (J) and centre of mass (m) at the split, and how long the bound still
/// holds (s). It is part of the body's state: a snapshot taken within [`RELAXATION_TIME`] of
/// a split must keep it for the restored body to continue exactly (with the `serde`
/// feature it serialises like the other components).
///
/// A body built with tearing carries it from the start, inactive ([`Default`]: no time
/// left), so that its pieces share the body's components.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TearRelaxation {
    kinetic: f64,
    held: f64,
    centre: Vector3<f32>,
    time_left: f32,
}

impl TearRelaxation {
    /// How long the bound still holds, s (0 once it has run out, or before any split).
    pub fn time_left(&self) -> f32 {
        self.time_left.max(0.0)
    }
}

/// The families whose compliant constraints store energy.
type Families<'a> = (
    Option<&'a EdgeConstraints>,
    Option<&'a VertexFaceConstraints>,
    Option<&'a VolumeConstraints>,
    Option<&'a NeoHookeanMaterial>,
);

/// Starts the bound on each of `pieces` (entities of bodies), at their energy now.
pub(crate) fn start(world: &mut World, pieces: impl Iterator<Item = Entity>, h: f32) {
    for e in pieces {
        let state = {
            let mut q = world.query_one::<(&Particles, &Tetrahedra, Families)>(e);
            let Ok((p, t, f)) = q.get() else {
                continue;
            };
            p.rigid_fit()
                .map(|fit| (kinetic(p), held_energy(p, t, f, h), fit.centre))
        };
        if let Some((kinetic, held, centre)) = state.filter(|s| s.0.is_finite()) {
            let _ = world.insert_one(
                e,
                TearRelaxation {
                    kinetic,
                    held,
                    centre,
                    time_left: RELAXATION_TIME,
                },
            );
        }
    }
}

/// Holds every awake piece still under the bound to it (module docs), after a frame of
/// length `dt` (s) under `gravity` (m/s²).
pub(crate) fn relax(world: &mut World, dt: f32, h: f32, gravity: Vector3<f32>) {
    let q = world.query_mut::<(
        &mut Particles,
        &Tetrahedra,
        &mut TearRelaxation,
        Option<&ExternalAcceleration>,
        Families,
    )>();
    for (p, t, r, accel, f) in q.without::<&Asleep>() {
        if r.time_left <= 0.0 {
            continue;
        }
        r.time_left -= dt;
        let Some(fit) = p.rigid_fit() else {
            continue;
        };
        let g = gravity + accel.map_or(Vector3::zeros(), |a| a.0);
        let work = f64::from(fit.mass) * f64::from(g.dot(&(fit.centre - r.centre)));
        let released = (r.held - held_energy(p, t, f, h)).max(0.0);
        let allowed = (r.kinetic + released + work).max(0.0);
        let total = kinetic(p);
        if total <= allowed || !total.is_finite() {
            continue;
        }
        // The rigid fit is the mass-weighted projection of the velocities on the rigid
        // motions: the kinetic energy splits into the fit's and the rest's.
        let rigid: f64 = (0..p.len())
            .filter(|&i| p.inv_masses[i] != 0.0)
            .map(|i| {
                0.5 * f64::from(p.masses[i])
                    * f64::from(fit.velocity_at(&p.positions[i]).norm_squared())
            })
            .sum();
        let deformation = (total - rigid).max(0.0);
        let (keep_rigid, keep_deformation) = if rigid <= allowed && deformation > 0.0 {
            (1.0, ((allowed - rigid) / deformation).sqrt() as f32)
        } else if rigid > 0.0 {
            ((allowed / rigid).sqrt() as f32, 0.0)
        } else {
            (0.0, 0.0)
        };
        for i in 0..p.len() {
            if p.inv_masses[i] == 0.0 {
                continue;
            }
            let v_rigid = fit.velocity_at(&p.positions[i]);
            p.velocities[i] = v_rigid * keep_rigid + (p.velocities[i] - v_rigid) * keep_deformation;
        }
    }
}

/// `Σ ½ mᵢ|vᵢ|²` over the free particles, J.
fn kinetic(p: &Particles) -> f64 {
    (0..p.len())
        .filter(|&i| p.inv_masses[i] != 0.0)
        .map(|i| 0.5 * f64::from(p.masses[i]) * f64::from(p.velocities[i].norm_squared()))
        .sum()
}

/// The elastic energy the compliant families hold, J: per constraint `½ |λ C| / h²`, the
/// work of the force `λ/h²` (N) the last substep (length `h`, s) applied over the violation
/// `C` (m for the edges and vertex–face heights, m³ for the volumes, with the multiplier in
/// the matching units), and the material's [`NeoHookeanMaterial::elastic_energy`]. Hard
/// families (α = 0) hold none. Converged, `λ = −C h²/α` and this is `C²/(2α)`; a stiff
/// body whose iterations have not converged is softer than its compliance, and `C²/(2α)`
/// of its stretch is not energy it holds (module docs).
pub(crate) fn held_energy(p: &Particles, t: &Tetrahedra, f: Families, h: f32) -> f64 {
    let (edges, vertex_face, volume, material) = f;
    let x = &p.positions;
    let inv_h2 = 1.0 / (f64::from(h) * f64::from(h));
    let term = |c: f32, lambda: f32| 0.5 * f64::from((c * lambda).abs()) * inv_h2;
    let mut u = 0.0f64;
    if let Some(e) = edges.filter(|e| e.compliance > 0.0) {
        let all = e.edges.iter().zip(&e.rest_lengths).zip(&e.lambdas);
        for ((&[a, b], &l), &lambda) in all {
            u += term((x[a as usize] - x[b as usize]).norm() - l, lambda);
        }
    }
    if let Some(v) = volume.filter(|v| v.compliance > 0.0) {
        for (k, (&v0, &lambda)) in t.rest_volumes.iter().zip(&v.lambdas).enumerate() {
            u += term(t.volume_at(k, x) - v0, lambda);
        }
    }
    if let Some(v) = vertex_face.filter(|v| v.compliance > 0.0) {
        let all = t.indices.iter().zip(&v.rest_heights).zip(&v.lambdas);
        for ((tet, rest), lambdas) in all {
            for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
                let [a, b, c, d] = order.map(|o| x[tet[o] as usize]);
                let height = bounded_height(&a, &b, &c, &d, VERTEX_FACE_KAPPA, rest[k]);
                u += term(height.unwrap_or(0.0) - rest[k], lambdas[k]);
            }
        }
    }
    if let Some(m) = material {
        u += m.elastic_energy(t, x);
    }
    if u.is_finite() {
        u
    } else {
        0.0
    }
}
