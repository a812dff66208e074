//! Immovable contacts are passive: while a soft body touches only immovable colliders,
//! its contacts stop the approach of its rigid motion as a rigid body's inelastic impact
//! would, and never give that motion kinetic energy.
//!
//! Why: a rigid cube loses most of its energy at each face landing — the landing edge's
//! inelastic impact, an impulse through the whole body's effective mass. A hard soft cube's
//! contacts stop only the few particles that touch; the rest of the body runs on into them,
//! the face is squashed (at a few substeps a stiff XPBD body is numerically springy) and
//! its recovery comes back as rigid motion — rotation about the next edge that rocks and
//! rolls the cube on like a ball, so it never comes to rest. Restitution
//! (`response::restitution`) caps the centre of mass's separating velocity, not the
//! rotation, and caps on the rotation at a contact point pumped energy through the lever or
//! hung bodies on their edges (`docs/decisions/contacts-that-are-no-impact-are-capped.md`).
//!
//! A fixed collider (or a kinematic one at rest) does no work: with friction and inelastic
//! contact, it only takes energy out of a body. Both rules below act on the rigid fit of
//! the body's velocities ([`tetpbd::Particles::rigid_fit`]: mass `M`, centre `c`, velocity
//! `v_c`, inertia `I` with pseudo-inverse `I⁺`, angular velocity `ω`), as rigid velocity
//! changes `Δvᵢ = Δv_c + Δω × (xᵢ − c)` of the free particles. Since `Σ mᵢ vᵢ = M v_c` and
//! `Σ mᵢ rᵢ × vᵢ = I ω`, such a change alters the body's whole kinetic energy exactly as it
//! alters the fit's `K = ½ M |v_c|² + ½ ωᵀ I ω`; the deformation's velocities are untouched.
//!
//! **1. The approach stops as a rigid body's would.** Per patch of contacts with one
//! collider (mean normal `n`, mean point `q`, `r = q − c`), where the fit approaches,
//! `v_n = n·(v_c + ω × r) < 0`, the impulse `j n` at `q` with
//!
//! ```text
//! w = 1/M + (r × n)ᵀ I⁺ (r × n),   j = −v_n / w,   Δv_c = j n / M,   Δω = I⁺ (r × n) j
//! ```
//!
//! makes `v_n = 0`: the perfectly inelastic impact of a rigid body at `q`, whose energy
//! change is `−v_n² / 2w` — it only removes energy, and it pushes (never pulls), so it does
//! not turn the body's translation into the spin a pull at a lever would.
//!
//! **2. Passivity.** Then `K` can grow only by the work of the loads that act on the rigid
//! motion: gravity and the uniform applied acceleration `a` (`M a·Δc`, `Δc` the centre's
//! displacement in the substep, exact for a uniform field) and what restitution
//! deliberately gives an impact with `e > 0` (`W_e`). A passivity episode per body keeps
//! the reference `K_ref`:
//!
//! ```text
//! start (first substep with only immovable contacts):  K_ref = K
//! each substep after:   K_ref ← max(0, K_ref + M a·Δc + W_e)
//!                       if K > K_ref: remove K − K_ref from the rigid motion
//!                       K_ref ← min(K_ref, K)
//! ```
//!
//! The excess comes out of the rotation first (`ω ← s ω`, `s = √((K_rot − ΔK)/K_rot)`), then
//! out of the translation (`v_c ← s v_c`). The recovering squash still restores the shape;
//! its energy just no longer throws the body. Neither rule can add energy, so nothing here
//! can launch a body or pump it.
//!
//! The episode ends (and a new one starts from the body's energy then), and neither rule
//! runs, as soon as any contact is with something that can do work: a dynamic body, a
//! kinematic one that moves, another soft body (a body whose bounds, grown by its motion
//! over the frame and the soft–soft margin, meet another soft body's counts as touching
//! it), or when the body is pinned, attached, grabbed or pushed by user forces (a torque
//! whose work `M a·Δc` does not count).
//!
//! Cost: one rigid fit per soft body in contact per substep, shared with the rolling
//! resistance ([`crate::response::rolling`]), one pass over the particles per approaching
//! patch and one when energy is removed: about 5 % of a frame for cubes resting awake on
//! the ground (`docs/decisions/immovable-contacts-are-passive.md`).

