//! Once-per-frame candidate gathering of soft–soft contacts: per-body caches, the broad
//! phase over bodies, BVH refits and particle–triangle candidates (see
//! [`crate::SoftContacts`] for the rules).

use hecs::{Entity, World};
use nalgebra::Vector3;
use rapier3d::parry::bounding_volume::Aabb;
use tetpbd::{Particles, Surface, Tetrahedra};

use crate::convert::{finite3, to_glam};
use crate::soft_collider::{SoftCollider, SoftPair};
use crate::soft_soft::body::FrameBody;
use crate::soft_soft::bvh::{triangle_normal, BodyCache};
use crate::soft_soft::separation::{Separation, Side};
use crate::soft_soft::settings::{SelfCollision, SoftContactSettings, SoftContactStats};

/// A particle–triangle contact candidate (slot indices).
#[derive(Clone, Debug)]
pub(crate) struct Candidate {
    pub p: u32,
    pub tri: [u32; 3],
    /// Deep particle (inside the other body at the frame start): not projected, resolved by
    /// [`crate::soft_soft::separation`].
    pub recovery: bool,
    /// Largest depth behind the triangle at which a regular candidate is active, m.
    pub depth_limit: f32,
    /// Thickness, friction and restitution of the two bodies' contact.
    pub props: SoftPair,
    /// Signed distance to the triangle's plane at the substep start, m.
    pub d_prev: f32,
    pub lambda_n: f32,
    pub lambda_t: f32,
    /// Projected in the current substep / in the frame.
    pub active: bool,
    pub ever: bool,
    /// Projected in the previous substep of the frame (`project::ContactFrame::velocity_pass`:
    /// a contact that lets go releases no held-back correction as speed).
    pub held_before: bool,
    /// Relative normal velocity `(v_p − v_q)·n` the contact left after its last velocity
    /// pass, m/s (≤ 0: approaching or resting).
    pub vn_held: f32,
    /// Limited by the separation speed in the current substep.
    pub clamped: bool,
    /// The particle projected inside the triangle at the substep start.
    pub prism_prev: bool,
    /// Candidates `group[0]..group[1]` are those of the same particle against the same
    /// body (this one included): the faces next to this triangle that the particle may be
    /// flush with (see `project::flush_beside`).
    pub group: [u32; 2],
    /// `w_p + Σ β² w` of the last projection, 1/kg.
    pub wsum: f32,
    /// Inverse masses `[w_p, w_a, w_b, w_c]` of the last projection, 1/kg: the particles'
    /// own, or zero on the side that carries the other (`carrying` module docs).
    pub weights: [f32; 4],
    /// Which side the last projection held still: 0 none, 1 the particle, 2 the triangle
    /// (`carrying` module docs).
    pub held: u8,
    /// Normal and barycentrics of the last projection.
    pub n: Vector3<f32>,
    pub bary: [f32; 3],
}

/// Flat per-slot state of the frame's surface particles, and the candidates.
#[derive(Clone, Debug, Default)]
pub(crate) struct ContactFrame {
    pub x: Vec<Vector3<f32>>,
    pub x_prev: Vec<Vector3<f32>>,
    pub v: Vec<Vector3<f32>>,
    pub w: Vec<f32>,
    pub motion: Vec<f32>,
    pub candidates: Vec<Candidate>,
    /// Scratch of the velocity pass: each body's surface momentum (kg·m/s) and mass (kg).
    pub body_motion: Vec<(Vector3<f32>, f32)>,
}

impl ContactFrame {
    fn clear(&mut self) {
        self.x.clear();
        self.x_prev.clear();
        self.v.clear();
        self.w.clear();
        self.motion.clear();
        self.candidates.clear();
    }
}

#[derive(Clone)]
struct CacheEntry {
    key: u64,
    seen: bool,
    cache: BodyCache,
}

/// Caches kept across frames and the frame's bodies.
#[derive(Clone, Default)]
pub(crate) struct Gather {
    caches: Vec<CacheEntry>,
    list: Vec<(u64, Entity, bool, SoftCollider)>,
    order: Vec<usize>,
    pub pairs: Vec<(usize, usize)>,
    /// Entity bits of the sleeping bodies (scratch of `list_bodies`).
    sleeping: Vec<u64>,
    /// Contact properties of each pair of `pairs`.
    pub pair_props: Vec<SoftPair>,
    deep_a: Vec<Vector3<f32>>,
    deep_b: Vec<Vector3<f32>>,
    /// Scratch of `refit`: whether a body's triangle / tetrahedron BVH is needed.
    need: Vec<(bool, bool)>,
    /// Scratch of `candidates`: triangles found near a particle.
    found: Vec<u32>,
    pub bodies: Vec<FrameBody>,
}

