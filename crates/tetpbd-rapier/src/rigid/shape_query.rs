//! Signed distance from a point to a rapier collider's shape, through parry's point
//! projection.
//!
//! Solid shapes (ball, cuboid, capsule, cylinder, cone, convex polyhedron, compound of
//! those, and their rounded variants) tell parry whether the point is inside. Two shapes
//! have no inside of their own and get a documented rule instead:
//!
//! * a **heightfield** is solid below its surface: a point whose offset from its projection
//!   points down (local −y) is inside;
//! * a **triangle mesh** has an inside only when it is closed and wound outwards; any other
//!   mesh (open, or wound inwards) is a thin sheet, and a point is inside it when it stands
//!   on the other side of the sheet than the side it came from (`mesh_side` module docs). A
//!   closed outward mesh without pseudo-normals (not built with `TriMeshFlags::ORIENTED` or
//!   `FIX_INTERNAL_EDGES`) is solid behind the face a point projects onto (against its
//!   counter-clockwise winding normal); with them parry answers.

use nalgebra::{Isometry3, Point3, Vector3};
use rapier3d::parry::query::PointQuery;
use rapier3d::parry::shape::Shape;

use crate::convert::{to_glam, to_na};

/// How "inside" is decided for a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum InsideRule {
    /// parry's `is_inside`.
    Solid,
    /// Below the heightfield's surface.
    HeightField,
    /// Behind the projected triangle of a closed, outward-wound mesh without pseudo-normals.
    OneSidedMesh,
    /// A thin sheet (open or inward-wound mesh): inside when on the other side than the
    /// point's reference side (`mesh_side` module docs).
    ThinMesh,
}

impl InsideRule {
    /// The rule of `shape`, a triangle mesh taken as closed and outward-wound (the coupling
    /// checks that: `mesh_side::MeshRules`).
    pub fn of(shape: &dyn Shape) -> InsideRule {
        if shape.as_heightfield().is_some() {
            InsideRule::HeightField
        } else if shape
            .as_trimesh()
            .is_some_and(|m| m.pseudo_normals().is_none())
        {
            InsideRule::OneSidedMesh
        } else {
            InsideRule::Solid
        }
    }
}

/// Closest point `q` on the shape's surface (world, m), unit normal `n` pointing from the
/// shape towards `p`'s outside side, and the signed distance `(p − q)·n` (negative inside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SurfacePoint {
    pub point: Vector3<f32>,
    pub normal: Vector3<f32>,
    pub distance: f32,
}

