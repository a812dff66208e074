//! The scalar kernel of the Neo-Hookean material (the reference): one coupled projection of a
//! tetrahedron's two constraints on the working copy; the runs of one colour class through it
//! or the SIMD kernel ([`crate::kernels::neo_hookean_lanes`]); and the serial sweep of one
//! body in colour-class order.
//!
//! Per tetrahedron (theory in `constraints/neo_hookean.rs`): `F = Ds Dm⁻¹`, the two
//! constraints and their gradients, the 2×2 coupled XPBD update with damping
//! ([`constraints::neo_hookean_update`]), the move bounded to `√3/‖Dm⁻¹‖_F` (about one
//! rest edge) so that a tetrahedron far from rest (inverted, crushed) recovers over a few
//! projections instead of overshooting, and the elastic energy released since the substep
//! start, for the energy limit. A tetrahedron crushed towards a point or a line is projected
//! along the hydrostatic constraint's recovery direction
//! ([`constraints::neo_hookean_hydrostatic_recovering`]) and counted as degenerate.

use nalgebra::{Matrix3, Vector3};
use wide::f32x4;

use crate::constraints::{self, Evaluated};
#[cfg(target_arch = "x86_64")]
use crate::kernels::class_runs::avx2;
use crate::kernels::count::{Kernel, ProjectionCount};
#[cfg(target_arch = "x86_64")]
use crate::kernels::lane_types::Y8;
use crate::kernels::lane_types::{Lane, X2};
use crate::kernels::lanes::{Bounded, LANES};
use crate::kernels::neo_hookean_lanes::{one, tets};
use crate::kernels::scalar::ParticleAccess;
use crate::ordering::ColourClasses;

/// The per-body constants of a sweep.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MaterialStep {
    /// `[1/(μ h²), 1/(λ' h²)]`, m³/(J·s²): `α̃ V₀` (divide by a tetrahedron's rest volume).
    pub alpha_tilde_volume: [f32; 2],
    /// `γ = 1 + μ/λ'`.
    pub rest_offset: f32,
    /// The collapse threshold `τ` ([`constraints::neo_hookean_collapse_threshold`]).
    pub collapse: f32,
    /// `β/h`, the XPBD damping factor.
    pub damping: f32,
    /// `h²`, s².
    pub h2: f32,
}

impl MaterialStep {
    /// The constants for `material` in a substep of length `h` (s).
    pub fn new(material: &crate::Material, h: f32) -> Self {
        let (mu, lambda) = material.lame();
        let lp = lambda + mu;
        let h2 = h * h;
        MaterialStep {
            alpha_tilde_volume: [1.0 / (mu * h2), 1.0 / (lp * h2)],
            rest_offset: constraints::neo_hookean_rest_offset(mu, lp),
            collapse: constraints::neo_hookean_collapse_threshold(mu, lp),
            damping: material.damping() / h,
            h2,
        }
    }
}

/// What one projection did: applied (with the energy it released, J), applied along the
/// recovery direction of a collapsed tetrahedron (likewise; counted as degenerate), or
/// degenerate (nothing done).
pub(crate) enum TetOutcome {
    Applied(f32),
    Recovered(f32),
    Degenerate,
    Skipped,
}

