//! The order of a ground-up sweep ([`crate::stabilisation::ground_up::project_stacked`]) within one family: items
//! (edges or tetrahedra) by level, each level in greedy colour classes so that the SIMD
//! kernels run a class in lanes, the per-sweep copies of the items' data in that order, and
//! the projections of one level.

use crate::kernels::class_runs;
use crate::kernels::count::{Kernel, ProjectionCount};
use crate::kernels::slots::WorkAccess;
use crate::ordering::colouring::{greedy_colour, OVERFLOW_COLOUR};

/// Colour of the overflow class of a greedy colouring (its items may share particles).
const OVERFLOW: usize = OVERFLOW_COLOUR as usize;

/// One family's items (edges or tetrahedra) in sweep order: by level, and within a level
/// in greedy colour classes (items of one class touch disjoint particles, so the SIMD
/// kernels run them in lanes).
#[derive(Clone, Debug, Default)]
pub(crate) struct LevelOrder {
    /// Item indices, level by level, each level's items sorted by colour (stable).
    pub(crate) order: Vec<u32>,
    /// Start of each level's items in `order` (`starts[L - 1]..starts[L]` is level `L`).
    pub(crate) starts: Vec<u32>,
    /// Start of each colour class in `order`, then `order.len()`.
    classes: Vec<u32>,
    /// Per class: whether its items may share particles (the overflow colour).
    dependent: Vec<bool>,
    /// First class of each level `L ≥ 1` (index `L - 1`), then the class count.
    level_classes: Vec<u32>,
    /// Scratch: the items' colours.
    colours: Vec<u8>,
    /// Scratch: one level's items while they are sorted.
    sorted: Vec<u32>,
}

impl LevelOrder {
    /// Sorts the items of `levels` (the level of each item) into levels `1..=top` and each
    /// level into greedy colour classes; `used` is a per-particle scratch of zeros (left
    /// zero). Allocates only while its buffers grow past their capacity.
    pub(crate) fn build<const N: usize>(
        &mut self,
        items: &[[u32; N]],
        levels: impl Iterator<Item = u32> + Clone,
        top: u32,
        used: &mut [u64],
    ) {
        // Every buffer at its largest size on the first build, so that a later change of
        // the roots (inside a step) does not allocate.
        let n = items.len();
        self.order.reserve(n);
        self.colours.reserve(n);
        self.sorted.reserve(n);
        self.classes.reserve(n + 1);
        self.dependent.reserve(n);
        self.level_classes.reserve(n + 1);
        self.starts.reserve(used.len() + 1);
        bucket(levels, top, &mut self.order, &mut self.starts);
        self.colours.clear();
        self.colours.resize(self.order.len(), 0);
        self.classes.clear();
        self.dependent.clear();
        self.level_classes.clear();
        for l in 0..top as usize {
            let (a, b) = (self.starts[l] as usize, self.starts[l + 1] as usize);
            self.level_classes.push(self.classes.len() as u32);
            let mut count = [0u32; OVERFLOW + 1];
            for k in a..b {
                let c = greedy_colour(&items[self.order[k] as usize], used);
                self.colours[k] = c;
                count[c as usize] += 1;
            }
            // Starts of the colours within the level, then a stable placement.
            let mut next = [0u32; OVERFLOW + 1];
            let mut at = a as u32;
            for (c, &n) in count.iter().enumerate() {
                next[c] = at;
                if n > 0 {
                    self.classes.push(at);
                    self.dependent.push(c == OVERFLOW);
                }
                at += n;
            }
            self.sorted.clear();
            self.sorted.resize(b - a, 0);
            for k in a..b {
                let c = self.colours[k] as usize;
                self.sorted[next[c] as usize - a] = self.order[k];
                next[c] += 1;
            }
            self.order[a..b].copy_from_slice(&self.sorted);
            for &k in &self.order[a..b] {
                for &i in &items[k as usize] {
                    used[i as usize] = 0;
                }
            }
        }
        self.level_classes.push(self.classes.len() as u32);
        self.classes.push(self.order.len() as u32);
    }

    /// The classes of level `l ≥ 1`: each as its range in `order` and whether it is
    /// independent.
    pub(crate) fn level(
        &self,
        l: u32,
    ) -> impl Iterator<Item = (std::ops::Range<usize>, bool)> + '_ {
        let l = l as usize;
        let (a, b) = match (self.level_classes.get(l - 1), self.level_classes.get(l)) {
            (Some(&a), Some(&b)) => (a as usize, b as usize),
            _ => (0, 0),
        };
        (a..b).map(|k| {
            (
                self.classes[k] as usize..self.classes[k + 1] as usize,
                !self.dependent[k],
            )
        })
    }
}

