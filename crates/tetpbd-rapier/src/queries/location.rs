//! [`SoftLocation`]: a material point of a soft body, as particles and weights.

/// Where on (or in) a soft body a query answered: a point of a surface triangle or of a
/// tetrahedron, given by the particles of that element and the point's barycentric weights
/// (each in `[0, 1]`, summing to 1). The point moves with the body: at any later time it is
/// `Σ wᵢ xᵢ` over those particles' positions, which is what a grab or an impulse at the
/// point uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SoftLocation {
    /// A point of a boundary triangle.
    Surface {
        /// Index into the body's `Surface::triangles()`.
        triangle: u32,
        /// The triangle's particles (indices into the body's `Particles`).
        particles: [u32; 3],
        /// Barycentric weights of the three particles.
        barycentric: [f32; 3],
    },
    /// A point inside a tetrahedron.
    Interior {
        /// Index into the body's `Tetrahedra::indices()`.
        tet: u32,
        /// The tetrahedron's particles (indices into the body's `Particles`).
        particles: [u32; 4],
        /// Barycentric weights of the four particles.
        barycentric: [f32; 4],
    },
}

impl SoftLocation {
    /// The particles of the element and their weights, as `(particle, weight)` pairs.
    pub fn weights(&self) -> impl Iterator<Item = (u32, f32)> + '_ {
        let (p, w): (&[u32], &[f32]) = match self {
            SoftLocation::Surface {
                particles,
                barycentric,
                ..
            } => (particles, barycentric),
            SoftLocation::Interior {
                particles,
                barycentric,
                ..
            } => (particles, barycentric),
        };
        p.iter().copied().zip(w.iter().copied())
    }

    /// The surface triangle, for a surface location.
    pub fn triangle(&self) -> Option<u32> {
        match self {
            SoftLocation::Surface { triangle, .. } => Some(*triangle),
            SoftLocation::Interior { .. } => None,
        }
    }

    /// The tetrahedron, for an interior location.
    pub fn tet(&self) -> Option<u32> {
        match self {
            SoftLocation::Interior { tet, .. } => Some(*tet),
            SoftLocation::Surface { .. } => None,
        }
    }
}
