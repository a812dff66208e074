//! Ground-up ("stacking") sweep over one body's constraints: one more Gauss–Seidel sweep,
//! ordered from the body's supports outwards with the supported particles held, after the
//! stacking order of Guendelman, Bridson and Fedkiw (2003, "Nonconvex rigid bodies with
//! stacking").
//!
//! Why: one Gauss–Seidel iteration carries a load through a chain of constraints poorly
//! when the load is heavy compared with the particles. A 1000 kg rigid box on a 1 kg slab
//! pushes the slab's top particles down by its share of `g·h²` every substep; the slab's
//! own constraints, projected once with the particles' masses, give back only part of
//! that, and the slab is crushed over a few hundred substeps.
//!
//! The sweep starts from *root* particles, which something immovable holds (a contact with
//! the ground, a pin), and gives every other particle its *level*: its distance from the
//! roots in tetrahedra (particles sharing a tetrahedron are neighbours). Then, for each
//! level `L = 1, 2, …` in turn, the constraints whose highest particle level is `L` are
//! projected once (families in the solver's order) with the roots held (inverse mass 0)
//! and every other particle at its own mass: each level is corrected against the levels
//! below it, which were corrected just before, so a support's reaction reaches the top of
//! the body within one sweep, if not all of it (a 3-cell column whose top was pushed 5 cm
//! down comes back 54–82 % of the way in one sweep, all of it in 50:
//! `tests/stacking.rs`). Of the vertex–face constraints only those holding a vertex of
//! level `L` above its face are projected (holding a root by moving the face alone is
//! ill-conditioned). Constraints among roots only (level 0) and constraints with a particle
//! no root reaches are left alone. Each constraint is projected at most once per sweep, so
//! a sweep costs about one more sweep over the body's constraints, plus a breadth-first
//! pass over its tetrahedra.
//!
//! Why the levels above the roots are not frozen too, as shock propagation freezes the
//! lower bodies of a rigid stack: fixing each level against a frozen one below is a march
//! from the ground up, and marching an elastic body's shape in one direction amplifies a
//! lateral error at every level. With the lower levels frozen, a 1000 kg box dropped on a
//! 1 kg slab (0.6 m wide, 0.1 m cells) gave slab peak speeds of 0.09, 0.14, 0.16, 0.17,
//! 0.28 and 0.71 m/s at 1 to 6 cells of depth and 26–30 m/s at 8 (the box driven 24 m
//! through the ground); a 100 kg box on a 1 m cube of 8³ or 12³ cells exploded likewise.
//! Lowering the lower levels' inverse mass to 10, 30 or 50 % of theirs instead of 0 moved
//! the explosion deeper (8, 12, 12 levels), not away. At their own mass the sweep is an
//! ordinary Gauss–Seidel sweep with the roots as its only fixed particles, stable at any
//! depth: the same slabs peak at 0.14–0.17 m/s from 2 to 8 cells and 0.43–0.55 m/s at 16
//! (over 3 and 10 s), the cubes at 0.16–0.24 m/s (`tests/issue_6_stacking_deep_bodies.rs`
//! at the workspace root).
//!
//! Holding the roots does not conserve the body's momentum: the impulses it leaves out are
//! the ones the roots' supports would have taken, which is right for a body resting on
//! something immovable and wrong for a free one. The caller decides when a body is stacked
//! (the rapier coupling runs it for a soft body on an immovable support that carries a much
//! heavier rigid body).

use crate::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::mesh::Tetrahedra;
use crate::particles::Particles;
use crate::projection::{self, ParticleAccess};
use crate::stats::Family;
use crate::systems::ProjectionCount;
use crate::work::{self, WorkAccess};

/// Level of a particle that no root reaches.
const UNREACHED: u32 = u32::MAX;

/// Levels of one body's particles and the constraint order of a ground-up sweep
/// ([`project_stacked`]). Built for one body ([`StackingLayers::new`]); keeps its
/// allocations, and its levels while the roots stay the same.
#[derive(Clone, Debug, Default)]
pub struct StackingLayers {
    /// Per particle: distance from the roots in tetrahedra, [`UNREACHED`] when none.
    level: Vec<u32>,
    /// Per particle, the tetrahedra it belongs to (compressed rows).
    first: Vec<u32>,
    incident: Vec<u32>,
    /// Number of tetrahedra of the body the rows were built for.
    tet_count: usize,
    queue: Vec<u32>,
    /// The roots of the current levels (sorted, unique) and the next call's candidates.
    roots: Vec<u32>,
    candidates: Vec<u32>,
    /// Edges and tetrahedra sorted by level, with the start of each level.
    edge_order: Vec<u32>,
    edge_starts: Vec<u32>,
    tet_order: Vec<u32>,
    tet_starts: Vec<u32>,
    /// Highest level reached.
    top: u32,
}

impl StackingLayers {
    /// Layers of a body with `n` particles and tetrahedra `tets`, with no roots yet.
    pub fn new(n: usize, tets: &Tetrahedra) -> Self {
        let mut s = StackingLayers {
            level: vec![UNREACHED; n],
            ..StackingLayers::default()
        };
        s.incidence(n, tets.indices());
        s
    }

