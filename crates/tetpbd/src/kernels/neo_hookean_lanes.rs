//! The SIMD kernel of the Neo-Hookean material: four or eight tetrahedra of one colour class
//! projected at once, one per lane, over the lane types of [`crate::kernels::lane_types`].
//!
//! The same steps as the scalar kernel ([`crate::kernels::neo_hookean::project_tet`], the
//! reference these lanes are tested against) written on lanes: `F = Ds Dm⁻¹`, the two
//! constraints and their gradients, the coupled 2×2 update in the basis that keeps the rest
//! state free of cancellation ([`crate::constraints::neo_hookean_update`]), the move bound of
//! about one rest edge, and the elastic energy released since the substep start. `Dm⁻¹` is
//! read as the nine floats of each tetrahedron's matrix (two 4 × 4 transposes and one row of
//! four per chunk).
//!
//! A chunk with a lane the scalar kernel would call degenerate (`‖F‖_F` vanishing, a
//! singular 2×2 system, a result not finite) is handed to the scalar kernel whole, which
//! owns those outcomes; a pair of chunks with one goes back to chunks of four. A lane whose
//! four particles are all pinned is left alone (its multipliers stay, it releases nothing),
//! as the scalar kernel skips it. Every lane does the same IEEE operations in a chunk of four
//! as in a pair, so pairs give the bits of their two chunks one after the other.

use nalgebra::{Matrix3, Vector3};
use wide::f32x4;

use crate::kernels::count::ProjectionCount;
use crate::kernels::lane_types::Lane;
use crate::kernels::lanes::{chunk, lanes_of, store_lanes, Bounded, LANES, V3};
use crate::kernels::neo_hookean::{project_tet, MaterialStep, TetOutcome, TetRun};
use crate::kernels::scalar::ParticleAccess;

/// The nine entries `Dm⁻¹[(k, c)]` (storage order `k + 3c`) of the `L::WIDTH` matrices from
/// `at`, as lanes.
#[inline(always)]
fn rest_inverse_lanes<L: Lane>(mats: &[Matrix3<f32>], at: usize) -> [L; 9] {
    let mut q = [[f32x4::ZERO; 9]; 2];
    for (c, quarter) in q.iter_mut().enumerate().take(L::WIDTH / LANES) {
        let m = chunk(mats, at + c * LANES).map(|m| {
            let s = m.as_slice();
            (
                f32x4::new([s[0], s[1], s[2], s[3]]),
                f32x4::new([s[4], s[5], s[6], s[7]]),
                s[8],
            )
        });
        let lo = f32x4::transpose(m.map(|r| r.0));
        let hi = f32x4::transpose(m.map(|r| r.1));
        quarter[..4].copy_from_slice(&lo);
        quarter[4..8].copy_from_slice(&hi);
        quarter[8] = f32x4::new(m.map(|r| r.2));
    }
    let mut out = [L::ZERO; 9];
    for (j, o) in out.iter_mut().enumerate() {
        *o = L::from_quarters([q[0][j], q[1][j]]);
    }
    out
}

/// Corner `k`'s positions in `prev` of the `L::WIDTH` tetrahedra from `at`, as lanes.
#[inline(always)]
fn prev_lanes<L: Lane>(tets: &[[u32; 4]], prev: &[Vector3<f32>], at: usize, k: usize) -> V3<L> {
    let mut rows = [[f32x4::ZERO; 4]; 2];
    for (c, r) in rows.iter_mut().enumerate().take(L::WIDTH / LANES) {
        *r = chunk(tets, at + c * LANES).map(|t| {
            let x = prev[t[k] as usize];
            f32x4::new([x.x, x.y, x.z, 0.0])
        });
    }
    let [x, y, z, _] = L::transpose_in(rows);
    V3 { x, y, z }
}

/// `Ds M` as columns, `Ds = [e1, e2, e3]`, `m` the nine entries of `M` in storage order.
#[inline(always)]
fn times<L: Lane>(e: [V3<L>; 3], m: &[L; 9]) -> [V3<L>; 3] {
    [
        combine(e, m[0], m[1], m[2]),
        combine(e, m[3], m[4], m[5]),
        combine(e, m[6], m[7], m[8]),
    ]
}

