//! SIMD kernels: four or eight constraints of one colour class projected at once, one per
//! lane.
//!
//! Constraints of one colour class share no particle (see [`crate::ordering::colouring`]), so four of
//! them are independent: the `[x, y, z, w]` rows of their particles (see [`crate::kernels::working_copy`])
//! are loaded and transposed into lanes (`wide::f32x4`), the same formulas as
//! [`crate::constraints`] run on all lanes, and the corrections are transposed back into
//! rows and added with the compensated update. The kernels are written over a [`Lane`] type:
//! a chunk of four (`f32x4`) or two chunks side by side ([`crate::kernels::lane_types::X2`]), which gives
//! the same bits as the two chunks one after the other (see [`crate::kernels::lane_types`]). The scalar
//! kernels in [`crate::kernels::scalar`] are the reference these are tested against.
//!
//! A chunk whose lanes hit a degenerate configuration (a zero-length edge, a face too close
//! to collinear) or, for vertex–face, a thin face (the thin branch of
//! [`crate::constraints::vertex_face_bounded`]) is handed to the scalar kernel, which owns the
//! documented fallbacks; a pair of chunks that has one goes back to chunks of four.

use wide::f32x4;

use crate::kernels::count::ProjectionCount;
use crate::kernels::lane_types::Lane;
use crate::kernels::scalar::{self, ParticleAccess};
pub(crate) use crate::kernels::vertex_face_lanes::vertex_faces;

/// Lanes per chunk.
pub(crate) const LANES: usize = 4;

/// 3-vectors, one per lane.
#[derive(Clone, Copy)]
pub(crate) struct V3<L> {
    pub x: L,
    pub y: L,
    pub z: L,
}

impl<L: Lane> V3<L> {
    pub(crate) const ZERO: V3<L> = V3 {
        x: L::ZERO,
        y: L::ZERO,
        z: L::ZERO,
    };

