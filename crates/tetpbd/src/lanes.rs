//! SIMD kernels: eight constraints of one colour class projected at once, one per lane.
//!
//! Constraints of one colour class share no particle (see [`crate::ordering`]), so eight of
//! them are independent: their particles are gathered into lanes (`wide::f32x8`), the same
//! formulas as [`crate::constraint`] run on all lanes, and the corrections are scattered
//! back with the compensated add. The scalar kernels in [`crate::projection`] are the
//! reference these are tested against (`tests/lanes.rs`).
//!
//! A chunk whose lanes hit a degenerate configuration (a zero-length edge, a tetrahedron
//! collapsed to a point) is handed to the scalar kernel, which owns the documented fallbacks.

use nalgebra::Vector3;
use wide::f32x8;

use crate::constraint::{VERTEX_FACE_KAPPA, VERTEX_FACE_ORDER};
use crate::projection::{self, ParticleAccess};
use crate::systems::ProjectionCount;

/// Lanes per chunk.
pub(crate) const LANES: usize = 8;

/// Eight 3-vectors, one per lane.
#[derive(Clone, Copy)]
struct V3 {
    x: f32x8,
    y: f32x8,
    z: f32x8,
}

impl V3 {
    const ZERO: V3 = V3 {
        x: f32x8::ZERO,
        y: f32x8::ZERO,
        z: f32x8::ZERO,
    };

    #[inline(always)]
    fn gather<A: ParticleAccess>(acc: &A, idx: &[usize; LANES]) -> V3 {
        let mut x = [0.0; LANES];
        let mut y = [0.0; LANES];
        let mut z = [0.0; LANES];
        for l in 0..LANES {
            let p = acc.x(idx[l]);
            x[l] = p.x;
            y[l] = p.y;
            z[l] = p.z;
        }
        V3 {
            x: x.into(),
            y: y.into(),
            z: z.into(),
        }
    }

