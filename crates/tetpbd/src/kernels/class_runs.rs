//! Runs of one colour class through the kernels, and the choice of instruction set.
//!
//! The SIMD kernels are written once over a lane type ([`crate::kernels::lane_types::Lane`]). On a CPU with
//! AVX2 and FMA, the runs are also compiled with those features enabled (`#[target_feature]`)
//! and chosen at run time (`is_x86_feature_detected!`): VEX-encoded three-operand
//! instructions drop most of the register copies SSE2's two-operand forms need, and pairs of
//! chunks run on one 256-bit register ([`crate::kernels::lane_types::Y8`]) instead of two 128-bit halves
//! ([`crate::kernels::lane_types::X2`], the SSE2 build). Rust never contracts `a * b + c` into a fused
//! multiply–add on its own, and both pair types do the same IEEE operations on every lane in
//! the same order, so both builds give bit-identical results: which one runs changes the
//! speed only, never the trajectory (and the serial and parallel sweeps, on any number of
//! threads, stay bit-identical).

use wide::f32x4;

use crate::kernels::count::{Kernel, ProjectionCount};
#[cfg(target_arch = "x86_64")]
use crate::kernels::lane_types::Y8;
use crate::kernels::lane_types::{Lane, X2};
use crate::kernels::lanes;
use crate::kernels::scalar::{self, ParticleAccess};

/// Projects a run of constraints of one colour class: when the class is independent and the
/// kernel is SIMD, in pairs of chunks of [`lanes::LANES`] ([`X2`]), then one chunk of four,
/// on the run's items with their indices checked once ([`lanes::Bounded`]); the rest one by
/// one. A pair gives the bits of its two chunks one after the other, so the results do not
/// depend on where a run starts (serial class or parallel part).
macro_rules! run_class {
    ($pair:ty, $kernel:expr, $independent:expr, $acc:expr, $items:expr,
     $lanes:ident($($arg:expr),*), |$a:ident, $k:ident| $scalar:expr) => {{
        let mut count = ProjectionCount::default();
        let mut start = 0;
        let (acc, items) = ($acc, $items);
        let len = items.len();
        if $kernel == Kernel::Simd && $independent && len >= lanes::LANES {
            let mut bounded = lanes::Bounded::new(acc, items);
            while start + 2 * lanes::LANES <= len {
                count += lanes::$lanes::<$pair, _>(&mut bounded, start, $($arg),*);
                start += 2 * lanes::LANES;
            }
            if start + lanes::LANES <= len {
                count += lanes::$lanes::<f32x4, _>(&mut bounded, start, $($arg),*);
                start += lanes::LANES;
            }
        }
        let $a = acc;
        for $k in start..len {
            count += $scalar;
        }
        count
    }};
}

/// Edges `edges[i]` with their rest lengths and multipliers, all of one colour class.
#[inline(always)]
fn edge_run_base<P: Lane, A: ParticleAccess>(
    acc: &mut A,
    edges: &[[u32; 2]],
    rest: &[f32],
    lambdas: &mut [f32],
    alpha_tilde: f32,
    kernel: Kernel,
    independent: bool,
) -> ProjectionCount {
    run_class!(
        P,
        kernel,
        independent,
        acc,
        edges,
        edges(rest, lambdas, alpha_tilde),
        |a, k| one(scalar::edge(
            a,
            edges[k],
            rest[k],
            &mut lambdas[k],
            alpha_tilde
        ))
    )
}

/// Volume constraints of a run of tetrahedra of one colour class.
#[inline(always)]
fn volume_run_base<P: Lane, A: ParticleAccess>(
    acc: &mut A,
    tets: &[[u32; 4]],
    rest: &[f32],
    lambdas: &mut [f32],
    alpha_tilde: f32,
    kernel: Kernel,
    independent: bool,
) -> ProjectionCount {
    run_class!(
        P,
        kernel,
        independent,
        acc,
        tets,
        volumes(rest, lambdas, alpha_tilde),
        |a, k| one(scalar::volume(
            a,
            tets[k],
            rest[k],
            &mut lambdas[k],
            alpha_tilde
        ))
    )
}

