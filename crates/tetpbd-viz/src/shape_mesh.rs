//! Rapier collider shapes → triangles, through parry's `to_trimesh` tessellations.

use nalgebra::{Isometry3, Vector3};
use rapier3d::math::Vector;
use rapier3d::parry::shape::{Shape, SupportMap, TypedShape};

use crate::mesh::TriangleMesh;

/// Subdivisions around the axis of balls, capsules, cylinders and cones.
const AROUND: u32 = 24;
/// Subdivisions from pole to pole of balls and capsules.
const POLE_TO_POLE: u32 = 12;
/// Half the side of the square drawn for a half-space, m.
const HALF_SPACE_EXTENT: f32 = 50.0;

fn from_parry(vertices: Vec<Vector>, triangles: Vec<[u32; 3]>) -> TriangleMesh {
    TriangleMesh {
        positions: vertices.into_iter().map(Vector3::from).collect(),
        triangles,
    }
}

/// The boundary of a convex shape sampled through its support map: a UV sphere whose every
/// vertex is moved to the shape's support point in that direction (rounded shapes, custom
/// convex shapes).
fn support_map_mesh(shape: &dyn SupportMap) -> TriangleMesh {
    let (sphere, triangles) =
        rapier3d::parry::shape::Ball::new(1.0).to_trimesh(AROUND, POLE_TO_POLE);
    let positions = sphere
        .into_iter()
        .map(|d| Vector3::from(shape.local_support_point(d)))
        .collect();
    TriangleMesh {
        positions,
        triangles,
    }
}

/// A square of side `2 × HALF_SPACE_EXTENT` on the plane through the origin with `normal`.
fn half_space_mesh(normal: Vector3<f32>) -> TriangleMesh {
    let n = normal.try_normalize(1e-12).unwrap_or_else(Vector3::y);
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = n.cross(&helper).normalize() * HALF_SPACE_EXTENT;
    let v = n.cross(&u);
    TriangleMesh {
        positions: vec![-u - v, u - v, u + v, -u + v],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// Triangles of `shape` in its local frame, or `None` for shapes without area (segments,
/// polylines) and custom shapes that are not convex.
///
/// Balls, capsules, cylinders and cones are tessellated with 24 subdivisions around their
/// axis; rounded shapes are sampled through their support map; a half-space is a 100 m square;
/// compounds are the union of their parts.
pub fn shape_mesh(shape: &dyn Shape) -> Option<TriangleMesh> {
    Some(match shape.as_typed_shape() {
        TypedShape::Ball(s) => {
            let (v, t) = s.to_trimesh(AROUND, POLE_TO_POLE);
            from_parry(v, t)
        }
        TypedShape::Cuboid(s) => {
            let (v, t) = s.to_trimesh();
            from_parry(v, t)
        }
        TypedShape::Capsule(s) => {
            let (v, t) = s.to_trimesh(AROUND, POLE_TO_POLE);
            from_parry(v, t)
        }
        TypedShape::Cylinder(s) => {
            let (v, t) = s.to_trimesh(AROUND);
            from_parry(v, t)
        }
        TypedShape::Cone(s) => {
            let (v, t) = s.to_trimesh(AROUND);
            from_parry(v, t)
        }
        TypedShape::ConvexPolyhedron(s) => {
            let (v, t) = s.to_trimesh();
            from_parry(v, t)
        }
        TypedShape::HeightField(s) => {
            let (v, t) = s.to_trimesh();
            from_parry(v, t)
        }
        TypedShape::Voxels(s) => {
            let (v, t) = s.to_trimesh();
            from_parry(v, t)
        }
        TypedShape::TriMesh(s) => from_parry(s.vertices().to_vec(), s.indices().to_vec()),
        TypedShape::Triangle(s) => from_parry(vec![s.a, s.b, s.c], vec![[0, 1, 2]]),
        TypedShape::HalfSpace(s) => half_space_mesh(Vector3::from(s.normal)),
        TypedShape::Compound(c) => {
            let mut all = TriangleMesh::default();
            for (pose, part) in c.shapes() {
                if let Some(m) = shape_mesh(part.as_ref()) {
                    all.append(m.transformed(&Isometry3::from(*pose)));
                }
            }
            all
        }
        TypedShape::RoundCuboid(s) => support_map_mesh(s),
        TypedShape::RoundTriangle(s) => support_map_mesh(s),
        TypedShape::RoundCylinder(s) => support_map_mesh(s),
        TypedShape::RoundCone(s) => support_map_mesh(s),
        TypedShape::RoundConvexPolyhedron(s) => support_map_mesh(s),
        TypedShape::Segment(_) | TypedShape::Polyline(_) => return None,
        TypedShape::Custom(s) => support_map_mesh(s.as_support_map()?),
    })
}