use nalgebra::Vector3;
use tetpbd::{Particles, RigidFit};

use crate::contacts::corner::CornerContact;
use crate::contacts::particle::ParticleContact;
use crate::response::restitution::contact_patch;
use crate::rigid::body::{BodyKind, BodyProxy};
use crate::rigid::collider::ColliderProxy;

/// The passivity episode of one soft body (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Episode {
    key: u64,
    /// `K_ref`, J.
    reference: f32,
    /// The centre of mass at the end of the last substep, m.
    centre: Vector3<f32>,
    seen: bool,
}

/// The passivity episodes of the soft bodies touching only immovable colliders, kept
/// across substeps and frames, sorted by entity.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Passivity {
    list: Vec<Episode>,
}

/// Whether a soft body has active contacts in the substep and all of them are with
/// immovable colliders, which can do no work on it: without a body or on a fixed one, or on
/// a kinematic one whose velocity is zero at every contact point.
pub(crate) fn only_immovable_contacts(
    contacts: &[ParticleContact],
    corners: &[CornerContact],
    bodies: &[BodyProxy],
    colliders: &[ColliderProxy],
) -> bool {
    let still = |ci: usize, q: &Vector3<f32>| {
        colliders[ci].body.is_none_or(|b| match bodies[b].kind {
            BodyKind::Fixed => true,
            BodyKind::Kinematic => bodies[b].velocity_at(q) == Vector3::zeros(),
            BodyKind::Dynamic | BodyKind::Supported => false,
        })
    };
    let mut any = false;
    for c in contacts.iter().filter(|c| c.active && c.solve) {
        if !still(c.collider, &c.point) {
            return false;
        }
        any = true;
    }
    for k in corners.iter().filter(|k| k.active) {
        if !still(k.collider, &k.point) {
            return false;
        }
        any = true;
    }
    any
}

/// Rule 1 of the module docs: stops the approach of the rigid motion (`fit`, updated) at
/// each patch of the body's active contacts (`active`, the sorted collider indices), as a
/// rigid body's inelastic impact would. Returns the energy removed, J.
pub(crate) fn stop_approach(
    active: &[usize],
    contacts: &[ParticleContact],
    corners: &[CornerContact],
    p: &mut Particles,
    fit: &mut RigidFit,
) -> f32 {
    let mut removed = 0.0;
    for &ci in active {
        let Some((n, q, _, _)) = contact_patch(ci, contacts, corners) else {
            continue;
        };
        removed += stop_at(p, fit, &n, &q);
    }
    removed
}

/// Rule 1 at one patch (unit normal `n` towards the body, point `q`): the impulse that stops
/// the fit's approach at `q`. Returns the energy removed, J (0 when `q` does not approach).
fn stop_at(p: &mut Particles, fit: &mut RigidFit, n: &Vector3<f32>, q: &Vector3<f32>) -> f32 {
    let r = q - fit.centre;
    let v_n = n.dot(&fit.velocity_at(q));
    let rn = r.cross(n);
    let w = 1.0 / fit.mass + rn.dot(&(fit.inverse_inertia * rn));
    let approaching = v_n < 0.0 && w > 0.0;
    if !approaching {
        return 0.0;
    }
    let j = -v_n / w;
    let dv = n * (j / fit.mass);
    let dw = fit.inverse_inertia * rn * j;
    if !dv.iter().chain(dw.iter()).all(|c| c.is_finite()) {
        return 0.0;
    }
    for i in 0..p.len() {
        if p.inv_masses()[i] > 0.0 {
            let x = p.positions()[i] - fit.centre;
            p.velocities_mut()[i] += dv + dw.cross(&x);
        }
    }
    fit.velocity += dv;
    fit.angular_velocity += dw;
    0.5 * v_n * v_n / w
}

/// The rigid kinetic energy of a fit, split into translation and rotation, J.
fn energies(fit: &RigidFit) -> (f32, f32) {
    let t = 0.5 * fit.mass * fit.velocity.norm_squared();
    let r = 0.5
        * fit
            .angular_velocity
            .dot(&(fit.inertia * fit.angular_velocity));
    (t, r.max(0.0))
}

