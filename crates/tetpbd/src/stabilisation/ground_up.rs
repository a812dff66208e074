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
//! down comes back 54–82 % of the way in one sweep, all of it in 50). Of the vertex–face constraints only those holding a vertex of
//! level `L` above its face are projected (holding a root by moving the face alone is
//! ill-conditioned). Constraints among roots only (level 0) and constraints with a particle
//! no root reaches are left alone. Each constraint is projected at most once per sweep, so
//! a sweep costs about one more sweep over the body's constraints, plus a breadth-first
//! pass over its tetrahedra when the roots change.
//!
//! Within a level the order is free, so each level's edges and tetrahedra are sorted into
//! greedy colour classes when the levels are built (items of one class share no particle),
//! and every family runs through the same SIMD kernels as the ordinary sweep, four or eight
//! at a time (on a 1 m cube of 8³ cells 97 % of the edges and 93 % of the tetrahedra fall in
//! full lanes). The kernels walk contiguous runs, so the sweep copies the families' indices
//! and rest values into level order when the order changes, and the multipliers before and
//! after every sweep. Of a tetrahedron's four vertex–face constraints only those holding a
//! vertex of the tetrahedron's level run: a mask per constraint, built with the levels, that
//! the kernel applies lane by lane. The roots are held by an inverse mass of 0 in the working copy for the length of the
//! sweep. The scalar kernel in the same order is the reference the SIMD one is tested against.
//!
//! Why the levels above the roots are not frozen too, as shock propagation freezes the
//! lower bodies of a rigid stack: fixing each level against a frozen one below is a march
//! from the ground up, and marching an elastic body's shape in one direction amplifies a
//! lateral error at every level. A heavy box on a light slab more than a few cells deep then
//! explodes, and a partly frozen lower level (a reduced inverse mass instead of 0) only moves
//! the explosion deeper. At their own mass the sweep is an ordinary Gauss–Seidel sweep with
//! the roots as its only fixed particles, stable at any depth.
//!
//! Holding the roots does not conserve the body's momentum: the impulses it leaves out are
//! the ones the roots' supports would have taken, which is right for a body resting on
//! something immovable and wrong for a free one. The caller decides when a body is stacked
//! (the rapier coupling runs it for a soft body on an immovable support that carries a much
//! heavier rigid body).

use crate::body::families::Family;
use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::constraints::VERTEX_FACE_ORDER;
use crate::kernels::count::{Kernel, ProjectionCount};
use crate::kernels::slots::WorkAccess;
use crate::kernels::working_copy;
use crate::stabilisation::ground_up_levels::{
    edge_level, shift_starts, vertex_face_level, volume_level, Gathered, LevelOrder,
};

/// Level of a particle that no root reaches.
const UNREACHED: u32 = u32::MAX;

/// Levels of one body's particles and the constraint order of a ground-up sweep
/// ([`project_stacked`]). Built for one body ([`StackingLayers::new`]); keeps its
/// allocations, and its levels while the roots stay the same.
#[derive(Clone, Debug, Default)]
pub(crate) struct StackingLayers {
    /// Per particle: distance from the roots in tetrahedra, [`UNREACHED`] when none.
    level: Vec<u32>,
    /// Per particle, the tetrahedra it belongs to (compressed rows).
    first: Vec<u32>,
    incident: Vec<u32>,
    /// Number of tetrahedra of the body the rows were built for.
    tet_count: usize,
    queue: Vec<u32>,
    /// Per particle: colours used so far in the level being coloured (scratch, zeros).
    used: Vec<u64>,
    /// The roots of the current levels (sorted, unique) and the next call's candidates.
    roots: Vec<u32>,
    candidates: Vec<u32>,
    /// Edges and tetrahedra in sweep order.
    edges: LevelOrder,
    tets: LevelOrder,
    /// Per-sweep data of the edge, vertex–face and volume families in sweep order.
    edge_data: Gathered<[u32; 2], f32>,
    vertex_face_data: Gathered<[u32; 4], [f32; 4]>,
    volume_data: Gathered<[u32; 4], f32>,
    /// Per tetrahedron in sweep order, per vertex–face constraint: 1 where it holds a vertex
    /// of the tetrahedron's own level, 0 otherwise (built with the vertex–face copies).
    vf_held: Vec<[f32; 4]>,
    /// The roots' inverse masses while a sweep holds them.
    held: Vec<f32>,
    /// Whether `edge_data` and `volume_data` hold the items and rest values of the
    /// current order (the multipliers are copied at every sweep).
    gathered: bool,
    /// Highest level reached.
    top: u32,
}

