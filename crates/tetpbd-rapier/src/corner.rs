//! Rigid features against soft surface triangles.
//!
//! A coarse soft body has few surface particles; a sharp rigid corner, or a ball smaller
//! than the gap between particles, can slip between them without any particle entering the
//! rigid shape. This is the seed's vertex–face constraint with a rigid point `v` as the
//! vertex. For a boundary triangle `(a, b, c)` with outward unit normal `n` and barycentric
//! weights `β` of `v`'s projection onto it:
//!
//! ```text
//! C = (v − (β_a a + β_b b + β_c c))·n − thickness ≥ 0
//! ∇_v C = n,   ∇_k C = −β_k n   (normal held fixed for the projection)
//! Δλ = −C / (Σ w_k β_k² + w_rigid(v, n))
//! ```
//!
//! The correction is spread over the triangle's particles barycentrically and the opposite
//! impulse goes to the rigid body at `v`; Coulomb friction acts on the relative tangential
//! motion as for particles. The rigid points are
//!
//! * every vertex of a polyhedral shape (cuboid, convex polyhedron, triangle; the inner
//!   vertices of the rounded variants, border radius added to the thickness), each its own
//!   constraint, so a face resting flat on the soft surface pushes evenly;
//! * the vertices of a triangle mesh or heightfield near the soft body (of its triangles
//!   inside the soft body's swept bounds), each paired only with the soft triangles near it;
//! * a compound's parts by these rules, each rounded part with its own border radius;
//! * for the other shapes with a support map (ball, capsule, cylinder, cone, segment and
//!   rounded variants), the support point in direction `−n`: the shape's deepest point
//!   towards the triangle.
//!
//! A point that crossed the triangle's plane from the front within the substep (a fast
//! rigid body, motion taken relative to the triangle) is caught at any depth, at the point
//! where it crossed (`sweep` module docs). Points of moving bodies that crossed are projected
//! in a pass of their own before the particle contacts, even where a vertex touches the
//! collider: one particle alone cannot stop a fast body, and its contact normal may be tilted
//! enough to let the body slip past it.
//!
//! A triangle whose vertex is itself in contact with the collider (in the same iteration)
//! is skipped: there the particle contacts hold the surface, and two sets of constraints on
//! the same spot only fight. The smooth parts of a compound take no part (their contacts
//! with the soft particles still act). `v` is only caught while its projection
//! falls inside the triangle (within 0.1 % of its barycentric range, so a point on a shared
//! edge is not lost between two triangles) and it is less than half the triangle's shortest
//! edge behind it, so triangles on the far side of the body never grab it.

use nalgebra::{Isometry3, Point3, Vector3};
use rapier3d::geometry::{Aabb, ColliderSet};
use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::parry::shape::Shape;
use tetpbd::{Particles, Surface};

use crate::bodies::{BodyKind, BodyProxy};
use crate::convert::{pose_to_glam, to_glam, to_na};
use crate::frame::{ColliderProxy, ParticleContact};

/// One rigid shape over one soft surface triangle.
#[derive(Clone, Debug)]
pub(crate) struct CornerContact {
    pub collider: usize,
    /// On the first candidate of a collider's run (they are gathered per collider, one run
    /// each): the run's length; 0 elsewhere. Lets the crossing pass skip fixed colliders.
    pub run: u32,
    /// A polyhedral shape's corner in its local frame; `None`: the support point.
    pub corner: Option<Vector3<f32>>,
    pub triangle: u32,
    /// The particle contacts of the triangle's vertices with the same collider (indices
    /// into the soft body's contacts).
    pub vertex_contacts: [Option<usize>; 3],
    pub thickness: f32,
    pub restitution: f32,
    pub active: bool,
    pub mu_d: f32,
    pub mu_s: f32,
    pub lambda_n: f32,
    pub lambda_t: f32,
    pub ever_active: bool,
    pub depth: f32,
    pub normal: Vector3<f32>,
    pub point: Vector3<f32>,
    /// Barycentric weights of `point` on the triangle at its last projection.
    pub beta: [f32; 3],
    pub sub_impulse: Vector3<f32>,
    pub impulse: Vector3<f32>,
}

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

/// Adds the corner–triangle candidates of one collider against one soft body. `corners` is
/// scratch space (its capacity is reused across calls).
#[allow(clippy::too_many_arguments)]
pub(crate) fn gather_corners(
    out: &mut Vec<CornerContact>,
    shape: &dyn Shape,
    collider: usize,
    collider_aabb: &Aabb,
    pose: &Isometry3<f32>,
    p: &Particles,
    surface: &Surface,
    dt: f32,
    thickness: f32,
    (mu_d, mu_s, restitution): (f32, f32, f32),
    vertex_contacts: &[(u32, usize)],
    corners: &mut Corners,
) {
    // The soft body's surface over the frame, in the collider's frame (at its end pose).
    let mut lo = Vector3::repeat(f32::INFINITY);
    let mut hi = Vector3::repeat(f32::NEG_INFINITY);
    for &i in surface.vertices() {
        let x = p.positions()[i as usize];
        let y = x + p.velocities()[i as usize] * dt;
        lo = lo.inf(&x.inf(&y));
        hi = hi.sup(&x.sup(&y));
    }
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
            // A mesh vertex only with the soft triangles near it.
            if corners.from_mesh
                && corner.is_some_and(|c| {
                    !ta.contains_local_point(to_glam(&(pose * Point3::from(c)).coords))
                })
            {
                continue;
            }
            out.push(CornerContact {
                collider,
                run: 0,
                corner,
                triangle: t as u32,
                vertex_contacts: vc,
                thickness: thickness + extra,
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
                sub_impulse: Vector3::zeros(),
                impulse: Vector3::zeros(),
            });
        }
    }
    let run = out.len() - first;
    if let Some(k) = out.get_mut(first) {
        k.run = u32::try_from(run).unwrap_or(u32::MAX);
    }
}