    #[inline(always)]
    pub(crate) fn add(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    #[inline(always)]
    pub(crate) fn sub(self, o: V3<L>) -> V3<L> {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    #[inline(always)]
    pub(crate) fn scale(self, s: L) -> V3<L> {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    #[inline(always)]
    pub(crate) fn neg(self) -> V3<L> {
        V3 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }

    #[inline(always)]
    pub(crate) fn dot(self, o: V3<L>) -> L {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    pub(crate) fn cross(self, o: V3<L>) -> V3<L> {
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

    /// Corner `k` of the `L::WIDTH` items from `at`: positions and inverse masses, one per
    /// lane.
    #[inline(always)]
    pub(crate) fn gather<L: Lane>(&self, at: usize, k: usize) -> (V3<L>, L) {
        let mut rows = [[f32x4::ZERO; 4]; 2];
        for (c, r) in rows.iter_mut().enumerate().take(L::WIDTH / LANES) {
            let it = chunk(self.items, at + c * LANES);
            // SAFETY: `it[l][k]` is an index of `self.items`, all of which are below
            // `self.acc.len()` (checked in `new`; neither changes afterwards: both are
            // borrowed for `'a`, the access mutably).
            let row = |l: usize| unsafe { self.acc.row_unchecked(it[l][k] as usize) };
            *r = [row(0), row(1), row(2), row(3)];
        }
        let [x, y, z, w] = L::transpose_in(rows);
        (V3 { x, y, z }, w)
    }

    /// The four corners of the tetrahedra from `at`.
    #[inline(always)]
    pub(crate) fn gather_corners<L: Lane>(&self, at: usize) -> ([V3<L>; 4], [L; 4]) {
        let (p0, w0) = self.gather(at, 0);
        let (p1, w1) = self.gather(at, 1);
        let (p2, w2) = self.gather(at, 2);
        let (p3, w3) = self.gather(at, 3);
        ([p0, p1, p2, p3], [w0, w1, w2, w3])
    }

    /// Moves corner `k` of item `at + l` by lane `l` of `d` (compensated).
    #[inline(always)]
    pub(crate) fn scatter<L: Lane>(&mut self, at: usize, k: usize, d: V3<L>) {
        let rows = L::transpose_out([d.x, d.y, d.z]);
        for (c, r) in rows.iter().enumerate().take(L::WIDTH / LANES) {
            let it = chunk(self.items, at + c * LANES);
            for (item, &row) in it.iter().zip(r) {
                // SAFETY: as in `gather`: an index of `self.items`, below `self.acc.len()`.
                unsafe { self.acc.add_row_unchecked(item[k] as usize, row) };
            }
        }
    }
}

/// Rows of four values from `at`, transposed: value `k` of every row as lanes.
#[inline(always)]
pub(crate) fn transpose_rows<L: Lane>(rows: &[[f32; 4]], at: usize) -> [L; 4] {
    let mut q = [[f32x4::ZERO; 4]; 2];
    for (c, quarter) in q.iter_mut().enumerate().take(L::WIDTH / LANES) {
        let r = chunk(rows, at + c * LANES);
        *quarter = f32x4::transpose(r.map(f32x4::new));
    }
    [0, 1, 2, 3].map(|k| L::from_quarters([q[0][k], q[1][k]]))
}

/// The inverse of [`transpose_rows`]: lane `l` of `lanes[k]` to value `k` of row `at + l`.
#[inline(always)]
pub(crate) fn untranspose_rows<L: Lane>(lanes: [L; 4], rows: &mut [[f32; 4]], at: usize) {
    let [q0, q1, q2, q3] = lanes.map(L::quarters);
    for c in 0..L::WIDTH / LANES {
        let r = chunk_mut(rows, at + c * LANES);
        let t = f32x4::transpose([q0[c], q1[c], q2[c], q3[c]]);
        for (row, l) in r.iter_mut().zip(t) {
            *row = l.to_array();
        }
    }
}

/// `L::WIDTH` consecutive values from `at` as lanes.
#[inline(always)]
pub(crate) fn lanes_of<L: Lane>(v: &[f32], at: usize) -> L {
    let mut q = [f32x4::ZERO; 2];
    for (c, quarter) in q.iter_mut().enumerate().take(L::WIDTH / LANES) {
        *quarter = f32x4::new(*chunk(v, at + c * LANES));
    }
    L::from_quarters(q)
}

/// Stores lanes to `L::WIDTH` consecutive values from `at`.
#[inline(always)]
pub(crate) fn store_lanes<L: Lane>(l: L, v: &mut [f32], at: usize) {
    let q = l.quarters();
    for (c, quarter) in q.iter().enumerate().take(L::WIDTH / LANES) {
        *chunk_mut(v, at + c * LANES) = quarter.to_array();
    }
}

/// `Δλ` on every lane; 0 where the denominator is not positive. Returns the mask of
/// applied lanes.
#[inline(always)]
pub(crate) fn delta_lambda<L: Lane>(c: L, lambda: L, alpha_tilde: L, w_grad_sq: L) -> (L, L) {
    let denom = w_grad_sq + alpha_tilde;
    let ok = denom.vgt(L::splat(f32::EPSILON * f32::EPSILON));
    let safe = ok.vsel(denom, L::ONE);
    (ok.vsel((-c - alpha_tilde * lambda) / safe, L::ZERO), ok)
}

/// [`crate::constraints::bounded_step`] on every lane: `dl` scaled down where a particle
/// could move further than `max_step` (m), the farthest move per unit `dl` taken as
/// `√(w_max · w_grad_sq)` (an upper bound of `maxₛ wₛ |gₛ|`, as the scalar kernel takes it).
/// `limit = max_step² / w_max` is computed once per chunk, so only `dl` and `w_grad_sq` are
/// read per projection. Lanes within the bound keep `dl` bit for bit.
#[inline(always)]
pub(crate) fn bounded_step<L: Lane>(dl: L, w_grad_sq: L, limit: L, max_step: L, w_max: L) -> L {
    let over = (dl * dl * w_grad_sq).vgt(limit);
    if over.vbits() == 0 {
        return dl;
    }
    let s = max_step / over.vsel(w_max * w_grad_sq, L::ONE).vsqrt();
    over.vsel(L::ZERO.vgt(dl).vsel(-s, s), dl)
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

/// Bits of the `L::WIDTH` lanes.
#[inline(always)]
pub(crate) fn all_lanes<L: Lane>() -> u32 {
    (1 << L::WIDTH) - 1
}

/// `L::WIDTH` edges from `at` of the run. See [`scalar::edge`]. A pair of chunks with a
/// zero-length edge goes to [`edges`] chunk by chunk, a chunk of four with one to the scalar
/// kernel.
#[inline(always)]
pub(crate) fn edges<L: Lane, A: ParticleAccess>(
    b: &mut Bounded<'_, A, 2>,
    at: usize,
    rest: &[f32],
    lambdas: &mut [f32],
    alpha_tilde: f32,
) -> ProjectionCount {
    let d: L = lanes_of(rest, at);
    let (pa, wa) = b.gather::<L>(at, 0);
    let (pb, wb) = b.gather::<L>(at, 1);
    let delta = pa.sub(pb);
    let len = delta.dot(delta).vsqrt();
    if !len.vgt(d * L::splat(1e-6)).vall() {
        let mut count = ProjectionCount::default();
        if L::WIDTH > LANES {
            for c in (0..L::WIDTH).step_by(LANES) {
                count += edges::<f32x4, A>(b, at + c, rest, lambdas, alpha_tilde);
            }
            return count;
        }
        let edges = chunk(b.items(), at);
        for (l, &e) in edges.iter().enumerate() {
            let k = at + l;
            count.add(scalar::edge(
                b.acc(),
                e,
                rest[k],
                &mut lambdas[k],
                alpha_tilde,
            ));
        }
        return count;
    }
    let n = delta.scale(L::ONE / len);
    let lam: L = lanes_of(lambdas, at);
    let (dl, ok) = delta_lambda(len - d, lam, L::splat(alpha_tilde), wa + wb);
    store_lanes(lam + dl, lambdas, at);
    b.scatter(at, 0, n.scale(wa * dl));
    b.scatter(at, 1, n.scale(-wb * dl));
    ProjectionCount {
        applied: u64::from(ok.vbits().count_ones()),
        degenerate: 0,
    }
}

/// `L::WIDTH` volume constraints from `at` of the run. See [`scalar::volume`].
#[inline(always)]
pub(crate) fn volumes<L: Lane, A: ParticleAccess>(
    bd: &mut Bounded<'_, A, 4>,
    at: usize,
    rest: &[f32],
    lambdas: &mut [f32],
    alpha_tilde: f32,
) -> ProjectionCount {
    let (p, w) = bd.gather_corners::<L>(at);
    let sixth = L::splat(1.0 / 6.0);
    let (a, b, c) = (p[1].sub(p[0]), p[2].sub(p[0]), p[3].sub(p[0]));
    let bc = b.cross(c);
    let g1 = bc.scale(sixth);
    let g2 = c.cross(a).scale(sixth);
    let g3 = a.cross(b).scale(sixth);
    let g0 = g1.add(g2).add(g3).neg();
    let cval = a.dot(bc) * sixth - lanes_of(rest, at);
    let g = [g0, g1, g2, g3];
    let (s0, s1, s2, s3) = (g0.dot(g0), g1.dot(g1), g2.dot(g2), g3.dot(g3));
    let v0: L = lanes_of(rest, at);
    // (q / |V₀|)³ < gate · |V₀|, q = Σ|∇C|²: scalar::volume_gradient_weak, lane by lane.
    let v = v0.vmax(-v0);
    let r = (s0 + s1 + s2 + s3) / v;
    if (L::splat(crate::constraints::VOLUME_GATE as f32) * v)
        .vgt(r * r * r)
        .vbits()
        != 0
    {
        return volumes_scalar::<L, A>(bd, at, rest, lambdas, alpha_tilde);
    }
    let w_grad_sq = w[0] * s0 + w[1] * s1 + w[2] * s2 + w[3] * s3;
    let lam: L = lanes_of(lambdas, at);
    let (dl, ok) = delta_lambda(cval, lam, L::splat(alpha_tilde), w_grad_sq);
    store_lanes(lam + dl, lambdas, at);
    for k in 0..4 {
        bd.scatter(at, k, g[k].scale(w[k] * dl));
    }
    let any_free = (w[0] + w[1] + w[2] + w[3]).vgt(L::ZERO);
    ProjectionCount {
        applied: u64::from(ok.vbits().count_ones()),
        degenerate: u64::from((!ok.vbits() & any_free.vbits() & all_lanes::<L>()).count_ones()),
    }
}

/// [`volumes`] of a chunk with a lane whose gradient is weak
/// ([`scalar::volume_gradient_weak`]): a pair of chunks chunk by chunk, a chunk of four
/// through the scalar kernel, which owns the recovery direction.
#[cold]
fn volumes_scalar<L: Lane, A: ParticleAccess>(
    bd: &mut Bounded<'_, A, 4>,
    at: usize,
    rest: &[f32],
    lambdas: &mut [f32],
    alpha_tilde: f32,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    if L::WIDTH > LANES {
        for c in (0..L::WIDTH).step_by(LANES) {
            count += volumes::<f32x4, A>(bd, at + c, rest, lambdas, alpha_tilde);
        }
        return count;
    }
    let tets = *chunk(bd.items(), at);
    for (l, &t) in tets.iter().enumerate() {
        let k = at + l;
        count.add(scalar::volume(
            bd.acc(),
            t,
            rest[k],
            &mut lambdas[k],
            alpha_tilde,
        ));
    }
    count
}