impl StackingLayers {
    /// Layers of a body with `n` particles and tetrahedra `tets`, with no roots yet.
    pub(crate) fn new(n: usize, tets: &Tetrahedra) -> Self {
        let mut s = StackingLayers {
            level: vec![UNREACHED; n],
            used: vec![0; n],
            queue: Vec::with_capacity(n),
            roots: Vec::with_capacity(n),
            candidates: Vec::with_capacity(n),
            held: Vec::with_capacity(n),
            ..StackingLayers::default()
        };
        s.incidence(n, tets.indices());
        s
    }

    /// Whether these layers were built for a body with `n` particles and tetrahedra `tets`
    /// (by their counts).
    pub(crate) fn fits(&self, n: usize, tets: &Tetrahedra) -> bool {
        self.level.len() == n
            && self.used.len() == n
            && self.first.len() == n + 1
            && self.tet_count == tets.len()
    }

    /// Gives every particle its level below the `roots` (particle indices; out-of-range ones
    /// are ignored) and orders the body's tetrahedra and `edges` by level, and each level in
    /// colour classes. `tets` and `edges` are those of the body the layers were built for.
    /// The levels are only recomputed when the set of roots differs from the previous
    /// call's. Returns the highest level reached (0 when there are no roots, or the layers
    /// do not fit `tets`).
    pub(crate) fn set_roots(
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
        self.gathered = false;
        self.edges
            .build::<2>(&[], std::iter::empty(), 0, &mut self.used);
        self.tets
            .build::<4>(&[], std::iter::empty(), 0, &mut self.used);
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
        self.tets.build(
            tets.indices(),
            tets.indices()
                .iter()
                .map(|t| t.iter().map(|&i| level[i as usize]).max().unwrap_or(0)),
            top,
            &mut self.used,
        );
        if let Some(e) = edges {
            self.edges.build(
                &e.edges,
                e.edges
                    .iter()
                    .map(|[a, b]| level[*a as usize].max(level[*b as usize])),
                top,
                &mut self.used,
            );
        }
        top
    }

