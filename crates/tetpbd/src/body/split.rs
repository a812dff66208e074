//! Splitting a tetrahedral mesh along faces, and its connected pieces (mesh level: indices
//! only; the components follow in `crate::body::pieces`).
//!
//! A torn face separates its two tetrahedra at each of its particles. Around particle `v`,
//! the tetrahedra using it are joined when they share a face through `v` that is not torn;
//! each group beyond the first (the group of the lowest-numbered tetrahedron keeps `v`) gets a
//! copy of `v`. A tear that does not yet separate the tetrahedra around a particle leaves that
//! particle shared. Everything is sorted, never hashed, so the result depends on the mesh alone.

use crate::body::tearing::face_key;

/// The mesh after a split: the tetrahedra (same order, corners renumbered) and, for each new
/// particle `n + k`, the particle it copies (`origin[k] < n`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Separation {
    pub tets: Vec<[u32; 4]>,
    pub origin: Vec<u32>,
}

/// Splits `tets` (over `n` particles) along the faces `torn` (sorted particle triples).
pub(crate) fn separate(tets: &[[u32; 4]], n: usize, torn: &[[u32; 3]]) -> Separation {
    let mut candidates: Vec<u32> = torn.iter().flatten().copied().collect();
    candidates.sort_unstable();
    candidates.dedup();
    // The star of every candidate: (particle, tetrahedron, corner), sorted.
    let mut star: Vec<(u32, u32, u8)> = Vec::new();
    for (t, tet) in tets.iter().enumerate() {
        for (c, &i) in tet.iter().enumerate() {
            if candidates.binary_search(&i).is_ok() {
                star.push((i, t as u32, c as u8));
            }
        }
    }
    star.sort_unstable();
    let mut out = Separation {
        tets: tets.to_vec(),
        origin: Vec::new(),
    };
    let mut faces: Vec<([u32; 3], u32)> = Vec::new();
    let mut from = 0;
    while from < star.len() {
        let v = star[from].0;
        let to = from + star[from..].partition_point(|s| s.0 == v);
        let group = &star[from..to];
        faces.clear();
        for (k, &(_, t, c)) in group.iter().enumerate() {
            let tet = &tets[t as usize];
            for opposite in (0..4).filter(|&o| o != c as usize) {
                faces.push((face_key(tet, opposite), k as u32));
            }
        }
        faces.sort_unstable();
        let mut parent: Vec<u32> = (0..group.len() as u32).collect();
        for w in faces.windows(2) {
            if w[0].0 == w[1].0 && torn.binary_search(&w[0].0).is_err() {
                union(&mut parent, w[0].1, w[1].1);
            }
        }
        // Groups in the order of their lowest tetrahedron (`group` is sorted by tetrahedron);
        // the first keeps `v`.
        let mut copy_of_root: Vec<(u32, u32)> = Vec::new();
        for (k, &(_, t, c)) in group.iter().enumerate() {
            let root = find(&mut parent, k as u32);
            if root == find(&mut parent, 0) {
                continue;
            }
            let copy = match copy_of_root.iter().find(|r| r.0 == root) {
                Some(&(_, copy)) => copy,
                None => {
                    let copy = (n + out.origin.len()) as u32;
                    out.origin.push(v);
                    copy_of_root.push((root, copy));
                    copy
                }
            };
            out.tets[t as usize][c as usize] = copy;
        }
        from = to;
    }
    out
}

/// The connected pieces of `tets` over `n` particles (tetrahedra joined through shared
/// particles): the piece of each tetrahedron, numbered in the order of their lowest
/// tetrahedron, and the piece count.
pub(crate) fn pieces(tets: &[[u32; 4]], n: usize) -> (Vec<u32>, usize) {
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for tet in tets {
        for &i in &tet[1..] {
            union(&mut parent, tet[0], i);
        }
    }
    let mut label = vec![u32::MAX; n];
    let mut count = 0u32;
    let piece_of = tets
        .iter()
        .map(|tet| {
            let root = find(&mut parent, tet[0]) as usize;
            if label[root] == u32::MAX {
                label[root] = count;
                count += 1;
            }
            label[root]
        })
        .collect();
    (piece_of, count as usize)
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

/// Joins the sets of `a` and `b`, the lower root becoming the root (deterministic).
fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    let (lo, hi) = (ra.min(rb), ra.max(rb));
    parent[hi as usize] = lo;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generators::{box_grid, CellSplit};
    use nalgebra::Vector3;

    /// Two tetrahedra sharing one face, torn along it: three copies, two pieces.
    #[test]
    fn a_torn_shared_face_separates_two_tetrahedra() {
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
        let s = separate(&tets, 5, &[[1, 2, 3]]);
        assert_eq!(s.origin, vec![1, 2, 3]);
        assert_eq!(s.tets[0], [0, 1, 2, 3]);
        assert_eq!(s.tets[1], [5, 6, 7, 4]);
        assert_eq!(pieces(&s.tets, 8).1, 2);
    }

    /// One torn face inside a grid, connected around its edges, splits nothing.
    #[test]
    fn a_crack_that_does_not_reach_across_splits_nothing() {
        let mesh = box_grid(Vector3::new(3.0, 3.0, 3.0), [3, 3, 3], CellSplit::Six).unwrap();
        let n = mesh.vertices.len();
        let faces = crate::body::tearing::interior_faces(&mesh.tets, &mesh.vertices);
        // A face with no particle on the boundary.
        let surface = crate::Surface::from_tetrahedra(&mesh.tets, &mesh.vertices);
        let f = faces
            .iter()
            .find(|f| {
                let key = face_key(&mesh.tets[f.tets[0] as usize], {
                    let tet = mesh.tets[f.tets[0] as usize];
                    tet.iter().position(|&i| i == f.apex[0]).unwrap()
                });
                key.iter()
                    .all(|i| surface.vertices().binary_search(i).is_err())
            })
            .expect("an interior face");
        let tet = mesh.tets[f.tets[0] as usize];
        let key = face_key(&tet, tet.iter().position(|&i| i == f.apex[0]).unwrap());
        let s = separate(&mesh.tets, n, &[key]);
        assert!(s.origin.is_empty());
        assert_eq!(s.tets, mesh.tets);
    }
}
