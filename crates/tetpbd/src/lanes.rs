//! SIMD kernels: four constraints of one colour class projected at once, one per lane.
//!
//! Constraints of one colour class share no particle (see [`crate::ordering`]), so four of
//! them are independent: the `[x, y, z, w]` rows of their particles (see [`crate::work`])
//! are loaded and transposed into lanes (`wide::f32x4`), the same formulas as
//! [`crate::constraint`] run on all lanes, and the corrections are transposed back into
//! rows and added with the compensated update. The scalar kernels in
//! [`crate::projection`] are the reference these are tested against (`tests/lanes.rs`).
//!
//! A chunk whose lanes hit a degenerate configuration (a zero-length edge, a face too close
//! to collinear) or, for vertex–face, a thin face (the thin branch of
//! [`crate::constraint::vertex_face_bounded`]) is handed to the scalar kernel, which owns the
//! documented fallbacks.

use wide::f32x4;

use crate::constraint::{VERTEX_FACE_KAPPA, VERTEX_FACE_ORDER};
use crate::projection::{self, ParticleAccess};
use crate::systems::ProjectionCount;

/// Lanes per chunk.
pub(crate) const LANES: usize = 4;

/// Four 3-vectors, one per lane.
#[derive(Clone, Copy)]
struct V3 {
    x: f32x4,
    y: f32x4,
    z: f32x4,
}

impl V3 {
    const ZERO: V3 = V3 {
        x: f32x4::ZERO,
        y: f32x4::ZERO,
        z: f32x4::ZERO,
    };

