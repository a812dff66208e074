//! A soft slab lying on the ground, its two ends attached to two rigid bodies that move
//! apart, tears in two: the coupling keeps working as the body's particle and surface
//! counts change (contacts, soft–soft structures, scene queries), each attachment follows
//! the piece holding its particle, and the pieces stay finite and on the ground. A cube cut
//! in two on the ground: its pieces rest against each other at the cut and, thrown together,
//! do not pass through each other.

mod coupling_common;

use coupling_common::{ground, scene};
use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::parry::query::Ray;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Blade, Particles, SoftBodyBuilder, Surface, TearingSettings};
use tetpbd_rapier::{follow_pieces, Attachments, CoupledWorld, SoftCollider, SoftQueryFilter};

const HALF: f32 = 0.5;

/// The slab (1 × 0.1 × 0.4 m) on the ground and the two bodies holding its end faces,
/// moving apart at `speed` m/s each.
fn slab_between_bodies(s: &mut CoupledWorld, speed: f32) -> (Entity, [RigidBodyHandle; 2]) {
    ground(s);
    let mesh = box_grid(
        Vector3::new(2.0 * HALF, 0.1, 0.4),
        [10, 1, 4],
        CellSplit::Six,
    )
    .unwrap();
    let body = SoftBodyBuilder::new(mesh)
        .edges(1e-6)
        .volume(1e-8)
        .tearing(TearingSettings {
            strain: Some(0.3),
            ..Default::default()
        })
        .translation(Vector3::new(0.0, 0.06, 0.0))
        .build()
        .unwrap();
    let mut handles = [RigidBodyHandle::invalid(); 2];
    let mut att = Attachments::new();
    for (k, side) in [-1.0f32, 1.0].into_iter().enumerate() {
        let (h, _) = s.physics.insert(
            RigidBodyBuilder::kinematic_velocity_based()
                .translation(Vector::new(side * (HALF + 0.05), 0.3, 0.0))
                .linvel(Vector::new(side * speed, 0.0, 0.0)),
            ColliderBuilder::cuboid(0.05, 0.05, 0.05),
        );
        handles[k] = h;
        for i in 0..body.particles.len() {
            if (body.particles.positions()[i].x - side * HALF).abs() < 1e-4 {
                att.attach_to_body(&body.particles, i as u32, &s.physics.bodies, h, 0.0)
                    .unwrap();
            }
        }
    }
    let e = body.spawn(&mut s.soft);
    s.soft.insert(e, (att, SoftCollider::default())).unwrap();
    (e, handles)
}

/// The bodies of the soft world holding attachments to `handle`, how many attachments they
/// hold in all, and whether every attached particle is within `tol` (m) of its anchor.
fn holders(s: &CoupledWorld, handle: RigidBodyHandle, tol: f32) -> (Vec<Entity>, usize, bool) {
    let mut out = Vec::new();
    let mut count = 0;
    let mut close = true;
    for (e, p, a) in s.soft.query::<(Entity, &Particles, &Attachments)>().iter() {
        let mut any = false;
        for item in a.items() {
            if let tetpbd_rapier::AttachTarget::Body {
                handle: h,
                local_point,
            } = item.target
            {
                if h != handle {
                    continue;
                }
                any = true;
                count += 1;
                let rb = &s.physics.bodies[h];
                let lp = Vector::new(local_point.x, local_point.y, local_point.z);
                let a = rb.position().transform_point(lp);
                let x = p.positions()[item.particle as usize];
                close &= (Vector3::new(a.x, a.y, a.z) - x).norm() < tol;
            }
        }
        if any {
            out.push(e);
        }
    }
    (out, count, close)
}

/// The centroid of the newest soft body's most upward-facing surface triangle (the largest
/// upward component of its unit normal: a ray straight down meets it square, not grazing), m.
fn newest_piece_top(s: &CoupledWorld) -> Vector3<f32> {
    let mut q = s.soft.query::<(Entity, &Particles, &Surface)>();
    let (_, p, surface) = q.iter().max_by_key(|(e, _, _)| *e).unwrap();
    let x = p.positions();
    let (_, centroid) = surface
        .triangles()
        .iter()
        .map(|&[a, b, c]| {
            let [a, b, c] = [a, b, c].map(|i| x[i as usize]);
            let up = (b - a).cross(&(c - a)).normalize().y;
            (up, (a + b + c) / 3.0)
        })
        .max_by(|u, v| u.0.total_cmp(&v.0))
        .unwrap();
    centroid
}

