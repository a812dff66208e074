//! Coulomb friction between a rigid point and a soft surface triangle it touches
//! ([`crate::contacts::corner`]): the rigid point is the first side, the triangle's point
//! with the contact's barycentric weights the second ([`crate::response::friction`]).

use nalgebra::{Point3, Vector3};
use tetpbd::Particles;

use crate::contacts::corner::CornerContact;
use crate::response::friction::{positional_friction, ContactStencil, Coulomb};
use crate::rigid::body::BodyProxy;

/// A rigid point `v` (first side) against a soft triangle's point with barycentric weights
/// `beta` (second side), for friction.
struct PointOnTriangle<'s> {
    p: &'s mut Particles,
    idx: [usize; 3],
    beta: [f32; 3],
    bodies: &'s mut [BodyProxy],
    body: Option<usize>,
    v: Vector3<f32>,
}

impl ContactStencil for PointOnTriangle<'_> {
    fn relative_motion(&self) -> Vector3<f32> {
        let (p, idx, beta) = (&*self.p, self.idx, self.beta);
        let tri_motion: Vector3<f32> = (0..3)
            .map(|j| (p.positions()[idx[j]] - p.prev_positions()[idx[j]]) * beta[j])
            .sum();
        let body_motion = self.body.map_or(Vector3::zeros(), |b| {
            let rb = &self.bodies[b];
            let local = rb.pose.inverse_transform_point(&Point3::from(self.v));
            (rb.pose * local).coords - (rb.prev * local).coords
        });
        body_motion - tri_motion
    }

    fn inv_mass(&self, t: &Vector3<f32>) -> f32 {
        let w = self.idx.map(|i| self.p.inv_masses()[i]);
        let w_body = self
            .body
            .map_or(0.0, |b| self.bodies[b].inv_mass_at(&self.v, t));
        (0..3)
            .map(|j| w[j] * self.beta[j] * self.beta[j])
            .sum::<f32>()
            + w_body
    }

    fn apply(&mut self, t: &Vector3<f32>, dl: f32) {
        let w = self.idx.map(|i| self.p.inv_masses()[i]);
        let x = self.p.positions_mut();
        for j in 0..3 {
            x[self.idx[j]] += t * (w[j] * self.beta[j] * dl);
        }
        if let Some(b) = self.body {
            self.bodies[b].apply_position_impulse(&(-t * dl), &self.v);
        }
    }
}

/// Coulomb friction between the rigid point `v` and the triangle
/// ([`crate::response::friction`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn friction(
    k: &mut CornerContact,
    p: &mut Particles,
    idx: [usize; 3],
    beta: [f32; 3],
    bodies: &mut [BodyProxy],
    body: Option<usize>,
    v: &Vector3<f32>,
    n: &Vector3<f32>,
) {
    let mut stencil = PointOnTriangle {
        p,
        idx,
        beta,
        bodies,
        body,
        v: *v,
    };
    let coulomb = Coulomb {
        lambda_n: k.lambda_n,
        mu_s: k.mu_s,
        mu_d: k.mu_d,
    };
    if let Some((t, dl)) = positional_friction(&mut stencil, n, coulomb, &mut k.lambda_t) {
        k.sub_impulse += t * dl;
    }
}