    /// Whether these layers were built for a body with `n` particles and tetrahedra `tets`
    /// (by their counts).
    pub fn fits(&self, n: usize, tets: &Tetrahedra) -> bool {
        self.level.len() == n && self.first.len() == n + 1 && self.tet_count == tets.len()
    }

    /// Gives every particle its level below the `roots` (particle indices; out-of-range ones
    /// are ignored) and orders the body's tetrahedra and `edges` by level. `tets` and
    /// `edges` are those of the body the layers were built for. The levels are only
    /// recomputed when the set of roots differs from the previous call's. Returns the
    /// highest level reached (0 when there are no roots, or the layers do not fit `tets`).
    pub fn set_roots(
        &mut self,
        tets: &Tetrahedra,
        edges: Option<&EdgeConstraints>,
        roots: impl IntoIterator<Item = u32>,
    ) -> u32 {
        let n = self.level.len();
        if !self.fits(n, tets) {
            return 0;
        }
        self.candidates.clear();
        self.candidates
            .extend(roots.into_iter().filter(|&r| (r as usize) < n));
        self.candidates.sort_unstable();
        self.candidates.dedup();
        if self.candidates == self.roots && !self.roots.is_empty() {
            return self.top;
        }
        std::mem::swap(&mut self.candidates, &mut self.roots);
        self.level.fill(UNREACHED);
        self.queue.clear();
        for &r in &self.roots {
            self.level[r as usize] = 0;
            self.queue.push(r);
        }
        self.top = 0;
        self.edge_order.clear();
        self.edge_starts.clear();
        self.tet_order.clear();
        self.tet_starts.clear();
        if self.queue.is_empty() {
            return 0;
        }
        // Breadth first through the tetrahedra.
        let mut head = 0;
        while head < self.queue.len() {
            let i = self.queue[head] as usize;
            head += 1;
            let next = self.level[i] + 1;
            let (a, b) = (self.first[i] as usize, self.first[i + 1] as usize);
            for k in a..b {
                for &j in &tets.indices()[self.incident[k] as usize] {
                    let l = &mut self.level[j as usize];
                    if *l == UNREACHED {
                        *l = next;
                        self.top = self.top.max(next);
                        self.queue.push(j);
                    }
                }
            }
        }
        let level = &self.level;
        let top = self.top;
        bucket(
            tets.indices()
                .iter()
                .map(|t| t.iter().map(|&i| level[i as usize]).max().unwrap_or(0)),
            top,
            &mut self.tet_order,
            &mut self.tet_starts,
        );
        if let Some(e) = edges {
            bucket(
                e.edges
                    .iter()
                    .map(|[a, b]| level[*a as usize].max(level[*b as usize])),
                top,
                &mut self.edge_order,
                &mut self.edge_starts,
            );
        }
        top
    }

    /// Level of particle `i` (`None` when no root reaches it or `i` is out of range).
    pub fn level(&self, i: usize) -> Option<u32> {
        self.level.get(i).copied().filter(|&l| l != UNREACHED)
    }

    /// Particle → tetrahedra rows.
    fn incidence(&mut self, n: usize, tets: &[[u32; 4]]) {
        self.first.clear();
        self.first.resize(n + 1, 0);
        for t in tets {
            for &i in t {
                if let Some(c) = self.first.get_mut(i as usize + 1) {
                    *c += 1;
                }
            }
        }
        for i in 0..n {
            self.first[i + 1] += self.first[i];
        }
        self.incident.clear();
        self.incident.resize(self.first[n] as usize, 0);
        self.tet_count = tets.len();
        // `first[i]` is row i's fill cursor; afterwards it holds row i + 1's start.
        for (k, t) in tets.iter().enumerate() {
            for &i in t {
                if let Some(f) = self.first[..n].get_mut(i as usize) {
                    self.incident[*f as usize] = k as u32;
                    *f += 1;
                }
            }
        }
        shift_starts(&mut self.first);
    }
}

/// Counting sort of items by level `1..=top` (level 0 and unreached ones are dropped):
/// `order` lists the items level by level, `starts[L - 1]..starts[L]` are those of level `L`.
fn bucket(
    levels: impl Iterator<Item = u32> + Clone,
    top: u32,
    order: &mut Vec<u32>,
    starts: &mut Vec<u32>,
) {
    let top = top as usize;
    starts.clear();
    starts.resize(top + 1, 0);
    for l in levels.clone().map(|l| l as usize) {
        if (1..=top).contains(&l) {
            starts[l] += 1;
        }
    }
    for j in 0..top {
        starts[j + 1] += starts[j];
    }
    order.clear();
    order.resize(starts[top] as usize, 0);
    // `starts[L - 1]` is level L's fill cursor; afterwards it holds level L + 1's start.
    for (k, l) in levels.map(|l| l as usize).enumerate() {
        if (1..=top).contains(&l) {
            order[starts[l - 1] as usize] = k as u32;
            starts[l - 1] += 1;
        }
    }
    shift_starts(starts);
}

