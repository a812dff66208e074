//! Rigid corners against soft surface triangles.
//!
//! A coarse soft body has few surface particles; a sharp rigid corner can slip between
//! them without any particle entering the rigid shape. This is the seed's vertex–face
//! constraint with the rigid corner as the vertex: for a corner `v` over a boundary
//! triangle `(a, b, c)` with outward unit normal `n` and barycentric weights `β` of `v`'s
//! projection,
//!
//! ```text
//! C = (v − (β_a a + β_b b + β_c c))·n − thickness ≥ 0
//! ∇_v C = n,   ∇_k C = −β_k n   (normal held fixed for the step)
//! Δλ = −C / (Σ w_k β_k² + w_rigid(v, n))
//! ```
//!
//! The correction is spread over the triangle's particles barycentrically and the opposite
//! impulse goes to the rigid body at the corner. Corners are the vertices of cuboids, round
//! cuboids (inner corners, border radius added to the thickness), convex polyhedra, cones
//! (apex) and triangles. A corner is only caught while it is less than half the triangle's
//! shortest edge behind it, so triangles on the far side of the body never grab it.
//! Friction is not applied at corner contacts.

use nalgebra::{Point3, Vector3};
use rapier3d::geometry::Aabb;
use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::parry::shape::Shape;
use tetpbd::{Particles, Surface};

use crate::bodies::BodyProxy;
use crate::convert::{to_glam, to_na};
use crate::frame::ColliderProxy;

/// One rigid corner over one soft surface triangle.
#[derive(Clone, Debug)]
pub(crate) struct CornerContact {
    pub collider: usize,
    pub corner: Vector3<f32>,
    pub triangle: u32,
    pub thickness: f32,
    pub ever_active: bool,
    pub depth: f32,
    pub normal: Vector3<f32>,
    pub point: Vector3<f32>,
    pub sub_impulse: Vector3<f32>,
    pub impulse: Vector3<f32>,
}

/// Corners of `shape` in its local frame, with the extra thickness of a rounded shape.
pub(crate) fn corners_of(shape: &dyn Shape) -> (Vec<Vector3<f32>>, f32) {
    let cuboid_corners = |h: Vector3<f32>| {
        (0..8)
            .map(|k| {
                Vector3::new(
                    if k & 1 == 0 { -h.x } else { h.x },
                    if k & 2 == 0 { -h.y } else { h.y },
                    if k & 4 == 0 { -h.z } else { h.z },
                )
            })
            .collect()
    };
    if let Some(c) = shape.as_cuboid() {
        (cuboid_corners(to_na(c.half_extents)), 0.0)
    } else if let Some(c) = shape.as_round_cuboid() {
        (
            cuboid_corners(to_na(c.inner_shape.half_extents)),
            c.border_radius,
        )
    } else if let Some(c) = shape.as_convex_polyhedron() {
        (c.points().iter().map(|p| to_na(*p)).collect(), 0.0)
    } else if let Some(c) = shape.as_round_convex_polyhedron() {
        (
            c.inner_shape.points().iter().map(|p| to_na(*p)).collect(),
            c.border_radius,
        )
    } else if let Some(c) = shape.as_cone() {
        (vec![Vector3::new(0.0, c.half_height, 0.0)], 0.0)
    } else if let Some(t) = shape.as_triangle() {
        (vec![to_na(t.a), to_na(t.b), to_na(t.c)], 0.0)
    } else {
        (Vec::new(), 0.0)
    }
}

/// Adds the corner–triangle candidates of one collider against one soft body.
#[allow(clippy::too_many_arguments)]
pub(crate) fn gather_corners(
    out: &mut Vec<CornerContact>,
    shape: &dyn Shape,
    collider: usize,
    collider_aabb: &Aabb,
    p: &Particles,
    surface: &Surface,
    dt: f32,
    thickness: f32,
) {
    let (corners, extra) = corners_of(shape);
    if corners.is_empty() {
        return;
    }
    let reach = thickness + extra;
    for (t, tri) in surface.triangles().iter().enumerate() {
        let mut lo = Vector3::repeat(f32::INFINITY);
        let mut hi = Vector3::repeat(f32::NEG_INFINITY);
        for &i in tri {
            let x = p.positions()[i as usize];
            let y = x + p.velocities()[i as usize] * dt;
            lo = lo.inf(&x.inf(&y));
            hi = hi.sup(&x.sup(&y));
        }
        let ta = Aabb::new(to_glam(&lo), to_glam(&hi)).loosened(reach);
        if !ta.intersects(collider_aabb) {
            continue;
        }
        for c in &corners {
            out.push(CornerContact {
                collider,
                corner: *c,
                triangle: t as u32,
                thickness: reach,
                ever_active: false,
                depth: 0.0,
                normal: Vector3::zeros(),
                point: Vector3::zeros(),
                sub_impulse: Vector3::zeros(),
                impulse: Vector3::zeros(),
            });
        }
    }
}

/// One Gauss–Seidel sweep over a soft body's corner contacts.
pub(crate) fn project_corners(
    corners: &mut [CornerContact],
    p: &mut Particles,
    surface: &Surface,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
) {
    for k in corners {
        let Some(tri) = surface.triangles().get(k.triangle as usize) else {
            continue;
        };
        let idx = tri.map(|i| i as usize);
        let [a, b, c] = idx.map(|i| p.positions()[i]);
        let cp = &colliders[k.collider];
        let v = (cp.pose(bodies) * Point3::from(k.corner)).coords;
        let m = (b - a).cross(&(c - a));
        let area2 = m.norm();
        let shortest = (b - a).norm().min((c - b).norm()).min((a - c).norm());
        if area2.is_nan() || area2 <= 1e-12 {
            continue;
        }
        let n = m / area2;
        let s = (v - a).dot(&n);
        let c_val = s - k.thickness;
        if c_val >= 0.0 || s < -0.5 * shortest {
            continue;
        }
        // Barycentric weights of v's projection onto the triangle's plane.
        let q = v - n * s;
        let wa = (b - q).cross(&(c - q)).dot(&n) / area2;
        let wb = (c - q).cross(&(a - q)).dot(&n) / area2;
        let wc = 1.0 - wa - wb;
        let beta = [wa, wb, wc];
        if beta.iter().any(|w| *w < 0.0 || *w > 1.0) {
            continue;
        }
        let w = idx.map(|i| p.inv_masses()[i]);
        let w_body = cp.body.map_or(0.0, |bi| bodies[bi].inv_mass_at(&v, &n));
        let denom: f32 = (0..3).map(|j| w[j] * beta[j] * beta[j]).sum::<f32>() + w_body;
        if denom.is_nan() || denom <= 0.0 {
            continue;
        }
        let dl = -c_val / denom;
        let x = p.positions_mut();
        for j in 0..3 {
            x[idx[j]] -= n * (w[j] * beta[j] * dl);
        }
        if let Some(bi) = cp.body {
            bodies[bi].apply_position_impulse(&(n * dl), &v);
        }
        k.ever_active = true;
        k.depth = k.depth.max(-c_val);
        k.normal = -n;
        k.point = v;
        k.sub_impulse -= n * dl;
    }
}
