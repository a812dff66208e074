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
//! motion as for particles. The rigid points (`gather::corner_points` module) are
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
//! where it crossed (`ccd` module docs). Points of moving bodies that crossed are projected
//! in a pass of their own before the particle contacts, even where a vertex touches the
//! collider: one particle alone cannot stop a fast body, and its contact normal may be tilted
//! enough to let the body slip past it.
//!
//! A point found behind its triangle without crossing it in the substep (the soft surface
//! slid over a corner already inside the body, or a body created overlapping) is an overlap,
//! not an impact: as for particle contacts (`contacts::particle` module docs), the depth it
//! had at the substep start, less `max_depenetration_speed · h`, is tolerated and shrinks by
//! that much every substep, so it is pushed out at the depenetration speed. (A draped soft
//! body whose bottom triangle slid over a box corner 15 cm inside it otherwise took the
//! whole depth at once, most of it as the whole body's motion ([`tetpbd::ImpactReach`]), and
//! jumped off the box at 5 m/s.) The depth at the start is looked at in every substep the
//! point is found behind, not only in the first: a pair that met shallow can later stand
//! deep (a body crushed over a box corner slides a triangle on whose plane the corner lies
//! 14 cm behind), and pushing that out in one substep of 0.4 ms threw a 51.6 kg body thrown
//! at 40 m/s onto a 0.95 kg box off at 109 m/s (its kinetic energy 41 → 380 kJ in one pass).
//!
//! A support point over a triangle with a vertex that *holds* the collider is skipped in the
//! ordinary pass: a vertex in contact with the collider (in the same iteration) whose contact
//! normal lies within 30° of the triangle's normal. There the particle contact holds the
//! surface, and two sets of constraints on the same spot only fight. A vertex touching the
//! collider's side (its normal tilted further) does not hold it: the body slides past that
//! particle into the triangle. (A fast ball pressing a vertex of a compliant slab into its
//! side tilts that vertex's normal about 45° off the triangle's; if every touching vertex
//! ruled its triangles out, the ball would sink into the slab.)
//!
//! Only a smooth shape's support point is left to a holding vertex: it lies on the same smooth
//! surface as the vertex's contact, near it (projecting it as well makes a ball bounce off a
//! compliant slab). A polyhedral corner is a feature of its own, which a vertex resting on a face
//! beside it does not keep out of the triangle (where the vertex rests on the corner itself, the
//! triangle's constraint is about met already), so it is always projected: a soft cube whose coarse
//! bottom face meets a smaller box top only at its centre particle would otherwise rest on that
//! particle alone, the box's top corners sinking unchecked into the triangles around it, and tip
//! over. Tolerating the corner within the triangle's skin (the thickness) while a vertex holds does
//! not do either: the skin is pushed out whenever the vertex lets go, which keeps the body
//! rattling.
//!
//! The smooth parts of a compound take no part (their contacts with the soft particles
//! still act). `v` is only caught while its projection
//! falls inside the triangle (within 0.1 % of its barycentric range, so a point on a shared
//! edge is not lost between two triangles) and it is less than half the triangle's shortest
//! edge behind it, so triangles on the far side of the body never grab it. A corner of a
//! fixed collider is therefore only paired with the triangles whose bounds over the frame
//! (the vertices' positions and their predicted positions one frame on), loosened by the
//! thickness and half the triangle's longest edge, contain it: the far corners of a ground
//! cuboid are not evaluated against every soft triangle beside the particles resting on it.

use nalgebra::{Isometry3, Point3, Vector3};
use rapier3d::geometry::ColliderSet;
use tetpbd::{Particles, Surface};

use crate::contacts::corner_friction::friction;
use crate::contacts::particle::ParticleContact;
use crate::convert::{to_glam, to_na};
use crate::rigid::body::{BodyKind, BodyProxy};
use crate::rigid::collider::ColliderProxy;
use tetpbd::ImpactReach;

/// Cosine of the largest angle between a vertex's particle contact normal and its triangle's
/// normal at which the particle contact still holds the collider against the triangle, so
/// the triangle is left to it in the ordinary pass (30°; not sensitive between 20° and 45°).
const HOLDING_ANGLE_COS: f32 = 0.866;

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
    /// Depth (m) this contact tolerates: the overlap the point had at the start of any
    /// substep it was found behind its triangle in, less one substep's push, shrinking by
    /// that push every substep (module docs).
    pub allowance: f32,
    pub sub_impulse: Vector3<f32>,
    pub impulse: Vector3<f32>,
}

