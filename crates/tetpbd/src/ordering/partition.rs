//! Domain decomposition of a large body, fixed at build time: fewer phases per sweep.
//!
//! A parallel sweep over plain colour classes ([`crate::ordering::colouring::colour_order`]) has one
//! phase per class, and between two phases every thread waits for the others: a
//! 100k-tetrahedron body has 30 classes of tetrahedra and 14 of edges, each a few hundred
//! microseconds of work or less, so the waits and the imbalance at each boundary cost a
//! good part of a second thread's gain.
//!
//! Here the particles are cut into `P` slabs of about equal work along the longest axis of
//! the body ([`slab_parts`]), and each constraint goes to the group of the slabs it touches:
//!
//! 1. *interior* of part `p` (all its particles in slab `p`): one task per part;
//! 2. *interface* `q` (particles in slabs `q` and `q + 1` only), `q` even: one task each;
//! 3. interface `q`, `q` odd: one task each;
//! 4. the rest (constraints spanning more than two slabs, or two slabs not adjacent):
//!    plain colour classes, one phase each.
//!
//! The tasks of one phase touch disjoint slabs, hence disjoint particles, and each task is
//! coloured on its own (greedy, stable by colour) so that its classes feed the SIMD kernels
//! independent items. A sweep has at most three phases plus the rest's classes instead of
//! one per class. The part count is a property of the body ([`auto_parts`], or
//! [`crate::SoftBodyBuilder::parts`]), never of the thread count: one thread runs the same
//! tasks in the same order as any number of threads, so results stay bit-identical. With
//! one part the layout is the plain one.

use nalgebra::Vector3;

use crate::ordering::colouring::{colour_order, greedy_colours, ColourClasses};

/// Tetrahedra per part of [`auto_parts`] at least (below it a body keeps the plain layout).
pub(crate) const TETS_PER_PART: usize = 25_000;

/// Parts of [`auto_parts`] at most.
pub(crate) const MAX_PARTS: usize = 8;

/// Slabs at least this many mean edge lengths thick (thinner slabs leave more constraints
/// spanning three slabs, which fall back to plain classes).
const MIN_SLAB_EDGES: f32 = 3.0;

/// The part count chosen for a body of `tets` tetrahedra whose longest extent is `extent`
/// mean edge lengths: one per [`TETS_PER_PART`] tetrahedra, at most [`MAX_PARTS`], slabs at
/// least three edges thick; 1 (the plain layout) for small bodies.
pub(crate) fn auto_parts(tets: usize, extent: f32) -> usize {
    let by_size = tets / TETS_PER_PART;
    let by_thickness = if extent.is_finite() && extent > 0.0 {
        (extent / MIN_SLAB_EDGES) as usize
    } else {
        1
    };
    by_size.min(by_thickness).clamp(1, MAX_PARTS)
}

/// The axis (0, 1, 2) of the longest extent of `positions`, preferring z, then y, on ties
/// (row order numbers particles by z first, see [`crate::ordering::spatial`]), and that extent.
pub(crate) fn longest_axis(positions: &[Vector3<f32>]) -> (usize, f32) {
    let mut lo = Vector3::repeat(f32::INFINITY);
    let mut hi = Vector3::repeat(f32::NEG_INFINITY);
    for p in positions.iter().filter(|p| p.iter().all(|c| c.is_finite())) {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let d = hi - lo;
    let mut axis = 2;
    for a in [1, 0] {
        if d[a] > d[axis] {
            axis = a;
        }
    }
    (axis, d[axis].max(0.0))
}

/// Part of each particle: `parts` slabs along `axis`, cut where the count of tetrahedron
/// corners (each particle weighted by the tetrahedra it belongs to) passes each multiple of
/// `1 / parts` of the total. Ties in the coordinate keep the index order, so the result is
/// deterministic.
pub(crate) fn slab_parts(
    positions: &[Vector3<f32>],
    tets: &[[u32; 4]],
    axis: usize,
    parts: usize,
) -> Vec<u32> {
    let n = positions.len();
    let parts = parts.max(1);
    let mut weight = vec![0u64; n];
    for t in tets {
        for &i in t {
            weight[i as usize] += 1;
        }
    }
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by(|&a, &b| {
        positions[a as usize][axis]
            .total_cmp(&positions[b as usize][axis])
            .then(a.cmp(&b))
    });
    let total: u64 = weight.iter().sum::<u64>().max(1);
    let mut part_of = vec![0u32; n];
    let mut before = 0u64;
    for &i in &order {
        let p = (before * parts as u64 / total).min(parts as u64 - 1);
        part_of[i as usize] = p as u32;
        before += weight[i as usize];
    }
    part_of
}

/// The group of an item touching parts `lo..=hi`: interior `lo` (`0..P`), interface `lo`
/// (`P..2P - 1`) or the rest (`2P - 1`).
fn group(lo: u32, hi: u32, parts: usize) -> usize {
    match hi - lo {
        0 => lo as usize,
        1 => parts + lo as usize,
        _ => 2 * parts - 1,
    }
}

/// The permutation that sorts `items` into the layout of the module docs for the part of
/// each particle `part_of` (values below `parts`), and the resulting classes. With
/// `parts ≤ 1` this is [`colour_order`].
pub(crate) fn part_order<const N: usize>(
    items: &[[u32; N]],
    part_of: &[u32],
    parts: usize,
    particles: usize,
) -> (Vec<usize>, ColourClasses) {
    if parts <= 1 {
        return colour_order(items, particles);
    }
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); 2 * parts];
    for (k, item) in items.iter().enumerate() {
        let (lo, hi) = item.iter().fold((u32::MAX, 0), |(lo, hi), &i| {
            let p = part_of[i as usize];
            (lo.min(p), hi.max(p))
        });
        groups[group(lo, hi, parts)].push(k);
    }
    let mut out = Layout::default();
    out.phase((0..parts).map(|p| &groups[p]), items, particles);
    for parity in [0, 1] {
        let tasks = (parity..parts - 1).step_by(2).map(|q| &groups[parts + q]);
        out.phase(tasks, items, particles);
    }
    // The rest: one phase per class.
    let rest = &groups[2 * parts - 1];
    let sub: Vec<[u32; N]> = rest.iter().map(|&k| items[k]).collect();
    let (order, classes) = colour_order(&sub, particles);
    for (r, independent) in classes.ranges() {
        let task: Vec<usize> = order[r].iter().map(|&j| rest[j]).collect();
        out.begin_phase();
        out.begin_task();
        out.class(&task, !independent);
        out.end_phase();
    }
    out.finish(items.len())
}