/// One coupled projection of the material of tetrahedron `tet`.
#[inline]
pub(crate) fn project_tet<A: ParticleAccess>(
    acc: &mut A,
    prev: &[Vector3<f32>],
    tet: [u32; 4],
    dm_inv: &Matrix3<f32>,
    rest_volume: f32,
    lambdas: &mut [f32; 2],
    k: &MaterialStep,
) -> TetOutcome {
    let idx = tet.map(|i| i as usize);
    let xw = idx.map(|i| {
        let [x, y, z, w] = acc.row(i).to_array();
        (Vector3::new(x, y, z), w)
    });
    let w = xw.map(|(_, w)| w);
    if w.iter().all(|&w| w == 0.0) {
        return TetOutcome::Skipped;
    }
    let p = xw.map(|(x, _)| x);
    // All four points at one place: `C_D = 0` with no direction, and no force either
    // (`C_D ∇C_D = F Dm⁻ᵀ` vanishes); the hydrostatic constraint's recovery direction
    // moves the points apart.
    let d = constraints::neo_hookean_deviatoric(&p, dm_inv).unwrap_or(Evaluated {
        c: 0.0,
        grad: [Vector3::zeros(); 4],
    });
    let y = constraints::neo_hookean_hydrostatic_recovering(&p, dm_inv, k.rest_offset, k.collapse);
    let v0 = rest_volume.abs();
    let at = k.alpha_tilde_volume.map(|a| a / v0);
    let rate = if k.damping > 0.0 {
        let moved: [Vector3<f32>; 4] = std::array::from_fn(|i| p[i] - prev[idx[i]]);
        let r = |e: &Evaluated<f32, 4>| (0..4).fold(0.0f32, |s, i| s + e.grad[i].dot(&moved[i]));
        [r(&d), r(&y)]
    } else {
        [0.0; 2]
    };
    let Some(up) = constraints::neo_hookean_update(&d, &y, w, *lambdas, at, k.damping, rate) else {
        return TetOutcome::Degenerate;
    };
    let (mut dl, mut dx) = (up.delta_lambda, up.moves);
    let longest = dx.iter().fold(0.0f32, |m, v| m.max(v.norm_squared()));
    // The bound: about one rest edge (√3/‖Dm⁻¹‖_F is the edge of a right-angled corner).
    let bound = 3.0 / dm_inv.norm_squared();
    if longest > bound {
        let s = (bound / longest).sqrt();
        dl = dl.map(|x| x * s);
        dx = dx.map(|v| v * s);
    }
    for i in 0..4 {
        acc.add_row(idx[i], f32x4::new([dx[i].x, dx[i].y, dx[i].z, 0.0]));
    }
    lambdas[0] += dl[0];
    lambdas[1] += dl[1];
    // The elastic energy released since the substep start x̄: U(x̄) − U(x + Δx), exactly,
    // as the change from x̄ to x (the prediction and earlier projections) plus the change of
    // this projection (`energy_change`).
    let f = constraints::deformation_gradient(&p, dm_inv);
    let ds =
        |v: &[Vector3<f32>; 4]| Matrix3::from_columns(&[v[1] - v[0], v[2] - v[0], v[3] - v[0]]);
    let back: [Vector3<f32>; 4] = std::array::from_fn(|i| prev[idx[i]] - p[i]);
    let df_back = ds(&back) * dm_inv;
    let to_start = energy_change(&f, &df_back, y.c, at, k.h2);
    let projected = energy_change(&f, &(ds(&dx) * dm_inv), y.c, at, k.h2);
    let released = to_start - projected;
    if constraints::recovery_weight(&constraints::cofactor(&f), k.collapse) > 0.0 {
        TetOutcome::Recovered(released)
    } else {
        TetOutcome::Applied(released)
    }
}

/// `U(F + dF) − U(F)` (J) of one tetrahedron's constraints, `U = C_D²/(2α_D) + C_H²/(2α_H)`,
/// `c_h = C_H(F)`, `at = α̃` and `h2 = h²` (`α = α̃ h²`). Without a difference of large numbers:
/// `‖F + dF‖² − ‖F‖² = (2F + dF) : dF` and `det(F + dF) − det F = cof F : dF + F : cof dF +
/// det dF`.
#[inline(always)]
fn energy_change(f: &Matrix3<f32>, df: &Matrix3<f32>, c_h: f32, at: [f32; 2], h2: f32) -> f32 {
    let d_norm = (f * 2.0 + df).dot(df);
    let d_det =
        constraints::cofactor(f).dot(df) + f.dot(&constraints::cofactor(df)) + df.determinant();
    d_norm / (2.0 * at[0] * h2) + d_det * (2.0 * c_h + d_det) / (2.0 * at[1] * h2)
}

