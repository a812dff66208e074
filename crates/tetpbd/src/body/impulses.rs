//! Impulses on a soft body: on the whole body, at a point, and in a sphere (an explosion).
//!
//! An impulse changes velocities only: particle `i` receiving the share `Jᵢ` (N·s) moves at
//! `vᵢ + Jᵢ / mᵢ` from then on. Shares go to free particles only (a pinned particle has no
//! velocity to change), so the body's linear momentum changes by exactly the impulse given.
//!
//! At a point `p` inside tetrahedron `t` with barycentric coordinates `bₖ` (`Σ bₖ = 1`,
//! `Σ bₖ xₖ = p`), corner `k` receives `bₖ J`: the momentum changes by `J` and the angular
//! momentum about any origin by `p × J`, as for a rigid body hit at `p`. A point outside the
//! body goes to the tetrahedron that holds it most nearly ([`MaterialPoint::locate`]).

use nalgebra::Vector3;

use crate::body::material_point::MaterialPoint;
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::error::StateError;

/// Where [`Particles::apply_impulse_at_point`] put an impulse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointImpulse {
    /// Index of the tetrahedron (in [`Tetrahedra::indices`]) that took it.
    pub tetrahedron: usize,
    /// The share of each of its corners (sums to 1 over the free corners).
    pub weights: [f32; 4],
    /// Whether the point lies inside that tetrahedron.
    pub inside: bool,
}

impl Particles {
    /// Gives the body the impulse `impulse` (N·s) spread over its free particles in
    /// proportion to their masses: every free particle's velocity changes by `J / M_free`.
    pub fn apply_impulse(&mut self, impulse: Vector3<f32>) -> Result<(), StateError> {
        finite(&impulse, "impulse")?;
        self.written = true;
        let free: f64 = self.free_masses().map(f64::from).sum();
        if free <= 0.0 {
            return Err(StateError::AllPinned);
        }
        let dv = (impulse.cast::<f64>() / free).cast::<f32>();
        for (v, w) in self.velocities.iter_mut().zip(&self.inv_masses) {
            if *w > 0.0 {
                *v += dv;
            }
        }
        Ok(())
    }

    /// Gives the body the impulse `impulse` (N·s) at `point` (m), spread over the corners of
    /// the tetrahedron holding it by their barycentric coordinates (see the module docs).
    pub fn apply_impulse_at_point(
        &mut self,
        tetrahedra: &Tetrahedra,
        impulse: Vector3<f32>,
        point: Vector3<f32>,
    ) -> Result<PointImpulse, StateError> {
        finite(&impulse, "impulse")?;
        self.written = true;
        let (at, inside) = MaterialPoint::locate(self, tetrahedra, point)?;
        let (corners, weights) = at.free_shares(self, tetrahedra)?;
        for (w, &i) in weights.iter().zip(&corners) {
            self.velocities[i] += impulse * (*w * self.inv_masses[i]);
        }
        Ok(PointImpulse {
            tetrahedron: at.tetrahedron(),
            weights,
            inside,
        })
    }

    /// An explosion at `centre` (m): every free particle within `radius` (m) gains the
    /// velocity `speed · (1 − r/R)` (m/s) away from the centre, `r` its distance from it.
    /// Returns the impulse the body received, N·s.
    pub fn apply_radial_impulse(
        &mut self,
        centre: Vector3<f32>,
        radius: f32,
        speed: f32,
    ) -> Result<Vector3<f32>, StateError> {
        finite(&centre, "centre")?;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(StateError::BadParameter {
                what: "radius",
                value: radius,
            });
        }
        if !speed.is_finite() {
            return Err(StateError::BadParameter {
                what: "speed",
                value: speed,
            });
        }
        self.written = true;
        let mut total = Vector3::zeros();
        for i in 0..self.positions.len() {
            let d = self.positions[i] - centre;
            let r = d.norm();
            if self.inv_masses[i] == 0.0 || r >= radius || r == 0.0 {
                continue;
            }
            let dv = d * (speed * (1.0 - r / radius) / r);
            self.velocities[i] += dv;
            total += dv * self.masses[i];
        }
        Ok(total)
    }

    pub(crate) fn free_masses(&self) -> impl Iterator<Item = f32> + '_ {
        self.masses
            .iter()
            .zip(&self.inv_masses)
            .filter(|(_, w)| **w > 0.0)
            .map(|(m, _)| *m)
    }
}

pub(crate) fn finite(v: &Vector3<f32>, what: &'static str) -> Result<(), StateError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(StateError::NonFinite { what, index: 0 })
    }
}