/// A layout under construction.
#[derive(Default)]
struct Layout {
    order: Vec<usize>,
    classes: ColourClasses,
}

impl Layout {
    /// One phase of the given tasks (empty ones left out), each coloured on its own.
    fn phase<'a, const N: usize>(
        &mut self,
        tasks: impl Iterator<Item = &'a Vec<usize>>,
        items: &[[u32; N]],
        particles: usize,
    ) {
        self.begin_phase();
        for task in tasks.filter(|t| !t.is_empty()) {
            let sub: Vec<[u32; N]> = task.iter().map(|&k| items[k]).collect();
            let colours = greedy_colours(&sub, particles);
            let mut order: Vec<usize> = (0..task.len()).collect();
            order.sort_by_key(|&j| colours[j]);
            self.begin_task();
            let mut from = 0;
            while from < order.len() {
                let c = colours[order[from]];
                let to = from + order[from..].partition_point(|&j| colours[j] == c);
                let class: Vec<usize> = order[from..to].iter().map(|&j| task[j]).collect();
                self.class(&class, c == 63);
                from = to;
            }
        }
        self.end_phase();
    }

    fn begin_phase(&mut self) {
        self.classes.phases.push(self.task_count());
    }

    fn end_phase(&mut self) {
        if self.classes.phases.last() == Some(&self.task_count()) {
            self.classes.phases.pop();
        }
    }

    fn begin_task(&mut self) {
        self.classes.tasks.push(self.class_count());
    }

    fn class(&mut self, items: &[usize], dependent: bool) {
        if dependent {
            self.classes.dependent.push(self.class_count());
        }
        self.classes.starts.push(self.order.len() as u32);
        self.order.extend_from_slice(items);
    }

    fn task_count(&self) -> u32 {
        self.classes.tasks.len() as u32
    }

    fn class_count(&self) -> u32 {
        self.classes.starts.len() as u32
    }

    fn finish(mut self, len: usize) -> (Vec<usize>, ColourClasses) {
        debug_assert_eq!(self.order.len(), len);
        self.classes.starts.push(len as u32);
        let classes = self.class_count() - 1;
        self.classes.tasks.push(classes);
        let tasks = self.task_count() - 1;
        self.classes.phases.push(tasks);
        (self.order, self.classes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::generators::{box_grid, CellSplit};

    /// Every item once; the tasks of a phase touch disjoint particles; every class of a
    /// task is independent; the phases cover the tasks and the tasks the classes.
    #[test]
    fn layout_is_a_valid_sweep() {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 2.0), [6, 6, 24], CellSplit::Six).unwrap();
        let n = mesh.vertices.len();
        for parts in [1, 2, 3, 4, 8] {
            let (axis, _) = longest_axis(&mesh.vertices);
            assert_eq!(axis, 2);
            let part_of = slab_parts(&mesh.vertices, &mesh.tets, axis, parts);
            let (order, c) = part_order(&mesh.tets, &part_of, parts, n);
            let mut seen = order.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..mesh.tets.len()).collect::<Vec<_>>());
            assert_eq!(c.phases.first(), Some(&0));
            assert_eq!(*c.phases.last().unwrap() as usize, c.task_count());
            assert_eq!(*c.tasks.last().unwrap() as usize, c.len());
            assert!(c.phases.windows(2).all(|w| w[0] < w[1]));
            assert!(c.tasks.windows(2).all(|w| w[0] < w[1]));
            assert!(c.dependent.is_empty());
            if parts > 1 {
                assert!(c.phase_count() < 8, "{} phases", c.phase_count());
            }
            for j in 0..c.phase_count() {
                let mut owner = vec![usize::MAX; n];
                for t in c.phases[j] as usize..c.phases[j + 1] as usize {
                    for k in c.task(t) {
                        let (r, independent) = c.class(k);
                        assert!(independent);
                        let mut in_class = vec![false; n];
                        for &item in &order[r] {
                            for &i in &mesh.tets[item] {
                                let i = i as usize;
                                assert!(!in_class[i], "class {k} reuses particle {i}");
                                in_class[i] = true;
                                assert!(owner[i] == usize::MAX || owner[i] == t);
                                owner[i] = t;
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn auto_parts_grow_with_size_and_thickness() {
        assert_eq!(auto_parts(10_000, 30.0), 1);
        assert_eq!(auto_parts(105_000, 30.0), 4);
        assert_eq!(auto_parts(105_000, 6.0), 2);
        assert_eq!(auto_parts(1_000_000, 60.0), 8);
        assert_eq!(auto_parts(1_000_000, f32::NAN), 1);
    }
}
