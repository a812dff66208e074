//! Corner–triangle candidates: which rigid points of a collider are paired with which soft
//! surface triangles for the frame (the rules are in the module docs of
//! [`crate::contacts::corner`]).

use nalgebra::{Isometry3, Point3, Vector3};
use rapier3d::geometry::Aabb;
use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::parry::shape::Shape;
use tetpbd::{Particles, Surface};

use crate::contacts::corner::CornerContact;
use crate::convert::{pose_to_glam, to_glam};
use crate::gather::corner_points::Corners;

/// Adds the corner–triangle candidates of one collider against one soft body. `corners` is
/// scratch space (its capacity is reused across calls). `still`: the collider stands at
/// `pose` for the whole frame (fixed), so each of its corners is only paired with the
/// triangles it can reach (`contacts::corner` module docs).
#[allow(clippy::too_many_arguments)]
pub(crate) fn gather_corners(
    out: &mut Vec<CornerContact>,
    shape: &dyn Shape,
    collider: usize,
    collider_aabb: &Aabb,
    pose: &Isometry3<f32>,
    still: bool,
    p: &Particles,
    surface: &Surface,
    dt: f32,
    thickness: f32,
    (mu_d, mu_s, restitution): (f32, f32, f32),
    vertex_contacts: &[(u32, usize)],
    corners: &mut Corners,
) {
    // The soft body's surface over the frame, in the collider's frame (at its end pose).
    let (lo, hi) = swept_bounds(p, surface.vertices(), dt);
    let near = Aabb::new(to_glam(&lo), to_glam(&hi))
        .loosened(thickness)
        .transform_by(&pose_to_glam(&pose.inverse()));
    corners.fill(shape, &near);
    // No corners: the support point of a shape with a support map, as the single `None`.
    let count = if !corners.points.is_empty() {
        corners.points.len()
    } else if shape.as_support_map().is_some() && !corners.from_mesh {
        1
    } else {
        return;
    };
    let max_extra = corners.points.iter().map(|c| c.1).fold(0.0f32, f32::max);
    let reach = thickness + max_extra;
    let first = out.len();
    for (t, tri) in surface.triangles().iter().enumerate() {
        let (lo, hi) = swept_bounds(p, tri, dt);
        let ta = Aabb::new(to_glam(&lo), to_glam(&hi)).loosened(reach);
        if !ta.intersects(collider_aabb) {
            continue;
        }
        // A still corner is caught only in front of the triangle or less than half its
        // shortest edge behind it, with its projection inside it.
        let [a, b, c] = tri.map(|i| p.positions()[i as usize]);
        let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        let reachable = ta.loosened(0.5 * longest);
        let vc = tri.map(|i| {
            vertex_contacts
                .binary_search_by_key(&i, |(p, _)| *p)
                .ok()
                .map(|k| vertex_contacts[k].1)
        });
        for j in 0..count {
            let (corner, extra) = match corners.points.get(j) {
                Some(&(c, r)) => (Some(c), r),
                None => (None, 0.0),
            };
            // A mesh vertex only with the soft triangles near it, a still corner only with
            // those it can reach.
            let world = corner.map(|c| to_glam(&(pose * Point3::from(c)).coords));
            if world.is_some_and(|w| {
                (corners.from_mesh && !ta.contains_local_point(w))
                    || (still && !reachable.contains_local_point(w))
            }) {
                continue;
            }
            out.push(CornerContact::candidate(
                collider,
                corner,
                t as u32,
                vc,
                thickness + extra,
                (mu_d, mu_s, restitution),
            ));
        }
    }
    let run = out.len() - first;
    if let Some(k) = out.get_mut(first) {
        k.run = u32::try_from(run).unwrap_or(u32::MAX);
    }
}

/// Bounds of particles `indices` over the frame (their positions and their predicted
/// positions one frame on), m.
fn swept_bounds(p: &Particles, indices: &[u32], dt: f32) -> (Vector3<f32>, Vector3<f32>) {
    let mut lo = Vector3::repeat(f32::INFINITY);
    let mut hi = Vector3::repeat(f32::NEG_INFINITY);
    for &i in indices {
        let x = p.positions()[i as usize];
        let y = x + p.velocities()[i as usize] * dt;
        lo = lo.inf(&x.inf(&y));
        hi = hi.sup(&x.sup(&y));
    }
    (lo, hi)
}

impl CornerContact {
    /// A fresh candidate of rigid point `corner` (`None`: the support point) over soft
    /// triangle `triangle`.
    fn candidate(
        collider: usize,
        corner: Option<Vector3<f32>>,
        triangle: u32,
        vertex_contacts: [Option<usize>; 3],
        thickness: f32,
        (mu_d, mu_s, restitution): (f32, f32, f32),
    ) -> CornerContact {
        CornerContact {
            collider,
            run: 0,
            corner,
            triangle,
            vertex_contacts,
            thickness,
            restitution,
            active: false,
            mu_d,
            mu_s,
            lambda_n: 0.0,
            lambda_t: 0.0,
            ever_active: false,
            depth: 0.0,
            normal: Vector3::zeros(),
            point: Vector3::zeros(),
            beta: [0.0; 3],
            allowance: 0.0,
            sub_impulse: Vector3::zeros(),
            impulse: Vector3::zeros(),
        }
    }
}