    /// Level of particle `i` (`None` when no root reaches it or `i` is out of range).
    pub(crate) fn level(&self, i: usize) -> Option<u32> {
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

    /// Copies the families' items, rest values and multipliers into level order (the items
    /// and rest values only when the order changed since the last sweep).
    fn gather(&mut self, tets: &Tetrahedra, families: &BodyConstraints<'_>) {
        let gathered = self.gathered;
        if let Some(e) = families.edges.as_deref() {
            let o = &self.edges.order;
            self.edge_data
                .gather(o, &e.edges, &e.rest_lengths, &e.lambdas, gathered);
        }
        if let Some(v) = families.vertex_face.as_deref() {
            let o = &self.tets.order;
            let data = &mut self.vertex_face_data;
            if data.gather(o, &tets.indices, &v.rest_heights, &v.lambdas, gathered) {
                held_masks(
                    &mut self.vf_held,
                    &self.tets,
                    &tets.indices,
                    &self.level,
                    self.top,
                );
            }
        }
        if let Some(v) = families.volume.as_deref() {
            let o = &self.tets.order;
            self.volume_data
                .gather(o, &tets.indices, &tets.rest_volumes, &v.lambdas, gathered);
        }
        self.gathered = true;
    }

    /// Copies the multipliers back from level order.
    fn scatter(&self, families: BodyConstraints<'_>) {
        if let Some(e) = families.edges {
            self.edge_data.scatter(&self.edges.order, &mut e.lambdas);
        }
        if let Some(v) = families.vertex_face {
            self.vertex_face_data
                .scatter(&self.tets.order, &mut v.lambdas);
        }
        if let Some(v) = families.volume {
            self.volume_data.scatter(&self.tets.order, &mut v.lambdas);
        }
    }
}

/// The held masks of the vertex–face constraints in sweep order (`StackingLayers::vf_held`):
/// constraint `k` of a tetrahedron of level `L` runs when its held vertex has level `L`.
fn held_masks(
    masks: &mut Vec<[f32; 4]>,
    order: &LevelOrder,
    tets: &[[u32; 4]],
    level: &[u32],
    top: u32,
) {
    masks.reserve(tets.len());
    masks.clear();
    for l in 1..=top {
        let (a, b) = (order.starts[l as usize - 1], order.starts[l as usize]);
        for &t in &order.order[a as usize..b as usize] {
            let tet = tets[t as usize];
            let on = |o: [usize; 4]| {
                if level[tet[o[1]] as usize] == l {
                    1.0
                } else {
                    0.0
                }
            };
            masks.push(VERTEX_FACE_ORDER.map(on));
        }
    }
}

/// The constraint families of one body, as [`project_stacked`] borrows them.
pub(crate) struct BodyConstraints<'a> {
    /// Edge distance constraints, if the body has them.
    pub(crate) edges: Option<&'a mut EdgeConstraints>,
    /// Vertex–face constraints, if the body has them.
    pub(crate) vertex_face: Option<&'a mut VertexFaceConstraints>,
    /// Volume constraints, if the body has them.
    pub(crate) volume: Option<&'a mut VolumeConstraints>,
}

/// One ground-up sweep over a body's constraints (module docs), with the levels of the
/// last [`StackingLayers::set_roots`] for this body: for each level `L ≥ 1`, the constraints
/// of level `L` in the family `order`, the roots held. XPBD with the families'
/// compliances and the substep length `h` (s); multipliers accumulate with the substep's
/// other projections. Does nothing when no root reaches the body or the layers were built
/// for another body ([`StackingLayers::fits`]).
///
/// Within a level, each family runs colour class by colour class with `kernel`
/// ([`Kernel::Simd`]: four or eight independent projections at once, the overflow class and
/// each class's remainder on the scalar kernel; [`Kernel::Scalar`]: the same order one by
/// one, the reference). Of the vertex–face constraints only the heights of the level's own
/// vertices are projected. The roots are held by setting their inverse mass to 0 in the
/// working copy for the sweep.
pub(crate) fn project_stacked(
    p: &mut Particles,
    tets: &Tetrahedra,
    families: BodyConstraints<'_>,
    order: [Family; 3],
    h: f32,
    layers: &mut StackingLayers,
    kernel: Kernel,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    if layers.top == 0 || !layers.fits(p.len(), tets) {
        return count;
    }
    layers.gather(tets, &families);
    let BodyConstraints {
        edges,
        vertex_face,
        volume,
    } = families;
    let StackingLayers {
        roots,
        edges: edge_order,
        tets: tet_order,
        edge_data,
        vertex_face_data,
        volume_data,
        vf_held,
        held,
        top,
        ..
    } = layers;
    working_copy::with_access(p, working_copy::CopyMode::PerSweep, |acc| {
        hold_roots(acc, roots, held);
        for l in 1..=*top {
            for family in order {
                count += match family {
                    Family::Edge => match edges.as_deref() {
                        Some(e) => {
                            let alpha_tilde = e.compliance / (h * h);
                            edge_level(acc, edge_order, edge_data, l, alpha_tilde, kernel)
                        }
                        None => continue,
                    },
                    // Only a vertex of this level is held above its face (`vf_held`): moving
                    // a face alone to hold a root is ill-conditioned (the height barely
                    // depends on a face point whose opposite edge passes under the vertex)
                    // and blows the slab up.
                    Family::VertexFace => match vertex_face.as_deref() {
                        Some(vf) => {
                            let alpha_tilde = vf.compliance / (h * h);
                            let data = (&mut *vertex_face_data, &vf_held[..]);
                            vertex_face_level(acc, tet_order, data, l, alpha_tilde, kernel)
                        }
                        None => continue,
                    },
                    Family::Volume => match volume.as_deref() {
                        Some(vol) => {
                            let alpha_tilde = vol.compliance / (h * h);
                            volume_level(acc, tet_order, volume_data, l, alpha_tilde, kernel)
                        }
                        None => continue,
                    },
                };
            }
        }
        release_roots(acc, roots, held);
    });
    layers.scatter(BodyConstraints {
        edges,
        vertex_face,
        volume,
    });
    count
}

