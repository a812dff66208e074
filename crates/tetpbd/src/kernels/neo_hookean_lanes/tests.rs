//! The lane kernels of the Neo-Hookean material against the scalar reference.

use nalgebra::Vector3;

use super::*;
use crate::body::generators::{box_grid, CellSplit};
use crate::kernels::count::Kernel;
use crate::kernels::neo_hookean::{run, sweep};
use crate::kernels::slots::{Slot, WorkAccess};
use crate::kernels::working_copy;
use crate::{Material, SoftBody, SoftBodyBuilder};

/// A 1 m cube of 5³ cells with the soft-tissue material, the top 0.3 m pinned (tetrahedra
/// with all four pinned: skipped lanes), the rest sheared and squashed from
/// its rest shape (kept as the substep start), and every 23rd particle pushed through
/// the body by 1.5 cells (inverted tetrahedra, the move bound), and one tetrahedron collapsed
/// to a point (the scalar kernel's recovery direction, counted as degenerate).
fn deformed() -> (SoftBody, Vec<Vector3<f32>>) {
    let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [5; 3], CellSplit::Six).unwrap();
    let high = mesh.vertices.iter().fold(f32::MIN, |m, x| m.max(x.y)) - 0.3;
    let top: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y > high)
        .collect();
    let mut body = SoftBodyBuilder::new(mesh)
        .material(Material::SOFT_TISSUE)
        .pinned(top)
        .build()
        .unwrap();
    let start = body.particles.positions.clone();
    for (i, x) in body.particles.positions.iter_mut().enumerate() {
        if body.particles.inv_masses[i] == 0.0 {
            continue;
        }
        *x = Vector3::new(x.x + 0.1 * x.y, 0.8 * x.y, x.z - 0.05 * x.x);
        if i % 23 == 0 {
            x.y -= 0.3;
        }
    }
    // One free tetrahedron of the first class collapsed to a point: projected along the
    // recovery direction (counted as degenerate), its chunk on the scalar kernel.
    let p = &mut body.particles;
    let free = |t: &&[u32; 4]| t.iter().all(|&i| p.inv_masses[i as usize] > 0.0);
    let t = body.tetrahedra.indices.iter().find(free).unwrap();
    for &i in t {
        p.positions[i as usize] = p.positions[t[0] as usize];
    }
    working_copy::load(&mut body.particles);
    (body, start)
}

/// Slots as bits, multipliers, released energies and counts after [`sweeps`].
type Swept = (Vec<[u32; 4]>, Vec<[f32; 2]>, Vec<f32>, ProjectionCount);

/// How the sweep runs each colour class.
#[derive(Clone, Copy, PartialEq)]
enum Runs {
    /// The scalar kernel.
    Scalar,
    /// The SSE2 build, each class as one run.
    Sse2,
    /// The dispatching run (the AVX2 + FMA build where the CPU has it), one per class.
    Dispatched,
    /// The dispatching run on runs of four tetrahedra from each class's start.
    ChunksOfFour,
}

/// Three sweeps of the material of [`deformed`], h = 1/600 s, as `runs` says: the slots
/// as bits, the multipliers and the released energies after it, and the counts.
fn sweeps(runs: Runs) -> Swept {
    let (body, prev) = deformed();
    let (tets, m) = (&body.tetrahedra, body.material.as_ref().unwrap());
    let k = MaterialStep::new(&m.material, 1.0 / 600.0);
    let mut slots: Vec<Slot> = body.particles.work.0.clone();
    let mut acc = WorkAccess {
        slots: &mut slots,
        rest: &body.particles.rest_positions,
    };
    let mut lambdas = vec![[0.0; 2]; tets.len()];
    let mut released = vec![0.0; tets.len()];
    let mut count = ProjectionCount::default();
    for _ in 0..3 {
        let mut r = TetRun {
            rest_inverse: &m.rest_inverse,
            rest_volumes: &tets.rest_volumes,
            lambdas: &mut lambdas,
            released: &mut released,
        };
        let (t, c) = (&tets.indices, &tets.classes);
        count += match runs {
            Runs::Scalar => sweep(&mut acc, &prev, t, c, &mut r, &k, Kernel::Scalar),
            Runs::Dispatched => sweep(&mut acc, &prev, t, c, &mut r, &k, Kernel::Simd),
            Runs::Sse2 | Runs::ChunksOfFour => {
                let mut n = ProjectionCount::default();
                for (range, ind) in c.ranges() {
                    let step = if runs == Runs::Sse2 {
                        range.len()
                    } else {
                        LANES
                    };
                    for s in range.clone().step_by(step.max(1)) {
                        let q = s..(s + step).min(range.end);
                        let mut part = TetRun {
                            rest_inverse: &r.rest_inverse[q.clone()],
                            rest_volumes: &r.rest_volumes[q.clone()],
                            lambdas: &mut r.lambdas[q.clone()],
                            released: &mut r.released[q.clone()],
                        };
                        let t = &t[q];
                        n += if runs == Runs::Sse2 {
                            run_sse2(&mut acc, &prev, t, &mut part, &k, ind)
                        } else {
                            run(&mut acc, &prev, t, &mut part, &k, Kernel::Simd, ind)
                        };
                    }
                }
                n
            }
        };
    }
    let bits = slots
        .iter()
        .map(|s| s.xw.to_array().map(f32::to_bits))
        .collect();
    (bits, lambdas, released, count)
}