/// Which rigid points a sweep over the corner contacts projects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CornerPass {
    /// Only points of moving (non-fixed) bodies that crossed their triangle within the
    /// substep: this pass runs before the particle contacts, so a fast body is stopped by
    /// the surface it hits first rather than by a particle poking into it from the side.
    Crossing,
    /// Every point, except on triangles with a vertex touching the same collider.
    Ordinary,
    /// Every point, on every triangle: the soft surface is frozen (the `stacking` pass), so
    /// a particle contact and a triangle on the same spot cannot fight; they both push the
    /// rigid body out.
    Frozen,
}

/// One Gauss–Seidel sweep over a soft body's corner contacts (see [`CornerPass`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn project_corners(
    corners: &mut [CornerContact],
    contacts: &[ParticleContact],
    p: &mut Particles,
    surface: &Surface,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
    set: &ColliderSet,
    pass: CornerPass,
) {
    if pass == CornerPass::Crossing {
        // Only the runs of moving colliders.
        let mut i = 0;
        while i < corners.len() {
            let run = (corners[i].run as usize).clamp(1, corners.len() - i);
            let moving = colliders[corners[i].collider]
                .body
                .is_some_and(|b| bodies[b].kind != BodyKind::Fixed);
            if moving {
                sweep_corners(
                    &mut corners[i..i + run],
                    contacts,
                    p,
                    surface,
                    bodies,
                    colliders,
                    set,
                    pass,
                );
            }
            i += run;
        }
    } else {
        sweep_corners(corners, contacts, p, surface, bodies, colliders, set, pass);
    }
}