/// After a counting-sort fill that advanced each row's start to the next row's, moves the
/// starts back one row (no scratch buffer: the pass runs inside a step).
fn shift_starts(starts: &mut [u32]) {
    for j in (1..starts.len()).rev() {
        starts[j] = starts[j - 1];
    }
    if let Some(s) = starts.first_mut() {
        *s = 0;
    }
}

/// The roots (level 0) held (inverse mass 0); every other particle at its own mass.
struct RootsHeld<'a, 'b> {
    inner: &'a mut WorkAccess<'b>,
    level: &'a [u32],
}

impl ParticleAccess for RootsHeld<'_, '_> {
    #[inline(always)]
    fn row(&self, i: usize) -> wide::f32x4 {
        let row = self.inner.row(i);
        if self.level[i] == 0 {
            let [x, y, z, _] = row.to_array();
            wide::f32x4::new([x, y, z, 0.0])
        } else {
            row
        }
    }
    #[inline(always)]
    fn rest(&self, i: usize) -> nalgebra::Vector3<f32> {
        self.inner.rest(i)
    }
    #[inline(always)]
    fn add_row(&mut self, i: usize, d: wide::f32x4) {
        self.inner.add_row(i, d);
    }
    #[inline(always)]
    fn len(&self) -> usize {
        self.inner.len()
    }
}

/// The constraint families of one body, as [`project_stacked`] borrows them.
pub struct BodyConstraints<'a> {
    /// Edge distance constraints, if the body has them.
    pub edges: Option<&'a mut EdgeConstraints>,
    /// Vertex–face constraints, if the body has them.
    pub vertex_face: Option<&'a mut VertexFaceConstraints>,
    /// Volume constraints, if the body has them.
    pub volume: Option<&'a mut VolumeConstraints>,
}

/// One ground-up sweep over a body's constraints (module docs), with the levels of the
/// last [`StackingLayers::set_roots`] for this body: for each level `L ≥ 1`, the constraints
/// of level `L` in the family `order`, the roots held. XPBD with the families'
/// compliances and the substep length `h` (s); multipliers accumulate with the substep's
/// other projections. Scalar kernels.
pub fn project_stacked(
    p: &mut Particles,
    tets: &Tetrahedra,
    families: BodyConstraints<'_>,
    order: [Family; 3],
    h: f32,
    layers: &StackingLayers,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    if layers.top == 0 || layers.level.len() != p.len() {
        return count;
    }
    let BodyConstraints {
        mut edges,
        mut vertex_face,
        mut volume,
    } = families;
    work::with_access(p, work::CopyMode::PerSweep, |inner| {
        let mut acc = RootsHeld {
            inner,
            level: &layers.level,
        };
        let range = |starts: &[u32], l: u32| {
            starts
                .get(l as usize - 1)
                .zip(starts.get(l as usize))
                .map_or(0..0, |(&a, &b)| a as usize..b as usize)
        };
        for l in 1..=layers.top {
            for family in order {
                match family {
                    Family::Edge => {
                        let Some(e) = edges.as_deref_mut() else {
                            continue;
                        };
                        let alpha_tilde = e.compliance / (h * h);
                        for &k in &layers.edge_order[range(&layers.edge_starts, l)] {
                            let k = k as usize;
                            count.add(projection::edge(
                                &mut acc,
                                e.edges[k],
                                e.rest_lengths[k],
                                &mut e.lambdas[k],
                                alpha_tilde,
                            ));
                        }
                    }
                    Family::VertexFace => {
                        let Some(vf) = vertex_face.as_deref_mut() else {
                            continue;
                        };
                        let alpha_tilde = vf.compliance / (h * h);
                        for &t in &layers.tet_order[range(&layers.tet_starts, l)] {
                            let t = t as usize;
                            // Only a vertex of this level is held above its face: moving a
                            // face alone to hold a root is ill-conditioned (the
                            // height barely depends on a face point whose opposite edge
                            // passes under the vertex) and blew the slab up.
                            let level = &layers.level;
                            let (a, d) = projection::vertex_face_held(
                                &mut acc,
                                tets.indices[t],
                                &vf.rest_heights[t],
                                &mut vf.lambdas[t],
                                alpha_tilde,
                                |i| level[i] == l,
                            );
                            count.applied += u64::from(a);
                            count.degenerate += u64::from(d);
                        }
                    }
                    Family::Volume => {
                        let Some(vol) = volume.as_deref_mut() else {
                            continue;
                        };
                        let alpha_tilde = vol.compliance / (h * h);
                        for &t in &layers.tet_order[range(&layers.tet_starts, l)] {
                            let t = t as usize;
                            count.add(projection::volume(
                                &mut acc,
                                tets.indices[t],
                                tets.rest_volumes[t],
                                &mut vol.lambdas[t],
                                alpha_tilde,
                            ));
                        }
                    }
                }
            }
        }
    });
    count
}
