//! Point queries against soft bodies: the nearest surface point
//! ([`SoftQueries::project_point`]) and the tetrahedron holding a point
//! ([`SoftQueries::contains_point`], [`SoftQueries::intersect_point`]).

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::parry::query::PointQuery;

use super::body::QueryBody;
use super::error::{check_limit, check_vector, QueryError};
use super::filter::SoftQueryFilter;
use super::location::SoftLocation;
use super::SoftQueries;
use crate::convert::{to_glam, to_na};
use crate::soft_soft::bvh::closest_barycentric;

/// The point of a soft body's surface nearest to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftPointProjection {
    /// The soft body.
    pub entity: Entity,
    /// The nearest surface point, world frame, m.
    pub point: Vector,
    /// Distance from the query point to `point`, m (≥ 0 on either side of the surface).
    pub distance: f32,
    /// `true` when the query point lies inside the body's tetrahedral volume.
    pub is_inside: bool,
    /// The triangle `point` lies on and its barycentric weights ([`SoftLocation::Surface`]).
    pub location: SoftLocation,
}

/// A point inside a soft body's tetrahedral volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftVolumePoint {
    /// The soft body.
    pub entity: Entity,
    /// The tetrahedron holding the point and the point's barycentric weights in it
    /// ([`SoftLocation::Interior`]).
    pub location: SoftLocation,
}

impl SoftQueries {
    /// The surface point nearest to `point` over the soft bodies `filter` sees, within
    /// `max_dist` (m; `f32::MAX` or `f32::INFINITY` for no limit). Always onto the surface,
    /// also from inside a body (parry's `solid = false`); `is_inside` tells the side.
    ///
    /// # Errors
    /// [`QueryError`] when `point` is not finite or `max_dist` is negative or NaN.
    pub fn project_point(
        &self,
        point: Vector,
        max_dist: f32,
        filter: SoftQueryFilter,
    ) -> Result<Option<SoftPointProjection>, QueryError> {
        check_vector("point", point)?;
        check_limit("max_dist", max_dist)?;
        let x = to_na(point);
        // The search keeps costs strictly below its limit; a point at exactly `max_dist` counts.
        let best = self.top.find_best(
            max_dist.next_up(),
            |node, _| node.aabb().distance_to_local_point(point, true),
            |leaf, best| {
                let body = self.bodies.get(leaf as usize)?;
                if !filter.test(body) {
                    return None;
                }
                project_on_body(body, &x, best).map(|p| (p.distance, p))
            },
        );
        Ok(best.map(|(_, (_, p))| p))
    }

    /// The first soft body (lowest entity) whose tetrahedral volume holds `point`, among those
    /// `filter` sees, with the tetrahedron and the point's barycentric weights. A point on
    /// the surface counts as inside.
    ///
    /// # Errors
    /// [`QueryError`] when `point` is not finite.
    pub fn contains_point(
        &self,
        point: Vector,
        filter: SoftQueryFilter,
    ) -> Result<Option<SoftVolumePoint>, QueryError> {
        Ok(self.intersect_point(point, filter)?.into_iter().next())
    }

    /// Every soft body whose tetrahedral volume holds `point`, among those `filter` sees,
    /// ordered by entity.
    ///
    /// # Errors
    /// [`QueryError`] when `point` is not finite.
    pub fn intersect_point(
        &self,
        point: Vector,
        filter: SoftQueryFilter,
    ) -> Result<Vec<SoftVolumePoint>, QueryError> {
        check_vector("point", point)?;
        let x = to_na(point);
        let mut leaves: Vec<u32> = self
            .top
            .leaves(|node| node.aabb().contains_local_point(point))
            .collect();
        leaves.sort_unstable();
        let found = leaves.into_iter().filter_map(|leaf| {
            let body = &self.bodies[leaf as usize];
            if !filter.test(body) {
                return None;
            }
            let location = body.locate(&x)?;
            Some(SoftVolumePoint {
                entity: body.entity,
                location,
            })
        });
        Ok(found.collect())
    }
}

/// The nearest surface point of one body to `x`, if closer than `max_dist`.
pub(crate) fn project_on_body(
    body: &QueryBody,
    x: &Vector3<f32>,
    max_dist: f32,
) -> Option<SoftPointProjection> {
    let q = to_glam(x);
    let (t, (distance, (barycentric, on))) = body.cache.tri_bvh.find_best(
        max_dist,
        |node, _| node.aabb().distance_to_local_point(q, true),
        |t, _| {
            let [a, b, c] = body.triangle(t as usize);
            let w = closest_barycentric(x, &a, &b, &c);
            let on = a * w[0] + b * w[1] + c * w[2];
            let d = (x - on).norm();
            d.is_finite().then_some((d, (w, on)))
        },
    )?;
    Some(SoftPointProjection {
        entity: body.entity,
        point: to_glam(&on),
        distance,
        is_inside: body.aabb.contains_local_point(q) && body.locate(x).is_some(),
        location: SoftLocation::Surface {
            triangle: t,
            particles: body.triangle_particles(t as usize),
            barycentric,
        },
    })
}
