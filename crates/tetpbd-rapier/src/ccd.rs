//! Continuous detection for fast motion between soft particles and rigid colliders.
//!
//! rapier steps first, so by the time the soft substeps run a fast rigid body may already
//! stand beyond a thin soft body (a ball at 100 m/s moves 1.7 m per frame at 60 Hz). Two
//! things keep it from tunnelling:
//!
//! * **Candidates from the swept motion.** rapier's broad-phase BVH holds each collider's
//!   AABB at its end pose only. Colliders of awake non-fixed bodies whose swept AABB over the
//!   frame (`P₀ → P₁`) reaches more than the margin beyond their end AABB are listed once
//!   per frame ([`fast_colliders`]) and tested against each soft body's bounds as well.
//! * **Contacts from the swept motion.** Inside a substep a particle can cross a collider's
//!   surface, or pass through a thin part of it, in one go; the closest point then lies on
//!   the far side and point projection would push the particle out the wrong way.
//!   [`swept_entry`] casts the particle's motion *relative to the collider* over the substep
//!   (previous pose → current pose, in the collider's frame) as a ray against the shape; when
//!   the ray enters the shape, the contact uses the entry point and the entry face's normal.
//!   The rigid-point–triangle contacts do the same with the point's motion relative to the
//!   triangle's plane (`contacts::corner` module docs).
//!
//! The rigid body itself is still integrated by rapier up to its end pose; inside the soft
//! substeps it follows its path `P₀ → P₁` plus the offset the soft contacts push it by
//! (`rigid::body` module docs), so a body stopped by a soft one is written back where the soft
//! contacts stopped it.
//!
//! Cost: one swept AABB per collider of each awake moving body per frame, one AABB test per
//! fast collider and soft body, one ray cast per particle contact and iteration whose
//! relative motion over the substep exceeds its distance to the surface (none at rest), and
//! a pass over the rigid-point candidates of moving colliders per iteration.

use nalgebra::{Isometry3, Point3, Vector3};
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use rapier3d::geometry::{Aabb, ColliderHandle, ColliderSet};
use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::parry::query::Ray;
use rapier3d::parry::shape::Shape;

use crate::convert::{pose_to_glam, pose_to_na, to_glam, to_na};
use crate::rigid::body::StartState;
use crate::rigid::shape_query::SurfacePoint;

/// Lists the colliders of awake non-fixed bodies whose swept AABB over the frame reaches
/// more than `margin` (m) beyond their AABB at the end pose, with that swept AABB.
/// `start_poses` are the bodies' poses before rapier's step, sorted by raw handle.
pub(crate) fn fast_colliders(
    out: &mut Vec<(ColliderHandle, Aabb)>,
    start_poses: &[((u32, u32), StartState)],
    bodies: &RigidBodySet,
    colliders: &ColliderSet,
    margin: f32,
) {
    out.clear();
    for &((index, generation), (start, _)) in start_poses {
        let Some(rb) = bodies.get(RigidBodyHandle::from_raw_parts(index, generation)) else {
            continue;
        };
        if rb.is_fixed() || rb.is_sleeping() {
            continue;
        }
        let end = pose_to_na(rb.position());
        for &ch in rb.colliders() {
            let Some(co) = colliders.get(ch) else {
                continue;
            };
            let local = co
                .position_wrt_parent()
                .map(pose_to_na)
                .unwrap_or_else(Isometry3::identity);
            let (p0, p1) = (pose_to_glam(&(start * local)), pose_to_glam(&(end * local)));
            let swept = co.shape().compute_swept_aabb(&p0, &p1);
            let at_end = co.shape().compute_aabb(&p1).loosened(margin);
            if !at_end.contains(&swept) {
                out.push((ch, swept));
            }
        }
    }
}