/// Which rigid points a sweep over the corner contacts projects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CornerPass {
    /// Only points of moving (non-fixed) bodies that crossed their triangle within the
    /// substep: this pass runs before the particle contacts, so a fast body is stopped by
    /// the surface it hits first rather than by a particle poking into it from the side.
    Crossing,
    /// Every point, except on triangles with a vertex holding the same collider (module docs).
    Ordinary,
    /// Every point, on every triangle: the soft surface is frozen (the heavy-load pass,
    /// `heavy_loads`), so a particle contact and a triangle on the same spot cannot fight; they
    /// both push the rigid body out.
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
    max_push: f32,
    impact: &mut ImpactReach,
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
                    (pass, max_push),
                    impact,
                );
            }
            i += run;
        }
    } else {
        sweep_corners(
            corners,
            contacts,
            p,
            surface,
            bodies,
            colliders,
            set,
            (pass, max_push),
            impact,
        );
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
    (pass, max_push): (CornerPass, f32),
    impact: &mut ImpactReach,
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
        let idx = tri.map(|i| i as usize);
        let [a, b, c] = idx.map(|i| p.positions()[i]);
        let Some((n, area2)) = unit_normal(&a, &b, &c) else {
            continue;
        };
        // In the ordinary pass a vertex holding the collider rules the triangle out for a
        // support point (a crossing there is only taken in the crossing pass); a polyhedral
        // corner is never left to a vertex (module docs).
        if pass == CornerPass::Ordinary && k.corner.is_none() && vertex_holds(k, contacts, &n) {
            continue;
        }
        let cp = &colliders[k.collider];
        let shortest = || (b - a).norm().min((c - b).norm()).min((a - c).norm());
        // The crossing pass only takes fast points; the others only need to know once the
        // point is found behind the plane.
        let early = crossing_only.then(|| {
            let shortest = shortest();
            (shortest, is_fast(k, cp, set, moved, shortest))
        });
        if early.is_some_and(|(_, fast)| !fast) {
            continue;
        }
        let pose = cp.pose(bodies);
        let Some(local) = rigid_point(k, cp, set, &pose, &n) else {
            continue;
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
        let (shortest, fast) = early.unwrap_or_else(|| {
            let shortest = shortest();
            (shortest, is_fast(k, cp, set, moved, shortest))
        });
        // Crossed the plane from the front within this substep (a fast rigid point, one that
        // itself moved more than a tenth of the shortest edge): caught at any depth, at the
        // crossing point. The point's start of the substep is carried along with the
        // triangle's vertex `a`, so the motion is relative to the triangle. Slow crossings (a
        // body settling on the surface, or the soft surface moving fast under a slow body)
        // are left to the ordinary rule: only within half the shortest edge behind the
        // plane, so triangles on the far side of the body never grab it.
        let crossing = fast.then(|| {
            let v_start = (cp.prev_pose(bodies) * Point3::from(local)).coords;
            let a_prev = p.prev_positions()[idx[0]];
            crossing_point(&v, &v_start, &a, &a_prev, &n, shortest)
        });
        let (q, c_val) = if let Some(Some(q)) = crossing {
            (q, c_val)
        } else if s >= -0.5 * shortest && !crossing_only {
            // Found behind the plane, not crossing it now: an overlap already there at the
            // substep start is pushed out at the depenetration speed (module docs).
            let v_start = (cp.prev_pose(bodies) * Point3::from(local)).coords;
            let s_start = (v_start - p.prev_positions()[idx[0]]).dot(&n);
            k.allowance = k.allowance.max(k.thickness - s_start - max_push);
            let c_val = c_val + k.allowance;
            if c_val >= 0.0 {
                continue;
            }
            (v, c_val)
        } else {
            continue;
        };
        let Some(beta) = barycentric(&q, [a, b, c], &n, area2) else {
            continue;
        };
        let hit = Hit { v, n, c_val, beta };
        push_out(k, p, idx, bodies, cp.body, &hit, impact);
    }
}

/// Unit outward normal and twice the area of triangle `(a, b, c)`; `None` when degenerate.
fn unit_normal(
    a: &Vector3<f32>,
    b: &Vector3<f32>,
    c: &Vector3<f32>,
) -> Option<(Vector3<f32>, f32)> {
    let m = (b - a).cross(&(c - a));
    let area2 = m.norm();
    if area2.is_nan() || area2 <= 1e-12 {
        return None;
    }
    Some((m / area2, area2))
}

/// Where the rigid point (now at `v`, at `v_start` at the substep start) crossed the plane of
/// a triangle (vertex `a`, at `a_prev` at the substep start; unit normal `n`) from the front
/// within the substep, its motion taken relative to the triangle; `None` if it did not or
/// moved less than a tenth of the triangle's `shortest` edge.
fn crossing_point(
    v: &Vector3<f32>,
    v_start: &Vector3<f32>,
    a: &Vector3<f32>,
    a_prev: &Vector3<f32>,
    n: &Vector3<f32>,
    shortest: f32,
) -> Option<Vector3<f32>> {
    let s = (v - a).dot(n);
    let v_prev = v_start + (a - a_prev);
    let s_prev = (v_prev - a).dot(n);
    let fast_point = (v - v_start).norm_squared() > (0.1 * shortest).powi(2);
    (s_prev > 0.0 && s < 0.0 && fast_point).then(|| v_prev + (v - v_prev) * (s_prev / (s_prev - s)))
}