/// Per-sweep copies of one family's data in sweep order (the SIMD kernels walk contiguous
/// runs). Gathered before a sweep, multipliers scattered back after it.
#[derive(Clone, Debug, Default)]
pub(crate) struct Gathered<T: Clone + Default, R: Clone + Default> {
    pub(crate) items: Vec<T>,
    pub(crate) rest: Vec<R>,
    pub(crate) lambdas: Vec<R>,
}

impl<T: Copy + Default, R: Copy + Default> Gathered<T, R> {
    /// Copies the family's data in `order`: the items and their rest values when `fresh`
    /// is false or the copies are not of `order`'s length (they do not change while a body
    /// lives, so once per order), the multipliers always (they accumulate over the
    /// substep's projections). Returns whether the items were copied.
    pub(crate) fn gather(
        &mut self,
        order: &[u32],
        items: &[T],
        rest: &[R],
        lambdas: &[R],
        fresh: bool,
    ) -> bool {
        let copy_items = !fresh || self.items.len() != order.len();
        if copy_items {
            // Sized for every item of the family at once (no allocation when more are
            // reached).
            self.items.reserve(items.len());
            self.rest.reserve(items.len());
            self.items.clear();
            self.items.extend(order.iter().map(|&k| pick(items, k)));
            self.rest.clear();
            self.rest.extend(order.iter().map(|&k| pick(rest, k)));
        }
        self.lambdas.reserve(lambdas.len());
        self.lambdas.clear();
        self.lambdas.extend(order.iter().map(|&k| pick(lambdas, k)));
        copy_items
    }

    /// Copies the multipliers back (after a sweep).
    pub(crate) fn scatter(&self, order: &[u32], lambdas: &mut [R]) {
        for (&k, &l) in order.iter().zip(&self.lambdas) {
            if let Some(x) = lambdas.get_mut(k as usize) {
                *x = l;
            }
        }
    }
}

/// `v[k]`, or the default value where `k` is out of range.
fn pick<T: Copy + Default>(v: &[T], k: u32) -> T {
    v.get(k as usize).copied().unwrap_or_default()
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
pub(crate) fn shift_starts(starts: &mut [u32]) {
    for j in (1..starts.len()).rev() {
        starts[j] = starts[j - 1];
    }
    if let Some(s) = starts.first_mut() {
        *s = 0;
    }
}

/// The vertex–face constraints of a sweep in level order.
pub(crate) type VertexFaceData = Gathered<[u32; 4], [f32; 4]>;

/// The edges of level `l`, class by class (`alpha_tilde = α/h²`).
pub(crate) fn edge_level(
    acc: &mut WorkAccess<'_>,
    order: &LevelOrder,
    data: &mut Gathered<[u32; 2], f32>,
    l: u32,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    for (r, independent) in order.level(l) {
        count += class_runs::edge_run(
            acc,
            &data.items[r.clone()],
            &data.rest[r.clone()],
            &mut data.lambdas[r],
            alpha_tilde,
            kernel,
            independent,
        );
    }
    count
}

/// The vertex–face constraints of the tetrahedra of level `l` that hold a vertex of that
/// level (`data`: the gathered constraints and their held masks).
pub(crate) fn vertex_face_level(
    acc: &mut WorkAccess<'_>,
    order: &LevelOrder,
    (data, held): (&mut VertexFaceData, &[[f32; 4]]),
    l: u32,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    for (r, independent) in order.level(l) {
        count += class_runs::vertex_face_run(
            acc,
            &data.items[r.clone()],
            &data.rest[r.clone()],
            &held[r.clone()],
            &mut data.lambdas[r],
            alpha_tilde,
            kernel,
            independent,
        );
    }
    count
}

/// The volume constraints of the tetrahedra of level `l`.
pub(crate) fn volume_level(
    acc: &mut WorkAccess<'_>,
    order: &LevelOrder,
    data: &mut Gathered<[u32; 4], f32>,
    l: u32,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    for (r, independent) in order.level(l) {
        count += class_runs::volume_run(
            acc,
            &data.items[r.clone()],
            &data.rest[r.clone()],
            &mut data.lambdas[r],
            alpha_tilde,
            kernel,
            independent,
        );
    }
    count
}