    #[inline(always)]
    fn lane(&self, l: usize) -> Vector3<f32> {
        Vector3::new(
            self.x.as_array()[l],
            self.y.as_array()[l],
            self.z.as_array()[l],
        )
    }

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
    fn scale(self, s: f32x8) -> V3 {
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
    fn dot(self, o: V3) -> f32x8 {
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

#[inline(always)]
fn gather_w<A: ParticleAccess>(acc: &A, idx: &[usize; LANES]) -> f32x8 {
    let mut w = [0.0; LANES];
    for l in 0..LANES {
        w[l] = acc.w(idx[l]);
    }
    w.into()
}

/// `Δλ` on every lane; 0 where the denominator is not positive. Returns the mask of
/// applied lanes.
#[inline(always)]
fn delta_lambda(c: f32x8, lambda: f32x8, alpha_tilde: f32x8, w_grad_sq: f32x8) -> (f32x8, f32x8) {
    let denom = w_grad_sq + alpha_tilde;
    let ok = denom.simd_gt(f32x8::splat(f32::EPSILON * f32::EPSILON));
    let safe = ok.select(denom, f32x8::ONE);
    (
        ok.select((-c - alpha_tilde * lambda) / safe, f32x8::ZERO),
        ok,
    )
}

fn lanes_of<const N: usize>(items: &[[u32; N]], k: usize) -> [usize; LANES] {
    let mut idx = [0usize; LANES];
    for (l, item) in items.iter().enumerate().take(LANES) {
        idx[l] = item[k] as usize;
    }
    idx
}

/// Eight edges (`edges.len() == LANES`). See [`projection::edge`].
pub(crate) fn edges<A: ParticleAccess>(
    acc: &mut A,
    edges: &[[u32; 2]],
    rest: &[f32],
    lambdas: &mut [f32],
    alpha_tilde: f32,
) -> ProjectionCount {
    let (ia, ib) = (lanes_of(edges, 0), lanes_of(edges, 1));
    let d = f32x8::from(<[f32; LANES]>::try_from(rest).unwrap_or([1.0; LANES]));
    let delta = V3::gather(acc, &ia).sub(V3::gather(acc, &ib));
    let len = delta.dot(delta).sqrt();
    if !len.simd_gt(d * f32x8::splat(1e-6)).all() {
        let mut count = ProjectionCount::default();
        for l in 0..LANES {
            count.add(projection::edge(
                acc,
                edges[l],
                rest[l],
                &mut lambdas[l],
                alpha_tilde,
            ));
        }
        return count;
    }
    let n = delta.scale(f32x8::ONE / len);
    let (wa, wb) = (gather_w(acc, &ia), gather_w(acc, &ib));
    let lam = f32x8::from(<[f32; LANES]>::try_from(&*lambdas).unwrap_or([0.0; LANES]));
    let (dl, ok) = delta_lambda(len - d, lam, f32x8::splat(alpha_tilde), wa + wb);
    lambdas.copy_from_slice((lam + dl).as_array());
    let da = n.scale(wa * dl);
    let db = n.scale(-wb * dl);
    for l in 0..LANES {
        acc.add(ia[l], da.lane(l));
        acc.add(ib[l], db.lane(l));
    }
    ProjectionCount {
        applied: ok.to_bitmask().count_ones() as u64,
        degenerate: 0,
    }
}

/// Eight volume constraints (`tets.len() == LANES`). See [`projection::volume`].
pub(crate) fn volumes<A: ParticleAccess>(
    acc: &mut A,
    tets: &[[u32; 4]],
    rest: &[f32],
    lambdas: &mut [f32],
    alpha_tilde: f32,
) -> ProjectionCount {
    let idx = [0, 1, 2, 3].map(|k| lanes_of(tets, k));
    let p = idx.map(|i| V3::gather(acc, &i));
    let w = idx.map(|i| gather_w(acc, &i));
    let sixth = f32x8::splat(1.0 / 6.0);
    let (a, b, c) = (p[1].sub(p[0]), p[2].sub(p[0]), p[3].sub(p[0]));
    let g1 = b.cross(c).scale(sixth);
    let g2 = c.cross(a).scale(sixth);
    let g3 = a.cross(b).scale(sixth);
    let g0 = g1.add(g2).add(g3).neg();
    let v0 = f32x8::from(<[f32; LANES]>::try_from(rest).unwrap_or([0.0; LANES]));
    let cval = a.dot(b.cross(c)) * sixth - v0;
    let g = [g0, g1, g2, g3];
    let w_grad_sq = (0..4).fold(f32x8::ZERO, |s, k| s + w[k] * g[k].dot(g[k]));
    let lam = f32x8::from(<[f32; LANES]>::try_from(&*lambdas).unwrap_or([0.0; LANES]));
    let (dl, ok) = delta_lambda(cval, lam, f32x8::splat(alpha_tilde), w_grad_sq);
    lambdas.copy_from_slice((lam + dl).as_array());
    for k in 0..4 {
        let d = g[k].scale(w[k] * dl);
        for (l, &i) in idx[k].iter().enumerate() {
            acc.add(i, d.lane(l));
        }
    }
    let mut count = ProjectionCount {
        applied: ok.to_bitmask().count_ones() as u64,
        degenerate: 0,
    };
    let any_free = (w[0] + w[1] + w[2] + w[3]).simd_gt(f32x8::ZERO);
    count.degenerate = (!ok.to_bitmask() & any_free.to_bitmask() & 0xff).count_ones() as u64;
    count
}

/// [`crate::constraint::vertex_face_bounded`] on all lanes: `(C̃, [∇p0, ∇p1, ∇p2, ∇p3],
/// valid)`, with `valid` false (and everything else meaningless) on lanes whose face has
/// collapsed to a point. `h` holds the rest values `d`, `kappa` the thinness threshold.
#[inline(always)]
fn vertex_face_bounded(a: V3, b: V3, c: V3, h: f32x8, kappa: f32) -> (f32x8, [V3; 4], f32x8) {
    let half = f32x8::splat(0.5);
    let m = b.cross(c);
    let s = m.dot(m).sqrt();
    let scale = b.dot(b) + c.dot(c);
    let q = scale * half;
    let point = !q.simd_gt(h * h * f32x8::splat(1e-12));
    let k = point.select(f32x8::ONE, f32x8::splat(kappa) * q);
    let f = a.dot(m);
    let grads = |inv_d: f32x8, e: f32x8, beta: f32x8| {
        let r = f * inv_d * inv_d;
        let g1 = m.scale(inv_d);
        let g2 = c
            .cross(a)
            .scale(inv_d)
            .sub(c.cross(m).scale(e).add(b.scale(beta)).scale(r));
        let g3 = a
            .cross(b)
            .scale(inv_d)
            .sub(m.cross(b).scale(e).add(c.scale(beta)).scale(r));
        (f * inv_d - h, [g1.add(g2).add(g3).neg(), g1, g2, g3])
    };
    let collinear = !s.simd_gt(scale * f32x8::splat(1e-7));
    if !s.simd_lt(k).any() {
        // Every lane healthy (the common case): the seed's height only.
        let safe = collinear.select(f32x8::ONE, s);
        let inv_s = f32x8::ONE / safe;
        let (c, g) = grads(inv_s, inv_s, f32x8::ZERO);
        return (c, g, !point & !collinear);
    }
    let r = s / k;
    let (thin_c, thin_g) = grads(
        f32x8::ONE / ((s * r + k) * half),
        f32x8::ONE / k,
        f32x8::splat(kappa) * half * (f32x8::ONE - r * r),
    );
    let strength = thin_g.iter().fold(f32x8::ZERO, |x, g| x + g.dot(*g));
    // The seed's height on healthy faces and on thin ones with weak gradients.
    let seed = !(s.simd_lt(k) & strength.simd_ge(f32x8::ONE));
    let valid = !point & !(seed & collinear);
    if !(seed & valid).any() {
        return (thin_c, thin_g, valid);
    }
    let safe = collinear.select(f32x8::ONE, s);
    let inv_s = f32x8::ONE / safe;
    let (seed_c, seed_g) = grads(inv_s, inv_s, f32x8::ZERO);
    let pick = |x: V3, y: V3| V3 {
        x: seed.select(x.x, y.x),
        y: seed.select(x.y, y.y),
        z: seed.select(x.z, y.z),
    };
    (
        seed.select(seed_c, thin_c),
        [0, 1, 2, 3].map(|i| pick(seed_g[i], thin_g[i])),
        valid,
    )
}

/// The four vertex–face constraints of eight tetrahedra (`tets.len() == LANES`), the four
/// one after another on all lanes, corrections accumulated in registers and scattered once.
/// See [`projection::vertex_face`]. A chunk with a face not healthy by a margin of 2
/// (`|b × c| ≤ 2κQ`) at its start goes to the scalar kernel; a lane whose face turns
/// degenerate within the chunk is skipped and counted.
pub(crate) fn vertex_faces<A: ParticleAccess>(
    acc: &mut A,
    tets: &[[u32; 4]],
    heights: &[[f32; 4]],
    lambdas: &mut [[f32; 4]],
    alpha_tilde: f32,
) -> ProjectionCount {
    let idx = [0, 1, 2, 3].map(|k| lanes_of(tets, k));
    let p0 = idx.map(|i| V3::gather(acc, &i));
    let w = idx.map(|i| gather_w(acc, &i));
    let hs = [0, 1, 2, 3].map(|k| f32x8::from([0, 1, 2, 3, 4, 5, 6, 7].map(|l| heights[l][k])));
    // Pre-check every face at the start of the chunk: all healthy with a margin of 2
    // (|b × c| > 2κQ), or the chunk goes to the scalar kernel.
    let margin = f32x8::splat(VERTEX_FACE_KAPPA);
    for order in VERTEX_FACE_ORDER {
        let (b, c) = (
            p0[order[2]].sub(p0[order[0]]),
            p0[order[3]].sub(p0[order[0]]),
        );
        let m = b.cross(c);
        let twice_k = margin * (b.dot(b) + c.dot(c));
        let ok = m.dot(m).simd_gt(twice_k * twice_k);
        if !ok.all() {
            let mut count = ProjectionCount::default();
            for l in 0..LANES {
                let (a, d) = projection::vertex_face(
                    acc,
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
    let at = f32x8::splat(alpha_tilde);
    let mut dp = [V3::ZERO; 4];
    let mut count = ProjectionCount::default();
    for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
        let q = order.map(|o| p0[o].add(dp[o]));
        let (a, b, c) = (q[1].sub(q[0]), q[2].sub(q[0]), q[3].sub(q[0]));
        let (cval, g, valid) = vertex_face_bounded(a, b, c, hs[k], VERTEX_FACE_KAPPA);
        let wo = order.map(|o| w[o]);
        let w_grad_sq = (0..4).fold(f32x8::ZERO, |s, s_| s + wo[s_] * g[s_].dot(g[s_]));
        let lam = f32x8::from([0, 1, 2, 3, 4, 5, 6, 7].map(|l| lambdas[l][k]));
        let (dl, ok) = delta_lambda(cval, lam, at, w_grad_sq);
        let dl = valid.select(dl, f32x8::ZERO);
        let ok = ok & valid;
        let new = (lam + dl).to_array();
        for l in 0..LANES {
            lambdas[l][k] = new[l];
        }
        for s in 0..4 {
            dp[order[s]] = dp[order[s]].add(g[s].scale(wo[s] * dl));
        }
        count.applied += ok.to_bitmask().count_ones() as u64;
        count.degenerate += (!valid.to_bitmask() & 0xff).count_ones() as u64;
    }
    for (corner, d) in idx.iter().zip(&dp) {
        for (l, &i) in corner.iter().enumerate() {
            acc.add(i, d.lane(l));
        }
    }
    count
}
