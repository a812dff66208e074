//! Ray casts against soft bodies: the first hit ([`SoftQueries::cast_ray`]) and every
//! surface crossing ([`SoftQueries::intersect_ray`]).

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::geometry::Ray;
use rapier3d::math::Vector;
use rapier3d::parry::partitioning::BvhNode;

use super::body::QueryBody;
use super::error::{check_limit, check_vector, QueryError};
use super::filter::SoftQueryFilter;
use super::location::SoftLocation;
use super::SoftQueries;
use crate::convert::{to_glam, to_na};
use crate::soft_soft::bvh::{ray_triangle_barycentric, triangle_normal};

/// How far outside a triangle (in barycentric units) a ray still hits it, so that a ray
/// through a vertex or edge shared by several triangles cannot slip between them by
/// rounding. The hit point is then clamped onto the triangle: it is off by at most this
/// fraction of the triangle's size.
const SLACK: f32 = 1e-5;

/// Where a ray met a soft body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftRayHit {
    /// The soft body.
    pub entity: Entity,
    /// Time of impact: the hit point is `ray.origin + ray.dir * time_of_impact` (m for a unit
    /// direction).
    pub time_of_impact: f32,
    /// The hit point, world frame, m.
    pub point: Vector,
    /// Outward unit normal of the triangle hit, world frame; zero for a solid cast that
    /// starts inside the body (as parry reports it).
    pub normal: Vector,
    /// The triangle hit ([`SoftLocation::Surface`]), or, for a solid cast starting inside
    /// the body, the tetrahedron holding the origin ([`SoftLocation::Interior`]).
    pub location: SoftLocation,
}

impl SoftQueries {
    /// The first soft body the ray meets within `max_toi` (in units of `|ray.dir|`; `f32::MAX`
    /// or `f32::INFINITY` for no limit), among the bodies `filter` sees.
    ///
    /// `solid` as in parry: when `true`, a ray starting inside a body hits it at time 0
    /// (normal zero, [`SoftLocation::Interior`]); when `false` it hits the surface where it
    /// leaves the body. Ties between bodies go to the one found first.
    ///
    /// # Errors
    /// [`QueryError`] when the ray's origin or direction is not finite or `max_toi` is
    /// negative or NaN.
    pub fn cast_ray(
        &self,
        ray: &Ray,
        max_toi: f32,
        solid: bool,
        filter: SoftQueryFilter,
    ) -> Result<Option<SoftRayHit>, QueryError> {
        check_ray(ray, max_toi)?;
        // The search keeps costs strictly below its limit; a hit at exactly `max_toi` counts.
        let best = self.top.find_best(
            max_toi.next_up(),
            |node, best| node.cast_ray(ray, best),
            |leaf, best| {
                let body = self.bodies.get(leaf as usize)?;
                if !filter.test(body) {
                    return None;
                }
                first_hit(body, ray, best, solid).map(|h| (h.time_of_impact, h))
            },
        );
        Ok(best.map(|(_, (_, hit))| hit))
    }

    /// Every crossing of the ray with the surfaces of the soft bodies `filter` sees, within
    /// `max_toi`, ordered by time of impact: a ray through a closed body meets it where it
    /// enters and where it leaves. With `solid`, a ray starting inside a body also reports
    /// that body first at time 0 ([`SoftLocation::Interior`]). A crossing through an edge or
    /// corner shared by several triangles of a body is reported once.
    ///
    /// # Errors
    /// As [`SoftQueries::cast_ray`].
    pub fn intersect_ray(
        &self,
        ray: &Ray,
        max_toi: f32,
        solid: bool,
        filter: SoftQueryFilter,
    ) -> Result<Vec<SoftRayHit>, QueryError> {
        check_ray(ray, max_toi)?;
        let mut bodies: Vec<u32> = self
            .top
            .leaves(|node| ray_meets(node, ray, max_toi))
            .collect();
        bodies.sort_unstable();
        let mut hits = Vec::new();
        for leaf in bodies {
            let body = &self.bodies[leaf as usize];
            if filter.test(body) {
                all_hits(body, ray, max_toi, solid, &mut hits);
            }
        }
        hits.sort_by(|a, b| a.time_of_impact.total_cmp(&b.time_of_impact));
        Ok(hits)
    }
}

