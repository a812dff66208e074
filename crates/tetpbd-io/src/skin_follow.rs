//! A skin following a tear: each embedded point re-bound to the piece that holds its
//! tetrahedron.
//!
//! A tear or a cut ([`TearEvent`]) never removes a tetrahedron; it duplicates particles and
//! renumbers them per piece, keeping the order of each tetrahedron's corners. A point bound to
//! tetrahedron `[a, b, c, d]` of the body before the event is bound afterwards to the piece
//! tetrahedron whose corners are `a, b, c, d` or copies of them
//! ([`TearEvent::copies`]), with the same barycentric weights: at the moment of the event it
//! is where it was, and it then moves with its piece. Sorted lookups, no hashing.

use tetpbd::TearEvent;

use crate::mesher_error::SkinError;
use crate::skin::{Skin, SkinBinding};

/// The skin of one piece after a tear: the points whose tetrahedron the piece holds.
#[derive(Clone, Debug, PartialEq)]
pub struct PieceSkin {
    /// The points, bound to the piece's particles and tetrahedra
    /// ([`Skin::deform`] with the piece's positions).
    pub skin: Skin,
    /// For each of them, its index in the skin before the event (ascending).
    pub points: Vec<u32>,
}

impl Skin {
    /// Splits this skin, embedded in a body, along `event` (a tear or a cut of that body):
    /// one [`PieceSkin`] per piece, in the event's order, each point bound to the piece that
    /// holds its tetrahedron. `piece_tets[k]` are the tetrahedra of piece `k` now
    /// (`Tetrahedra::indices` of `event.pieces[k].entity`). An event that changed nothing
    /// gives the skin back as one piece.
    ///
    /// Errors: [`SkinError::LengthMismatch`] (`piece_tets` not one per piece),
    /// [`SkinError::LostTetrahedron`] (a point whose tetrahedron no piece holds).
    pub fn follow(
        &self,
        event: &TearEvent,
        piece_tets: &[&[[u32; 4]]],
    ) -> Result<Vec<PieceSkin>, SkinError> {
        if event.pieces.is_empty() {
            let points = (0..self.bindings.len() as u32).collect();
            return Ok(vec![PieceSkin {
                skin: self.clone(),
                points,
            }]);
        }
        if piece_tets.len() != event.pieces.len() {
            return Err(SkinError::LengthMismatch {
                what: "pieces",
                expected: event.pieces.len(),
                found: piece_tets.len(),
            });
        }
        // (source particle, copy) of every copy, sorted.
        let mut copies: Vec<(u32, u32)> = event
            .copies
            .iter()
            .enumerate()
            .map(|(k, &s)| (s, (event.particles_before + k) as u32))
            .collect();
        copies.sort_unstable();
        // Each piece's tetrahedra by their sorted corners.
        let sorted: Vec<Vec<([u32; 4], u32)>> = piece_tets
            .iter()
            .map(|tets| {
                let mut v: Vec<([u32; 4], u32)> = tets
                    .iter()
                    .enumerate()
                    .map(|(t, tet)| (sorted4(*tet), t as u32))
                    .collect();
                v.sort_unstable();
                v
            })
            .collect();
        let mut out: Vec<PieceSkin> = event
            .pieces
            .iter()
            .map(|p| PieceSkin {
                skin: Skin {
                    bindings: Vec::new(),
                    vertex_count: p.particles.len(),
                },
                points: Vec::new(),
            })
            .collect();
        for (point, b) in self.bindings.iter().enumerate() {
            let (k, binding) = (0..event.pieces.len())
                .find_map(|k| {
                    let particles = &event.pieces[k].particles;
                    rebind(b, particles, &copies, &sorted[k], piece_tets[k]).map(|nb| (k, nb))
                })
                .ok_or(SkinError::LostTetrahedron { point })?;
            out[k].skin.bindings.push(binding);
            out[k].points.push(point as u32);
        }
        Ok(out)
    }
}

/// Binding `b` re-bound to a piece whose particles (body numbering after the split,
/// ascending) are `particles` and whose tetrahedra are `tets` (`sorted` by sorted corners),
/// if the piece holds its tetrahedron.
fn rebind(
    b: &SkinBinding,
    particles: &[u32],
    copies: &[(u32, u32)],
    sorted: &[([u32; 4], u32)],
    tets: &[[u32; 4]],
) -> Option<SkinBinding> {
    // Each corner's candidates in the piece: the particle itself and its copies, as piece
    // indices.
    let candidates = b.vertices.map(|v| {
        let start = copies.partition_point(|c| c.0 < v);
        std::iter::once(v)
            .chain(copies[start..].iter().take_while(|c| c.0 == v).map(|c| c.1))
            .filter_map(|i| particles.binary_search(&i).ok().map(|j| j as u32))
            .collect::<Vec<u32>>()
    });
    for &i0 in &candidates[0] {
        for &i1 in &candidates[1] {
            for &i2 in &candidates[2] {
                for &i3 in &candidates[3] {
                    let corners = [i0, i1, i2, i3];
                    let Ok(at) = sorted.binary_search_by_key(&sorted4(corners), |s| s.0) else {
                        continue;
                    };
                    let t = sorted[at].1;
                    let tet = tets[t as usize];
                    // The weights follow the corners, whatever order the piece keeps them in.
                    let weights = tet.map(|c| {
                        let j = corners.iter().position(|&x| x == c).unwrap_or(0);
                        b.weights[j]
                    });
                    return Some(SkinBinding {
                        tet: t,
                        vertices: tet,
                        weights,
                        distance: b.distance,
                    });
                }
            }
        }
    }
    None
}

/// The four indices, ascending.
fn sorted4(mut t: [u32; 4]) -> [u32; 4] {
    t.sort_unstable();
    t
}