/// Holds the roots: inverse mass 0 in the working copy for the sweep, the old values kept
/// in `held`.
fn hold_roots(acc: &mut WorkAccess<'_>, roots: &[u32], held: &mut Vec<f32>) {
    held.clear();
    for &r in roots {
        let slot = &mut acc.slots[r as usize];
        let [x, y, z, w] = slot.xw.to_array();
        held.push(w);
        slot.xw = wide::f32x4::new([x, y, z, 0.0]);
    }
}

/// Gives the roots their inverse masses back after the sweep.
fn release_roots(acc: &mut WorkAccess<'_>, roots: &[u32], held: &[f32]) {
    for (&r, &w) in roots.iter().zip(held.iter()) {
        let slot = &mut acc.slots[r as usize];
        let [x, y, z, _] = slot.xw.to_array();
        slot.xw = wide::f32x4::new([x, y, z, w]);
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::body::generators::{box_grid, CellSplit};
    use crate::SoftBodyBuilder;

    /// Checks one family's sweep order: every reached item once, levels ascending, and the
    /// items of an independent class on pairwise distinct particles.
    fn check<const N: usize>(o: &LevelOrder, items: &[[u32; N]], level: &[u32], top: u32) {
        let item_level = |k: u32| {
            items[k as usize]
                .iter()
                .map(|&i| level[i as usize])
                .max()
                .unwrap()
        };
        let reached = (0..items.len() as u32)
            .filter(|&k| (1..=top).contains(&item_level(k)))
            .count();
        let mut seen = vec![false; items.len()];
        let mut count = 0;
        for l in 1..=top {
            for (r, independent) in o.level(l) {
                let mut touched = std::collections::BTreeSet::new();
                for &k in &o.order[r] {
                    assert_eq!(item_level(k), l);
                    assert!(!std::mem::replace(&mut seen[k as usize], true));
                    count += 1;
                    for &i in &items[k as usize] {
                        assert!(!independent || touched.insert(i), "shared particle {i}");
                    }
                }
            }
        }
        assert_eq!(count, reached);
    }

    #[test]
    fn levels_are_split_into_independent_colour_classes() {
        let mesh = box_grid(Vector3::new(1.0, 2.0, 1.0), [3, 6, 3], CellSplit::Six).unwrap();
        let body = SoftBodyBuilder::new(mesh)
            .edges(0.0)
            .volume(0.0)
            .build()
            .unwrap();
        let x = body.particles.positions();
        let bottom = (0..x.len() as u32).filter(|&i| x[i as usize].y < -0.99);
        let edges = body.edges.as_ref().unwrap();
        let mut layers = StackingLayers::new(x.len(), &body.tetrahedra);
        let top = layers.set_roots(&body.tetrahedra, Some(edges), bottom);
        assert_eq!(top, 6);
        check(&layers.edges, edges.edges(), &layers.level, top);
        check(&layers.tets, body.tetrahedra.indices(), &layers.level, top);
        assert!(layers.used.iter().all(|&u| u == 0));
        // A level of a 3 × 3 cell layer has more than one class and runs mostly in lanes.
        let (r, independent) = layers.tets.level(3).next().unwrap();
        assert!(independent && r.len() >= 4, "{r:?}");
    }
}
