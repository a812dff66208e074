//! The coupling's components follow a soft body's pieces after a tear or a cut: each
//! attachment moves to the piece holding its particle (renumbered there), and each new
//! piece gets the body's [`SoftCollider`] and [`SelfCollision`].
//!
//! [`Coupling::step`](crate::Coupling::step) does it for the tears of its step; after a
//! [`tetpbd::cut`], call [`follow_pieces`] with the event. The per-body structures the
//! coupling keeps across frames (the soft–soft BVHs, the scene queries' snapshot) compare
//! each body's particle, tetrahedron and surface counts every frame and are rebuilt when
//! they change; the rest is gathered anew every frame.

use hecs::World;
use tetpbd::TearEvent;

use crate::attachments::Attachments;
use crate::soft_collider::SoftCollider;
use crate::soft_soft::settings::SelfCollision;

/// Moves the coupling's components of the body of `event` to its pieces (module docs).
/// Does nothing for an event whose mesh did not change.
pub fn follow_pieces(world: &mut World, event: &TearEvent) {
    if event.pieces.is_empty() {
        return;
    }
    let body = event.body;
    let collider = world.get::<&SoftCollider>(body).ok().map(|c| *c);
    let self_collision = world.get::<&SelfCollision>(body).is_ok();
    let attachments = world.get::<&Attachments>(body).ok().map(|a| (*a).clone());
    let mut lists = vec![Attachments::new(); event.pieces.len()];
    if let Some(a) = &attachments {
        for item in a.items() {
            if let Some((k, particle)) = event.moved(item.particle) {
                let mut moved = *item;
                moved.particle = particle;
                lists[k].items.push(moved);
            }
        }
    }
    for (k, (piece, list)) in event.pieces.iter().zip(lists).enumerate() {
        let e = piece.entity;
        if attachments.is_some() && (k == 0 || !list.is_empty()) {
            let _ = world.insert_one(e, list);
        }
        if k == 0 {
            continue;
        }
        if let Some(c) = collider {
            let _ = world.insert_one(e, c);
        }
        if self_collision {
            let _ = world.insert_one(e, SelfCollision);
        }
    }
}