#[test]
fn a_slab_pulled_apart_by_two_bodies_tears_and_each_piece_keeps_its_body() {
    for speed in [1.0f32, 5.0, 20.0] {
        let mut s = scene(10);
        let (e, [left, right]) = slab_between_bodies(&mut s, speed);
        let attached = s.soft.get::<&Attachments>(e).unwrap().len() / 2;
        let mut events = 0;
        let frames = (60.0 * 0.6 / speed).ceil() as usize + 60;
        for frame in 0..frames {
            // Stop the bodies once the slab is well past its strain.
            if frame as f32 / 60.0 * speed > 0.6 {
                for h in [left, right] {
                    s.physics.bodies[h].set_linvel(Vector::ZERO, true);
                }
            }
            s.step().unwrap();
            events += s.coupling.tear_events().len();
            // The scene queries rebuild what changed: a ray cast down onto the top triangle
            // of the newest piece meets it (or something above it) a metre down.
            let top = newest_piece_top(&s);
            let (q, _) = s.queries();
            let ray = Ray::new(
                Vector::new(top.x, top.y + 1.0, top.z),
                Vector::new(0.0, -1.0, 0.0),
            );
            let hit = q
                .cast_ray(&ray, 2.0, true, SoftQueryFilter::default())
                .unwrap();
            let toi = hit.map_or(f32::INFINITY, |h| h.time_of_impact);
            assert!(
                toi <= 1.0 + 1e-3,
                "speed {speed}, frame {frame}: the ray missed the piece's top ({toi})"
            );
        }
        assert!(events > 0, "speed {speed}: the slab never tore");
        // Every attachment is still there, once, on the piece holding its particle, and no
        // piece is held by both bodies: the slab came apart between them.
        let (l, l_count, l_close) = holders(&s, left, 0.02);
        let (r, r_count, r_close) = holders(&s, right, 0.02);
        let pieces = s.soft.query::<&Particles>().iter().count();
        println!(
            "speed {speed} m/s: {events} tear events, {pieces} pieces, left end on {} and right end on {} of them",
            l.len(),
            r.len()
        );
        assert_eq!((l_count, r_count), (attached, attached), "speed {speed}");
        assert!(
            l.iter().all(|e| !r.contains(e)),
            "speed {speed}: a piece on both bodies"
        );
        assert!(
            l_close && r_close,
            "speed {speed}: an attachment lost its anchor"
        );
        for (p, c) in s.soft.query::<(&Particles, &SoftCollider)>().iter() {
            let _ = c;
            assert!(p
                .positions()
                .iter()
                .all(|x| x.iter().all(|c| c.is_finite())));
            assert!(p.masses().iter().all(|&m| m > 0.0));
            // Nothing fell through the ground: no particle above the ground's 10 × 10 m
            // top face is under it. (A fragment the tear flings off the edge may fall
            // past it; that is not tunnelling.)
            let sunk = p
                .positions()
                .iter()
                .filter(|x| x.x.abs() < 5.0 && x.z.abs() < 5.0)
                .map(|x| x.y)
                .fold(f32::INFINITY, f32::min);
            assert!(sunk > -0.05, "speed {speed}: a piece sank to {sunk}");
        }
    }
}

/// A cut through a coupled body: [`follow_pieces`] moves the attachments and the collider,
/// and the coupling steps the pieces on.
#[test]
fn a_cut_body_keeps_its_attachments_on_the_right_piece() {
    let mut s = scene(10);
    let (e, [left, right]) = slab_between_bodies(&mut s, 0.0);
    s.step().unwrap();
    let blade = Blade::Plane {
        point: Vector3::new(0.05, 0.0, 0.0),
        normal: Vector3::x(),
    };
    let event = tetpbd::cut(&mut s.soft, e, &blade).unwrap().unwrap();
    follow_pieces(&mut s.soft, &event);
    assert_eq!(event.pieces.len(), 2);
    for _ in 0..30 {
        s.step().unwrap();
    }
    let (l, _, l_close) = holders(&s, left, 0.01);
    let (r, _, r_close) = holders(&s, right, 0.01);
    assert_eq!((l.len(), r.len()), (1, 1));
    assert_ne!(l, r);
    assert!(l_close && r_close);
    let colliders = s.soft.query::<&SoftCollider>().iter().count();
    assert_eq!(colliders, 2, "the new piece has no collider");
}

