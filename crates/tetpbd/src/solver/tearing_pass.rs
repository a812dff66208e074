//! The tearing pass: once per frame, after the substeps, each awake body with a
//! [`Tearing`] smooths the strain across its interior faces and tears the faces past its
//! threshold (the measure, the filter and the split are documented on [`Tearing`]).

use hecs::{Entity, World};

use crate::body::activation::Asleep;
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::body::pieces::{split_body, TearEvent};
use crate::body::tearing::Tearing;

/// Smooths the strain of every interior face of every awake body with a [`Tearing`] over a
/// frame of length `dt` (s), tears the faces whose smoothed strain exceeds the body's
/// threshold and splits the bodies they belong to, appending one [`TearEvent`] per torn body
/// to `events`. Returns the number of faces torn.
///
/// A frame in which nothing tears reads one distance per interior face and allocates
/// nothing; a body whose component does not fit it ([`Tearing::fits`]) is skipped. A
/// non-finite strain (a particle restored this frame) leaves the face's smoothed value as it
/// was.
pub fn tear_by_strain(world: &mut World, dt: f32, events: &mut Vec<TearEvent>) -> usize {
    let mut torn_bodies: Vec<(Entity, usize)> = Vec::new();
    let q = world.query_mut::<(Entity, &Particles, &Tetrahedra, &mut Tearing)>();
    for (entity, p, t, tearing) in q.without::<&Asleep>() {
        if !tearing.fits(p, t) {
            continue;
        }
        let threshold = tearing.settings.strain;
        let weight = tearing.settings.filter_weight(dt);
        let mut torn = 0;
        for f in &mut tearing.faces {
            if f.torn {
                continue;
            }
            let d = (p.positions[f.apex[0] as usize] - p.positions[f.apex[1] as usize]).norm();
            let s = d * f.inv_rest - 1.0;
            if !s.is_finite() {
                continue;
            }
            f.smoothed += weight * (s - f.smoothed);
            if f.smoothed > threshold {
                f.torn = true;
                torn += 1;
            }
        }
        if torn > 0 {
            torn_bodies.push((entity, torn));
        }
    }
    let mut total = 0;
    for (entity, newly) in torn_bodies {
        let Some(mode) = pieces_of(world, entity) else {
            continue;
        };
        // The faces just marked torn are in the body's `Tearing`, which the split reads.
        if let Some(mut event) = split_body(world, entity, &[], mode) {
            event.faces_torn = newly;
            events.push(event);
        }
        total += newly;
    }
    total
}

/// The pieces setting of body `entity`'s [`Tearing`].
fn pieces_of(world: &World, entity: Entity) -> Option<crate::Pieces> {
    let t = world.get::<&Tearing>(entity).ok()?;
    Some(t.settings.pieces)
}
