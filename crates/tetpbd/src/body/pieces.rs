//! Splitting a body of a world along faces: its particles duplicated where the faces
//! separate them (`crate::body::split`), its masses re-lumped, its components rebuilt
//! (`crate::body::rebuild`), and its disconnected pieces made separate entities if its
//! [`Pieces`] setting asks; the [`TearEvent`] says what happened.

use hecs::{Entity, World};
use nalgebra::Vector3;

use crate::body::activation::{Activation, Asleep};
use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::forces::UserForces;
use crate::body::grab::Grab;
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::particles::{ExternalAcceleration, Particles};
use crate::body::plasticity::Plasticity;
use crate::body::rebuild::{assemble, PieceParts, SplitBody};
use crate::body::split::{pieces, separate};
use crate::body::tearing::{face_key, Pieces, Tearing};
use crate::constraints::signed_volume;
use crate::stabilisation::deformation_damping::DeformationDamping;
use crate::stabilisation::untangle::Untangle;

/// One piece of a body after a split.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Piece {
    /// The entity holding the piece (the body's own for the first piece).
    pub entity: Entity,
    /// For each of the piece's particles, in its order, the particle of the body it comes
    /// from: an index below [`TearEvent::particles_before`] is that particle itself, an index
    /// `particles_before + k` is the copy [`TearEvent::copies`]`[k]` names. Ascending.
    pub particles: Vec<u32>,
}

/// What a tear or a cut did to one body.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TearEvent {
    /// The body (its entity now holds the first piece).
    pub body: Entity,
    /// Faces torn (or cut) in this event, split or not yet (a torn face whose particles stay
    /// connected around it waits, see [`crate::Tearing`]).
    pub faces_torn: usize,
    /// The body's particle count before the event.
    pub particles_before: usize,
    /// Particles added (copies): `copies[k]` is the particle that copy `particles_before + k`
    /// was made from.
    pub copies: Vec<u32>,
    /// The pieces, the body's own first; empty when no particle was split (the mesh did not
    /// change). With [`Pieces::KeepOne`] there is one piece, the body.
    pub pieces: Vec<Piece>,
}

impl TearEvent {
    /// Particles added by the split.
    pub fn particles_added(&self) -> usize {
        self.copies.len()
    }

    /// The entities created for the pieces after the first.
    pub fn new_entities(&self) -> impl Iterator<Item = Entity> + '_ {
        self.pieces.iter().skip(1).map(|p| p.entity)
    }

    /// Where the body's particle `particle` (numbered as before the event) went: the index of
    /// its piece in [`TearEvent::pieces`] and its index there. A particle that was split stays
    /// in the piece of its lowest-numbered tetrahedron; its copies are elsewhere. `None` when the
    /// mesh did not change or there was no such particle.
    pub fn moved(&self, particle: u32) -> Option<(usize, u32)> {
        if particle as usize >= self.particles_before {
            return None;
        }
        self.pieces.iter().enumerate().find_map(|(k, p)| {
            let at = p.particles.binary_search(&particle).ok()?;
            Some((k, at as u32))
        })
    }
}

