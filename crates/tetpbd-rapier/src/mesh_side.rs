//! Which side of a triangle mesh collider a particle belongs on.
//!
//! A rigid body rests on a triangle mesh whatever its winding: rapier's contacts take the
//! triangle's side from where the other shape is. A particle has no extent, so the coupling
//! decides its side from **where it came from**: a mesh that is not a closed, consistently
//! outward-wound surface ([`InsideRule::ThinMesh`]: open meshes such as a ground of two
//! triangles, and closed meshes wound inwards) is a thin sheet with two outsides, and a
//! particle is inside it when it stands on the other side of the sheet than at the start of
//! the substep (against the collider's pose then; the contact's `side`). The particle's own
//! path carries it across a sheet only through a swept contact (`ccd` module docs), which
//! stops it at the side it came from. Only a closed mesh whose triangles all point out
//! (every edge shared by exactly two triangles, in opposite directions, positive enclosed
//! volume) has an inside: with pseudo-normals (`TriMeshFlags::ORIENTED`,
//! `FIX_INTERNAL_EDGES`) parry decides it ([`InsideRule::Solid`]), without them the face a
//! point projects onto does ([`InsideRule::OneSidedMesh`]). A particle created inside such a
//! mesh is pushed out; one created below a thin sheet stays below it.
//!
//! The rule of each mesh is computed once (an edge sort, `O(t log t)` for `t` triangles) and
//! kept across frames by collider handle and mesh storage ([`MeshRules`]).

use rapier3d::geometry::ColliderHandle;
use rapier3d::parry::shape::{Shape, TriMesh};

use crate::rigid::shape_query::InsideRule;

/// The inside rule of a triangle mesh (module docs).
pub(crate) fn trimesh_rule(mesh: &TriMesh) -> InsideRule {
    if !closed_outwards(mesh.vertices(), mesh.indices()) {
        InsideRule::ThinMesh
    } else if mesh.pseudo_normals().is_some() {
        InsideRule::Solid
    } else {
        InsideRule::OneSidedMesh
    }
}

/// Whether the triangles form closed surfaces wound outwards: every edge used by exactly two
/// triangles in opposite directions, and a positive enclosed volume.
pub(crate) fn closed_outwards(vertices: &[rapier3d::math::Vector], indices: &[[u32; 3]]) -> bool {
    if indices.is_empty() {
        return false;
    }
    // Directed edges; a closed consistently wound surface has each reversed edge exactly once.
    let mut edges: Vec<(u32, u32)> = indices
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    edges.sort_unstable();
    if edges.windows(2).any(|w| w[0] == w[1]) {
        return false;
    }
    let paired = edges
        .iter()
        .all(|&(a, b)| a != b && edges.binary_search(&(b, a)).is_ok());
    if !paired {
        return false;
    }
    let volume: f64 = indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize].as_dvec3());
            a.dot(b.cross(c))
        })
        .sum();
    volume > 0.0
}

/// A mesh collider: its handle's raw parts, the address of its vertices, its triangle count.
type MeshKey = ((u32, u32), usize, usize);

/// Inside rules of the meshes seen, by collider handle and mesh storage (kept across frames;
/// a collider whose shape was replaced gets its rule again).
#[derive(Clone, Debug, Default)]
pub(crate) struct MeshRules {
    /// `(collider handle, address of the mesh's vertices, triangle count)` and its rule,
    /// sorted.
    rules: Vec<(MeshKey, InsideRule)>,
}

impl MeshRules {
    /// The rule of collider `handle` with shape `shape`.
    pub fn rule(&mut self, handle: ColliderHandle, shape: &dyn Shape) -> InsideRule {
        let Some(mesh) = shape.as_trimesh() else {
            return InsideRule::of(shape);
        };
        let key = (
            handle.into_raw_parts(),
            mesh.vertices().as_ptr() as usize,
            mesh.indices().len(),
        );
        match self.rules.binary_search_by_key(&key, |r| r.0) {
            Ok(k) => self.rules[k].1,
            Err(k) => {
                // Drop an older entry of the same collider (its shape was replaced).
                let rule = trimesh_rule(mesh);
                let k = if k > 0 && self.rules[k - 1].0 .0 == key.0 {
                    self.rules.remove(k - 1);
                    k - 1
                } else if k < self.rules.len() && self.rules[k].0 .0 == key.0 {
                    self.rules.remove(k);
                    k
                } else {
                    k
                };
                self.rules.insert(k, (key, rule));
                rule
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d::math::Vector;

    fn tetrahedron() -> (Vec<Vector>, Vec<[u32; 3]>) {
        let v = vec![
            Vector::new(0.0, 0.0, 0.0),
            Vector::new(1.0, 0.0, 0.0),
            Vector::new(0.0, 1.0, 0.0),
            Vector::new(0.0, 0.0, 1.0),
        ];
        (v, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    }

    #[test]
    fn a_closed_outward_surface_is_recognised() {
        let (v, idx) = tetrahedron();
        assert!(closed_outwards(&v, &idx));
    }

    #[test]
    fn inward_open_and_inconsistent_surfaces_are_not() {
        let (v, idx) = tetrahedron();
        let inward: Vec<[u32; 3]> = idx.iter().map(|t| [t[0], t[2], t[1]]).collect();
        assert!(!closed_outwards(&v, &inward));
        assert!(!closed_outwards(&v, &idx[..3]));
        let mut mixed = idx.clone();
        mixed[0] = [0, 1, 2];
        assert!(!closed_outwards(&v, &mixed));
        assert!(!closed_outwards(&v, &[]));
    }
}
