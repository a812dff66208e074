//! Solver order: constraints sorted into colour classes so that consecutive projections
//! rarely touch the same particle.
//!
//! Gauss–Seidel projects constraints one after another. When two consecutive constraints
//! share a particle, the second waits for the first's store (a dependency chain of a square
//! root and two divisions); sorted edges `[a, b]` share `a` almost every time. Greedy
//! colouring (each item gets the lowest colour none of its particles has used yet) and a
//! stable sort by colour turn that chain into independent work the CPU overlaps. Within a
//! colour the original order, and with it memory locality, is kept. The items of a class
//! are what the parallel sweep runs concurrently; a large body's classes are grouped by the
//! parts of the body first ([`crate::ordering::partition`]).

/// Greedy colour of each item (an edge or a tetrahedron given by its particle indices).
/// Colours above 63 share the last class; the order stays valid, only less independent.
pub(crate) fn greedy_colours<const N: usize>(items: &[[u32; N]], particles: usize) -> Vec<u8> {
    let mut used = vec![0u64; particles];
    items
        .iter()
        .map(|item| greedy_colour(item, &mut used))
        .collect()
}

/// The last colour of a greedy colouring: items that found every lower colour taken share
/// it, so its class may hold items with a common particle (it runs one item after another).
pub(crate) const OVERFLOW_COLOUR: u8 = 63;

/// The colour of one item in a greedy colouring: the lowest colour (at most 63) none of its
/// particles has used yet, marked as used in `used` (one bit per colour and particle).
#[inline]
pub(crate) fn greedy_colour(item: &[u32], used: &mut [u64]) -> u8 {
    let mask = item.iter().fold(0u64, |m, &i| m | used[i as usize]);
    let colour = (!mask).trailing_zeros().min(u32::from(OVERFLOW_COLOUR));
    for &i in item {
        used[i as usize] |= 1u64 << colour;
    }
    colour as u8
}

/// Items sorted into colour classes, and the classes grouped into the tasks and phases of a
/// sweep.
///
/// A sweep runs the phases one after another. The tasks of one phase touch pairwise disjoint
/// particles, and a task's classes run in order (on one thread, with the `parallel`
/// feature). In the plain layout (`colour_order`) every class is a task and a phase of its
/// own (its items, independent, are split among the threads); a partitioned body groups
/// the classes of each part of a body into one task. Serially, the classes run in storage
/// order, which is phase order, task order within a phase and class order within a task: the
/// same operations in the same order on any number of threads.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ColourClasses {
    /// Start of each class in the sorted order, then the total: class `k` is
    /// `starts[k]..starts[k + 1]`.
    pub starts: Vec<u32>,
    /// The classes (ascending) whose items may share particles (colour 63 of a greedy
    /// colouring, the overflow) and must run one after another.
    pub dependent: Vec<u32>,
    /// First class of each task, then the class count.
    pub tasks: Vec<u32>,
    /// First task of each phase, then the task count.
    pub phases: Vec<u32>,
}

/// What one phase of a sweep is (the parallel sweep's unit of work).
#[cfg(feature = "parallel")]
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Phase {
    /// One class, alone in its task (its items may be split among threads when independent).
    Class(usize),
    /// Tasks of several classes or several tasks: each task runs whole on one thread.
    Tasks(std::ops::Range<usize>),
}

impl ColourClasses {
    /// The plain layout of classes `starts` (every class its own task and phase); the last
    /// class is dependent when `overflow`.
    pub fn plain(starts: Vec<u32>, overflow: bool) -> ColourClasses {
        let classes = starts.len().saturating_sub(1) as u32;
        ColourClasses {
            starts,
            dependent: if overflow && classes > 0 {
                vec![classes - 1]
            } else {
                Vec::new()
            },
            tasks: (0..=classes).collect(),
            phases: (0..=classes).collect(),
        }
    }

    /// Number of classes.
    pub fn len(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    /// `true` when there are no classes (no items).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of phases of a sweep.
    pub fn phase_count(&self) -> usize {
        self.phases.len().saturating_sub(1)
    }

    /// Number of tasks.
    pub fn task_count(&self) -> usize {
        self.tasks.len().saturating_sub(1)
    }

    /// Class `k` (`k < len()`) as a range, with `true` when its items are independent.
    pub fn class(&self, k: usize) -> (std::ops::Range<usize>, bool) {
        let range = self.starts[k] as usize..self.starts[k + 1] as usize;
        (range, self.dependent.binary_search(&(k as u32)).is_err())
    }

    /// The classes of task `t`.
    pub fn task(&self, t: usize) -> std::ops::Range<usize> {
        self.tasks[t] as usize..self.tasks[t + 1] as usize
    }

    /// Phase `j` (`j < phase_count()`).
    #[cfg(feature = "parallel")]
    pub(crate) fn phase(&self, j: usize) -> Phase {
        let tasks = self.phases[j] as usize..self.phases[j + 1] as usize;
        if tasks.len() == 1 && self.task(tasks.start).len() == 1 {
            Phase::Class(self.tasks[tasks.start] as usize)
        } else {
            Phase::Tasks(tasks)
        }
    }

    /// The classes as ranges, in storage (and sweep) order, each with `true` when its items
    /// are independent.
    pub fn ranges(&self) -> impl Iterator<Item = (std::ops::Range<usize>, bool)> + '_ {
        (0..self.len()).map(|k| self.class(k))
    }
}

/// The permutation that sorts `items` by greedy colour (stable within a colour), and the
/// resulting classes.
pub(crate) fn colour_order<const N: usize>(
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
    let overflow = last == Some(OVERFLOW_COLOUR);
    (order, ColourClasses::plain(starts, overflow))
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::greedy_colours;
    use crate::generators::{box_grid, CellSplit};

    #[test]
    fn items_of_one_colour_share_no_particle() {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [4, 4, 4], CellSplit::Six).unwrap();
        let n = mesh.vertices.len();
        let colours = greedy_colours(&mesh.tets, n);
        let max = *colours.iter().max().unwrap();
        assert!(max < 63, "the grid needs {} colours", max + 1);
        for c in 0..=max {
            let mut seen = vec![false; n];
            for (t, tet) in mesh
                .tets
                .iter()
                .enumerate()
                .filter(|(t, _)| colours[*t] == c)
            {
                for &i in tet {
                    assert!(
                        !seen[i as usize],
                        "colour {c}: tetrahedron {t} reuses particle {i}"
                    );
                    seen[i as usize] = true;
                }
            }
        }
    }
}
