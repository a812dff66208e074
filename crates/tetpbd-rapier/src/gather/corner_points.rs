//! The rigid points of a shape for the rigid-point–soft-triangle contacts (`contacts::corner`
//! module docs): polyhedron vertices, the vertices of triangle meshes and heightfields near the
//! soft body, and a compound's parts by the same rules, each with its part's border radius.

use nalgebra::Vector3;
use rapier3d::geometry::Aabb;
use rapier3d::parry::shape::Shape;

use crate::convert::{to_glam, to_na};

/// The rigid points of a shape, in its local frame: scratch space whose capacity is reused
/// from one collider to the next, so gathering allocates nothing once warm.
#[derive(Clone, Debug, Default)]
pub(crate) struct Corners {
    /// Each point with the extra thickness of its (rounded) part, m.
    pub points: Vec<(Vector3<f32>, f32)>,
    /// Some points are vertices of a triangle mesh or heightfield: many, so each is only
    /// paired with the soft triangles near it.
    pub from_mesh: bool,
}

impl Corners {
    /// Replaces the points with the corners of `shape`. A triangle mesh or heightfield
    /// contributes the vertices of its triangles inside `near` (local frame).
    pub fn fill(&mut self, shape: &dyn Shape, near: &Aabb) {
        self.points.clear();
        self.from_mesh = append_corners(shape, near, &mut self.points);
    }
}

/// Appends the corners of `shape` to `out`; returns whether some are mesh vertices.
fn append_corners(shape: &dyn Shape, near: &Aabb, out: &mut Vec<(Vector3<f32>, f32)>) -> bool {
    let cuboid_corners = |h: Vector3<f32>, extra: f32, out: &mut Vec<(Vector3<f32>, f32)>| {
        out.extend((0..8).map(|k| {
            let c = Vector3::new(
                if k & 1 == 0 { -h.x } else { h.x },
                if k & 2 == 0 { -h.y } else { h.y },
                if k & 4 == 0 { -h.z } else { h.z },
            );
            (c, extra)
        }));
    };
    if let Some(c) = shape.as_cuboid() {
        cuboid_corners(to_na(c.half_extents), 0.0, out);
    } else if let Some(c) = shape.as_round_cuboid() {
        cuboid_corners(to_na(c.inner_shape.half_extents), c.border_radius, out);
    } else if let Some(c) = shape.as_convex_polyhedron() {
        out.extend(c.points().iter().map(|p| (to_na(*p), 0.0)));
    } else if let Some(c) = shape.as_round_convex_polyhedron() {
        let r = c.border_radius;
        out.extend(c.inner_shape.points().iter().map(|p| (to_na(*p), r)));
    } else if let Some(t) = shape.as_triangle() {
        out.extend([t.a, t.b, t.c].map(|v| (to_na(v), 0.0)));
    } else if let Some(mesh) = shape.as_trimesh() {
        let first = out.len();
        for t in mesh.bvh().intersect_aabb(near) {
            let tri = mesh.triangle(t);
            out.extend([tri.a, tri.b, tri.c].map(|v| (to_na(v), 0.0)));
        }
        dedup_mesh_vertices(out, first);
        return true;
    } else if let Some(hf) = shape.as_heightfield() {
        let first = out.len();
        hf.map_elements_in_local_aabb(near, &mut |_, tri| {
            out.extend([tri.a, tri.b, tri.c].map(|v| (to_na(v), 0.0)));
        });
        dedup_mesh_vertices(out, first);
        return true;
    } else if let Some(compound) = shape.as_compound() {
        // The corners of every part, in the compound's frame, each with its part's radius.
        let mut from_mesh = false;
        for (pose, part) in compound.shapes() {
            let part_near = near.transform_by(&pose.inverse());
            let first = out.len();
            from_mesh |= append_corners(part.as_ref(), &part_near, out);
            for (c, _) in &mut out[first..] {
                *c = to_na(pose.transform_point(to_glam(c)));
            }
        }
        return from_mesh;
    }
    false
}

/// Mesh vertices from `first` on without repeats (sorted by coordinates, so the order is
/// deterministic).
fn dedup_mesh_vertices(out: &mut Vec<(Vector3<f32>, f32)>, first: usize) {
    let key = |p: &(Vector3<f32>, f32)| [p.0.x.to_bits(), p.0.y.to_bits(), p.0.z.to_bits()];
    out[first..].sort_unstable_by_key(key);
    let mut keep = first;
    for k in first..out.len() {
        if keep == first || key(&out[k]) != key(&out[keep - 1]) {
            out[keep] = out[k];
            keep += 1;
        }
    }
    out.truncate(keep);
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d::geometry::SharedShape;
    use rapier3d::math::{Pose, Vector};

    #[test]
    fn compound_parts_keep_their_own_border_radius() {
        let compound = SharedShape::compound(vec![
            (
                Pose::translation(-1.0, 0.0, 0.0),
                SharedShape::cuboid(0.5, 0.5, 0.5),
            ),
            (
                Pose::translation(1.0, 0.0, 0.0),
                SharedShape::round_cuboid(0.4, 0.4, 0.4, 0.1),
            ),
        ]);
        let near = Aabb::new(Vector::splat(-10.0), Vector::splat(10.0));
        let mut c = Corners::default();
        c.fill(compound.as_ref(), &near);
        assert_eq!(c.points.len(), 16);
        assert!(!c.from_mesh);
        for (p, r) in &c.points {
            let expected = if p.x > 0.0 { 0.1 } else { 0.0 };
            assert_eq!(*r, expected, "corner {p:?}");
        }
    }

    #[test]
    fn mesh_vertices_only_near_the_soft_body_and_once_each() {
        let v = vec![
            Vector::new(0.0, 0.0, 0.0),
            Vector::new(1.0, 0.0, 0.0),
            Vector::new(0.0, 0.0, 1.0),
            Vector::new(10.0, 0.0, 10.0),
            Vector::new(11.0, 0.0, 10.0),
            Vector::new(10.0, 0.0, 11.0),
        ];
        let mesh = SharedShape::trimesh(v, vec![[0, 2, 1], [1, 2, 0], [3, 5, 4]]).expect("mesh");
        let near = Aabb::new(Vector::splat(-1.0), Vector::splat(2.0));
        let mut c = Corners::default();
        c.fill(mesh.as_ref(), &near);
        assert!(c.from_mesh);
        assert_eq!(c.points.len(), 3, "{:?}", c.points);
        assert!(c.points.iter().all(|(p, _)| p.x < 2.0 && p.z < 2.0));
    }
}