/// Vertex–face constraints of a run of tetrahedra of one colour class.
#[inline(always)]
// The run's slices (items, rest values, held masks, multipliers) and the kernel choice are
// what every family's run takes; bundling them would hide which slice is which.
#[allow(clippy::too_many_arguments)]
fn vertex_face_run_base<P: Lane, A: ParticleAccess>(
    acc: &mut A,
    tets: &[[u32; 4]],
    heights: &[[f32; 4]],
    held: &[[f32; 4]],
    lambdas: &mut [[f32; 4]],
    alpha_tilde: f32,
    kernel: Kernel,
    independent: bool,
) -> ProjectionCount {
    run_class!(
        P,
        kernel,
        independent,
        acc,
        tets,
        vertex_faces(heights, held, lambdas, alpha_tilde),
        |a, k| {
            let (ap, d) = scalar::vertex_face_held(
                a,
                tets[k],
                &heights[k],
                &mut lambdas[k],
                alpha_tilde,
                scalar::held_mask(held, k),
            );
            ProjectionCount {
                applied: u64::from(ap),
                degenerate: u64::from(d),
            }
        }
    )
}

fn one(o: scalar::Outcome) -> ProjectionCount {
    let mut c = ProjectionCount::default();
    c.add(o);
    c
}

/// `true` when the AVX2 + FMA build of the kernels can run on this CPU.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn avx2() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// Defines `$name` (dispatching) over `$base`, with an AVX2 + FMA build `$fast` of it.
macro_rules! dispatched {
    ($(#[$doc:meta])* $name:ident, $fast:ident, $base:ident, ($($arg:ident: $ty:ty),*)) => {
        $(#[$doc])*
        #[allow(clippy::too_many_arguments)] // as for `vertex_face_run_base`
        pub(crate) fn $name<A: ParticleAccess>(
            acc: &mut A,
            $($arg: $ty,)*
            alpha_tilde: f32,
            kernel: Kernel,
            independent: bool,
        ) -> ProjectionCount {
            #[cfg(target_arch = "x86_64")]
            if kernel == Kernel::Simd && independent && avx2() {
                // SAFETY: the CPU has AVX2 and FMA (checked just above).
                return unsafe { $fast(acc, $($arg,)* alpha_tilde) };
            }
            $base::<X2, A>(acc, $($arg,)* alpha_tilde, kernel, independent)
        }

        /// The same, compiled for AVX2 + FMA.
        ///
        /// # Safety
        /// The CPU must support AVX2 and FMA.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2,fma")]
        unsafe fn $fast<A: ParticleAccess>(
            acc: &mut A,
            $($arg: $ty,)*
            alpha_tilde: f32,
        ) -> ProjectionCount {
            $base::<Y8, A>(acc, $($arg,)* alpha_tilde, Kernel::Simd, true)
        }
    };
}

dispatched!(
    /// Edges `edges[i]` with their rest lengths and multipliers, all of one colour class.
    edge_run, edge_run_avx2, edge_run_base,
    (edges: &[[u32; 2]], rest: &[f32], lambdas: &mut [f32])
);
dispatched!(
    /// Volume constraints of a run of tetrahedra of one colour class.
    volume_run, volume_run_avx2, volume_run_base,
    (tets: &[[u32; 4]], rest: &[f32], lambdas: &mut [f32])
);
dispatched!(
    /// Vertex–face constraints of a run of tetrahedra of one colour class; `held` as
    /// [`lanes::vertex_faces`] takes it (empty: every constraint).
    vertex_face_run, vertex_face_run_avx2, vertex_face_run_base,
    (tets: &[[u32; 4]], heights: &[[f32; 4]], held: &[[f32; 4]], lambdas: &mut [[f32; 4]])
);

#[cfg(test)]
mod tests {
    use std::ops::Range;

    use nalgebra::Vector3;

    use super::*;
    use crate::body::generators::{box_grid, CellSplit};
    use crate::kernels::slots::{Slot, WorkAccess};
    use crate::kernels::working_copy;
    use crate::{SoftBody, SoftBodyBuilder};

    /// A 1 m cube of `cells³` cells with all three families (edges 1e-6, volume 1e-9,
    /// vertex–face 1e-6), each particle moved from `x` to `f(i, x)`, loaded into its work
    /// slots.
    fn deformed(cells: u32, f: impl Fn(usize, Vector3<f32>) -> Vector3<f32>) -> SoftBody {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Six).unwrap();
        let mut body = SoftBodyBuilder::new(mesh)
            .edges(1e-6)
            .volume(1e-9)
            .vertex_face(1e-6)
            .build()
            .unwrap();
        for (i, x) in body.particles.positions.iter_mut().enumerate() {
            *x = f(i, *x);
        }
        working_copy::load(&mut body.particles);
        body
    }

    /// Every slot's position, inverse mass and rounding residual, as bits.
    fn bits(slots: &[Slot]) -> Vec<[u32; 8]> {
        slots
            .iter()
            .map(|s| {
                let [a, b, c, d] = s.xw.to_array();
                let [e, f, g, h] = s.r.to_array();
                [a, b, c, d, e, f, g, h].map(f32::to_bits)
            })
            .collect()
    }

    /// How [`sweep`] runs the colour classes (all with the SIMD kernel).
    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Runs {
        /// Each class as one run of the SSE2 build.
        #[cfg(target_arch = "x86_64")]
        Sse2,
        /// Each independent class as one run of the AVX2 + FMA build, the others as `Sse2`.
        #[cfg(target_arch = "x86_64")]
        Avx2,
        /// Each class as one run through the dispatching `*_run`.
        Dispatched,
        /// Each class as runs of [`lanes::LANES`] items from its start (one chunk each),
        /// through the dispatching `*_run`.
        ChunksOfFour,
    }

    /// One run of the `edge`, `volume` or `vertex_face` family as `runs` says, on `$arg`s,
    /// α̃ = 1e-3, the SIMD kernel.
    macro_rules! run {
        (edge, $($t:tt)*) => { run!(@ edge_run, edge_run_avx2, edge_run_base, $($t)*) };
        (volume, $($t:tt)*) => { run!(@ volume_run, volume_run_avx2, volume_run_base, $($t)*) };
        (vertex_face, $($t:tt)*) => {
            run!(@ vertex_face_run, vertex_face_run_avx2, vertex_face_run_base, $($t)*)
        };
        (@ $name:ident, $fast:ident, $base:ident, $runs:expr, $ind:expr, $($arg:expr),*) => {
            match $runs {
                // SAFETY: `sweep` checked `avx2()`.
                #[cfg(target_arch = "x86_64")]
                Runs::Avx2 if $ind => unsafe { $fast($($arg,)* 1e-3) },
                Runs::Dispatched | Runs::ChunksOfFour => $name($($arg,)* 1e-3, Kernel::Simd, $ind),
                #[cfg(target_arch = "x86_64")]
                Runs::Sse2 | Runs::Avx2 => $base::<X2, _>($($arg,)* 1e-3, Kernel::Simd, $ind),
            }
        };
    }

    /// One sweep of each family of `body` (edges, then each tetrahedron class's volume and
    /// vertex–face constraints) from its work slots and zero multipliers, α̃ = 1e-3: the
    /// slots and the multipliers after it as bits, and what it counted.
    fn sweep(body: &SoftBody, runs: Runs) -> (Vec<[u32; 8]>, Vec<u32>, ProjectionCount) {
        #[cfg(target_arch = "x86_64")]
        assert!(runs != Runs::Avx2 || avx2(), "no AVX2 + FMA on this CPU");
        let (tets, p) = (&body.tetrahedra, &body.particles);
        let (e, vf) = (
            body.edges.as_ref().unwrap(),
            body.vertex_face.as_ref().unwrap(),
        );
        let mut slots = p.work.0.clone();
        let mut acc = WorkAccess {
            slots: &mut slots,
            rest: &p.rest_positions,
        };
        let mut lam_e = vec![0.0; e.edges.len()];
        let mut lam_v = vec![0.0; tets.len()];
        let mut lam_f = vec![[0.0; 4]; tets.len()];
        let mut count = ProjectionCount::default();
        let parts = |r: Range<usize>| {
            let step = if runs == Runs::ChunksOfFour {
                lanes::LANES
            } else {
                r.len().max(1)
            };
            (r.start..r.end)
                .step_by(step)
                .map(move |s| s..(s + step).min(r.end))
        };
        for (r, ind) in e.classes.ranges() {
            for q in parts(r) {
                let (x, d, l) = (
                    &e.edges[q.clone()],
                    &e.rest_lengths[q.clone()],
                    &mut lam_e[q],
                );
                count += run!(edge, runs, ind, &mut acc, x, d, l);
            }
        }
        for (r, ind) in tets.classes.ranges() {
            let t = |q: &Range<usize>| &tets.indices[q.clone()];
            for q in parts(r.clone()) {
                let (v, l) = (&tets.rest_volumes[q.clone()], &mut lam_v[q.clone()]);
                count += run!(volume, runs, ind, &mut acc, t(&q), v, l);
            }
            for q in parts(r) {
                let (h, l) = (&vf.rest_heights[q.clone()], &mut lam_f[q.clone()]);
                count += run!(vertex_face, runs, ind, &mut acc, t(&q), h, &[], l);
            }
        }
        let lam: Vec<u32> = lam_e
            .iter()
            .chain(&lam_v)
            .chain(lam_f.iter().flatten())
            .map(|x| x.to_bits())
            .collect();
        (bits(&slots), lam, count)
    }

    /// The AVX2 + FMA build of the kernels moves every particle and multiplier exactly as
    /// the SSE2 build does (one sweep of each family on a deformed body).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_build_is_bit_identical_to_sse2() {
        if !avx2() {
            eprintln!("no AVX2 + FMA on this CPU: only the SSE2 build runs here");
            return;
        }
        let body = deformed(4, |_, x| {
            Vector3::new(
                x.x + 0.1 * x.y,
                0.7 * x.y + 0.02 * x.z * x.x,
                x.z - 0.05 * x.x,
            )
        });
        let (sse2, avx2) = (sweep(&body, Runs::Sse2), sweep(&body, Runs::Avx2));
        assert!(
            sse2.0 != bits(&body.particles.work.0),
            "the sweep moves particles"
        );
        assert!(
            (&sse2.0, &sse2.1) == (&avx2.0, &avx2.1),
            "the AVX2 build differs from the SSE2 build"
        );
    }

    /// Pairs of chunks move every particle and multiplier exactly as chunks of four alone
    /// do: each colour class swept as one run (pairs of chunks, then a chunk, then the scalar
    /// tail) and as runs of four items from the class start (one chunk each), on a sheared
    /// body and on one squashed to 0.2 % of its height (faces across the squashed axis have
    /// `|b × c| / Q` about 0.002, below κ: the pair and chunk fallbacks to the scalar kernel
    /// run).
    #[test]
    fn pairs_are_bit_identical_to_chunks_of_four() {
        for squash in [0.7, 0.002] {
            let body = deformed(5, |i, x| {
                let jitter = ((i * 7919) % 13) as f32 * 3e-5;
                Vector3::new(x.x + 0.1 * x.y, squash * x.y + jitter, x.z - 0.05 * x.x)
            });
            let (pairs, chunks) = (
                sweep(&body, Runs::Dispatched),
                sweep(&body, Runs::ChunksOfFour),
            );
            assert!(
                pairs == chunks,
                "pairs differ from chunks (squash {squash})"
            );
        }
    }

    /// One sweep of the vertex–face family with a held mask per constraint, on `kernel`:
    /// the slots and multipliers after it.
    fn masked_sweep(
        body: &SoftBody,
        kernel: Kernel,
        held: &[[f32; 4]],
    ) -> (Vec<Slot>, Vec<[f32; 4]>) {
        let (tets, p) = (&body.tetrahedra, &body.particles);
        let vf = body.vertex_face.as_ref().unwrap();
        let mut slots = p.work.0.clone();
        let mut acc = WorkAccess {
            slots: &mut slots,
            rest: &p.rest_positions,
        };
        let mut lam = vec![[0.0; 4]; tets.len()];
        for (r, ind) in tets.classes.ranges() {
            let (t, h, m) = (
                &tets.indices[r.clone()],
                &vf.rest_heights[r.clone()],
                &held[r.clone()],
            );
            vertex_face_run(&mut acc, t, h, m, &mut lam[r], 1e-3, kernel, ind);
        }
        (slots, lam)
    }

    /// A held mask leaves the masked constraints alone on either kernel (their multipliers
    /// stay 0; an all-zero mask moves nothing), and the SIMD kernel agrees with the scalar
    /// one to rounding on the constraints it projects.
    #[test]
    fn masked_vertex_faces_agree_with_the_scalar_kernel() {
        let body = deformed(4, |_, x| {
            Vector3::new(x.x + 0.1 * x.y, 0.8 * x.y, x.z - 0.05 * x.x)
        });
        let n = body.tetrahedra.len();
        let held: Vec<[f32; 4]> = (0..n)
            .map(|t| [0, 1, 2, 3].map(|k| f32::from(u8::from((t + k) % 3 != 0))))
            .collect();
        let (scalar, lam_s) = masked_sweep(&body, Kernel::Scalar, &held);
        let (simd, lam_v) = masked_sweep(&body, Kernel::Simd, &held);
        for (t, h) in held.iter().enumerate() {
            for k in 0..4 {
                if h[k] == 0.0 {
                    assert_eq!(
                        (lam_s[t][k], lam_v[t][k]),
                        (0.0, 0.0),
                        "tet {t} constraint {k}"
                    );
                }
            }
        }
        let worst = scalar
            .iter()
            .zip(&simd)
            .map(|(a, b)| {
                (a.xw - b.xw)
                    .to_array()
                    .iter()
                    .fold(0.0f32, |m, d| m.max(d.abs()))
            })
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-5, "SIMD and scalar differ by {worst} m");
        assert!(
            bits(&scalar) != bits(&body.particles.work.0),
            "the sweep moves particles"
        );
        let none = vec![[0.0; 4]; n];
        let (still, _) = masked_sweep(&body, Kernel::Simd, &none);
        assert!(
            bits(&still) == bits(&body.particles.work.0),
            "an all-zero mask moved particles"
        );
    }
}