#[allow(clippy::too_many_arguments)]
fn sweep_corners(
    corners: &mut [CornerContact],
    contacts: &[ParticleContact],
    p: &mut Particles,
    surface: &Surface,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
    set: &ColliderSet,
    pass: CornerPass,
) {
    let crossing_only = pass == CornerPass::Crossing;
    for k in corners {
        // The crossing pass only sees moving bodies; a fixed one cannot cross by itself.
        let moved = match colliders[k.collider].body {
            Some(b) if bodies[b].kind != BodyKind::Fixed => Some(bodies[b].substep_motion),
            _ => None,
        };
        if crossing_only && moved.is_none() {
            continue;
        }
        let Some(tri) = surface.triangles().get(k.triangle as usize) else {
            continue;
        };
        // Where a vertex already touches the collider, the particle contacts hold the
        // surface; the triangle only stops what slips between particles (and what crosses
        // it within the substep, below).
        let vertex_touches = k
            .vertex_contacts
            .iter()
            .flatten()
            .any(|&c| contacts.get(c).is_some_and(|c| c.active));
        // In the ordinary pass a touching vertex rules the triangle out (a crossing there is
        // only taken in the crossing pass).
        if vertex_touches && pass == CornerPass::Ordinary {
            continue;
        }
        let idx = tri.map(|i| i as usize);
        let [a, b, c] = idx.map(|i| p.positions()[i]);
        let cp = &colliders[k.collider];
        let shortest = (b - a).norm().min((c - b).norm()).min((a - c).norm());
        // Fast: the rigid point moves more than a tenth of the shortest edge in the substep
        // (bounded by the body's shift plus its turn times the point's distance from the
        // body's origin; support points bounded by the shape's bounding sphere).
        let fast = moved.is_some_and(|(shift, turn)| {
            let limit = 0.1 * shortest;
            if shift > limit || turn <= 0.0 {
                return shift > limit;
            }
            let radius = match k.corner {
                Some(c) => c.norm(),
                None => set.get(cp.handle).map_or(f32::INFINITY, |co| {
                    let sphere = co.shape().compute_local_bounding_sphere();
                    sphere.radius + to_na(sphere.center).norm()
                }),
            };
            shift + turn * (radius + cp.local.translation.vector.norm()) > limit
        });
        if crossing_only && !fast {
            continue;
        }
        let m = (b - a).cross(&(c - a));
        let area2 = m.norm();
        if area2.is_nan() || area2 <= 1e-12 {
            continue;
        }
        let n = m / area2;
        let pose = cp.pose(bodies);
        let local = match k.corner {
            Some(c) => c,
            None => {
                let Some(support) = set
                    .get(cp.handle)
                    .and_then(|co| co.shape().as_support_map())
                else {
                    continue;
                };
                let dir = pose.rotation.inverse() * (-n);
                to_na(support.local_support_point(to_glam(&dir)))
            }
        };
        let v = (pose * Point3::from(local)).coords;
        if !crate::convert::finite3(&v) {
            continue;
        }
        let s = (v - a).dot(&n);
        let c_val = s - k.thickness;
        if c_val >= 0.0 {
            continue;
        }
        // Crossed the plane from the front within this substep (a fast rigid point, one that
        // itself moved more than a tenth of the shortest edge): caught at any depth, at the
        // crossing point. The point's start of the substep is carried along with the
        // triangle's vertex `a`, so the motion is relative to the triangle. Slow crossings (a
        // body settling on the surface, or the soft surface moving fast under a slow body)
        // are left to the ordinary rule: only within half the shortest edge behind the
        // plane, so triangles on the far side of the body never grab it.
        let crossing = fast.then(|| {
            let v_start = (cp.prev_pose(bodies) * Point3::from(local)).coords;
            let v_prev = v_start + (a - p.prev_positions()[idx[0]]);
            let s_prev = (v_prev - a).dot(&n);
            let fast_point = (v - v_start).norm_squared() > (0.1 * shortest).powi(2);
            (s_prev > 0.0 && s < 0.0 && fast_point)
                .then(|| v_prev + (v - v_prev) * (s_prev / (s_prev - s)))
        });
        let q = if let Some(Some(q)) = crossing {
            q
        } else if s >= -0.5 * shortest && !crossing_only {
            v
        } else {
            continue;
        };
        // Barycentric weights of q's projection onto the triangle's plane.
        let q = q - n * (q - a).dot(&n);
        let wa = (b - q).cross(&(c - q)).dot(&n) / area2;
        let wb = (c - q).cross(&(a - q)).dot(&n) / area2;
        let wc = 1.0 - wa - wb;
        // A point on a shared edge must not fall through the crack between two triangles:
        // accept a small tolerance and clamp.
        const TOL: f32 = 1e-3;
        if [wa, wb, wc].iter().any(|w| *w < -TOL || *w > 1.0 + TOL) {
            continue;
        }
        let clamped = [wa, wb, wc].map(|w| w.clamp(0.0, 1.0));
        let sum: f32 = clamped.iter().sum();
        let beta = clamped.map(|w| w / sum);
        let w = idx.map(|i| p.inv_masses()[i]);
        let w_body = cp.body.map_or(0.0, |bi| bodies[bi].inv_mass_pushed(&v, &n));
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
        k.active = true;
        k.depth = k.depth.max(-c_val);
        k.normal = -n;
        k.point = v;
        k.beta = beta;
        k.sub_impulse -= n * dl;
        k.lambda_n += dl;
        friction(k, p, idx, beta, bodies, cp.body, &v, &n);
    }
}

/// Coulomb friction between the rigid point `v` and the triangle (as for particles, see
/// [`crate::contact`]): the relative tangential motion over the substep is removed while
/// the tangential multiplier stays under `μ_s λ_n`, else limited to `μ_d λ_n`.
#[allow(clippy::too_many_arguments)]
fn friction(
    k: &mut CornerContact,
    p: &mut Particles,
    idx: [usize; 3],
    beta: [f32; 3],
    bodies: &mut [BodyProxy],
    body: Option<usize>,
    v: &Vector3<f32>,
    n: &Vector3<f32>,
) {
    let tri_motion: Vector3<f32> = (0..3)
        .map(|j| (p.positions()[idx[j]] - p.prev_positions()[idx[j]]) * beta[j])
        .sum();
    let body_motion = body.map_or(Vector3::zeros(), |b| {
        let rb = &bodies[b];
        let local = rb.pose.inverse_transform_point(&Point3::from(*v));
        (rb.pose * local).coords - (rb.prev * local).coords
    });
    let d = body_motion - tri_motion;
    let dt = d - n * n.dot(&d);
    let len = dt.norm();
    if len.is_nan() || len <= 1e-9 {
        return;
    }
    let t = dt / len;
    let w = idx.map(|i| p.inv_masses()[i]);
    let w_body = body.map_or(0.0, |b| bodies[b].inv_mass_at(v, &t));
    let denom: f32 = (0..3).map(|j| w[j] * beta[j] * beta[j]).sum::<f32>() + w_body;
    if denom.is_nan() || denom <= 0.0 {
        return;
    }
    let full = len / denom;
    let applied = if k.lambda_t + full <= k.mu_s * k.lambda_n {
        full
    } else {
        full.min((k.mu_d * k.lambda_n - k.lambda_t).max(0.0))
    };
    if applied <= 0.0 {
        return;
    }
    let x = p.positions_mut();
    for j in 0..3 {
        x[idx[j]] += t * (w[j] * beta[j] * applied);
    }
    if let Some(b) = body {
        bodies[b].apply_position_impulse(&(-t * applied), v);
    }
    k.lambda_t += applied;
    k.sub_impulse += t * applied;
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
