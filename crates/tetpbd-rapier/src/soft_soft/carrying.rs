//! Shock propagation between soft bodies: a soft body resting on an immovable support that
//! carries a much heavier soft body holds still under it.
//!
//! One Gauss–Seidel iteration per substep cannot carry a large mass ratio through a contact
//! between two soft bodies, as it cannot through a soft body under a heavy rigid one
//! (`heavy_loads` module docs): a 1.5 t soft cube landing on a 24 kg soft slab on the ground
//! pushes the slab's surface particles (their share of the correction is `w_light /
//! (w_light + w_heavy)`, 98 %) several centimetres into the slab every substep, the slab's
//! own constraints and the ground push them back within the next substep, and the contact
//! pushes them down again. The surface then moves by centimetres per substep in both
//! directions: `Δx/h` of hundreds of m/s at 40 substeps, with the contact and ground pushes
//! counted as external work in the correction-energy budget. The slab shot out from under
//! the cube at up to 240 m/s with 70 kJ gained (`docs/decisions/soft-soft-carrying.md`).
//!
//! So, as Guendelman et al. (2003) propagate shocks through a stack, a contact between a
//! particle and a triangle of two different bodies is *carried* when
//!
//! * the lighter side's body touches an immovable support in this substep (the coupling
//!   reports it: a fixed or kinematic collider, or a supported rigid body; the heavier
//!   body may rest on the support beside it too),
//! * the heavier side is at least [`crate::StackingSettings::mass_ratio`] times
//!   heavier (the particle's mass against the triangle's mean particle mass), and
//! * the contact normal, taken from the lighter to the heavier side, points within 60° of
//!   up (against gravity): the lighter body carries the heavier one's weight.
//!
//! A carried contact treats the lighter side as immovable (inverse masses 0) in its
//! projection, its friction and its velocity pass: the heavy body is pushed out of the
//! surface entirely and comes to rest on it as on a frozen one, and the light body is never
//! squeezed by it. The correction a converged solve would give the light body is left out,
//! so a very compliant light body is squashed less under a heavy load than it should be,
//! and momentum is not conserved: what is left out is what the support takes, which is why
//! the light body must rest on one. Contacts of bodies of similar masses, of bodies neither
//! of which rests on a support, or side by side, are untouched. A bare
//! [`crate::SoftContacts`] (no coupling) has no supports and never carries.
//!
//! The light side is held, not immovable: where its own motion in the substep drove it into
//! the heavy side (a squeezed light body springing back), that part of the violation is
//! handed to the heavy side at no more than the separation speed
//! ([`crate::SoftContactSettings::max_separation_speed`]). Otherwise a recoil of the light
//! body's particles became the heavy body's velocity at any speed: a 218 kg body on a squeezed
//! 4.7 kg one gained 35 kJ in a frame (the seeded random-scene search, scene 44).

use nalgebra::Vector3;

/// Largest angle between the carrying normal and up, as its cosine (60°).
const CARRY_COS: f32 = 0.5;

/// Which bodies of a frame rest on an immovable support in the current substep, and the
/// mass ratio from which a contact is carried (module docs).
#[derive(Clone, Debug)]
pub(crate) struct Carrying {
    /// Entity bits of the soft bodies touching an immovable support (sorted), as reported
    /// by the coupling for the current substep.
    pub supported: Vec<u64>,
    /// Per frame body: whether it is in `supported` (refreshed each projection).
    pub on_support: Vec<bool>,
    /// Mass ratio from which the heavier side is carried (`f32::INFINITY`: never).
    pub ratio: f32,
    /// Unit vector against gravity (zero without gravity: nothing is carried).
    pub up: Vector3<f32>,
}

impl Default for Carrying {
    fn default() -> Self {
        Carrying {
            supported: Vec::new(),
            on_support: Vec::new(),
            ratio: f32::INFINITY,
            up: Vector3::zeros(),
        }
    }
}

impl Carrying {
    /// Whether any body of the frame could carry another.
    pub fn any(&self) -> bool {
        self.ratio.is_finite() && self.on_support.iter().any(|&s| s)
    }

    /// The inverse masses `[w_p, w_a, w_b, w_c]` (1/kg) a contact of the particle `p` of
    /// body `bp` against the triangle of body `bt` uses, with unit normal `n` pointing from
    /// the triangle's body to the particle's: the particles' own inverse masses, or zero on
    /// the side that carries (module docs).
    pub fn weights(&self, bp: usize, bt: usize, w: [f32; 4], n: &Vector3<f32>) -> [f32; 4] {
        if bp == bt || !self.ratio.is_finite() {
            return w;
        }
        let (sp, st) = (self.on_support[bp], self.on_support[bt]);
        let w_tri = (w[1] + w[2] + w[3]) / 3.0;
        let up = n.dot(&self.up);
        if st && w[0] > 0.0 && w[0] * self.ratio <= w_tri && up >= CARRY_COS {
            // The triangle's body rests on the support and carries the heavy particle.
            return [w[0], 0.0, 0.0, 0.0];
        }
        if sp && w_tri > 0.0 && w_tri * self.ratio <= w[0] && -up >= CARRY_COS {
            // The particle's body rests on the support and carries the heavy triangle.
            return [0.0, w[1], w[2], w[3]];
        }
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn carrying(on_support: [bool; 2]) -> Carrying {
        Carrying {
            supported: Vec::new(),
            on_support: on_support.to_vec(),
            ratio: 10.0,
            up: Vector3::y(),
        }
    }

    #[test]
    fn a_supported_light_body_holds_a_heavy_one_above_it() {
        let w = [0.1, 2.0, 2.0, 2.0];
        // Heavy particle of body 0 on the triangle of supported body 1, normal up.
        let c = carrying([false, true]);
        assert_eq!(c.weights(0, 1, w, &Vector3::y()), [0.1, 0.0, 0.0, 0.0]);
        // Sideways contact: untouched.
        assert_eq!(c.weights(0, 1, w, &Vector3::x()), w);
        // The heavy body resting on the support too (beside the light one): still held.
        let both = carrying([true, true]);
        assert_eq!(both.weights(0, 1, w, &Vector3::y()), [0.1, 0.0, 0.0, 0.0]);
        // The light body on no support: untouched.
        assert_eq!(carrying([true, false]).weights(0, 1, w, &Vector3::y()), w);
        assert_eq!(carrying([false, false]).weights(0, 1, w, &Vector3::y()), w);
        // Similar masses: untouched.
        let even = [1.0, 2.0, 2.0, 2.0];
        assert_eq!(c.weights(0, 1, even, &Vector3::y()), even);
    }

    #[test]
    fn a_supported_light_particle_holds_a_heavy_triangle_above_it() {
        let w = [2.0, 0.1, 0.1, 0.1];
        let c = carrying([true, false]);
        // The normal points from the heavy triangle (above) down to the light particle.
        assert_eq!(c.weights(0, 1, w, &-Vector3::y()), [0.0, 0.1, 0.1, 0.1]);
        assert_eq!(c.weights(0, 1, w, &Vector3::y()), w);
    }
}
