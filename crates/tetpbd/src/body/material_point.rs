//! [`MaterialPoint`]: a point of a body's material, named by the tetrahedron holding it and
//! its barycentric coordinates there, so it moves with the body as the body deforms.
//!
//! A point `p` inside tetrahedron `t` (corners `x₀ … x₃`) has coordinates `bₖ` with
//! `Σ bₖ = 1` and `Σ bₖ xₖ = p` (ratios of signed volumes). A point outside the body goes to
//! the tetrahedron that holds it most nearly (the largest smallest coordinate), its
//! negative coordinates set to 0 and the rest renormalised: the material point is then the nearest
//! point of that tetrahedron's interior in barycentric terms, on the body's boundary.
//! Impulses, forces and grabs at a point all use this one rule.

use nalgebra::Vector3;

use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::constraints::signed_volume;
use crate::error::StateError;

/// A point of a body's material: a tetrahedron (index in [`Tetrahedra::indices`]) and the
/// point's barycentric coordinates in it (each in `[0, 1]`, summing to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MaterialPoint {
    tetrahedron: usize,
    coords: [f32; 4],
}

impl MaterialPoint {
    /// The material point at barycentric coordinates `coords` of tetrahedron `tetrahedron`.
    ///
    /// Errors: [`StateError::TetrahedronOutOfRange`] for an index the body does not have;
    /// [`StateError::BadBarycentric`] for coordinates that are not finite, negative beyond
    /// `1e-4`, or do not sum to 1 within `1e-3` (they are then clamped and renormalised).
    pub fn new(
        tetrahedra: &Tetrahedra,
        tetrahedron: usize,
        coords: [f32; 4],
    ) -> Result<MaterialPoint, StateError> {
        let len = tetrahedra.len();
        if tetrahedron >= len {
            return Err(StateError::TetrahedronOutOfRange {
                index: tetrahedron,
                len,
            });
        }
        let sum: f32 = coords.iter().sum();
        let bad = coords.iter().any(|b| !b.is_finite() || *b < -1e-4) || (sum - 1.0).abs() > 1e-3;
        if bad {
            return Err(StateError::BadBarycentric { coords });
        }
        let clamped = coords.map(|b| f64::from(b.max(0.0)));
        let s: f64 = clamped.iter().sum();
        Ok(MaterialPoint {
            tetrahedron,
            coords: clamped.map(|b| (b / s) as f32),
        })
    }

    /// The material point at `point` (m) in the body's current shape (see the module docs
    /// for a point outside it), and whether `point` lies inside the body.
    ///
    /// Errors: [`StateError::NonFinite`] for a non-finite point,
    /// [`StateError::NoTetrahedra`] for a body without a tetrahedron (or only flat ones),
    /// [`StateError::ParticleOutOfRange`] when `tetrahedra` refer to particles `particles`
    /// does not have.
    pub fn locate(
        particles: &Particles,
        tetrahedra: &Tetrahedra,
        point: Vector3<f32>,
    ) -> Result<(MaterialPoint, bool), StateError> {
        if !point.iter().all(|c| c.is_finite()) {
            return Err(StateError::NonFinite {
                what: "point",
                index: 0,
            });
        }
        let (tetrahedron, b) = holding_tetrahedron(particles, tetrahedra, &point)?;
        let inside = b.iter().all(|b| *b >= 0.0);
        let clamped = b.map(|b| b.max(0.0));
        let s: f64 = clamped.iter().sum();
        let coords = if s > 0.0 {
            clamped.map(|b| (b / s) as f32)
        } else {
            [0.25; 4]
        };
        Ok((
            MaterialPoint {
                tetrahedron,
                coords,
            },
            inside,
        ))
    }

    /// The same point in tetrahedron `t` (the same tetrahedron renumbered, after a split).
    pub(crate) fn renumbered(self, t: usize) -> MaterialPoint {
        MaterialPoint {
            tetrahedron: t,
            ..self
        }
    }

    /// Index of the tetrahedron holding the point.
    pub fn tetrahedron(&self) -> usize {
        self.tetrahedron
    }

    /// Barycentric coordinates in that tetrahedron (in `[0, 1]`, summing to 1).
    pub fn coords(&self) -> [f32; 4] {
        self.coords
    }

