//! [`TriangleMesh`]: positions and triangles, the one geometry type rendering and OBJ export share.

use nalgebra::{Isometry3, Point3, Vector3};

/// A triangle soup with shared vertices, in world coordinates (m).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions, m.
    pub positions: Vec<Vector3<f32>>,
    /// Triangles as indices into `positions`, counter-clockwise seen from outside when the
    /// source has an outside.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Appends `other`, re-indexing its triangles.
    pub fn append(&mut self, other: TriangleMesh) {
        let offset = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + offset)));
    }

    /// The mesh moved by `pose`.
    pub fn transformed(mut self, pose: &Isometry3<f32>) -> TriangleMesh {
        for p in &mut self.positions {
            *p = pose.transform_point(&Point3::from(*p)).coords;
        }
        self
    }

    /// Smallest and largest corner of the positions' bounding box, or `None` when empty.
    pub fn aabb(&self) -> Option<(Vector3<f32>, Vector3<f32>)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.inf(p), hi.sup(p))),
        )
    }
}
