//! Overlap queries against soft bodies: bounds against an AABB
//! ([`SoftQueries::intersect_aabb`]) and a parry shape against the bodies' surfaces and
//! volumes ([`SoftQueries::intersect_shape`]).

use hecs::Entity;
use rapier3d::geometry::Aabb;
use rapier3d::math::{Pose, Vector};
use rapier3d::parry::query::intersection_test;
use rapier3d::parry::shape::{Shape, Triangle};

use super::body::QueryBody;
use super::error::{check_vector, QueryError};
use super::filter::SoftQueryFilter;
use super::SoftQueries;
use crate::convert::{to_glam, to_na};

impl SoftQueries {
    /// The soft bodies `filter` sees whose bounds (the box of their particles at the
    /// snapshot) intersect `aabb` (touching counts), ordered by entity. Conservative, like
    /// rapier's `intersect_aabb_conservative`: a body reported may not touch the box itself.
    ///
    /// # Errors
    /// [`QueryError`] when a corner of `aabb` is not finite.
    pub fn intersect_aabb(
        &self,
        aabb: &Aabb,
        filter: SoftQueryFilter,
    ) -> Result<Vec<Entity>, QueryError> {
        check_vector("aabb mins", aabb.mins)?;
        check_vector("aabb maxs", aabb.maxs)?;
        Ok(self.seen_in(aabb, &filter).map(|b| b.entity).collect())
    }

    /// The soft bodies `filter` sees that `shape` at `pose` intersects, ordered by entity:
    /// the shape touches one of the body's surface triangles, or lies inside its
    /// tetrahedral volume. Both are solid, as in parry: a shape wholly inside a body, or a
    /// body wholly inside a shape, intersect. Pairs parry has no intersection test for
    /// (e.g. a heightfield or a triangle mesh against a triangle) are not reported.
    ///
    /// # Errors
    /// [`QueryError`] when the pose's translation is not finite.
    pub fn intersect_shape(
        &self,
        pose: &Pose,
        shape: &dyn Shape,
        filter: SoftQueryFilter,
    ) -> Result<Vec<Entity>, QueryError> {
        check_vector("shape pose translation", pose.translation)?;
        let rot = pose.rotation;
        if !(rot.x.is_finite() && rot.y.is_finite() && rot.z.is_finite() && rot.w.is_finite()) {
            return Err(QueryError::NonFiniteVector {
                what: "shape pose rotation (x, y, z)",
                value: [rot.x, rot.y, rot.z],
            });
        }
        let aabb = shape.compute_aabb(pose);
        // A point of the shape (its point nearest to its own origin), to find a shape lying
        // wholly inside a body.
        let inner = shape.project_point(pose, pose.translation, true).point;
        Ok(self
            .seen_in(&aabb, &filter)
            .filter(|b| overlaps(b, pose, shape, &aabb, inner))
            .map(|b| b.entity)
            .collect())
    }

    /// The bodies `filter` sees whose bounds meet `aabb`, ordered by entity.
    fn seen_in<'s>(
        &'s self,
        aabb: &Aabb,
        filter: &'s SoftQueryFilter,
    ) -> impl Iterator<Item = &'s QueryBody> + 's {
        let mut leaves: Vec<u32> = self.top.intersect_aabb(aabb).collect();
        leaves.sort_unstable();
        leaves
            .into_iter()
            .map(|l| &self.bodies[l as usize])
            .filter(|b| filter.test(b))
    }
}

/// `true` when `shape` at `pose` (bounds `aabb`, containing the point `inner`) touches a
/// surface triangle of `body` or lies inside its volume.
fn overlaps(body: &QueryBody, pose: &Pose, shape: &dyn Shape, aabb: &Aabb, inner: Vector) -> bool {
    let touches = body.cache.tri_bvh.intersect_aabb(aabb).any(|t| {
        let [a, b, c] = body.triangle(t as usize).map(|v| to_glam(&v));
        intersection_test(pose, shape, &Pose::IDENTITY, &Triangle::new(a, b, c))
            .is_ok_and(|hit| hit.intersecting)
    });
    touches || (inner.is_finite() && body.locate(&to_na(inner)).is_some())
}