impl Passivity {
    /// Runs the episode of body `key` for one substep: `fit` is the body's rigid fit after
    /// the substep's contact responses (updated in place when energy is removed), `accel`
    /// the uniform acceleration of gravity and the applied loads (m/s²), `given` the energy
    /// restitution gave the body in the substep (J). Returns the energy removed, J.
    pub fn run(
        &mut self,
        key: u64,
        p: &mut Particles,
        fit: &mut RigidFit,
        accel: &Vector3<f32>,
        given: f32,
    ) -> f32 {
        let (k_t, k_r) = energies(fit);
        let k = k_t + k_r;
        let ep = match self.list.binary_search_by(|ep| ep.key.cmp(&key)) {
            Ok(i) => &mut self.list[i],
            Err(i) => {
                self.list.insert(
                    i,
                    Episode {
                        key,
                        reference: k,
                        centre: fit.centre,
                        seen: true,
                    },
                );
                return 0.0;
            }
        };
        ep.seen = true;
        let work = fit.mass * accel.dot(&(fit.centre - ep.centre)) + given.max(0.0);
        ep.centre = fit.centre;
        if work.is_finite() {
            ep.reference = (ep.reference + work).max(0.0);
        }
        let excess = k - ep.reference;
        let over = excess > 0.0 && k.is_finite();
        if !over {
            ep.reference = ep.reference.min(k.max(0.0));
            return 0.0;
        }
        remove_energy(p, fit, excess, k_r, k_t);
        let (k_t, k_r) = energies(fit);
        ep.reference = ep.reference.min(k_t + k_r);
        excess
    }

    /// Ends the substep: drops the episodes of bodies that did not run one in it.
    pub fn end_substep(&mut self) {
        self.list.retain(|ep| ep.seen);
        for ep in self.list.iter_mut() {
            ep.seen = false;
        }
    }
}

/// Removes `excess` (J) of the rigid kinetic energy of `fit` from the free particles:
/// rotation first (`k_r`, J), then translation (`k_t`, J), as rigid velocity changes about
/// the centre of mass (module docs). Updates `fit`.
fn remove_energy(p: &mut Particles, fit: &mut RigidFit, excess: f32, k_r: f32, k_t: f32) {
    let from_rotation = excess.min(k_r);
    let dw = if k_r > 0.0 {
        let s = ((k_r - from_rotation) / k_r).max(0.0).sqrt();
        fit.angular_velocity * (s - 1.0)
    } else {
        Vector3::zeros()
    };
    let rest = excess - from_rotation;
    let dv = if rest > 0.0 && k_t > 0.0 {
        let s = ((k_t - rest) / k_t).max(0.0).sqrt();
        fit.velocity * (s - 1.0)
    } else {
        Vector3::zeros()
    };
    if !dw.iter().chain(dv.iter()).all(|c| c.is_finite()) {
        return;
    }
    for i in 0..p.len() {
        if p.inv_masses()[i] > 0.0 {
            let r = p.positions()[i] - fit.centre;
            p.velocities_mut()[i] += dv + dw.cross(&r);
        }
    }
    fit.angular_velocity += dw;
    fit.velocity += dv;
}

#[cfg(test)]
mod tests {
    use super::*;
    use tetpbd::generators::{box_grid, CellSplit};
    use tetpbd::SoftBodyBuilder;

    fn spinning_cube(w: Vector3<f32>, v: Vector3<f32>) -> Particles {
        let mesh = box_grid(Vector3::repeat(0.5), [2; 3], CellSplit::Six).expect("mesh");
        let mut p = SoftBodyBuilder::new(mesh)
            .density(1000.0)
            .build()
            .expect("body")
            .particles;
        let c = p.center_of_mass();
        for i in 0..p.len() {
            let r = p.positions()[i] - c;
            p.velocities_mut()[i] = v + w.cross(&r);
        }
        p
    }