    #[inline(always)]
    fn add(self, o: V3) -> V3 {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    #[inline(always)]
    fn sub(self, o: V3) -> V3 {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    #[inline(always)]
    fn scale(self, s: f32x4) -> V3 {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    #[inline(always)]
    fn neg(self) -> V3 {
        V3 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }

    #[inline(always)]
    fn dot(self, o: V3) -> f32x4 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    fn cross(self, o: V3) -> V3 {
        V3 {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }
}

/// The items of one run (edges or tetrahedra as particle indices) with the particles they
/// index, every index checked once against the particle count: the kernels then read and
/// move the items' particles without a bounds check per access.
pub(crate) struct Bounded<'a, A, const N: usize> {
    acc: &'a mut A,
    items: &'a [[u32; N]],
}

impl<'a, A: ParticleAccess, const N: usize> Bounded<'a, A, N> {
    /// Checks that every index of `items` is below `acc.len()` (one vectorised pass over the
    /// run; panics on an index out of range, as a checked access would).
    #[inline(always)]
    pub(crate) fn new(acc: &'a mut A, items: &'a [[u32; N]]) -> Self {
        let max = items.as_flattened().iter().fold(0, |m, &i| m.max(i));
        assert!(
            items.is_empty() || (max as usize) < acc.len(),
            "particle index {max} out of range ({} particles)",
            acc.len()
        );
        Bounded { acc, items }
    }

    /// The particles, for the scalar kernels (bounds-checked).
    #[inline(always)]
    pub(crate) fn acc(&mut self) -> &mut A {
        self.acc
    }

    /// The items.
    #[inline(always)]
    pub(crate) fn items(&self) -> &'a [[u32; N]] {
        self.items
    }

    /// Corner `k` of the `LANES` items from `at`: positions and inverse masses, one per lane.
    #[inline(always)]
    fn gather(&self, at: usize, k: usize) -> (V3, f32x4) {
        let it = chunk(self.items, at);
        // SAFETY: `it[l][k]` is an index of `self.items`, all of which are below
        // `self.acc.len()` (checked in `new`; neither changes afterwards: both are borrowed
        // for `'a`, the access mutably).
        let row = |l: usize| unsafe { self.acc.row_unchecked(it[l][k] as usize) };
        let [x, y, z, w] = f32x4::transpose([row(0), row(1), row(2), row(3)]);
        (V3 { x, y, z }, w)
    }

    /// The four corners of the four tetrahedra from `at`.
    #[inline(always)]
    fn gather_corners(&self, at: usize) -> ([V3; 4], [f32x4; 4]) {
        let (p0, w0) = self.gather(at, 0);
        let (p1, w1) = self.gather(at, 1);
        let (p2, w2) = self.gather(at, 2);
        let (p3, w3) = self.gather(at, 3);
        ([p0, p1, p2, p3], [w0, w1, w2, w3])
    }

    /// Moves corner `k` of item `at + l` by lane `l` of `d` (compensated).
    #[inline(always)]
    fn scatter(&mut self, at: usize, k: usize, d: V3) {
        let it = chunk(self.items, at);
        let rows = f32x4::transpose([d.x, d.y, d.z, f32x4::ZERO]);
        for (item, row) in it.iter().zip(rows) {
            // SAFETY: as in `gather`: an index of `self.items`, below `self.acc.len()`.
            unsafe { self.acc.add_row_unchecked(item[k] as usize, row) };
        }
    }
}

/// Four rows of four values, transposed: item `k` of every row as lanes.
#[inline(always)]
fn transpose_rows(rows: &[[f32; 4]; LANES]) -> [f32x4; 4] {
    f32x4::transpose([
        f32x4::new(rows[0]),
        f32x4::new(rows[1]),
        f32x4::new(rows[2]),
        f32x4::new(rows[3]),
    ])
}

/// `Δλ` on every lane; 0 where the denominator is not positive. Returns the mask of
/// applied lanes.
#[inline(always)]
fn delta_lambda(c: f32x4, lambda: f32x4, alpha_tilde: f32x4, w_grad_sq: f32x4) -> (f32x4, f32x4) {
    let denom = w_grad_sq + alpha_tilde;
    let ok = denom.simd_gt(f32x4::splat(f32::EPSILON * f32::EPSILON));
    let safe = ok.select(denom, f32x4::ONE);
    (
        ok.select((-c - alpha_tilde * lambda) / safe, f32x4::ZERO),
        ok,
    )
}

/// Four consecutive values as lanes.
#[inline(always)]
fn lanes_of(v: &[f32; LANES]) -> f32x4 {
    f32x4::new(*v)
}

/// `LANES` items of `s` from `at` (the caller keeps `at + LANES ≤ s.len()`).
#[inline(always)]
pub(crate) fn chunk<T>(s: &[T], at: usize) -> &[T; LANES] {
    s[at..at + LANES]
        .try_into()
        .expect("a chunk of LANES items")
}

/// `LANES` items of `s` from `at`, for writing.
#[inline(always)]
pub(crate) fn chunk_mut<T>(s: &mut [T], at: usize) -> &mut [T; LANES] {
    (&mut s[at..at + LANES])
        .try_into()
        .expect("a chunk of LANES items")
}

/// Four edges. See [`projection::edge`].
#[inline(always)]
pub(crate) fn edges<A: ParticleAccess>(
    b: &mut Bounded<'_, A, 2>,
    at: usize,
    rest: &[f32; LANES],
    lambdas: &mut [f32; LANES],
    alpha_tilde: f32,
) -> ProjectionCount {
    let d = lanes_of(rest);
    let (pa, wa) = b.gather(at, 0);
    let (pb, wb) = b.gather(at, 1);
    let delta = pa.sub(pb);
    let len = delta.dot(delta).sqrt();
    if !len.simd_gt(d * f32x4::splat(1e-6)).all() {
        let edges = chunk(b.items(), at);
        let mut count = ProjectionCount::default();
        for l in 0..LANES {
            count.add(projection::edge(
                b.acc(),
                edges[l],
                rest[l],
                &mut lambdas[l],
                alpha_tilde,
            ));
        }
        return count;
    }
    let n = delta.scale(f32x4::ONE / len);
    let lam = lanes_of(lambdas);
    let (dl, ok) = delta_lambda(len - d, lam, f32x4::splat(alpha_tilde), wa + wb);
    *lambdas = (lam + dl).to_array();
    b.scatter(at, 0, n.scale(wa * dl));
    b.scatter(at, 1, n.scale(-wb * dl));
    ProjectionCount {
        applied: ok.to_bitmask().count_ones() as u64,
        degenerate: 0,
    }
}

/// Four volume constraints. See [`projection::volume`].
#[inline(always)]
pub(crate) fn volumes<A: ParticleAccess>(
    bd: &mut Bounded<'_, A, 4>,
    at: usize,
    rest: &[f32; LANES],
    lambdas: &mut [f32; LANES],
    alpha_tilde: f32,
) -> ProjectionCount {
    let (p, w) = bd.gather_corners(at);
    let sixth = f32x4::splat(1.0 / 6.0);
    let (a, b, c) = (p[1].sub(p[0]), p[2].sub(p[0]), p[3].sub(p[0]));
    let bc = b.cross(c);
    let g1 = bc.scale(sixth);
    let g2 = c.cross(a).scale(sixth);
    let g3 = a.cross(b).scale(sixth);
    let g0 = g1.add(g2).add(g3).neg();
    let cval = a.dot(bc) * sixth - lanes_of(rest);
    let g = [g0, g1, g2, g3];
    let w_grad_sq = (0..4).fold(f32x4::ZERO, |s, k| s + w[k] * g[k].dot(g[k]));
    let lam = lanes_of(lambdas);
    let (dl, ok) = delta_lambda(cval, lam, f32x4::splat(alpha_tilde), w_grad_sq);
    *lambdas = (lam + dl).to_array();
    for k in 0..4 {
        bd.scatter(at, k, g[k].scale(w[k] * dl));
    }
    let any_free = (w[0] + w[1] + w[2] + w[3]).simd_gt(f32x4::ZERO);
    ProjectionCount {
        applied: ok.to_bitmask().count_ones() as u64,
        degenerate: (!ok.to_bitmask() & any_free.to_bitmask() & 0xf).count_ones() as u64,
    }
}

/// The four vertex–face constraints of four tetrahedra, the four one after another on all
/// lanes, corrections accumulated in registers and scattered once. See
/// [`projection::vertex_face`]: on healthy faces [`crate::constraint::vertex_face_bounded`]
/// is the seed's height, which these lanes compute. A chunk with a face not healthy by a
/// margin of 2 at its start (`|b × c| ≤ 2κQ`, κ = [`VERTEX_FACE_KAPPA`]) goes to the scalar
/// kernel; a lane whose face turns thin (`|b × c| < κQ`) within the chunk skips that
/// projection and counts it as degenerate.
#[inline(always)]
pub(crate) fn vertex_faces<A: ParticleAccess>(
    bd: &mut Bounded<'_, A, 4>,
    at: usize,
    heights: &[[f32; 4]; LANES],
    lambdas: &mut [[f32; 4]; LANES],
    alpha_tilde: f32,
) -> ProjectionCount {
    let (p0, w) = bd.gather_corners(at);
    let kappa = f32x4::splat(VERTEX_FACE_KAPPA);
    // Pre-check every face at the start of the chunk: healthy with a margin of 2.
    for order in VERTEX_FACE_ORDER {
        let (b, c) = (
            p0[order[2]].sub(p0[order[0]]),
            p0[order[3]].sub(p0[order[0]]),
        );
        let m = b.cross(c);
        let twice_k = kappa * (b.dot(b) + c.dot(c));
        let ok = m.dot(m).simd_gt(twice_k * twice_k);
        if !ok.all() {
            let tets = chunk(bd.items(), at);
            let mut count = ProjectionCount::default();
            for l in 0..LANES {
                let (a, d) = projection::vertex_face(
                    bd.acc(),
                    tets[l],
                    &heights[l],
                    &mut lambdas[l],
                    alpha_tilde,
                );
                count.applied += u64::from(a);
                count.degenerate += u64::from(d);
            }
            return count;
        }
    }
    let alpha = f32x4::splat(alpha_tilde);
    // Per constraint k, the four tetrahedra's heights and multipliers as lanes.
    let h = transpose_rows(heights);
    let mut lam = transpose_rows(lambdas);
    let mut dp = [V3::ZERO; 4];
    let mut count = ProjectionCount::default();
    for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
        let q = [
            p0[order[0]].add(dp[order[0]]),
            p0[order[1]].add(dp[order[1]]),
            p0[order[2]].add(dp[order[2]]),
            p0[order[3]].add(dp[order[3]]),
        ];
        let (a, b, c) = (q[1].sub(q[0]), q[2].sub(q[0]), q[3].sub(q[0]));
        let m = b.cross(c);
        let m_len = m.dot(m).sqrt();
        // Healthy (`s ≥ κQ`, Q = (|b|² + |c|²)/2): the seed's height.
        let valid = m_len.simd_ge((b.dot(b) + c.dot(c)) * kappa * f32x4::splat(0.5));
        let inv = valid.select(f32x4::ONE / m_len, f32x4::ZERO);
        let n = m.scale(inv);
        let na = n.dot(a);
        let g1 = n;
        let g2 = c.cross(a).add(n.cross(c).scale(na)).scale(inv);
        let g3 = b.cross(a).add(n.cross(b).scale(na)).scale(inv).neg();
        let g0 = g1.add(g2).add(g3).neg();
        let g = [g0, g1, g2, g3];
        let wo = [w[order[0]], w[order[1]], w[order[2]], w[order[3]]];
        let w_grad_sq = (0..4).fold(f32x4::ZERO, |s, s_| s + wo[s_] * g[s_].dot(g[s_]));
        let (dl, ok) = delta_lambda(na - h[k], lam[k], alpha, w_grad_sq);
        let dl = valid.select(dl, f32x4::ZERO);
        let ok = ok & valid;
        lam[k] += dl;
        for s in 0..4 {
            dp[order[s]] = dp[order[s]].add(g[s].scale(wo[s] * dl));
        }
        count.applied += ok.to_bitmask().count_ones() as u64;
        count.degenerate += (!valid.to_bitmask() & 0xf).count_ones() as u64;
    }
    let lam = f32x4::transpose(lam);
    for (row, l) in lambdas.iter_mut().zip(lam) {
        *row = l.to_array();
    }
    for (k, d) in dp.into_iter().enumerate() {
        bd.scatter(at, k, d);
    }
    count
}
