//! The tearing pass: once per frame, after the substeps, each awake body with a
//! [`Tearing`] smooths the strain (and, tearing by force, the force) across its interior
//! faces and tears the faces past a threshold (the measures, the filter and the split are
//! documented on [`Tearing`], the force in `crate::body::face_forces`).

use hecs::{Entity, World};

use crate::body::activation::Asleep;
use crate::body::face_forces::{BodyFamilies, FaceForceScratch};
use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::particles::Particles;
use crate::body::pieces::{split_body, TearEvent};
use crate::body::tearing::Tearing;

/// Smooths the strain and force of every interior face of every awake body with a
/// [`Tearing`] over a frame of length `dt` (s) whose last substep lasted `h` (s), tears the
/// faces whose smoothed strain or force exceeds the body's threshold and splits the bodies
/// they belong to, appending one [`TearEvent`] per torn body to `events`. Returns the number
/// of faces torn.
///
/// The forces come from the multipliers the families hold after the frame's last substep
/// (`λ/h²`), so the pass must run after the substeps and before anything resets them. A frame
/// in which nothing tears reads one distance per interior face (and, tearing by force, the
/// multipliers of every tetrahedron) and allocates nothing; a body whose component does not
/// fit it ([`Tearing::fits`]) is skipped. A non-finite strain or force (a particle restored
/// this frame) leaves the face's smoothed value as it was.
pub fn tear_faces(world: &mut World, dt: f32, h: f32, events: &mut Vec<TearEvent>) -> usize {
    let mut torn_bodies: Vec<(Entity, usize)> = Vec::new();
    let q = world.query_mut::<(
        Entity,
        &Particles,
        &Tetrahedra,
        &mut Tearing,
        Option<&EdgeConstraints>,
        Option<&VertexFaceConstraints>,
        Option<&VolumeConstraints>,
        Option<&NeoHookeanMaterial>,
    )>();
    for (entity, p, t, tearing, edges, vertex_face, volume, material) in q.without::<&Asleep>() {
        if !tearing.fits_cached(p, t) {
            continue;
        }
        let families = BodyFamilies {
            edges,
            vertex_face,
            volume,
            material,
        };
        let torn = tear_body(tearing, p, t, &families, dt, h);
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
            let pieces = event.pieces.iter().map(|p| p.entity);
            crate::body::tear_relaxation::start(world, pieces, h);
            events.push(event);
        }
        total += newly;
    }
    total
}

/// Smooths one body's face strains and forces and marks the faces past a threshold torn;
/// returns how many.
fn tear_body(
    tearing: &mut Tearing,
    p: &Particles,
    t: &Tetrahedra,
    families: &BodyFamilies,
    dt: f32,
    h: f32,
) -> usize {
    let settings = tearing.settings;
    let weight = settings.filter_weight(dt);
    let by_force = settings.force.is_some() && h > 0.0;
    if by_force {
        let forces = &mut tearing.forces;
        if !forces.fits(t.len(), families.edges) {
            // A component made without the scratch (or for other edges): made once here.
            *forces = FaceForceScratch::new(&t.indices, families.edges);
        }
        let (x, rest) = (&p.positions, &p.rest_positions);
        forces.measure(&t.indices, &t.rest_volumes, x, rest, families, h);
    }
    let strain_limit = settings.strain.unwrap_or(f32::INFINITY);
    let force_limit = settings.force.unwrap_or(f32::INFINITY);
    let Tearing { faces, forces, .. } = tearing;
    let mut torn = 0;
    for f in faces.iter_mut().filter(|f| !f.torn) {
        if settings.strain.is_some() {
            let d = (p.positions[f.apex[0] as usize] - p.positions[f.apex[1] as usize]).norm();
            let s = d * f.inv_rest - 1.0;
            if s.is_finite() {
                f.smoothed += weight * (s - f.smoothed);
            }
        }
        if by_force {
            if let Some(force) = forces.face_force(f, &t.indices, &p.positions) {
                f.smoothed_force += weight * (force - f.smoothed_force);
            }
        }
        if f.smoothed > strain_limit || f.smoothed_force > force_limit {
            f.torn = true;
            torn += 1;
        }
    }
    torn
}

/// The pieces setting of body `entity`'s [`Tearing`].
fn pieces_of(world: &World, entity: Entity) -> Option<crate::Pieces> {
    let t = world.get::<&Tearing>(entity).ok()?;
    Some(t.settings.pieces)
}