/// `v0 a + v1 b + v2 c`. (Helpers are functions, not closures: a closure does not inherit
/// the AVX2 build's target features, and its lane operations would not be inlined.)
#[inline(always)]
fn combine<L: Lane>(v: [V3<L>; 3], a: L, b: L, c: L) -> V3<L> {
    v[0].scale(a).add(v[1].scale(b)).add(v[2].scale(c))
}

/// The particle gradients `[−Σ, h1, h2, h3]`, `hᵢ` = column `i − 1` of `P Dm⁻ᵀ` (`P` as
/// columns).
#[inline(always)]
fn gradients<L: Lane>(p: [V3<L>; 3], m: &[L; 9]) -> [V3<L>; 4] {
    let h = [
        combine(p, m[0], m[3], m[6]),
        combine(p, m[1], m[4], m[7]),
        combine(p, m[2], m[5], m[8]),
    ];
    [h[0].add(h[1]).add(h[2]).neg(), h[0], h[1], h[2]]
}

/// The cofactor matrix's columns `[f1 × f2, f2 × f0, f0 × f1]`.
#[inline(always)]
fn cofactor<L: Lane>(f: &[V3<L>; 3]) -> [V3<L>; 3] {
    [f[1].cross(f[2]), f[2].cross(f[0]), f[0].cross(f[1])]
}

/// `A : B`, both as columns.
#[inline(always)]
fn ddot<L: Lane>(a: &[V3<L>; 3], b: &[V3<L>; 3]) -> L {
    a[0].dot(b[0]) + a[1].dot(b[1]) + a[2].dot(b[2])
}

/// `Σ wᵢ aᵢ · bᵢ`.
#[inline(always)]
fn weighted<L: Lane>(w: &[L; 4], a: &[V3<L>; 4], b: &[V3<L>; 4]) -> L {
    w[0] * a[0].dot(b[0]) + w[1] * a[1].dot(b[1]) + w[2] * a[2].dot(b[2]) + w[3] * a[3].dot(b[3])
}

/// The edge matrix of corner moves `d` as columns `[d1 − d0, d2 − d0, d3 − d0]`.
#[inline(always)]
fn edges_of<L: Lane>(d: &[V3<L>; 4]) -> [V3<L>; 3] {
    [d[1].sub(d[0]), d[2].sub(d[0]), d[3].sub(d[0])]
}

/// `(2F + dF) : dF` and `det(F + dF) − det F` (as `cof F : dF + F : cof dF + det dF`), the
/// parts of the scalar kernel's `energy_change`.
#[inline(always)]
fn changes<L: Lane>(f: &[V3<L>; 3], cof_f: &[V3<L>; 3], df: &[V3<L>; 3]) -> (L, L) {
    let two = L::splat(2.0);
    let twice = [
        f[0].scale(two).add(df[0]),
        f[1].scale(two).add(df[1]),
        f[2].scale(two).add(df[2]),
    ];
    let cof_df = cofactor(df);
    let det_df = df[0].dot(cof_df[0]);
    (
        ddot(&twice, df),
        ddot(cof_f, df) + ddot(f, &cof_df) + det_df,
    )
}