impl Gather {
    /// The cache of a frame body.
    pub fn cache(&self, b: &FrameBody) -> &BodyCache {
        &self.caches[b.cache].cache
    }

    /// Clears the previous frame, then gathers this frame's bodies and candidates, with the
    /// settings `s` and the collider of bodies without one, `default`.
    pub fn run(
        &mut self,
        world: &mut World,
        dt: f32,
        (s, default): (&SoftContactSettings, &SoftCollider),
        frame: &mut ContactFrame,
        sep: &mut Separation,
        stats: &mut SoftContactStats,
    ) {
        frame.clear();
        sep.clear();
        self.bodies.clear();
        self.pairs.clear();
        self.pair_props.clear();
        self.sleeping.clear();
        self.list_bodies(world, default);
        if self.list.len() < 2 && !self.list.iter().any(|l| l.2) {
            // Nothing can touch: no pair and no self collision.
            return;
        }
        let dt = if dt.is_finite() && dt > 0.0 { dt } else { 0.0 };
        let fall = 0.5 * s.max_acceleration * dt * dt;
        for li in 0..self.list.len() {
            let (key, e, self_collide, collider) = self.list[li];
            let Ok((p, surface, tets)) =
                world.query_one_mut::<(&Particles, &Surface, &Tetrahedra)>(e)
            else {
                continue;
            };
            let Some(ci) = self.cache_of(key, p, surface, tets) else {
                stats.skipped_bodies += 1;
                continue;
            };
            let cache = &mut self.caches[ci].cache;
            let finite = cache.vertices.iter().all(|&i| {
                finite3(&p.positions()[i as usize]) && finite3(&p.velocities()[i as usize])
            });
            if !finite || cache.vertices.is_empty() {
                stats.skipped_bodies += 1;
                continue;
            }
            let offset = frame.x.len();
            let (lo, hi) = load_particles(frame, p, &cache.vertices, dt, fall);
            if self_collide {
                cache.ensure_rings();
            }
            let inv_mass = p.rigid_inv_mass();
            self.bodies.push(FrameBody {
                entity: e,
                cache: ci,
                offset,
                len: cache.vertices.len(),
                lo,
                hi,
                self_collide,
                collider,
                inv_mass,
                involved: false,
            });
        }
        stats.bodies = self.bodies.len();
        self.broad_phase(s.margin);
        stats.body_pairs = self.pairs.len();
        self.refit(world, frame);
        self.pair_candidates(world, frame, s, sep, stats);
        stats.candidates = frame.candidates.len();
    }

    /// Lists the enabled soft bodies of `world` by entity bits and drops the caches of bodies
    /// gone. Sleeping bodies are listed (their caches kept) but take no part: the coupling
    /// woke every sleeping body an awake one comes near (`sleeping` module docs).
    fn list_bodies(&mut self, world: &mut World, default: &SoftCollider) {
        self.list.clear();
        for (e, _, _, _, sc, collider, asleep) in world.query_mut::<(
            Entity,
            &Particles,
            &Surface,
            &Tetrahedra,
            Option<&SelfCollision>,
            Option<&SoftCollider>,
            Option<&tetpbd::Asleep>,
        )>() {
            let collider = *collider.unwrap_or(default);
            if collider.is_enabled() {
                if asleep.is_some() {
                    self.sleeping.push(e.to_bits().get());
                    continue;
                }
                self.list
                    .push((e.to_bits().get(), e, sc.is_some(), collider));
            }
        }
        self.list.sort_unstable_by_key(|l| l.0);
        self.sleeping.sort_unstable();
        for c in &mut self.caches {
            c.seen = self.list.binary_search_by_key(&c.key, |l| l.0).is_ok()
                || self.sleeping.binary_search(&c.key).is_ok();
        }
        self.caches.retain(|c| c.seen);
    }

    /// The index of the body's cache (entity bits `key`), built or rebuilt when missing or
    /// stale; `None` when the body has no usable cache.
    fn cache_of(
        &mut self,
        key: u64,
        p: &Particles,
        surface: &Surface,
        tets: &Tetrahedra,
    ) -> Option<usize> {
        match self.caches.binary_search_by_key(&key, |c| c.key) {
            Ok(ci) if self.caches[ci].cache.matches(surface, tets, p.len()) => Some(ci),
            Ok(ci) => match BodyCache::build(surface, tets, p.len()) {
                Some(cache) => {
                    self.caches[ci].cache = cache;
                    Some(ci)
                }
                None => {
                    self.caches.remove(ci);
                    None
                }
            },
            Err(ci) => BodyCache::build(surface, tets, p.len()).map(|cache| {
                self.caches.insert(
                    ci,
                    CacheEntry {
                        key,
                        seen: true,
                        cache,
                    },
                );
                ci
            }),
        }
    }