/// The contact of a particle that moved from `x_prev` (at the collider's pose `prev`) to
/// `x` (at `pose`), when its motion relative to the collider entered the shape during the
/// substep: the entry point and the entry face's outward normal, with the signed distance
/// `(x − q)·n` (negative beyond the entry face). `None` when the relative motion did not
/// enter the shape, or when `current` (the closest-point answer at `x`) finds the particle
/// inside with a normal on the entry's side.
pub(crate) fn swept_entry(
    shape: &dyn Shape,
    pose: &Isometry3<f32>,
    prev: &Isometry3<f32>,
    x: &Vector3<f32>,
    x_prev: &Vector3<f32>,
    current: Option<&SurfacePoint>,
) -> Option<SurfacePoint> {
    // A collider that did not move this substep (fixed ground, resting bodies): the relative
    // motion is the particle's own, and a slow particle needs no transform at all.
    if pose == prev {
        let len = (x - x_prev).norm();
        if len.is_nan() || len <= 1e-7 || current.is_some_and(|c| c.distance > len) {
            return None;
        }
    }
    let now = pose.inverse_transform_point(&Point3::from(*x)).coords;
    let before = prev.inverse_transform_point(&Point3::from(*x_prev)).coords;
    let d = now - before;
    let len = d.norm();
    // The segment can only touch the shape if the particle is now closer to the surface
    // than the segment's length.
    if len.is_nan() || len <= 1e-7 || current.is_some_and(|c| c.distance > len) {
        return None;
    }
    let ray = Ray::new(to_glam(&before), to_glam(&d));
    let hit = shape.cast_local_ray_and_get_normal(&ray, 1.0, true)?;
    let n_local = to_na(hit.normal);
    // Started outside (toi > 0) and moving into the face it hit.
    if !(hit.time_of_impact > 0.0 && n_local.dot(&d) < 0.0) {
        return None;
    }
    let q = pose * Point3::from(before + d * hit.time_of_impact);
    let n = pose.rotation * n_local;
    let distance = (x - q.coords).dot(&n);
    // Where point projection finds the particle inside on the entry side, it is the better
    // answer (it follows curved surfaces); the entry only wins where the closest point lies
    // on the other side or the particle passed through.
    if !distance.is_finite() || current.is_some_and(|c| c.distance < 0.0 && c.normal.dot(&n) > 0.0)
    {
        return None;
    }
    Some(SurfacePoint {
        point: q.coords,
        normal: n,
        distance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d::geometry::SharedShape;

    #[test]
    fn a_particle_passing_through_a_ball_is_caught_at_the_entry_face() {
        let ball = SharedShape::ball(0.1);
        let id = Isometry3::identity();
        // From 0.3 m above the centre to 0.15 m below it in one substep.
        let x_prev = Vector3::new(0.02, 0.3, 0.0);
        let x = Vector3::new(0.02, -0.15, 0.0);
        let sp = swept_entry(ball.as_ref(), &id, &id, &x, &x_prev, None).expect("entry");
        assert!(sp.normal.y > 0.9, "normal {:?}", sp.normal);
        assert!(sp.point.y > 0.09, "entry point {:?}", sp.point);
        assert!(sp.distance < -0.2, "distance {}", sp.distance);
    }

    #[test]
    fn the_ball_moving_onto_a_resting_particle_counts_too() {
        let ball = SharedShape::ball(0.1);
        let x = Vector3::new(0.0, 0.0, 0.0);
        let prev = Isometry3::translation(0.0, 0.3, 0.0);
        let pose = Isometry3::translation(0.0, -0.12, 0.0);
        let sp = swept_entry(ball.as_ref(), &pose, &prev, &x, &x, None).expect("entry");
        // Entered through the ball's bottom, so the particle belongs below it.
        assert!(sp.normal.y < -0.9 && sp.distance < 0.0, "{sp:?}");
    }

    #[test]
    fn slow_motion_and_motion_away_are_left_to_point_projection() {
        let ball = SharedShape::ball(0.1);
        let id = Isometry3::identity();
        let x_prev = Vector3::new(0.0, 0.2, 0.0);
        let x = Vector3::new(0.0, 0.19, 0.0);
        assert!(swept_entry(ball.as_ref(), &id, &id, &x, &x_prev, None).is_none());
        let away = Vector3::new(0.0, 0.5, 0.0);
        assert!(swept_entry(ball.as_ref(), &id, &id, &away, &x_prev, None).is_none());
    }
}
