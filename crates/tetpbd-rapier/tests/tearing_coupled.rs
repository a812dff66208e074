//! A soft slab lying on the ground, its two ends attached to two rigid bodies that move
//! apart, tears in two: the coupling keeps working as the body's particle and surface
//! counts change (contacts, soft–soft structures, scene queries), each attachment follows
//! the piece holding its particle, and the pieces stay finite and on the ground.

mod coupling_common;

use coupling_common::{ground, scene};
use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::parry::query::Ray;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Blade, Particles, SoftBodyBuilder, TearingSettings};
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
            // The scene queries rebuild what changed.
            let (q, qp) = s.queries();
            let _ = qp;
            let ray = Ray::new(Vector::new(0.0, 1.0, 0.0), Vector::new(0.0, -1.0, 0.0));
            q.cast_ray(&ray, 2.0, true, SoftQueryFilter::default())
                .unwrap();
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