    /// The corners' particle indices, or `None` when the point's tetrahedron or one of its
    /// particles is not in the body (a material point of another body).
    pub fn corners(&self, particles: &Particles, tetrahedra: &Tetrahedra) -> Option<[usize; 4]> {
        let tet = tetrahedra.indices().get(self.tetrahedron)?;
        let corners = tet.map(|i| i as usize);
        corners
            .iter()
            .all(|i| *i < particles.len())
            .then_some(corners)
    }

    /// Where the point is now, `Σ bₖ xₖ` (m); `None` as for [`MaterialPoint::corners`].
    pub fn position(&self, particles: &Particles, tetrahedra: &Tetrahedra) -> Option<Vector3<f32>> {
        let corners = self.corners(particles, tetrahedra)?;
        let x = particles.positions();
        Some(
            corners
                .iter()
                .zip(&self.coords)
                .fold(Vector3::zeros(), |acc, (i, b)| acc + x[*i] * *b),
        )
    }

    /// The shares of a load applied at the point: the coordinates over the free corners,
    /// renormalised to sum to 1 (a pinned corner takes none), with the corners' particles.
    ///
    /// Errors: [`StateError::AllPinned`] when every corner with a share is pinned;
    /// [`StateError::TetrahedronOutOfRange`] as for [`MaterialPoint::corners`].
    pub fn free_shares(
        &self,
        particles: &Particles,
        tetrahedra: &Tetrahedra,
    ) -> Result<([usize; 4], [f32; 4]), StateError> {
        let corners =
            self.corners(particles, tetrahedra)
                .ok_or(StateError::TetrahedronOutOfRange {
                    index: self.tetrahedron,
                    len: tetrahedra.len(),
                })?;
        let w = particles.inv_masses();
        let mut shares = self.coords.map(f64::from);
        for (s, &i) in shares.iter_mut().zip(&corners) {
            if w[i] == 0.0 {
                *s = 0.0;
            }
        }
        let sum: f64 = shares.iter().sum();
        if sum <= 0.0 {
            return Err(StateError::AllPinned);
        }
        Ok((corners, shares.map(|s| (s / sum) as f32)))
    }
}

/// The tetrahedron holding `p` most nearly and `p`'s barycentric coordinates in it (f64).
fn holding_tetrahedron(
    particles: &Particles,
    tetrahedra: &Tetrahedra,
    p: &Vector3<f32>,
) -> Result<(usize, [f64; 4]), StateError> {
    let x = particles.positions();
    let n = x.len();
    let mut best: Option<(usize, [f64; 4], f64)> = None;
    for (t, tet) in tetrahedra.indices().iter().enumerate() {
        if let Some(&i) = tet.iter().find(|i| **i as usize >= n) {
            return Err(StateError::ParticleOutOfRange {
                index: i as usize,
                len: n,
            });
        }
        let Some(b) = barycentric(tet.map(|i| x[i as usize]), p) else {
            continue;
        };
        let smallest = b.iter().copied().fold(f64::INFINITY, f64::min);
        if best.is_none_or(|(_, _, s)| smallest > s) {
            best = Some((t, b, smallest));
        }
    }
    best.map(|(t, b, _)| (t, b)).ok_or(StateError::NoTetrahedra)
}

/// Barycentric coordinates of `p` in the tetrahedron `x` (ratios of signed volumes), or `None`
/// for a flat tetrahedron.
fn barycentric(x: [Vector3<f32>; 4], p: &Vector3<f32>) -> Option<[f64; 4]> {
    // Relative to the first corner, in f64: far from the origin the f32 coordinates would
    // cancel.
    let o = x[0].cast::<f64>();
    let x = x.map(|c| c.cast::<f64>() - o);
    let p = &(p.cast::<f64>() - o);
    let v = signed_volume::<f64>;
    let total = v(&x[0], &x[1], &x[2], &x[3]);
    if total == 0.0 || !total.is_finite() {
        return None;
    }
    Some([
        v(p, &x[1], &x[2], &x[3]) / total,
        v(&x[0], p, &x[2], &x[3]) / total,
        v(&x[0], &x[1], p, &x[3]) / total,
        v(&x[0], &x[1], &x[2], p) / total,
    ])
}