    /// The candidates of every body pair (both ways, and the pair's deep-overlap separation)
    /// and of every self-colliding body; marks the bodies that some candidate refers to.
    fn pair_candidates(
        &mut self,
        world: &mut World,
        frame: &mut ContactFrame,
        s: &SoftContactSettings,
        sep: &mut Separation,
        stats: &mut SoftContactStats,
    ) {
        for k in 0..self.pairs.len() {
            let (a, b) = self.pairs[k];
            let c0 = frame.candidates.len();
            self.candidates(world, frame, s, a, b, stats);
            let c1 = frame.candidates.len();
            self.candidates(world, frame, s, b, a, stats);
            let deep = |c: &Candidate| c.recovery.then(|| frame.x[c.p as usize]);
            self.deep_a.clear();
            self.deep_a
                .extend(frame.candidates[c0..c1].iter().filter_map(deep));
            self.deep_b.clear();
            self.deep_b
                .extend(frame.candidates[c1..].iter().filter_map(deep));
            let side_a = self.side(a, &self.deep_a, frame);
            let side_b = self.side(b, &self.deep_b, frame);
            sep.add_pair(a, b, &side_a, &side_b, self.pair_props[k].thickness);
        }
        for a in 0..self.bodies.len() {
            if self.bodies[a].self_collide {
                stats.self_bodies += 1;
                self.candidates(world, frame, s, a, a, stats);
            }
        }
        for c in &frame.candidates {
            for slot in std::iter::once(c.p).chain(c.tri) {
                let b = self.body_of_slot(slot as usize);
                self.bodies[b].involved = true;
            }
        }
    }

    fn side<'s>(&'s self, k: usize, deep: &'s [Vector3<f32>], frame: &'s ContactFrame) -> Side<'s> {
        let body = &self.bodies[k];
        Side {
            cache: &self.caches[body.cache].cache,
            xs: &frame.x[body.offset..body.offset + body.len],
            deep,
            centre: (body.lo + body.hi) / 2.0,
        }
    }

    /// Index of the frame body owning `slot`.
    pub fn body_of_slot(&self, slot: usize) -> usize {
        self.bodies.partition_point(|b| b.offset + b.len <= slot)
    }

    /// Sweep and prune along x over the motion-grown body AABBs (grown again by `margin`
    /// and the pair's thickness), keeping the pairs whose collision groups accept each other.
    fn broad_phase(&mut self, margin: f32) {
        let bodies = &self.bodies;
        let thickest = bodies
            .iter()
            .map(|b| b.collider.thickness())
            .fold(0.0f32, f32::max);
        self.order.clear();
        self.order.extend(0..bodies.len());
        self.order
            .sort_unstable_by(|&i, &j| bodies[i].lo.x.total_cmp(&bodies[j].lo.x).then(i.cmp(&j)));
        for (ii, &i) in self.order.iter().enumerate() {
            let reach = margin + bodies[i].collider.thickness() + thickest;
            for &j in &self.order[ii + 1..] {
                if bodies[j].lo.x > bodies[i].hi.x + reach {
                    break;
                }
                let (a, b) = (&bodies[i], &bodies[j]);
                let pad = margin + a.collider.thickness() + b.collider.thickness();
                let overlap = (0..3).all(|k| a.lo[k] <= b.hi[k] + pad && b.lo[k] <= a.hi[k] + pad);
                let groups = a.collider.collision_groups();
                if overlap && groups.test(b.collider.collision_groups()) {
                    self.pairs.push((i.min(j), i.max(j)));
                }
            }
        }
        self.pairs.sort_unstable();
        let bodies = &self.bodies;
        self.pair_props.extend(
            self.pairs
                .iter()
                .map(|&(a, b)| bodies[a].collider.against_soft(&bodies[b].collider)),
        );
    }

    /// Refits the triangle BVH of every body in a pair or colliding with itself, and the
    /// tetrahedron BVH of every body in a pair.
    fn refit(&mut self, world: &mut World, frame: &ContactFrame) {
        let need = &mut self.need;
        need.clear();
        need.resize(self.bodies.len(), (false, false));
        for &(a, b) in &self.pairs {
            need[a] = (true, true);
            need[b] = (true, true);
        }
        for (k, b) in self.bodies.iter().enumerate() {
            if b.self_collide {
                need[k].0 = true;
            }
        }
        for (k, b) in self.bodies.iter().enumerate() {
            let cache = &mut self.caches[b.cache].cache;
            let range = b.offset..b.offset + b.len;
            if need[k].0 {
                cache.refit_triangles(&frame.x[range.clone()], &frame.motion[range]);
            }
            if need[k].1 {
                if let Ok(p) = world.query_one_mut::<&Particles>(b.entity) {
                    cache.refit_tets(p.positions());
                }
            }
        }
    }

    /// Candidates of the surface particles of body `a` against the triangles of body `b`.
    fn candidates(
        &mut self,
        world: &mut World,
        frame: &mut ContactFrame,
        s: &SoftContactSettings,
        a: usize,
        b: usize,
        stats: &mut SoftContactStats,
    ) {
        let (ba, bb) = (&self.bodies[a], &self.bodies[b]);
        let props = ba.collider.against_soft(&bb.collider);
        let cache_a = &self.caches[ba.cache].cache;
        let cache_b = &self.caches[bb.cache].cache;
        let own = a == b;
        let Ok(pb) = world.query_one_mut::<&Particles>(bb.entity) else {
            return;
        };
        let pad = s.margin + props.thickness;
        let xb = &frame.x[bb.offset..bb.offset + bb.len];
        let found = &mut self.found;
        for k in 0..ba.len {
            let slot = ba.offset + k;
            let x0 = frame.x[slot];
            let m = frame.motion[slot];
            let r = Vector3::repeat(m + pad);
            let (lo, hi) = (x0 - r, x0 + r);
            if (0..3).any(|i| hi[i] < bb.lo[i] || lo[i] > bb.hi[i]) {
                continue;
            }
            if !own && cache_b.contains(&x0, pb.positions()) {
                if let Some(t) = cache_b.closest_triangle(&x0, xb) {
                    let tri = cache_b.triangles[t].map(|v| (bb.offset as u32) + v);
                    frame
                        .candidates
                        .push(candidate(slot as u32, tri, props, f32::MAX));
                    stats.deep += 1;
                }
                continue;
            }
            let first = frame.candidates.len() as u32;
            let query = Aabb::new(to_glam(&lo), to_glam(&hi));
            found.clear();
            found.extend(cache_b.tri_bvh.intersect_aabb(&query));
            found.sort_unstable();
            for &t in found.iter() {
                let t = t as usize;
                if own && cache_a.excluded(k, t) {
                    continue;
                }
                let tri = cache_b.triangles[t].map(|v| (bb.offset as u32) + v);
                let [pa, pb_, pc] = tri.map(|i| frame.x[i as usize]);
                let Some(n) = triangle_normal(&pa, &pb_, &pc) else {
                    continue;
                };
                if (x0 - pa).dot(&n) < -props.thickness {
                    continue;
                }
                let tri_motion = tri
                    .iter()
                    .map(|&i| frame.motion[i as usize])
                    .fold(0.0f32, f32::max);
                let depth_limit = m + tri_motion + 2.0 * props.thickness + s.margin;
                let mut c = candidate(slot as u32, tri, props, depth_limit);
                c.recovery = false;
                frame.candidates.push(c);
            }
            let last = frame.candidates.len() as u32;
            for c in &mut frame.candidates[first as usize..] {
                c.group = [first, last];
            }
        }
    }
}

