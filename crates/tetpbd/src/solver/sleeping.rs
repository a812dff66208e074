//! The sleeping systems (rule: `body::activation` module docs): waking written bodies at the
//! start of a frame, observing speeds and putting ready islands to sleep at its end.
//!
//! Islands: every awake body with an [`Activation`] is a node; each pair a hook reports in
//! [`Touching::pairs`] joins two nodes (union–find over the bodies sorted by entity, so the
//! result does not depend on the order pairs arrive in). An island falls asleep when every
//! body in it is ready and none is in [`Touching::keep_awake`]; a pair with a sleeping body
//! or a body without an [`Activation`] keeps the other body's island awake only if that body
//! is not ready itself (it is moving, or never sleeps).

use hecs::{Entity, World};
use nalgebra::Vector3;

use crate::body::activation::{Activation, Asleep};
use crate::body::particles::Particles;

/// Who touches whom at the end of a frame, as a [`crate::SubstepHook`] reports it
/// ([`crate::SubstepHook::touching`]): the islands of sleeping.
#[derive(Clone, Debug, Default)]
pub struct Touching {
    /// Pairs of soft bodies in contact (directly, or through a dynamic body of another
    /// engine they both touch): they sleep and wake together.
    pub pairs: Vec<(Entity, Entity)>,
    /// Soft bodies that must stay awake (they touch something awake and moving that is
    /// not a soft body of this world, e.g. an awake rigid body).
    pub keep_awake: Vec<Entity>,
}

impl Touching {
    /// Empties both lists (capacity kept).
    pub fn clear(&mut self) {
        self.pairs.clear();
        self.keep_awake.clear();
    }
}

/// Whether `entity` is asleep (`false` for a missing entity).
pub fn is_sleeping(world: &World, entity: Entity) -> bool {
    world.satisfies::<&Asleep>(entity)
}

/// Wakes `entity` if it sleeps: removes its [`Asleep`] marker and restarts its timer.
/// Returns whether it was asleep (`false` for a missing entity or one without an
/// [`Activation`]). Its particles keep their positions and their zero velocities.
pub fn wake(world: &mut World, entity: Entity) -> bool {
    let Ok(mut a) = world.get::<&mut Activation>(entity) else {
        return false;
    };
    let was = a.sleeping();
    a.set_sleeping(false);
    drop(a);
    if was {
        let _ = world.remove_one::<Asleep>(entity);
    }
    was
}

/// Wakes the sleeping bodies whose particles were written since the last step and restarts
/// the timer of every written body; puts back the [`Asleep`] marker where it disagrees with
/// [`Activation::sleeping`] (a body restored from a snapshot, which holds the
/// [`Activation`]). Returns the number woken.
pub(crate) fn wake_written(world: &mut World, scratch: &mut Vec<(Entity, bool)>) -> usize {
    scratch.clear();
    let mut woken = 0;
    for (e, p, a, marked, grab, forces) in world.query_mut::<(
        Entity,
        &Particles,
        &mut Activation,
        Option<&Asleep>,
        Option<&crate::Grab>,
        Option<&crate::UserForces>,
    )>() {
        // A grabbed body, or one with a user force on it, is driven like a written one.
        let pushed = forces.is_some_and(|f| f.forces().iter().any(|f| *f != Vector3::zeros()));
        let driven = p.written || grab.is_some() || pushed;
        if driven && a.sleeping() {
            a.set_sleeping(false);
            woken += 1;
        } else if driven {
            a.restart();
        }
        if a.sleeping() != marked.is_some() {
            scratch.push((e, a.sleeping()));
        }
    }
    for &(e, sleeping) in scratch.iter() {
        if sleeping {
            let _ = world.insert_one(e, Asleep);
        } else {
            let _ = world.remove_one::<Asleep>(e);
        }
    }
    woken
}

/// Scratch of [`fall_asleep`] (kept by the solver so that a step allocates nothing).
#[derive(Clone, Debug, Default)]
pub(crate) struct Islands {
    /// The awake bodies with an [`Activation`], sorted by entity, and whether each is ready.
    nodes: Vec<(Entity, bool)>,
    /// Union–find parents.
    parent: Vec<usize>,
    /// Whether the island of each root is held awake.
    blocked: Vec<bool>,
}

/// What [`fall_asleep`] did.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SleepCount {
    /// Bodies that fell asleep.
    pub fell_asleep: usize,
    /// Bodies asleep after it.
    pub asleep: usize,
}

/// Observes every awake body's fastest particle over the frame `dt` (s), joins the
/// `touching` islands and puts every ready island to sleep; clears every body's write mark.
pub(crate) fn fall_asleep(
    world: &mut World,
    dt: f32,
    touching: &Touching,
    scratch: &mut Islands,
) -> SleepCount {
    let Islands {
        nodes,
        parent,
        blocked,
    } = scratch;
    nodes.clear();
    for (e, p, a) in world
        .query_mut::<(Entity, &Particles, &mut Activation)>()
        .without::<&Asleep>()
    {
        a.observe(p.max_speed(), dt);
        nodes.push((e, a.ready()));
    }
    nodes.sort_unstable_by_key(|(e, _)| e.to_bits());
    let index = |nodes: &[(Entity, bool)], e: Entity| {
        nodes
            .binary_search_by_key(&e.to_bits(), |(n, _)| n.to_bits())
            .ok()
    };
    parent.clear();
    parent.extend(0..nodes.len());
    // An island is held awake by a member that is not ready; `blocked[root]` after joining.
    blocked.clear();
    blocked.extend(nodes.iter().map(|(_, r)| !r));
    for &e in &touching.keep_awake {
        if let Some(i) = index(nodes, e) {
            blocked[i] = true;
        }
    }
    for &(a, b) in &touching.pairs {
        match (index(nodes, a), index(nodes, b)) {
            (Some(i), Some(j)) => {
                let (ri, rj) = (find(parent, i), find(parent, j));
                if ri != rj {
                    let (lo, hi) = (ri.min(rj), ri.max(rj));
                    parent[hi] = lo;
                    blocked[lo] |= blocked[hi];
                }
            }
            // A partner outside the nodes (asleep, or without an Activation) holds the island
            // awake unless it sleeps.
            (Some(i), None) | (None, Some(i)) => {
                let other = if index(nodes, a).is_some() { b } else { a };
                if !is_sleeping(world, other) {
                    blocked[i] = true;
                }
            }
            (None, None) => {}
        }
    }
    let mut count = SleepCount::default();
    for (i, &(entity, _)) in nodes.iter().enumerate() {
        let r = find(parent, i);
        if !blocked[r] {
            put_to_sleep(world, entity);
            count.fell_asleep += 1;
        }
    }
    for (p, asleep) in world.query_mut::<(&mut Particles, Option<&Asleep>)>() {
        p.written = false;
        count.asleep += usize::from(asleep.is_some());
    }
    count
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Zeroes the body's velocities, makes its positions the substep start and marks it asleep.
fn put_to_sleep(world: &mut World, entity: Entity) {
    if let Ok((p, a)) = world.query_one_mut::<(&mut Particles, &mut Activation)>(entity) {
        p.velocities.fill(Vector3::zeros());
        p.prev_positions.copy_from_slice(&p.positions);
        p.residuals.fill(Vector3::zeros());
        p.hook.energy = 0.0;
        p.hook.push = Vector3::zeros();
        a.set_sleeping(true);
    }
    let _ = world.insert_one(entity, Asleep);
}
