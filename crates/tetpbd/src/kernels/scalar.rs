//! One projection of one constraint, written once and run by both the serial and the
//! parallel sweeps through a [`ParticleAccess`].

use nalgebra::Vector3;
use wide::f32x4;

use crate::constraints::{self, Evaluated, VERTEX_FACE_ORDER};

/// How a projection reads and moves particles (see [`crate::kernels::working_copy`] for the layout).
pub(crate) trait ParticleAccess {
    /// `[x, y, z, w]`: position (m) and inverse mass (1/kg) of particle `i`.
    fn row(&self, i: usize) -> f32x4;
    /// Rest position of particle `i`.
    fn rest(&self, i: usize) -> Vector3<f32>;
    /// Moves particle `i` by `d = [dx, dy, dz, 0]`, compensated (see
    /// [`crate::solver::systems::add_compensated`]).
    fn add_row(&mut self, i: usize, d: f32x4);
    /// Number of particles: `i < len()` is in range. Constant while the access lives (the
    /// unchecked accesses below rely on it).
    fn len(&self) -> usize;
    /// [`ParticleAccess::row`] without the bounds check.
    ///
    /// # Safety
    /// `i < self.len()`.
    #[inline(always)]
    unsafe fn row_unchecked(&self, i: usize) -> f32x4 {
        self.row(i)
    }
    /// [`ParticleAccess::add_row`] without the bounds check.
    ///
    /// # Safety
    /// `i < self.len()`.
    #[inline(always)]
    unsafe fn add_row_unchecked(&mut self, i: usize, d: f32x4) {
        self.add_row(i, d);
    }

    /// Position of particle `i`.
    #[inline(always)]
    fn x(&self, i: usize) -> Vector3<f32> {
        let [x, y, z, _] = self.row(i).to_array();
        Vector3::new(x, y, z)
    }
    /// Inverse mass of particle `i`.
    #[inline(always)]
    fn w(&self, i: usize) -> f32 {
        self.row(i).to_array()[3]
    }
    /// Moves particle `i` by `d`.
    #[inline(always)]
    fn add(&mut self, i: usize, d: Vector3<f32>) {
        self.add_row(i, f32x4::new([d.x, d.y, d.z, 0.0]));
    }
}

/// What one projection did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Outcome {
    Applied,
    /// Degenerate: skipped, or projected along the documented fallback direction.
    Degenerate,
    /// Nothing to do (all particles pinned with α = 0).
    Skipped,
}

/// One XPBD projection of `e`; no particle moves further than `max_step` (m; see
/// [`constraints::bounded_step`], `f32::INFINITY` for no bound).
#[inline(always)]
fn apply<A: ParticleAccess, const N: usize>(
    a: &mut A,
    idx: [usize; N],
    e: &Evaluated<f32, N>,
    lambda: &mut f32,
    alpha_tilde: f32,
    max_step: f32,
) -> bool {
    let w = idx.map(|i| a.w(i));
    let w_grad_sq = w
        .iter()
        .zip(&e.grad)
        .fold(0.0f32, |s, (w, g)| s + w * g.norm_squared());
    match constraints::xpbd_delta_lambda(e.c, *lambda, alpha_tilde, w_grad_sq) {
        Some(dl) => {
            // `w_max Σ wᵢ|∇ᵢC|² ≥ maxᵢ (wᵢ|∇ᵢC|)²`: the bound holds for every particle.
            let w_max = w.iter().fold(0.0f32, |m, &x| m.max(x));
            let dl = constraints::bounded_step(dl, w_max * w_grad_sq, max_step);
            *lambda += dl;
            for k in 0..N {
                a.add(idx[k], e.grad[k] * (w[k] * dl));
            }
            true
        }
        None => false,
    }
}

/// Edge `[a, b]` of rest length `d`. A zero-length edge (`|p0 − p1| < 1e-6 d`) is pushed
/// apart along its rest-pose direction.
#[inline(always)]
pub(crate) fn edge<A: ParticleAccess>(
    acc: &mut A,
    [a, b]: [u32; 2],
    d: f32,
    lambda: &mut f32,
    alpha_tilde: f32,
) -> Outcome {
    let (a, b) = (a as usize, b as usize);
    let delta = acc.x(a) - acc.x(b);
    let len = delta.norm();
    let (n, degenerate) = if len > 1e-6 * d {
        (delta * (1.0 / len), false)
    } else {
        ((acc.rest(a) - acc.rest(b)) * (1.0 / d), true)
    };
    let (wa, wb) = (acc.w(a), acc.w(b));
    let Some(dl) = constraints::xpbd_delta_lambda(len - d, *lambda, alpha_tilde, wa + wb) else {
        return Outcome::Skipped;
    };
    *lambda += dl;
    acc.add(a, n * (wa * dl));
    acc.add(b, n * (-wb * dl));
    if degenerate {
        Outcome::Degenerate
    } else {
        Outcome::Applied
    }
}