/// The rigid point of `k` in its collider's frame: the polyhedral corner, or the support
/// point of the shape (placed at `pose`) in the direction `−n`.
fn rigid_point(
    k: &CornerContact,
    cp: &ColliderProxy,
    set: &ColliderSet,
    pose: &Isometry3<f32>,
    n: &Vector3<f32>,
) -> Option<Vector3<f32>> {
    match k.corner {
        Some(c) => Some(c),
        None => {
            let support = set
                .get(cp.handle)
                .and_then(|co| co.shape().as_support_map())?;
            let dir = pose.rotation.inverse() * (-n);
            Some(to_na(support.local_support_point(to_glam(&dir))))
        }
    }
}

/// Barycentric weights of `q`'s projection onto the plane of triangle `[a, b, c]` (unit
/// normal `n`, `area2` twice its area), clamped and normalised; `None` outside it. A point on
/// a shared edge must not fall through the crack between two triangles: a small tolerance
/// is accepted and clamped.
fn barycentric(
    q: &Vector3<f32>,
    [a, b, c]: [Vector3<f32>; 3],
    n: &Vector3<f32>,
    area2: f32,
) -> Option<[f32; 3]> {
    let q = q - n * (q - a).dot(n);
    let wa = (b - q).cross(&(c - q)).dot(n) / area2;
    let wb = (c - q).cross(&(a - q)).dot(n) / area2;
    let wc = 1.0 - wa - wb;
    const TOL: f32 = 1e-3;
    if [wa, wb, wc].iter().any(|w| *w < -TOL || *w > 1.0 + TOL) {
        return None;
    }
    let clamped = [wa, wb, wc].map(|w| w.clamp(0.0, 1.0));
    let sum: f32 = clamped.iter().sum();
    Some(clamped.map(|w| w / sum))
}

/// A rigid point found behind its triangle.
struct Hit {
    /// The rigid point (world, m) and the triangle's unit outward normal.
    v: Vector3<f32>,
    n: Vector3<f32>,
    /// Constraint value (< 0), m.
    c_val: f32,
    /// Barycentric weights of the point's projection on the triangle.
    beta: [f32; 3],
}

/// Projects the corner contact `k` (module docs) and applies its friction.
fn push_out(
    k: &mut CornerContact,
    p: &mut Particles,
    idx: [usize; 3],
    bodies: &mut [BodyProxy],
    body: Option<usize>,
    hit: &Hit,
    impact: &mut ImpactReach,
) {
    let Hit { v, n, beta, .. } = *hit;
    let mut c_val = hit.c_val;
    let w = idx.map(|i| p.inv_masses()[i]);
    let w_body = body.map_or(0.0, |bi| bodies[bi].inv_mass_pushed(&v, &n));
    // Deeper than the surface takes locally: the rest meets the whole soft body (`tetpbd::ImpactReach`
    // module docs).
    if let Some((dl, excess)) = impact.take_excess(p, c_val, w_body, &(-n)) {
        if let Some(bi) = body {
            bodies[bi].apply_position_impulse(&(n * dl), &v);
        }
        k.sub_impulse -= n * dl;
        k.lambda_n += dl;
        c_val += excess;
    }
    let denom: f32 = (0..3).map(|j| w[j] * beta[j] * beta[j]).sum::<f32>() + w_body;
    if denom.is_nan() || denom <= 0.0 {
        return;
    }
    let dl = -c_val / denom;
    let x = p.positions_mut();
    for j in 0..3 {
        x[idx[j]] -= n * (w[j] * beta[j] * dl);
    }
    if let Some(bi) = body {
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
    friction(k, p, idx, beta, bodies, body, &v, &n);
}

/// Whether a vertex of the triangle (unit outward normal `n`) already touches the collider with a
/// contact normal close to the triangle's: that particle contact then holds the body against the
/// surface, and the triangle only stops a support point that slips between particles (and what
/// crosses it within the substep). A vertex touching the body's side, its normal tilted more than
/// `HOLDING_ANGLE_COS` from the triangle's, does not hold it: the body slides past that particle
/// into the triangle.
fn vertex_holds(k: &CornerContact, contacts: &[ParticleContact], n: &Vector3<f32>) -> bool {
    k.vertex_contacts.iter().flatten().any(|&i| {
        contacts
            .get(i)
            .is_some_and(|c| c.active && -c.normal.dot(n) > HOLDING_ANGLE_COS)
    })
}

/// Whether the rigid point of `k` moves more than a tenth of the triangle's `shortest` edge
/// in the substep (`moved`: the body's shift and turn, `None` for a fixed body). Bounded by
/// the body's shift plus its turn times the point's distance from the body's origin; support
/// points by the shape's bounding sphere.
fn is_fast(
    k: &CornerContact,
    cp: &ColliderProxy,
    set: &ColliderSet,
    moved: Option<(f32, f32)>,
    shortest: f32,
) -> bool {
    moved.is_some_and(|(shift, turn)| {
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
    })
}