/// A candidate of particle slot `p` against triangle slots `tri`; a deep one (recovery)
/// unless the caller clears `recovery`.
fn candidate(p: u32, tri: [u32; 3], props: SoftPair, depth_limit: f32) -> Candidate {
    Candidate {
        p,
        tri,
        recovery: true,
        depth_limit,
        props,
        d_prev: 0.0,
        lambda_n: 0.0,
        lambda_t: 0.0,
        active: false,
        ever: false,
        held_before: false,
        vn_held: 0.0,
        clamped: false,
        prism_prev: false,
        group: [0, 0],
        wsum: 0.0,
        weights: [0.0; 4],
        held: 0,
        n: Vector3::zeros(),
        bary: [1.0 / 3.0; 3],
    }
}

/// Appends a body's surface particles (`vertices`) to the frame's slots with their motion
/// bound `|v| dt + fall` (m); returns the bounds of their swept neighbourhoods, m.
fn load_particles(
    frame: &mut ContactFrame,
    p: &Particles,
    vertices: &[u32],
    dt: f32,
    fall: f32,
) -> (Vector3<f32>, Vector3<f32>) {
    let (mut lo, mut hi) = (Vector3::repeat(f32::MAX), Vector3::repeat(f32::MIN));
    for &i in vertices {
        let i = i as usize;
        let x = p.positions()[i];
        let m = p.velocities()[i].norm() * dt + fall;
        frame.x.push(x);
        frame.x_prev.push(x);
        frame.v.push(p.velocities()[i]);
        frame.w.push(p.inv_masses()[i]);
        frame.motion.push(m);
        lo = lo.inf(&(x - Vector3::repeat(m)));
        hi = hi.sup(&(x + Vector3::repeat(m)));
    }
    (lo, hi)
}