/// The four vertex–face constraints of one tetrahedron, one after another, in the
/// degeneracy-aware form [`constraints::vertex_face_bounded`] with
/// [`constraints::VERTEX_FACE_KAPPA`]; only the constraints `k` with `held[k]` (constraint `k`
/// holds vertex `tet[VERTEX_FACE_ORDER[k][1]]` above the face of the other three; all four
/// in an ordinary sweep), the others are left alone. A face collapsed to a point falls back
/// to holding `p1` at its rest value above `p0` along the face's rest normal (linear in
/// `p0`, `p1`; re-expands a collapsed tetrahedron). No projection moves a particle further
/// than [`constraints::vertex_face_step_bound`] of the tetrahedron's rest values (bounded
/// corrections: [`constraints::bounded_step`]).
#[inline(always)]
pub(crate) fn vertex_face_held<A: ParticleAccess>(
    acc: &mut A,
    tet: [u32; 4],
    rest_heights: &[f32; 4],
    lambdas: &mut [f32; 4],
    alpha_tilde: f32,
    held: [bool; 4],
) -> (u32, u32) {
    let (mut applied, mut degenerate) = (0, 0);
    let max_step = constraints::vertex_face_step_bound(rest_heights);
    for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
        if !held[k] {
            continue;
        }
        let idx = order.map(|o| tet[o] as usize);
        let p = idx.map(|i| acc.x(i));
        match constraints::vertex_face_bounded(
            &p[0],
            &p[1],
            &p[2],
            &p[3],
            rest_heights[k],
            constraints::VERTEX_FACE_KAPPA,
        ) {
            Some(e) => {
                if apply(acc, idx, &e, &mut lambdas[k], alpha_tilde, max_step) {
                    applied += 1;
                }
            }
            None => {
                degenerate += 1;
                let rest = idx.map(|i| acc.rest(i));
                let n = (rest[2] - rest[0]).cross(&(rest[3] - rest[0]));
                let n = n / n.norm().max(f32::MIN_POSITIVE);
                let e = Evaluated {
                    c: (p[1] - p[0]).dot(&n) - rest_heights[k],
                    grad: [-n, n, Vector3::zeros(), Vector3::zeros()],
                };
                apply(acc, idx, &e, &mut lambdas[k], alpha_tilde, max_step);
            }
        }
    }
    (applied, degenerate)
}

/// The signed volume constraint of one tetrahedron. A weak gradient
/// ([`volume_gradient_weak`]: the four points near a line or a point) takes the recovery
/// direction of [`constraints::volume_recovering`] from the rest positions; a rest shape with
/// no inverse, or vanishing directions, skip it.
#[inline(always)]
pub(crate) fn volume<A: ParticleAccess>(
    acc: &mut A,
    tet: [u32; 4],
    rest_volume: f32,
    lambda: &mut f32,
    alpha_tilde: f32,
) -> Outcome {
    let idx = tet.map(|i| i as usize);
    let p = idx.map(|i| acc.x(i));
    let mut e = constraints::volume(&p[0], &p[1], &p[2], &p[3], rest_volume);
    let q = e.grad.iter().fold(0.0f32, |s, g| s + g.norm_squared());
    let weak = volume_gradient_weak(q, rest_volume);
    if weak {
        let r = idx.map(|i| acc.rest(i));
        let dm = nalgebra::Matrix3::from_columns(&[r[1] - r[0], r[2] - r[0], r[3] - r[0]]);
        if let Some(dm_inv) = dm.try_inverse() {
            e = constraints::volume_recovering(&p, &dm_inv, rest_volume);
        }
    }
    if apply(acc, idx, &e, lambda, alpha_tilde, f32::INFINITY) {
        if weak {
            Outcome::Degenerate
        } else {
            Outcome::Applied
        }
    } else if idx.iter().any(|&i| acc.w(i) > 0.0) {
        Outcome::Degenerate
    } else {
        Outcome::Skipped
    }
}

/// Whether a volume constraint's gradient is weak enough for the recovery direction:
/// `q³ < VOLUME_GATE · V₀⁴`, `q = Σᵢ |∇ᵢC|²` (m⁴), `V₀` the rest volume (m³), evaluated as
/// `(q/|V₀|)³ < VOLUME_GATE · |V₀|` (terms of the order of the tetrahedron's size cubed: no
/// underflow on small bodies). The SIMD kernel hands a chunk with such a lane to [`volume`].
#[inline(always)]
pub(crate) fn volume_gradient_weak(q: f32, rest_volume: f32) -> bool {
    let v = rest_volume.abs();
    let r = q / v;
    r * r * r < constraints::VOLUME_GATE as f32 * v
}

/// Constraint `k`'s entry of a run's held masks (`1.0` held, `0.0` left alone; an empty
/// slice holds every constraint), as [`vertex_face_held`] takes it.
#[inline(always)]
pub(crate) fn held_mask(held: &[[f32; 4]], k: usize) -> [bool; 4] {
    held.get(k).map_or([true; 4], |h| h.map(|x| x > 0.0))
}
