//! Memory locality: particles renumbered along a space-filling curve at build time.
//!
//! The projections gather and scatter the positions of a constraint's particles. Mesh files
//! (TetGen, Gmsh, volume meshers) often number vertices in an order unrelated to space, so
//! the particles of one tetrahedron lie far apart in memory and almost every gather misses
//! the cache. Sorting the particles by the Morton (Z-order) code of their rest position
//! puts particles that are close in space close in memory; the tetrahedra are then sorted by
//! their smallest particle index, so consecutive constraints touch neighbouring memory.
//!
//! The renumbering is a permutation `source`: particle `k` of the built body is vertex
//! `source[k]` of the input mesh (see [`crate::Particles::source`] and
//! [`crate::Particles::particle_of`]).

use nalgebra::Vector3;

/// Bits per axis of the Morton code (30-bit codes: 1024 cells per axis).
const BITS: u32 = 10;

/// Spreads the low 10 bits of `v` to every third bit.
fn spread(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    x = (x | (x << 2)) & 0x0924_9249;
    x
}

/// Morton code of `p` quantized to a 1024³ grid over the box `lo..lo + extent`.
fn morton(p: &Vector3<f32>, lo: &Vector3<f32>, inv_cell: f32) -> u32 {
    let max = ((1u32 << BITS) - 1) as f32;
    let q = |k: usize| ((p[k] - lo[k]) * inv_cell).clamp(0.0, max) as u32;
    spread(q(0)) | (spread(q(1)) << 1) | (spread(q(2)) << 2)
}

/// The particle order along the Morton curve of `positions`: element `k` is the input index
/// of the `k`-th particle. Ties (and non-finite input) keep the input order, so the result
/// is deterministic.
pub fn morton_order(positions: &[Vector3<f32>]) -> Vec<u32> {
    let mut lo = Vector3::repeat(f32::INFINITY);
    let mut hi = Vector3::repeat(f32::NEG_INFINITY);
    for p in positions.iter().filter(|p| p.iter().all(|c| c.is_finite())) {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let extent = (hi - lo).max();
    let inv_cell = if extent.is_finite() && extent > 0.0 {
        ((1u32 << BITS) - 1) as f32 / extent
    } else {
        0.0
    };
    let mut keyed: Vec<(u32, u32)> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| (morton(p, &lo, inv_cell), i as u32))
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// The inverse of a permutation: `inverse[order[k]] = k`.
pub fn inverse(order: &[u32]) -> Vec<u32> {
    let mut inv = vec![0u32; order.len()];
    for (k, &i) in order.iter().enumerate() {
        inv[i as usize] = k as u32;
    }
    inv
}

/// Tetrahedra renumbered by `index` (input vertex → particle) and sorted by their smallest
/// particle index (stable); returns the tetrahedra and, for each, its input index.
pub fn relabel_tets(tets: &[[u32; 4]], index: &[u32]) -> (Vec<[u32; 4]>, Vec<u32>) {
    let relabelled: Vec<[u32; 4]> = tets.iter().map(|t| t.map(|i| index[i as usize])).collect();
    let mut order: Vec<u32> = (0..tets.len() as u32).collect();
    order.sort_by_key(|&t| relabelled[t as usize].iter().copied().min());
    let sorted = order.iter().map(|&t| relabelled[t as usize]).collect();
    (sorted, order)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_interleaves_the_axes() {
        assert_eq!(spread(0b11), 0b1001);
        let lo = Vector3::zeros();
        assert_eq!(morton(&Vector3::new(1.0, 0.0, 0.0), &lo, 1.0), 1);
        assert_eq!(morton(&Vector3::new(0.0, 1.0, 0.0), &lo, 1.0), 2);
        assert_eq!(morton(&Vector3::new(0.0, 0.0, 1.0), &lo, 1.0), 4);
    }

    #[test]
    fn order_is_a_permutation_and_inverse_inverts_it() {
        let pts: Vec<Vector3<f32>> = (0..50)
            .map(|i| Vector3::new((i * 7 % 13) as f32, (i * 3 % 5) as f32, i as f32 * 0.1))
            .collect();
        let order = morton_order(&pts);
        let inv = inverse(&order);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..50).collect::<Vec<u32>>());
        for (k, &i) in order.iter().enumerate() {
            assert_eq!(inv[i as usize], k as u32);
        }
    }

    #[test]
    fn nearby_points_get_nearby_indices() {
        // Two clusters given interleaved end up contiguous.
        let pts: Vec<Vector3<f32>> = (0..20)
            .map(|i| Vector3::repeat(if i % 2 == 0 { 0.0 } else { 10.0 } + i as f32 * 1e-3))
            .collect();
        let order = morton_order(&pts);
        assert!(order[..10].iter().all(|i| i % 2 == 0));
        assert!(order[10..].iter().all(|i| i % 2 == 1));
    }
}