/// Projects `p` (world) onto `shape` placed at `pose`. `fallback` is the normal used when
/// `p` lies exactly on the surface; without it such a point returns `None`. For a
/// [`InsideRule::ThinMesh`], `side` (world) points to the side `p` belongs on (`fallback`,
/// then the face's winding normal, when it is `None`).
pub(crate) fn surface_point(
    shape: &dyn Shape,
    rule: InsideRule,
    pose: &Isometry3<f32>,
    p: &Vector3<f32>,
    fallback: Option<Vector3<f32>>,
    side: Option<Vector3<f32>>,
) -> Option<SurfacePoint> {
    let local = pose.inverse_transform_point(&Point3::from(*p)).coords;
    let lp = to_glam(&local);
    let (proj_point, inside) = match rule {
        InsideRule::Solid => {
            let proj = shape.project_local_point(lp, false);
            (to_na(proj.point), proj.is_inside)
        }
        InsideRule::HeightField => {
            let proj = shape.project_local_point(lp, false);
            let q = to_na(proj.point);
            (q, local.y < q.y)
        }
        InsideRule::ThinMesh => {
            let mesh = shape.as_trimesh()?;
            let (proj, _) = mesh.project_local_point_and_get_feature(lp);
            let q = to_na(proj.point);
            let reference = match side.or(fallback) {
                Some(r) => pose.rotation.inverse() * r,
                None => mesh
                    .triangle(proj.subshape)
                    .normal()
                    .map(to_na)
                    .unwrap_or_default(),
            };
            (q, (local - q).dot(&reference) < 0.0)
        }
        InsideRule::OneSidedMesh => {
            let mesh = shape.as_trimesh()?;
            let (proj, _) = mesh.project_local_point_and_get_feature(lp);
            let q = to_na(proj.point);
            let behind = mesh
                .triangle(proj.subshape)
                .normal()
                .is_some_and(|n| (local - q).dot(&to_na(n)) < 0.0);
            (q, behind)
        }
    };
    let d = local - proj_point;
    let dist = d.norm();
    if !dist.is_finite() || !proj_point.iter().all(|c| c.is_finite()) {
        return None;
    }
    let point = pose * Point3::from(proj_point);
    let (normal, distance) = if dist > 1e-7 {
        let n_local = if inside { -d / dist } else { d / dist };
        (pose.rotation * n_local, if inside { -dist } else { dist })
    } else {
        (fallback?, 0.0)
    };
    Some(SurfacePoint {
        point: point.coords,
        normal,
        distance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d::geometry::{Array2, SharedShape, TriMeshFlags};
    use rapier3d::math::Vector;

    fn query(shape: &SharedShape, p: Vector3<f32>) -> SurfacePoint {
        let rule = InsideRule::of(shape.as_ref());
        surface_point(shape.as_ref(), rule, &Isometry3::identity(), &p, None, None).unwrap()
    }

    #[test]
    fn solid_shapes_report_inside_with_negative_distance() {
        let ball = SharedShape::ball(1.0);
        let out = query(&ball, Vector3::new(0.0, 1.5, 0.0));
        assert!((out.distance - 0.5).abs() < 1e-5);
        assert!((out.normal - Vector3::y()).norm() < 1e-5);
        let inside = query(&ball, Vector3::new(0.0, 0.75, 0.0));
        assert!((inside.distance + 0.25).abs() < 1e-5);
        assert!((inside.normal - Vector3::y()).norm() < 1e-5);
        assert!((inside.point - Vector3::y()).norm() < 1e-5);
    }

    #[test]
    fn heightfield_is_solid_below_its_surface() {
        let hf = SharedShape::heightfield(Array2::repeat(3, 3, 0.0), Vector::new(2.0, 1.0, 2.0));
        assert_eq!(InsideRule::of(hf.as_ref()), InsideRule::HeightField);
        let above = query(&hf, Vector3::new(0.1, 0.2, 0.1));
        let below = query(&hf, Vector3::new(0.1, -0.2, 0.1));
        assert!((above.distance - 0.2).abs() < 1e-5 && above.normal.y > 0.99);
        assert!((below.distance + 0.2).abs() < 1e-5 && below.normal.y > 0.99);
    }

    #[test]
    fn one_sided_rule_is_solid_behind_the_winding_normal() {
        let v = vec![
            Vector::new(-1.0, 0.0, -1.0),
            Vector::new(1.0, 0.0, -1.0),
            Vector::new(1.0, 0.0, 1.0),
            Vector::new(-1.0, 0.0, 1.0),
        ];
        let mesh =
            SharedShape::trimesh_with_flags(v, vec![[0, 2, 1], [0, 3, 2]], TriMeshFlags::empty())
                .unwrap();
        assert_eq!(InsideRule::of(mesh.as_ref()), InsideRule::OneSidedMesh);
        let above = query(&mesh, Vector3::new(0.2, 0.1, 0.3));
        let below = query(&mesh, Vector3::new(0.2, -0.1, 0.3));
        assert!((above.distance - 0.1).abs() < 1e-5 && above.normal.y > 0.99);
        assert!((below.distance + 0.1).abs() < 1e-5 && below.normal.y > 0.99);
    }

    #[test]
    fn a_thin_mesh_keeps_a_point_on_the_side_it_came_from() {
        let v = vec![
            Vector::new(-1.0, 0.0, -1.0),
            Vector::new(1.0, 0.0, -1.0),
            Vector::new(1.0, 0.0, 1.0),
            Vector::new(-1.0, 0.0, 1.0),
        ];
        for idx in [vec![[0, 2, 1], [0, 3, 2]], vec![[0, 1, 2], [0, 2, 3]]] {
            let mesh =
                SharedShape::trimesh_with_flags(v.clone(), idx, TriMeshFlags::empty()).unwrap();
            let rule = crate::mesh_side::trimesh_rule(mesh.as_trimesh().unwrap());
            assert_eq!(rule, InsideRule::ThinMesh);
            let id = Isometry3::identity();
            for (from, at, inside) in [
                (0.1, 0.05, false),
                (0.1, -0.05, true),
                (-0.1, -0.05, false),
                (-0.1, 0.05, true),
            ] {
                let side = Some(Vector3::new(0.0, from, 0.0));
                let p = Vector3::new(0.2, at, 0.3);
                let sp = surface_point(mesh.as_ref(), rule, &id, &p, None, side).unwrap();
                assert_eq!(sp.distance < 0.0, inside, "from {from} to {at}: {sp:?}");
                assert!(
                    (sp.normal.y * from).signum() > 0.0,
                    "normal towards the side it came from"
                );
            }
        }
    }

    #[test]
    fn a_point_on_the_surface_needs_a_fallback_normal() {
        let cuboid = SharedShape::cuboid(1.0, 1.0, 1.0);
        let rule = InsideRule::of(cuboid.as_ref());
        let p = Vector3::new(0.0, 1.0, 0.0);
        let id = Isometry3::identity();
        assert!(surface_point(cuboid.as_ref(), rule, &id, &p, None, None).is_none());
        let sp = surface_point(cuboid.as_ref(), rule, &id, &p, Some(Vector3::y()), None).unwrap();
        assert_eq!(sp.distance, 0.0);
        assert_eq!(sp.normal, Vector3::y());
    }
}
