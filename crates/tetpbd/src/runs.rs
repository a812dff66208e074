//! Runs of one colour class through the kernels, and the choice of instruction set.
//!
//! The SIMD kernels are written once over a lane type ([`crate::simd::Lane`]). On a CPU with
//! AVX2 and FMA, the runs are also compiled with those features enabled (`#[target_feature]`)
//! and chosen at run time (`is_x86_feature_detected!`): VEX-encoded three-operand
//! instructions drop most of the register copies SSE2's two-operand forms need, and pairs of
//! chunks run on one 256-bit register ([`crate::simd::Y8`]) instead of two 128-bit halves
//! ([`crate::simd::X2`], the SSE2 build). Rust never contracts `a * b + c` into a fused
//! multiply–add on its own, and both pair types do the same IEEE operations on every lane in
//! the same order, so both builds give bit-identical results: which one runs changes the
//! speed only, never the trajectory (and the serial and parallel sweeps, on any number of
//! threads, stay bit-identical).

use wide::f32x4;

use crate::lanes;
use crate::projection::{self, ParticleAccess};
#[cfg(target_arch = "x86_64")]
use crate::simd::Y8;
use crate::simd::{Lane, X2};
use crate::systems::{Kernel, ProjectionCount};

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
        |a, k| one(projection::edge(
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
        |a, k| one(projection::volume(
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
fn vertex_face_run_base<P: Lane, A: ParticleAccess>(
    acc: &mut A,
    tets: &[[u32; 4]],
    heights: &[[f32; 4]],
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
        vertex_faces(heights, lambdas, alpha_tilde),
        |a, k| {
            let (ap, d) =
                projection::vertex_face(a, tets[k], &heights[k], &mut lambdas[k], alpha_tilde);
            ProjectionCount {
                applied: u64::from(ap),
                degenerate: u64::from(d),
            }
        }
    )
}

fn one(o: projection::Outcome) -> ProjectionCount {
    let mut c = ProjectionCount::default();
    c.add(o);
    c
}

/// `true` when the AVX2 + FMA build of the kernels can run on this CPU.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// Defines `$name` (dispatching) over `$base`, with an AVX2 + FMA build `$fast` of it.
macro_rules! dispatched {
    ($(#[$doc:meta])* $name:ident, $fast:ident, $base:ident, ($($arg:ident: $ty:ty),*)) => {
        $(#[$doc])*
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
    /// Vertex–face constraints of a run of tetrahedra of one colour class.
    vertex_face_run, vertex_face_run_avx2, vertex_face_run_base,
    (tets: &[[u32; 4]], heights: &[[f32; 4]], lambdas: &mut [[f32; 4]])
);

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::generators::{box_grid, CellSplit};
    use crate::work::{self, Slot, WorkAccess};
    use crate::SoftBodyBuilder;

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

    /// The AVX2 + FMA build of the kernels moves every particle and multiplier exactly as
    /// the SSE2 build does (one sweep of each family on a deformed body).
    #[test]
    fn avx2_build_is_bit_identical_to_sse2() {
        if !avx2() {
            eprintln!("no AVX2 + FMA on this CPU: only the SSE2 build runs here");
            return;
        }
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [4; 3], CellSplit::Six).unwrap();
        let mut body = SoftBodyBuilder::new(mesh)
            .edges(1e-6)
            .volume(1e-9)
            .vertex_face(1e-6)
            .build()
            .unwrap();
        for x in &mut body.particles.positions {
            *x = Vector3::new(
                x.x + 0.1 * x.y,
                0.7 * x.y + 0.02 * x.z * x.x,
                x.z - 0.05 * x.x,
            );
        }
        work::load(&mut body.particles);
        let (tets, p) = (&body.tetrahedra, &body.particles);
        let (e, vf) = (
            body.edges.as_ref().unwrap(),
            body.vertex_face.as_ref().unwrap(),
        );
        let sweep = |fast: bool| {
            let mut slots = p.work.0.clone();
            let mut acc = WorkAccess {
                slots: &mut slots,
                rest: &p.rest_positions,
            };
            let mut lam_e = vec![0.0; e.edges.len()];
            let mut lam_v = vec![0.0; tets.len()];
            let mut lam_f = vec![[0.0; 4]; tets.len()];
            let at = 1e-3;
            for (r, ind) in e.classes.ranges() {
                let (x, d, l) = (
                    &e.edges[r.clone()],
                    &e.rest_lengths[r.clone()],
                    &mut lam_e[r],
                );
                if fast && ind {
                    // SAFETY: `avx2()` checked above.
                    unsafe { edge_run_avx2(&mut acc, x, d, l, at) };
                } else {
                    edge_run_base::<X2, _>(&mut acc, x, d, l, at, Kernel::Simd, ind);
                }
            }
            for (r, ind) in tets.classes.ranges() {
                let (t, v, l) = (
                    &tets.indices[r.clone()],
                    &tets.rest_volumes[r.clone()],
                    &mut lam_v[r.clone()],
                );
                if fast && ind {
                    // SAFETY: `avx2()` checked above.
                    unsafe { volume_run_avx2(&mut acc, t, v, l, at) };
                } else {
                    volume_run_base::<X2, _>(&mut acc, t, v, l, at, Kernel::Simd, ind);
                }
                let (h, l) = (&vf.rest_heights[r.clone()], &mut lam_f[r]);
                if fast && ind {
                    // SAFETY: `avx2()` checked above.
                    unsafe { vertex_face_run_avx2(&mut acc, t, h, l, at) };
                } else {
                    vertex_face_run_base::<X2, _>(&mut acc, t, h, l, at, Kernel::Simd, ind);
                }
            }
            let lam: Vec<u32> = lam_e
                .iter()
                .chain(&lam_v)
                .chain(lam_f.iter().flatten())
                .map(|x| x.to_bits())
                .collect();
            (bits(&slots), lam)
        };
        let (sse2, avx2) = (sweep(false), sweep(true));
        assert!(sse2.0 != bits(&p.work.0), "the sweep moves particles");
        assert!(sse2 == avx2, "the AVX2 build differs from the SSE2 build");
    }
}

#[cfg(test)]
mod pair_tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::generators::{box_grid, CellSplit};
    use crate::work::{self, WorkAccess};
    use crate::SoftBodyBuilder;

    /// Pairs of chunks move every particle and multiplier exactly as chunks of four alone
    /// do: each colour class swept as one run (pairs of chunks, then a chunk, then the scalar
    /// tail) and as runs of four items from the class start (one chunk each), on a sheared
    /// body and on one squashed to 0.2 % of its height (faces across the squashed axis have
    /// `|b × c| / Q` about 0.002, below κ: the pair and chunk fallbacks to the scalar kernel
    /// run).
    #[test]
    fn pairs_are_bit_identical_to_chunks_of_four() {
        for squash in [0.7, 0.002] {
            let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [5; 3], CellSplit::Six).unwrap();
            let mut body = SoftBodyBuilder::new(mesh)
                .edges(1e-6)
                .volume(1e-9)
                .vertex_face(1e-6)
                .build()
                .unwrap();
            for (i, x) in body.particles.positions.iter_mut().enumerate() {
                let jitter = ((i * 7919) % 13) as f32 * 3e-5;
                *x = Vector3::new(x.x + 0.1 * x.y, squash * x.y + jitter, x.z - 0.05 * x.x);
            }
            work::load(&mut body.particles);
            let (tets, p) = (&body.tetrahedra, &body.particles);
            let (e, vf) = (
                body.edges.as_ref().unwrap(),
                body.vertex_face.as_ref().unwrap(),
            );
            let sweep = |split: bool| {
                let mut slots = p.work.0.clone();
                let mut acc = WorkAccess {
                    slots: &mut slots,
                    rest: &p.rest_positions,
                };
                let mut lam_e = vec![0.0; e.edges.len()];
                let mut lam_v = vec![0.0; tets.len()];
                let mut lam_f = vec![[0.0; 4]; tets.len()];
                let mut count = ProjectionCount::default();
                let at = 1e-3;
                let parts = |r: std::ops::Range<usize>| {
                    let step = if split { lanes::LANES } else { r.len().max(1) };
                    (r.start..r.end)
                        .step_by(step)
                        .map(move |s| s..(s + step).min(r.end))
                };
                let k = Kernel::Simd;
                for (r, ind) in e.classes.ranges() {
                    for q in parts(r) {
                        let (x, d) = (&e.edges[q.clone()], &e.rest_lengths[q.clone()]);
                        count += edge_run(&mut acc, x, d, &mut lam_e[q], at, k, ind);
                    }
                }
                for (r, ind) in tets.classes.ranges() {
                    for q in parts(r.clone()) {
                        let (t, v) = (&tets.indices[q.clone()], &tets.rest_volumes[q.clone()]);
                        count += volume_run(&mut acc, t, v, &mut lam_v[q], at, k, ind);
                    }
                    for q in parts(r) {
                        let (t, h) = (&tets.indices[q.clone()], &vf.rest_heights[q.clone()]);
                        count += vertex_face_run(&mut acc, t, h, &mut lam_f[q], at, k, ind);
                    }
                }
                let lam: Vec<u32> = lam_e
                    .iter()
                    .chain(&lam_v)
                    .chain(lam_f.iter().flatten())
                    .map(|x| x.to_bits())
                    .collect();
                let bits: Vec<[u32; 8]> = slots
                    .iter()
                    .map(|s| {
                        let [a, b, c, d] = s.xw.to_array();
                        let [e, f, g, h] = s.r.to_array();
                        [a, b, c, d, e, f, g, h].map(f32::to_bits)
                    })
                    .collect();
                (bits, lam, count)
            };
            let (pairs, chunks) = (sweep(false), sweep(true));
            assert!(
                pairs == chunks,
                "pairs differ from chunks (squash {squash})"
            );
        }
    }
}