/// A cube resting on the ground cut in two: the pieces meet at the cut, face to face, and
/// their soft–soft contacts hold them there without pushing them apart or through each
/// other; thrown back against each other, they do not pass through.
#[test]
fn the_pieces_of_a_cut_cube_rest_against_each_other() {
    for split in [CellSplit::Five, CellSplit::Six] {
        let mut s = scene(10);
        ground(&mut s);
        let mesh = box_grid(Vector3::new(0.4, 0.4, 0.4), [4, 4, 4], split).unwrap();
        let body = SoftBodyBuilder::new(mesh)
            .edges(0.0)
            .volume(0.0)
            .translation(Vector3::new(0.0, 0.2, 0.0))
            .build()
            .unwrap();
        let e = body.spawn(&mut s.soft);
        s.soft.insert_one(e, SoftCollider::default()).unwrap();
        for _ in 0..60 {
            s.step().unwrap();
        }
        let blade = Blade::Plane {
            point: Vector3::new(0.0, 0.0, 0.0),
            normal: Vector3::x(),
        };
        let event = tetpbd::cut(&mut s.soft, e, &blade).unwrap().unwrap();
        follow_pieces(&mut s.soft, &event);
        assert_eq!(event.pieces.len(), 2);
        let centre = |s: &CoupledWorld, e: Entity| {
            let p = s.soft.get::<&Particles>(e).unwrap();
            let m: f32 = p.masses().iter().sum();
            p.positions()
                .iter()
                .zip(p.masses())
                .fold(Vector3::zeros(), |c, (x, &w)| c + x * w)
                / m
        };
        let pieces: Vec<Entity> = event.pieces.iter().map(|p| p.entity).collect();
        let start: Vec<Vector3<f32>> = pieces.iter().map(|&e| centre(&s, e)).collect();
        // A gap between the pieces: the left piece's largest x and the right one's smallest.
        let gap = |s: &CoupledWorld| {
            let xs: Vec<(f32, f32)> = pieces
                .iter()
                .map(|&e| {
                    let p = s.soft.get::<&Particles>(e).unwrap();
                    let lo = p
                        .positions()
                        .iter()
                        .map(|x| x.x)
                        .fold(f32::INFINITY, f32::min);
                    let hi = p
                        .positions()
                        .iter()
                        .map(|x| x.x)
                        .fold(f32::NEG_INFINITY, f32::max);
                    (lo, hi)
                })
                .collect();
            let (left, right) = if xs[0].0 < xs[1].0 {
                (xs[0], xs[1])
            } else {
                (xs[1], xs[0])
            };
            right.0 - left.1
        };
        for _ in 0..120 {
            s.step().unwrap();
        }
        for (k, &e) in pieces.iter().enumerate() {
            let moved = (centre(&s, e) - start[k]).norm();
            let speed = s.soft.get::<&Particles>(e).unwrap().max_speed();
            assert!(moved < 0.01, "{split:?}: piece {k} moved {moved} m");
            assert!(speed < 0.05, "{split:?}: piece {k} still at {speed} m/s");
        }
        assert!(
            gap(&s) > -0.01,
            "{split:?}: the pieces overlap by {}",
            -gap(&s)
        );
        // Thrown at each other at 3 m/s: they meet and stop, not through.
        for &e in &pieces {
            let mut p = s.soft.get::<&mut Particles>(e).unwrap();
            let c = centre_x(&p);
            for i in 0..p.len() {
                p.set_velocity(i, Vector3::new(-3.0f32.copysign(c), 0.0, 0.0))
                    .unwrap();
            }
        }
        for _ in 0..60 {
            s.step().unwrap();
            assert!(
                gap(&s) > -0.05,
                "{split:?}: the thrown pieces passed through each other"
            );
        }
    }
}

/// The mean x of a body's particles, m.
fn centre_x(p: &Particles) -> f32 {
    p.positions().iter().map(|x| x.x).sum::<f32>() / p.len() as f32
}
