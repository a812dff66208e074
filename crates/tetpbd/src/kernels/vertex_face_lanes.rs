//! The SIMD kernel of the seed's vertex–face family: the four signed vertex–face constraints
//! of four or eight tetrahedra of one colour class projected at once, one tetrahedron per
//! lane, over the lane toolkit of [`crate::kernels::lanes`]. The scalar kernel
//! ([`crate::kernels::scalar::vertex_face_held`]) is the reference these lanes are tested
//! against and owns the fallbacks of thin faces.

use wide::f32x4;

use crate::constraints::{
    VERTEX_FACE_KAPPA, VERTEX_FACE_MAX_STEP, VERTEX_FACE_ORDER, VERTEX_FACE_SLIVER,
};
use crate::kernels::count::ProjectionCount;
use crate::kernels::lane_types::Lane;
use crate::kernels::lanes::{
    all_lanes, bounded_step, chunk, delta_lambda, transpose_rows, untranspose_rows, Bounded, LANES,
    V3,
};
use crate::kernels::scalar::{self, ParticleAccess};

/// The four vertex–face constraints of `L::WIDTH` tetrahedra from `at` of the run, the four
/// one after another on all lanes, corrections accumulated in registers and scattered once.
/// See [`scalar::vertex_face_held`]: on healthy faces
/// [`crate::constraints::vertex_face_bounded`] is the seed's height, which these lanes
/// compute. A chunk of four with a face not healthy by a margin of 2 at its start
/// (`|b × c| ≤ 2κQ`, κ = [`VERTEX_FACE_KAPPA`]) goes to the scalar kernel (a pair of chunks
/// with one, to this kernel chunk by chunk); a lane whose face turns thin (`|b × c| < κQ`)
/// within the chunk skips that projection and counts it as degenerate. Every projection's
/// `Δλ` is bounded as in the scalar kernel ([`crate::constraints::bounded_step`] with
/// [`crate::constraints::vertex_face_step_bound`]), lane by lane. `held` (one row of four
/// 1/0 masks per tetrahedron of the run, or empty for all) leaves the constraints with 0
/// alone, as [`scalar::vertex_face_held`] does.
#[inline(always)]
pub(crate) fn vertex_faces<L: Lane, A: ParticleAccess>(
    bd: &mut Bounded<'_, A, 4>,
    at: usize,
    heights: &[[f32; 4]],
    held: &[[f32; 4]],
    lambdas: &mut [[f32; 4]],
    alpha_tilde: f32,
) -> ProjectionCount {
    let (p0, w) = bd.gather_corners::<L>(at);
    let kappa = L::splat(VERTEX_FACE_KAPPA);
    if !faces_healthy(&p0, kappa) {
        return vertex_faces_elsewhere::<L, A>(bd, at, heights, held, lambdas, alpha_tilde);
    }
    let alpha = L::splat(alpha_tilde);
    // Per constraint k, the tetrahedra's heights and multipliers as lanes.
    let h: [L; 4] = transpose_rows(heights, at);
    let mut lam: [L; 4] = transpose_rows(lambdas, at);
    // Per constraint k, 1 where it is projected, 0 where it is left alone (all held when
    // the run has no masks).
    let masked = !held.is_empty();
    let mask: [L; 4] = if masked {
        transpose_rows(held, at)
    } else {
        [L::ONE; 4]
    };
    // The move bound, as in `constraints::vertex_face_step_bound`: a multiple of max_k |d_k|,
    // or of min_k |d_k| on a sliver (`√(d²) = |d|` exactly in IEEE arithmetic).
    let largest = h.iter().fold(L::ZERO, |m, &d| m.vmax(d * d));
    let smallest = h
        .iter()
        .fold(L::splat(f32::INFINITY), |m, &d| m.vgt(d * d).vsel(d * d, m));
    let sliver = (largest * L::splat(VERTEX_FACE_SLIVER * VERTEX_FACE_SLIVER)).vgt(smallest);
    let size = sliver.vsel(smallest, largest).vsqrt();
    let max_step = L::splat(VERTEX_FACE_MAX_STEP) * size;
    let w_max = w.iter().fold(L::ZERO, |m, &x| m.vmax(x));
    // All four pinned (w_max = 0): the limit is infinite (or NaN), no lane is over.
    let limit = max_step * max_step / w_max;
    let mut dp = [V3::<L>::ZERO; 4];
    let mut count = ProjectionCount::default();
    for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
        let q = [
            p0[order[0]].add(dp[order[0]]),
            p0[order[1]].add(dp[order[1]]),
            p0[order[2]].add(dp[order[2]]),
            p0[order[3]].add(dp[order[3]]),
        ];
        let (na, valid, g) = height_and_gradients(q, kappa);
        let wo = [w[order[0]], w[order[1]], w[order[2]], w[order[3]]];
        let w_grad_sq = (0..4).fold(L::ZERO, |s, s_| s + wo[s_] * g[s_].dot(g[s_]));
        let (dl, ok) = delta_lambda(na - h[k], lam[k], alpha, w_grad_sq);
        let (dl, ok) = if masked {
            let on = mask[k].vgt(L::ZERO);
            (on.vsel(dl, L::ZERO), ok & on)
        } else {
            (dl, ok)
        };
        let dl = bounded_step(valid.vsel(dl, L::ZERO), w_grad_sq, limit, max_step, w_max);
        let ok = ok & valid;
        lam[k] += dl;
        for s in 0..4 {
            dp[order[s]] = dp[order[s]].add(g[s].scale(wo[s] * dl));
        }
        count.applied += u64::from(ok.vbits().count_ones());
        let counted = if masked {
            mask[k].vgt(L::ZERO).vbits()
        } else {
            all_lanes::<L>()
        };
        count.degenerate += u64::from((!valid.vbits() & counted).count_ones());
    }
    untranspose_rows(lam, lambdas, at);
    for (k, d) in dp.into_iter().enumerate() {
        bd.scatter(at, k, d);
    }
    count
}