    #[test]
    fn a_rise_of_rigid_energy_is_taken_from_the_rotation_first() {
        let mut p = spinning_cube(Vector3::new(0.0, 0.0, 4.0), Vector3::new(1.0, 0.0, 0.0));
        let mut passivity = Passivity::default();
        let mut fit = p.rigid_fit().expect("fit");
        let zero = Vector3::zeros();
        assert_eq!(passivity.run(7, &mut p, &mut fit, &zero, 0.0), 0.0);
        passivity.end_substep();
        // The body's spin rises by half (as a recovering squash would make it).
        let c = p.center_of_mass();
        for i in 0..p.len() {
            let r = p.positions()[i] - c;
            let dw = Vector3::new(0.0, 0.0, 2.0).cross(&r);
            p.velocities_mut()[i] += dw;
        }
        let before = p.rigid_fit().expect("fit");
        let (k_t0, k_r0) = energies(&before);
        let mut fit = before;
        let removed = passivity.run(7, &mut p, &mut fit, &zero, 0.0);
        let after = p.rigid_fit().expect("fit");
        let (k_t, k_r) = energies(&after);
        assert!(removed > 0.0);
        assert!((k_t - k_t0).abs() < 1e-4 * k_t0, "translation kept");
        assert!(
            (k_r0 - k_r - removed).abs() < 1e-3 * k_r0,
            "{k_r0} {k_r} {removed}"
        );
        assert!((after.angular_velocity.z - 4.0).abs() < 1e-3);
        assert!((after.velocity - before.velocity).norm() < 1e-5);
    }

    #[test]
    fn an_approaching_corner_is_stopped_inelastically_at_the_rigid_cost() {
        // Falling at 2 m/s and spinning about z, so the patch point approaches faster.
        let mut p = spinning_cube(Vector3::new(0.0, 0.0, 3.0), Vector3::new(0.0, -2.0, 0.0));
        let c = p.center_of_mass();
        let q = c + Vector3::new(0.25, -0.25, 0.0);
        let mut fit = p.rigid_fit().expect("fit");
        let n = Vector3::y();
        let v_n = n.dot(&fit.velocity_at(&q));
        assert!(v_n < 0.0);
        let r = q - fit.centre;
        let rn = r.cross(&n);
        let w = 1.0 / fit.mass + rn.dot(&(fit.inverse_inertia * rn));
        let before = p.kinetic_energy();
        let removed = stop_at(&mut p, &mut fit, &n, &q);
        let after = p.rigid_fit().expect("fit");
        assert!(
            n.dot(&after.velocity_at(&q)).abs() < 1e-4,
            "the point stops"
        );
        let expected = 0.5 * v_n * v_n / w;
        assert!((removed - expected).abs() < 1e-4 * expected);
        let lost = before - p.kinetic_energy();
        assert!(
            (lost - expected).abs() < 2e-3 * expected,
            "{lost} {expected}"
        );
        // A separating point is left alone.
        let mut fit = after;
        assert_eq!(stop_at(&mut p, &mut fit, &(-n), &q), 0.0);
    }

    #[test]
    fn the_work_of_gravity_lets_the_energy_grow() {
        let mut p = spinning_cube(Vector3::zeros(), Vector3::new(0.0, -1.0, 0.0));
        let mut passivity = Passivity::default();
        let g = Vector3::new(0.0, -9.81, 0.0);
        let mut fit = p.rigid_fit().expect("fit");
        passivity.run(1, &mut p, &mut fit, &g, 0.0);
        passivity.end_substep();
        // Falling 0.1 m at 1.5 m/s: ½ M (1.5² − 1²) = 0.625 M < M g 0.1 = 0.981 M.
        for i in 0..p.len() {
            p.positions_mut()[i].y -= 0.1;
            p.velocities_mut()[i].y = -1.5;
        }
        let mut fit = p.rigid_fit().expect("fit");
        assert_eq!(passivity.run(1, &mut p, &mut fit, &g, 0.0), 0.0);
        passivity.end_substep();
        // Rising 0.1 m instead leaves only ½ M 1.5² − M g 0.1 = 0.144 M.
        for i in 0..p.len() {
            p.positions_mut()[i].y += 0.1;
        }
        let mut fit = p.rigid_fit().expect("fit");
        let removed = passivity.run(1, &mut p, &mut fit, &g, 0.0);
        let m = fit.mass;
        assert!((removed - 0.981 * m).abs() < 1e-3 * m, "{removed}");
        let v = p.linear_momentum() / m;
        assert!((0.5 * v.norm_squared() - 0.144).abs() < 2e-3, "{v}");
    }
}