/// Splits body `entity` along the faces `torn` (sorted particle triples) and, if it has a
/// [`Tearing`], the faces it holds torn (marking `torn` there too), and rebuilds or splits it. Returns `None` when the entity is not a body
/// (no [`Particles`] or [`Tetrahedra`]).
pub(crate) fn split_body(
    world: &mut World,
    entity: Entity,
    torn: &[[u32; 3]],
    mode: Pieces,
) -> Option<TearEvent> {
    let mut q = world.query_one::<(
        &mut Particles,
        &mut Tetrahedra,
        Option<&EdgeConstraints>,
        Option<&VertexFaceConstraints>,
        Option<&VolumeConstraints>,
        Option<&Plasticity>,
        Option<&NeoHookeanMaterial>,
        Option<&mut Tearing>,
        Option<&UserForces>,
    )>(entity);
    let (
        particles,
        tetrahedra,
        edges,
        vertex_face,
        volume,
        plasticity,
        material,
        mut tearing,
        forces,
    ) = q.get().ok()?;
    let before = particles.len();
    let all = match tearing.as_deref_mut() {
        Some(t) => {
            mark_torn(t, &tetrahedra.indices, torn);
            torn_keys(t, &tetrahedra.indices)
        }
        None => torn.to_vec(),
    };
    let sep = separate(&tetrahedra.indices, before, &all);
    let mut event = TearEvent {
        body: entity,
        faces_torn: torn.len(),
        particles_before: before,
        copies: sep.origin.clone(),
        pieces: Vec::new(),
    };
    if sep.origin.is_empty() {
        return Some(event);
    }
    add_copies(particles, &tetrahedra.indices, &sep.tets, &sep.origin);
    tetrahedra.indices = sep.tets;
    let (piece_of, count) = pieces(&tetrahedra.indices, particles.len());
    let count = if mode == Pieces::KeepOne { 1 } else { count };
    let origin: Vec<u32> = (0..before as u32)
        .chain(sep.origin.iter().copied())
        .collect();
    let mut old_edges: Vec<([u32; 2], u32)> = edges.map_or(Vec::new(), |e| {
        (e.edges.iter().enumerate())
            .map(|(k, &[a, b])| ([a.min(b), a.max(b)], k as u32))
            .collect()
    });
    old_edges.sort_unstable();
    let split = SplitBody {
        particles,
        tetrahedra,
        edges,
        vertex_face,
        volume,
        plasticity,
        material,
        tearing: tearing.as_deref(),
        forces,
        origin: &origin,
        old_edges: &old_edges,
    };
    let built: Vec<(PieceParts, Vec<u32>)> = (0..count as u32)
        .map(|k| {
            let tets: Vec<u32> = (0..piece_of.len() as u32)
                .filter(|&t| count == 1 || piece_of[t as usize] == k)
                .collect();
            let mut used: Vec<u32> = tets
                .iter()
                .flat_map(|&t| split.tetrahedra.indices[t as usize])
                .collect();
            used.sort_unstable();
            used.dedup();
            (assemble(&split, &used, &tets), tets)
        })
        .collect();
    drop(q);
    place_pieces(world, entity, built, &mut event);
    Some(event)
}

/// Marks the faces of `tearing` whose particles are `torn` (sorted triples) as torn.
fn mark_torn(tearing: &mut Tearing, tets: &[[u32; 4]], torn: &[[u32; 3]]) {
    for f in &mut tearing.faces {
        let tet = &tets[f.tets[0] as usize];
        if let Some(o) = tet.iter().position(|&i| i == f.apex[0]) {
            if torn.binary_search(&face_key(tet, o)).is_ok() {
                f.torn = true;
            }
        }
    }
}

/// The particle triples of every face `tearing` holds torn, sorted.
pub(crate) fn torn_keys(tearing: &Tearing, tets: &[[u32; 4]]) -> Vec<[u32; 3]> {
    let mut keys: Vec<[u32; 3]> = tearing
        .faces
        .iter()
        .filter(|f| f.torn)
        .filter_map(|f| {
            let tet = &tets[f.tets[0] as usize];
            let o = tet.iter().position(|&i| i == f.apex[0])?;
            Some(face_key(tet, o))
        })
        .collect();
    keys.sort_unstable();
    keys.dedup();
    keys
}

/// Appends the copies `origin` to `p` and re-lumps the masses of every particle from the
/// tetrahedra that use it after the split (`after`; `before` the same tetrahedra before):
/// each particle keeps its density `m / Σ|V⁰|/4`, so the body's mass is kept; a copy of a
/// pinned particle is pinned.
fn add_copies(p: &mut Particles, before: &[[u32; 4]], after: &[[u32; 4]], origin: &[u32]) {
    for &v in origin {
        let v = v as usize;
        p.positions.push(p.positions[v]);
        p.prev_positions.push(p.prev_positions[v]);
        p.velocities.push(p.velocities[v]);
        p.inv_masses.push(p.inv_masses[v]);
        p.masses.push(p.masses[v]);
        p.rest_positions.push(p.rest_positions[v]);
        p.residuals.push(p.residuals[v]);
        p.source.push(p.source[v]);
    }
    let n = p.len();
    let share = |tets: &[[u32; 4]], len: usize| {
        let mut s = vec![0.0f64; len];
        for tet in tets {
            let [a, b, c, d] = tet.map(|i| p.rest_positions[i as usize]);
            let v = f64::from(signed_volume(&a, &b, &c, &d).abs()) / 4.0;
            for &i in tet {
                s[i as usize] += v;
            }
        }
        s
    };
    let (old, new) = (share(before, n - origin.len()), share(after, n));
    let first = |i: usize| {
        if i < old.len() {
            i
        } else {
            origin[i - old.len()] as usize
        }
    };
    let old_mass: Vec<f32> = p.masses.clone();
    for (i, &share) in new.iter().enumerate() {
        let o = first(i);
        if old[o] <= 0.0 || share <= 0.0 {
            continue;
        }
        let m = (f64::from(old_mass[o]) / old[o] * share) as f32;
        p.masses[i] = m;
        if p.inv_masses[i] != 0.0 && m > 0.0 {
            p.inv_masses[i] = 1.0 / m;
        }
    }
    p.work.0.resize(n, Default::default());
    p.written = true;
}