/// The SSE2 build of a run.
fn run_sse2(
    acc: &mut WorkAccess<'_>,
    prev: &[Vector3<f32>],
    t: &[[u32; 4]],
    r: &mut TetRun<'_>,
    k: &MaterialStep,
    ind: bool,
) -> ProjectionCount {
    crate::kernels::neo_hookean::run_base::<crate::kernels::lane_types::X2, _>(
        acc,
        prev,
        t,
        r,
        k,
        Kernel::Simd,
        ind,
    )
}

/// The SIMD kernel moves every particle as the scalar kernel does, to rounding, and
/// gives the same multipliers and released energies to rounding, on a body with skipped,
/// inverted and bounded tetrahedra.
#[test]
fn simd_material_matches_the_scalar_kernel() {
    let (body, _) = deformed();
    let (scalar, simd) = (sweeps(Runs::Scalar), sweeps(Runs::Dispatched));
    assert_eq!(scalar.3, simd.3, "counts differ");
    let n = 3 * body.tetrahedra.len() as u64;
    let c = scalar.3;
    assert!(
        c.applied > 0 && c.applied < n && c.degenerate > 0,
        "{c:?} of {n}"
    );
    let pos = |b: &[u32; 4]| Vector3::new(b[0], b[1], b[2]).map(f32::from_bits);
    let worst = scalar
        .0
        .iter()
        .zip(&simd.0)
        .map(|(a, b)| (pos(a) - pos(b)).norm())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-5, "positions differ by {worst} m");
    let moved = scalar
        .0
        .iter()
        .zip(&body.particles.work.0)
        .any(|(a, s)| (pos(a) - pos(&s.xw.to_array().map(f32::to_bits))).norm() > 1e-3);
    assert!(moved, "the sweeps move particles");
    let scale = scalar
        .1
        .iter()
        .flatten()
        .fold(0.0f32, |m, x| m.max(x.abs()));
    for (a, b) in scalar.1.iter().flatten().zip(simd.1.iter().flatten()) {
        assert!((a - b).abs() <= 1e-4 * scale, "multipliers {a} and {b}");
    }
    let total = |e: &[f32]| e.iter().map(|&x| f64::from(x)).sum::<f64>();
    let (es, ev) = (total(&scalar.2), total(&simd.2));
    // The body was deformed from its substep start: it stores energy (releases < 0).
    assert!(es < 0.0, "the deformed body stores energy ({es} J)");
    assert!(
        (es - ev).abs() <= 1e-4 * es.abs(),
        "released {es} J vs {ev} J"
    );
}

/// Every build and split of the runs gives the same bits: the SSE2 build, the dispatched
/// one (AVX2 + FMA where the CPU has it), and runs of four tetrahedra (no pairs).
#[test]
fn material_runs_are_bit_identical_across_builds_and_splits() {
    let bits = |r: Swept| {
        let l: Vec<u32> =
            r.1.iter()
                .flatten()
                .chain(&r.2)
                .map(|x| x.to_bits())
                .collect();
        (r.0, l, r.3)
    };
    let sse2 = bits(sweeps(Runs::Sse2));
    assert!(
        sse2 == bits(sweeps(Runs::Dispatched)),
        "the dispatched build differs"
    );
    assert!(
        sse2 == bits(sweeps(Runs::ChunksOfFour)),
        "chunks of four differ from pairs"
    );
}
