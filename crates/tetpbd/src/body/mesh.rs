//! Tetrahedra and their boundary surface.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use nalgebra::Vector3;

use crate::constraints::signed_volume;

/// The tetrahedra of one soft body with their signed rest volumes (a hecs component).
///
/// Indices refer to the body's [`crate::Particles`]. The tetrahedra are stored in solver
/// order (colour classes: items of one class share no particle), not in the order they were given:
/// [`Tetrahedra::source`] maps each back to its index in the input mesh. A tetrahedron may have either
/// orientation; its rest volume keeps the sign it was built with, and it counts as
/// inverted when its current signed volume has the opposite sign.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Tetrahedra {
    pub(crate) indices: Vec<[u32; 4]>,
    pub(crate) rest_volumes: Vec<f32>,
    pub(crate) source: Vec<u32>,
    /// Colour classes of `indices` (tetrahedra of one class share no particle).
    pub(crate) classes: crate::ordering::colouring::ColourClasses,
    /// The slivers among `indices`, by index: their orientation constraints are projected
    /// once more after the edges ([`crate::stabilisation::sliver_orientation`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pub(crate) slivers: Vec<u32>,
}

impl Tetrahedra {
    /// Number of tetrahedra.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// `true` when there are no tetrahedra.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// The sweep order of the tetrahedra: colour classes, tasks and phases (see
    /// [`crate::ordering::colouring::ColourClasses`]).
    pub fn classes(&self) -> &crate::ordering::colouring::ColourClasses {
        &self.classes
    }

    /// Particle indices of each tetrahedron.
    pub fn indices(&self) -> &[[u32; 4]] {
        &self.indices
    }

    /// For each stored tetrahedron, its index in the mesh the body was built from.
    pub fn source(&self) -> &[u32] {
        &self.source
    }

    /// Signed rest volume of each tetrahedron, m³.
    pub fn rest_volumes(&self) -> &[f32] {
        &self.rest_volumes
    }

    /// Signed volume of tetrahedron `t` at `positions`, m³.
    pub fn volume_at(&self, t: usize, positions: &[Vector3<f32>]) -> f32 {
        let [a, b, c, d] = self.indices[t].map(|i| positions[i as usize]);
        signed_volume(&a, &b, &c, &d)
    }

    /// Sum of the signed volumes at `positions` divided by the sum of the rest volumes; 1 at
    /// rest. Both sums are signed, so an inverted body reads negative.
    pub fn volume_ratio(&self, positions: &[Vector3<f32>]) -> f32 {
        let rest: f64 = self.rest_volumes.iter().map(|v| f64::from(v.abs())).sum();
        let now: f64 = (0..self.len())
            .map(|t| {
                f64::from(self.volume_at(t, positions)) * f64::from(self.rest_volumes[t].signum())
            })
            .sum();
        if rest > 0.0 {
            (now / rest) as f32
        } else {
            1.0
        }
    }

    /// Number of tetrahedra whose signed volume at `positions` has the opposite sign of
    /// (or is zero against) their rest volume.
    pub fn count_inverted(&self, positions: &[Vector3<f32>]) -> usize {
        (0..self.len())
            // A non-finite volume counts as inverted (NaN compares false).
            .filter(|&t| {
                let product = self.volume_at(t, positions) * self.rest_volumes[t];
                product.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
            })
            .count()
    }
}

/// The boundary of a tetrahedral mesh: faces used by exactly one tetrahedron
/// (a hecs component, built with the body).
///
/// Triangles are wound so that their normal `(b − a) × (c − a)` points out of the body
/// at rest. Collision code uses it; the core solver does not.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Surface {
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) vertices: Vec<u32>,
}

impl Surface {
    /// Outward-wound boundary triangles.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Sorted indices of the particles on the boundary.
    pub fn vertices(&self) -> &[u32] {
        &self.vertices
    }

    /// Extracts the boundary of `tets` (deterministic: sorted, no hash maps).
    pub fn from_tetrahedra(tets: &[[u32; 4]], positions: &[Vector3<f32>]) -> Surface {
        // Faces opposite each corner, wound outward for a positively oriented tetrahedron.
        const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
        let mut faces: Vec<([u32; 3], [u32; 3])> = Vec::with_capacity(tets.len() * 4);
        for tet in tets {
            let positive = {
                let [a, b, c, d] = tet.map(|i| positions[i as usize]);
                signed_volume(&a, &b, &c, &d) >= 0.0
            };
            for f in FACES {
                let mut tri = f.map(|k| tet[k]);
                if !positive {
                    tri.swap(1, 2);
                }
                let mut key = tri;
                key.sort_unstable();
                faces.push((key, tri));
            }
        }
        faces.sort_unstable();
        let mut triangles = Vec::new();
        let mut i = 0;
        while i < faces.len() {
            let mut j = i + 1;
            while j < faces.len() && faces[j].0 == faces[i].0 {
                j += 1;
            }
            if j - i == 1 {
                triangles.push(faces[i].1);
            }
            i = j;
        }
        let mut vertices: Vec<u32> = triangles.iter().flatten().copied().collect();
        vertices.sort_unstable();
        vertices.dedup();
        Surface {
            triangles,
            vertices,
        }
    }
}