/// The slices of a run of tetrahedra of one colour class (indexed alike): rest shapes,
/// rest volumes (m³), multipliers, and the energy each projection released (J; written by
/// every projection, 0 where it did nothing).
pub(crate) struct TetRun<'a> {
    pub rest_inverse: &'a [Matrix3<f32>],
    pub rest_volumes: &'a [f32],
    pub lambdas: &'a mut [[f32; 2]],
    pub released: &'a mut [f32],
}

/// A run of tetrahedra `tets` of one colour class: with the SIMD kernel and an independent
/// class, in pairs of chunks of [`LANES`] (lane type `P`), then one chunk of four, on the
/// run's items with their indices checked once; the rest one by one on the scalar kernel.
#[inline(always)]
pub(crate) fn run_base<P: Lane, A: ParticleAccess>(
    acc: &mut A,
    prev: &[Vector3<f32>],
    tets_: &[[u32; 4]],
    run: &mut TetRun<'_>,
    k: &MaterialStep,
    kernel: Kernel,
    independent: bool,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    let mut start = 0;
    let len = tets_.len();
    if kernel == Kernel::Simd && independent && len >= LANES {
        assert!(
            prev.len() >= acc.len(),
            "{} start positions for {} particles",
            prev.len(),
            acc.len()
        );
        let mut bounded = Bounded::new(acc, tets_);
        while start + 2 * LANES <= len {
            count += tets::<P, A>(&mut bounded, start, prev, run, k);
            start += 2 * LANES;
        }
        if start + LANES <= len {
            count += tets::<f32x4, A>(&mut bounded, start, prev, run, k);
            start += LANES;
        }
    }
    // Indexing several slices alike: a range reads plainer than a zip of five.
    #[allow(clippy::needless_range_loop)]
    for t in start..len {
        let o = project_tet(
            acc,
            prev,
            tets_[t],
            &run.rest_inverse[t],
            run.rest_volumes[t],
            &mut run.lambdas[t],
            k,
        );
        count += one(&mut run.released[t], o);
    }
    count
}

/// [`run_base`] on the widest build this CPU runs (AVX2 + FMA when it has them, SSE2
/// otherwise; the two give the same bits).
pub(crate) fn run<A: ParticleAccess>(
    acc: &mut A,
    prev: &[Vector3<f32>],
    tets_: &[[u32; 4]],
    run: &mut TetRun<'_>,
    k: &MaterialStep,
    kernel: Kernel,
    independent: bool,
) -> ProjectionCount {
    #[cfg(target_arch = "x86_64")]
    if kernel == Kernel::Simd && independent && avx2() {
        // SAFETY: the CPU has AVX2 and FMA (checked just above).
        return unsafe { run_avx2(acc, prev, tets_, run, k) };
    }
    run_base::<X2, A>(acc, prev, tets_, run, k, kernel, independent)
}

/// [`run_base`] compiled for AVX2 + FMA, on [`Y8`] pairs.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn run_avx2<A: ParticleAccess>(
    acc: &mut A,
    prev: &[Vector3<f32>],
    tets_: &[[u32; 4]],
    run: &mut TetRun<'_>,
    k: &MaterialStep,
) -> ProjectionCount {
    run_base::<Y8, A>(acc, prev, tets_, run, k, Kernel::Simd, true)
}

/// One Gauss–Seidel sweep of a body's material on its working copy (`acc`), colour class by
/// colour class on `kernel`; `prev` are the substep's start positions (for the damping and
/// the energy). Each projection's released energy (J) goes to `run.released`.
pub(crate) fn sweep<A: ParticleAccess>(
    acc: &mut A,
    prev: &[Vector3<f32>],
    tets_: &[[u32; 4]],
    classes: &ColourClasses,
    run: &mut TetRun<'_>,
    k: &MaterialStep,
    kernel: Kernel,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    for (r, independent) in classes.ranges() {
        let mut part = TetRun {
            rest_inverse: &run.rest_inverse[r.clone()],
            rest_volumes: &run.rest_volumes[r.clone()],
            lambdas: &mut run.lambdas[r.clone()],
            released: &mut run.released[r.clone()],
        };
        count += self::run(acc, prev, &tets_[r], &mut part, k, kernel, independent);
    }
    count
}
