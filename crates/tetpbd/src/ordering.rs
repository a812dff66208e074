//! Solver order: constraints sorted into colour classes so that consecutive projections
//! rarely touch the same particle.
//!
//! Gauss–Seidel projects constraints one after another. When two consecutive constraints
//! share a particle, the second waits for the first's store (a dependency chain of a square
//! root and two divisions); sorted edges `[a, b]` share `a` almost every time. Greedy
//! colouring (each item gets the lowest colour none of its particles has used yet) and a
//! stable sort by colour turn that chain into independent work the CPU overlaps. Within a
//! colour the original order, and with it memory locality, is kept. The same classes are
//! what a parallel solver would run concurrently.

/// Greedy colour of each item (an edge or a tetrahedron given by its particle indices).
/// Colours above 63 share the last class; the order stays valid, only less independent.
pub fn greedy_colours<const N: usize>(items: &[[u32; N]], particles: usize) -> Vec<u8> {
    let mut used = vec![0u64; particles];
    items
        .iter()
        .map(|item| {
            let mask = item.iter().fold(0u64, |m, &i| m | used[i as usize]);
            let colour = (!mask).trailing_zeros().min(63);
            for &i in item {
                used[i as usize] |= 1u64 << colour;
            }
            colour as u8
        })
        .collect()
}

/// Items sorted into colour classes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ColourClasses {
    /// Start of each class in the sorted order, then the total: class `k` is
    /// `starts[k]..starts[k + 1]`.
    pub starts: Vec<u32>,
    /// Whether the last class is the overflow class (colour 63), whose items may share
    /// particles and must run serially.
    pub overflow: bool,
}

impl ColourClasses {
    /// Number of classes.
    pub fn len(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    /// `true` when there are no classes (no items).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Class `k` (`k < len()`) as a range, with `true` when its items are independent.
    pub fn class(&self, k: usize) -> (std::ops::Range<usize>, bool) {
        let range = self.starts[k] as usize..self.starts[k + 1] as usize;
        (range, !(self.overflow && k + 1 == self.len()))
    }

    /// The classes as ranges, each with `true` when its items are independent.
    pub fn ranges(&self) -> impl Iterator<Item = (std::ops::Range<usize>, bool)> + '_ {
        (0..self.len()).map(|k| self.class(k))
    }
}

/// The permutation that sorts `items` by greedy colour (stable within a colour), and the
/// resulting classes.
pub fn colour_order<const N: usize>(
    items: &[[u32; N]],
    particles: usize,
) -> (Vec<usize>, ColourClasses) {
    let colours = greedy_colours(items, particles);
    let mut order: Vec<usize> = (0..items.len()).collect();
    order.sort_by_key(|&i| colours[i]);
    let mut starts = Vec::new();
    let mut last = None;
    for (k, &i) in order.iter().enumerate() {
        if last != Some(colours[i]) {
            starts.push(k as u32);
            last = Some(colours[i]);
        }
    }
    starts.push(items.len() as u32);
    let overflow = last == Some(63);
    (order, ColourClasses { starts, overflow })
}