/// `true` when the ray meets the node's box within `max_toi` (`BvhNode::cast_ray` answers
/// `f32::MAX` for a miss).
fn ray_meets(node: &BvhNode, ray: &Ray, max_toi: f32) -> bool {
    let toi = node.cast_ray(ray, max_toi);
    toi < f32::MAX && toi <= max_toi
}

/// Rejects a non-finite ray or a bad `max_toi`.
pub(crate) fn check_ray(ray: &Ray, max_toi: f32) -> Result<(), QueryError> {
    check_vector("ray origin", ray.origin)?;
    check_vector("ray direction", ray.dir)?;
    check_limit("max_toi", max_toi)
}

/// A solid cast starting inside `body`: the hit at time 0.
fn inside_hit(body: &QueryBody, ray: &Ray) -> Option<SoftRayHit> {
    if !body.aabb.contains_local_point(ray.origin) {
        return None;
    }
    let location = body.locate(&to_na(ray.origin))?;
    Some(SoftRayHit {
        entity: body.entity,
        time_of_impact: 0.0,
        point: ray.origin,
        normal: Vector::ZERO,
        location,
    })
}

/// The hit of the ray on surface triangle `t` of `body`, if any.
fn triangle_hit(
    body: &QueryBody,
    t: usize,
    o: &Vector3<f32>,
    d: &Vector3<f32>,
) -> Option<SoftRayHit> {
    let [a, b, c] = body.triangle(t);
    let (toi, barycentric) = ray_triangle_barycentric(o, d, [&a, &b, &c], SLACK)?;
    let normal = triangle_normal(&a, &b, &c).map_or(Vector::ZERO, |n| to_glam(&n));
    Some(SoftRayHit {
        entity: body.entity,
        time_of_impact: toi,
        point: to_glam(&(o + d * toi)),
        normal,
        location: SoftLocation::Surface {
            triangle: t as u32,
            particles: body.triangle_particles(t),
            barycentric,
        },
    })
}

/// The first hit of the ray on one body within `max_toi`.
fn first_hit(body: &QueryBody, ray: &Ray, max_toi: f32, solid: bool) -> Option<SoftRayHit> {
    if solid {
        if let Some(hit) = inside_hit(body, ray) {
            return Some(hit);
        }
    }
    let (o, d) = (to_na(ray.origin), to_na(ray.dir));
    let (t, _) = body.cache.tri_bvh.cast_ray(ray, max_toi, |t, _| {
        let [a, b, c] = body.triangle(t as usize);
        ray_triangle_barycentric(&o, &d, [&a, &b, &c], SLACK).map(|(toi, _)| toi)
    })?;
    triangle_hit(body, t as usize, &o, &d)
}

/// Every crossing of the ray with one body's surface within `max_toi`, appended to `out`
/// (one per crossing: hits of the same sense within a relative 1e-5 of each other, from
/// triangles sharing the edge or corner crossed, are merged).
fn all_hits(body: &QueryBody, ray: &Ray, max_toi: f32, solid: bool, out: &mut Vec<SoftRayHit>) {
    let start = out.len();
    if solid {
        out.extend(inside_hit(body, ray));
    }
    let (o, d) = (to_na(ray.origin), to_na(ray.dir));
    let tris = body
        .cache
        .tri_bvh
        .leaves(|node| ray_meets(node, ray, max_toi));
    for t in tris {
        if let Some(hit) = triangle_hit(body, t as usize, &o, &d) {
            if hit.time_of_impact <= max_toi {
                out.push(hit);
            }
        }
    }
    let mine = &mut out[start..];
    mine.sort_by(|a, b| {
        a.time_of_impact
            .total_cmp(&b.time_of_impact)
            .then(a.location.triangle().cmp(&b.location.triangle()))
    });
    let scale = ray.dir.length().max(f32::MIN_POSITIVE);
    let mut kept = start;
    for i in start..out.len() {
        let hit = out[i];
        let duplicate = kept > start && {
            let prev = &out[kept - 1];
            let same_sense = (prev.normal.dot(ray.dir) > 0.0) == (hit.normal.dot(ray.dir) > 0.0)
                && prev.location.triangle().is_some() == hit.location.triangle().is_some();
            let tol = 1e-5 * (1.0 + hit.time_of_impact.abs() * scale) / scale;
            same_sense && hit.time_of_impact - prev.time_of_impact <= tol
        };
        if !duplicate {
            out[kept] = hit;
            kept += 1;
        }
    }
    out.truncate(kept);
}