/// One coupled projection of the material of the `L::WIDTH` tetrahedra from `at` of the run.
/// See the module docs; `run` holds the run's rest shapes and multipliers (indexed like
/// `bd`'s items), `prev` the substep's start positions of the body's particles.
#[inline(always)]
pub(crate) fn tets<L: Lane, A: ParticleAccess>(
    bd: &mut Bounded<'_, A, 4>,
    at: usize,
    prev: &[Vector3<f32>],
    run: &mut TetRun<'_>,
    k: &MaterialStep,
) -> ProjectionCount {
    let (p, w) = bd.gather_corners::<L>(at);
    let free = (w[0] + w[1] + w[2] + w[3]).vgt(L::ZERO);
    let m = rest_inverse_lanes::<L>(run.rest_inverse, at);
    let e = edges_of(&p);
    let f = times(e, &m);
    let c_d = ddot(&f, &f).vsqrt();
    let tiny = L::splat(f32::EPSILON * f32::EPSILON);
    let cof_f = cofactor(&f);
    // A lane collapsed towards a point or a line (the recovery direction's region,
    // `‖cof F‖²_F < 3τ²`) or with all points at one place goes to the scalar kernel.
    let weak = L::splat(3.0 * k.collapse * k.collapse);
    let ok = c_d.vgt(tiny) & ddot(&cof_f, &cof_f).vge(weak);
    if free.vbits() & !ok.vbits() != 0 {
        return elsewhere::<L, A>(bd, at, prev, run, k);
    }
    let c_h = f[0].dot(cof_f[0]) - L::splat(k.rest_offset);
    let inv_c = ok.vsel(L::ONE / c_d, L::ZERO);
    let g_d = gradients(
        [f[0].scale(inv_c), f[1].scale(inv_c), f[2].scale(inv_c)],
        &m,
    );
    let g_h = gradients(cof_f, &m);
    // The substep's start: x̄ − x per corner (the damping's rate and the energy's first part).
    let items = bd.items();
    let back = [
        prev_lanes::<L>(items, prev, at, 0).sub(p[0]),
        prev_lanes::<L>(items, prev, at, 1).sub(p[1]),
        prev_lanes::<L>(items, prev, at, 2).sub(p[2]),
        prev_lanes::<L>(items, prev, at, 3).sub(p[3]),
    ];
    let v0 = lanes_of::<L>(run.rest_volumes, at);
    let v0 = v0.vmax(-v0);
    let at_d = L::splat(k.alpha_tilde_volume[0]) / v0;
    let at_h = L::splat(k.alpha_tilde_volume[1]) / v0;
    let (lam_d, lam_h) = multipliers::<L>(run.lambdas, at);
    let damping = L::splat(k.damping);
    // The 2×2 system, as `constraints::neo_hookean_update` solves it.
    let g_dd = weighted(&w, &g_d, &g_d);
    let g_dh = weighted(&w, &g_d, &g_h);
    let r = g_dd.vgt(L::ZERO).vsel(g_dh / g_dd, L::ZERO);
    let perp = [
        g_h[0].sub(g_d[0].scale(r)),
        g_h[1].sub(g_d[1].scale(r)),
        g_h[2].sub(g_d[2].scale(r)),
        g_h[3].sub(g_d[3].scale(r)),
    ];
    let g_perp = weighted(&w, &perp, &perp);
    let kk = L::ONE + damping;
    let (mut b0, mut b1) = (-c_d - at_d * lam_d, -c_h - at_h * lam_h);
    if k.damping > 0.0 {
        // rate = ∇C · (x − x̄) = −∇C · back.
        let ones = [L::ONE; 4];
        let (rate_d, rate_h) = (-weighted(&ones, &g_d, &back), -weighted(&ones, &g_h, &back));
        b0 = b0 - damping * rate_d;
        b1 = b1 - damping * rate_h;
    }
    let pp = kk * g_dd + at_d;
    let q = kk * g_perp + at_h;
    let det = pp * q + at_d * r * r * kk * g_dd;
    let u = (b0 * q + at_d * r * b1) / det;
    let dl_h = (pp * b1 - kk * r * g_dd * b0) / det;
    let dl_d = u - r * dl_h;
    let fine = det.vgt(L::ZERO) & finite(u) & finite(dl_h) & finite(dl_d);
    if free.vbits() & !fine.vbits() != 0 {
        return elsewhere::<L, A>(bd, at, prev, run, k);
    }
    let mut dx = [V3::ZERO; 4];
    for i in 0..4 {
        dx[i] = g_d[i].scale(u).add(perp[i].scale(dl_h)).scale(w[i]);
    }
    let (mut dl_d, mut dl_h) = (free.vsel(dl_d, L::ZERO), free.vsel(dl_h, L::ZERO));
    // The bound: about one rest edge, 3/‖Dm⁻¹‖²_F (squared).
    let longest = dx[0]
        .dot(dx[0])
        .vmax(dx[1].dot(dx[1]))
        .vmax(dx[2].dot(dx[2]))
        .vmax(dx[3].dot(dx[3]));
    let mut norm2 = L::ZERO;
    for x in m {
        norm2 += x * x;
    }
    let bound = L::splat(3.0) / norm2;
    let over = longest.vgt(bound);
    if over.vbits() != 0 {
        let s = over.vsel((bound / over.vsel(longest, L::ONE)).vsqrt(), L::ONE);
        dl_d = dl_d * s;
        dl_h = dl_h * s;
        for d in &mut dx {
            *d = d.scale(s);
        }
    }
    for d in &mut dx {
        *d = V3 {
            x: free.vsel(d.x, L::ZERO),
            y: free.vsel(d.y, L::ZERO),
            z: free.vsel(d.z, L::ZERO),
        };
    }
    for (i, d) in dx.iter().enumerate() {
        bd.scatter(at, i, *d);
    }
    store_multipliers(lam_d + dl_d, lam_h + dl_h, run.lambdas, at);
    // The energy released since x̄: U(x̄) − U(x) − (U(x + Δx) − U(x)).
    let (n_back, d_back) = changes(&f, &cof_f, &times(edges_of(&back), &m));
    let (n_dx, d_dx) = changes(&f, &cof_f, &times(edges_of(&dx), &m));
    let h2 = L::splat(k.h2);
    let two_ch = c_h + c_h;
    let energy = (n_back - n_dx) / ((at_d + at_d) * h2)
        + (d_back * (two_ch + d_back) - d_dx * (two_ch + d_dx)) / ((at_h + at_h) * h2);
    store_lanes(free.vsel(energy, L::ZERO), run.released, at);
    ProjectionCount {
        applied: u64::from(free.vbits().count_ones()),
        degenerate: 0,
    }
}