/// Whether every face of the chunk's tetrahedra is healthy with a margin of 2
/// (`|b × c| > 2κQ` on every lane) at the start of the chunk.
#[inline(always)]
fn faces_healthy<L: Lane>(p0: &[V3<L>; 4], kappa: L) -> bool {
    for order in VERTEX_FACE_ORDER {
        let (b, c) = (
            p0[order[2]].sub(p0[order[0]]),
            p0[order[3]].sub(p0[order[0]]),
        );
        let m = b.cross(c);
        let twice_k = kappa * (b.dot(b) + c.dot(c));
        let ok = m.dot(m).vgt(twice_k * twice_k);
        if !ok.vall() {
            return false;
        }
    }
    true
}

/// [`vertex_faces`] of a chunk with a face not healthy by the margin: a pair of chunks goes
/// back to chunks of four, a chunk of four to the scalar kernel.
#[inline(always)]
fn vertex_faces_elsewhere<L: Lane, A: ParticleAccess>(
    bd: &mut Bounded<'_, A, 4>,
    at: usize,
    heights: &[[f32; 4]],
    held: &[[f32; 4]],
    lambdas: &mut [[f32; 4]],
    alpha_tilde: f32,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    if L::WIDTH > LANES {
        for c in (0..L::WIDTH).step_by(LANES) {
            count += vertex_faces::<f32x4, A>(bd, at + c, heights, held, lambdas, alpha_tilde);
        }
        return count;
    }
    let tets = chunk(bd.items(), at);
    for (l, &t) in tets.iter().enumerate() {
        let k = at + l;
        let (a, d) = scalar::vertex_face_held(
            bd.acc(),
            t,
            &heights[k],
            &mut lambdas[k],
            alpha_tilde,
            scalar::held_mask(held, k),
        );
        count.applied += u64::from(a);
        count.degenerate += u64::from(d);
    }
    count
}

/// The seed's height `n·a` of corner `q[1]` above the face `q[0], q[2], q[3]`, whether the
/// face is healthy (`s ≥ κQ`, Q = (|b|² + |c|²)/2) and the four gradients (zero on a lane
/// whose face is not).
#[inline(always)]
fn height_and_gradients<L: Lane>(q: [V3<L>; 4], kappa: L) -> (L, L, [V3<L>; 4]) {
    let (a, b, c) = (q[1].sub(q[0]), q[2].sub(q[0]), q[3].sub(q[0]));
    let m = b.cross(c);
    let m_len = m.dot(m).vsqrt();
    let valid = m_len.vge((b.dot(b) + c.dot(c)) * kappa * L::splat(0.5));
    let inv = valid.vsel(L::ONE / m_len, L::ZERO);
    let n = m.scale(inv);
    let na = n.dot(a);
    let g1 = n;
    let g2 = c.cross(a).add(n.cross(c).scale(na)).scale(inv);
    let g3 = b.cross(a).add(n.cross(b).scale(na)).scale(inv).neg();
    let g0 = g1.add(g2).add(g3).neg();
    (na, valid, [g0, g1, g2, g3])
}
