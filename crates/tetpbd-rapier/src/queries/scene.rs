//! Queries over rapier's colliders and the soft bodies in one call: the nearest ray hit
//! ([`SoftQueries::cast_ray_scene`]) and the nearest surface point
//! ([`SoftQueries::project_point_scene`]) of either kind.

use rapier3d::geometry::{ColliderHandle, PointProjection, Ray, RayIntersection};
use rapier3d::math::Vector;
use rapier3d::pipeline::QueryPipeline;

use super::error::{check_limit, check_vector, QueryError};
use super::filter::SoftQueryFilter;
use super::point::SoftPointProjection;
use super::ray::{check_ray, SoftRayHit};
use super::SoftQueries;

/// The nearest ray hit over rigid colliders and soft bodies.
#[derive(Clone, Copy, Debug)]
pub enum SceneRayHit {
    /// A rapier collider, as rapier's `cast_ray_and_get_normal` reports it.
    Rigid {
        /// The collider hit.
        collider: ColliderHandle,
        /// Time of impact, normal and feature.
        intersection: RayIntersection,
    },
    /// A soft body.
    Soft(SoftRayHit),
}

impl SceneRayHit {
    /// Time of impact, in units of the ray direction's length (m for a unit direction).
    pub fn time_of_impact(&self) -> f32 {
        match self {
            SceneRayHit::Rigid { intersection, .. } => intersection.time_of_impact,
            SceneRayHit::Soft(hit) => hit.time_of_impact,
        }
    }

    /// Unit normal at the hit, world frame (zero for a solid cast starting inside).
    pub fn normal(&self) -> Vector {
        match self {
            SceneRayHit::Rigid { intersection, .. } => intersection.normal,
            SceneRayHit::Soft(hit) => hit.normal,
        }
    }
}

/// The nearest surface point over rigid colliders and soft bodies.
#[derive(Clone, Copy, Debug)]
pub enum ScenePointProjection {
    /// A rapier collider, as rapier's `project_point` reports it (`solid = false`).
    Rigid {
        /// The collider.
        collider: ColliderHandle,
        /// The projection.
        projection: PointProjection,
    },
    /// A soft body.
    Soft(SoftPointProjection),
}

impl ScenePointProjection {
    /// The nearest surface point, world frame, m.
    pub fn point(&self) -> Vector {
        match self {
            ScenePointProjection::Rigid { projection, .. } => projection.point,
            ScenePointProjection::Soft(p) => p.point,
        }
    }

    /// `true` when the query point is inside the collider or body.
    pub fn is_inside(&self) -> bool {
        match self {
            ScenePointProjection::Rigid { projection, .. } => projection.is_inside,
            ScenePointProjection::Soft(p) => p.is_inside,
        }
    }
}

impl SoftQueries {
    /// The first thing the ray meets within `max_toi`: a rapier collider of `rigid` (seen
    /// through `rigid.filter`, rapier's `QueryFilter`) or a soft body `filter` sees; `solid`
    /// as in [`SoftQueries::cast_ray`] for both. On a tie the rigid collider wins.
    ///
    /// `rigid` is rapier's query pipeline, e.g.
    /// `broad_phase.as_query_pipeline(narrow_phase.query_dispatcher(), &bodies, &colliders,
    /// QueryFilter::default())`; it sees colliders as rapier's broad phase last placed them
    /// (after rapier's step), the soft bodies as of [`SoftQueries::update`].
    ///
    /// # Errors
    /// As [`SoftQueries::cast_ray`].
    pub fn cast_ray_scene(
        &self,
        rigid: &QueryPipeline,
        ray: &Ray,
        max_toi: f32,
        solid: bool,
        filter: SoftQueryFilter,
    ) -> Result<Option<SceneRayHit>, QueryError> {
        check_ray(ray, max_toi)?;
        let rigid_hit = rigid.cast_ray_and_get_normal(ray, max_toi, solid);
        let limit = rigid_hit.map_or(max_toi, |(_, h)| h.time_of_impact);
        let soft = self.cast_ray(ray, limit, solid, filter)?;
        Ok(match (soft, rigid_hit) {
            (Some(s), Some((_, r))) if s.time_of_impact < r.time_of_impact => {
                Some(SceneRayHit::Soft(s))
            }
            (Some(s), None) => Some(SceneRayHit::Soft(s)),
            (_, Some((collider, intersection))) => Some(SceneRayHit::Rigid {
                collider,
                intersection,
            }),
            (None, None) => None,
        })
    }

    /// The surface point nearest to `point` within `max_dist` (m) over the colliders of
    /// `rigid` (rapier's `project_point` with `solid = false`) and the soft bodies `filter`
    /// sees. On a tie the rigid collider wins.
    ///
    /// # Errors
    /// As [`SoftQueries::project_point`].
    pub fn project_point_scene(
        &self,
        rigid: &QueryPipeline,
        point: Vector,
        max_dist: f32,
        filter: SoftQueryFilter,
    ) -> Result<Option<ScenePointProjection>, QueryError> {
        check_vector("point", point)?;
        check_limit("max_dist", max_dist)?;
        let rigid_hit = rigid.project_point(point, max_dist, false);
        let rigid_dist = rigid_hit.map(|(_, p)| (p.point - point).length());
        let soft = self.project_point(point, rigid_dist.unwrap_or(max_dist), filter)?;
        Ok(match (soft, rigid_hit, rigid_dist) {
            (Some(s), Some(_), Some(d)) if s.distance < d => Some(ScenePointProjection::Soft(s)),
            (Some(s), None, _) => Some(ScenePointProjection::Soft(s)),
            (_, Some((collider, projection)), _) => Some(ScenePointProjection::Rigid {
                collider,
                projection,
            }),
            _ => None,
        })
    }
}