/// A mask of the lanes where `x` is finite.
#[inline(always)]
fn finite<L: Lane>(x: L) -> L {
    // `x · 0` is 0 for finite `x` and NaN for ±∞ and NaN.
    (x * L::ZERO).vge(L::ZERO)
}

/// The multipliers `[λ_D, λ_H]` of the `L::WIDTH` tetrahedra from `at`, as lanes.
#[inline(always)]
fn multipliers<L: Lane>(lambdas: &[[f32; 2]], at: usize) -> (L, L) {
    let mut q = [[f32x4::ZERO; 2]; 2];
    for (c, quarter) in q.iter_mut().enumerate().take(L::WIDTH / LANES) {
        let l = chunk(lambdas, at + c * LANES);
        *quarter = [
            f32x4::new([l[0][0], l[1][0], l[2][0], l[3][0]]),
            f32x4::new([l[0][1], l[1][1], l[2][1], l[3][1]]),
        ];
    }
    (
        L::from_quarters([q[0][0], q[1][0]]),
        L::from_quarters([q[0][1], q[1][1]]),
    )
}

/// Stores [`multipliers`] back.
#[inline(always)]
fn store_multipliers<L: Lane>(d: L, h: L, lambdas: &mut [[f32; 2]], at: usize) {
    let (d, h) = (d.quarters(), h.quarters());
    for c in 0..L::WIDTH / LANES {
        let (d, h) = (d[c].to_array(), h[c].to_array());
        for (l, x) in lambdas[at + c * LANES..at + (c + 1) * LANES]
            .iter_mut()
            .enumerate()
        {
            *x = [d[l], h[l]];
        }
    }
}

/// [`tets`] of a chunk with a lane the scalar kernel owns: a pair of chunks goes back to
/// chunks of four, a chunk of four to the scalar kernel.
#[inline(always)]
fn elsewhere<L: Lane, A: ParticleAccess>(
    bd: &mut Bounded<'_, A, 4>,
    at: usize,
    prev: &[Vector3<f32>],
    run: &mut TetRun<'_>,
    k: &MaterialStep,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    if L::WIDTH > LANES {
        for c in (0..L::WIDTH).step_by(LANES) {
            count += tets::<f32x4, A>(bd, at + c, prev, run, k);
        }
        return count;
    }
    let items = chunk(bd.items(), at);
    for (l, &t) in items.iter().enumerate() {
        count += one(&mut run.released[at + l], {
            let i = at + l;
            project_tet(
                bd.acc(),
                prev,
                t,
                &run.rest_inverse[i],
                run.rest_volumes[i],
                &mut run.lambdas[i],
                k,
            )
        });
    }
    count
}

/// Records what one scalar projection did: its released energy in `released`, and its count.
#[inline(always)]
pub(crate) fn one(released: &mut f32, o: TetOutcome) -> ProjectionCount {
    let mut c = ProjectionCount::default();
    *released = 0.0;
    match o {
        TetOutcome::Applied(e) => {
            c.applied = 1;
            *released = e;
        }
        TetOutcome::Recovered(e) => {
            c.degenerate = 1;
            *released = e;
        }
        TetOutcome::Degenerate => c.degenerate = 1,
        TetOutcome::Skipped => {}
    }
    c
}

#[cfg(test)]
mod tests;