/// Writes the first piece over the body's components and spawns the others with copies of
/// the body's per-body components; wakes every piece; fills the event's pieces.
fn place_pieces(
    world: &mut World,
    entity: Entity,
    built: Vec<(PieceParts, Vec<u32>)>,
    event: &mut TearEvent,
) {
    let activation = world.get::<&Activation>(entity).ok().map(|a| *a);
    // Each piece is untangled as the body was (or not, without the component), from a fresh
    // state: the body's windows and moves describe a shape that no longer exists.
    let untangle = world.get::<&Untangle>(entity).ok().map(|u| u.restarted());
    let damping = world.get::<&DeformationDamping>(entity).ok().map(|d| *d);
    let accel = world.get::<&ExternalAcceleration>(entity).ok().map(|a| *a);
    let grab = world.get::<&Grab>(entity).ok().map(|g| (*g).clone());
    let _ = world.remove_one::<Grab>(entity);
    let _ = world.remove_one::<Asleep>(entity);
    if let Some(mut a) = activation {
        a.restart();
        let _ = world.insert_one(entity, a);
    }
    for (k, (piece, tets)) in built.into_iter().enumerate() {
        let PieceParts {
            body,
            forces,
            particles,
            from,
        } = piece;
        let target = if k == 0 {
            write_over(world, entity, body);
            entity
        } else {
            let e = body.spawn(world);
            if untangle.is_none() {
                let _ = world.remove_one::<Untangle>(e);
            }
            if let Some(a) = activation {
                let mut a = a;
                a.restart();
                let _ = world.insert_one(e, a);
            }
            if let Some(d) = damping {
                let _ = world.insert_one(e, d);
            }
            if let Some(a) = accel {
                let _ = world.insert_one(e, a);
            }
            e
        };
        if let Some(u) = &untangle {
            let _ = world.insert_one(target, u.clone());
        }
        if let Some(f) = forces {
            let _ = world.insert_one(target, f);
        }
        if let Some(g) = &grab {
            // The grab follows the piece holding its tetrahedron.
            let held = g.material_point().tetrahedron() as u32;
            if tets.binary_search(&held).is_ok() {
                if let Some(t) = from.iter().position(|&f| f == held) {
                    let _ = world.insert_one(target, g.clone().renumbered(t));
                }
            }
        }
        event.pieces.push(Piece {
            entity: target,
            particles,
        });
    }
}

/// Replaces the components of `entity` with those of `body` (the same families: the piece
/// was built from them).
fn write_over(world: &mut World, entity: Entity, body: crate::SoftBody) {
    let _ = world.insert(entity, (body.particles, body.tetrahedra, body.surface));
    if let Some(e) = body.edges {
        let _ = world.insert_one(entity, e);
    }
    if let Some(v) = body.vertex_face {
        let _ = world.insert_one(entity, v);
    }
    if let Some(v) = body.volume {
        let _ = world.insert_one(entity, v);
    }
    if let Some(p) = body.plasticity {
        let _ = world.insert_one(entity, p);
    }
    if let Some(m) = body.material {
        let _ = world.insert_one(entity, m);
    }
    if let Some(t) = body.tearing {
        let _ = world.insert_one(entity, t);
    }
}

/// The centroid of tetrahedron `tet` at `x`, m.
pub(crate) fn centroid(tet: &[u32; 4], x: &[Vector3<f32>]) -> Vector3<f32> {
    tet.iter()
        .fold(Vector3::zeros(), |acc, &i| acc + x[i as usize])
        / 4.0
}
