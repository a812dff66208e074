//! Bounded vertex–face corrections: no vertex–face projection moves a particle further than
//! [`VERTEX_FACE_MAX_STEP`] of its tetrahedron's rest size, so the hard vertex–face family
//! alone does not blow up on a sliver mesh (the stability matrix's "slivers, aspect 1000"
//! case, which this test steps; unbounded, its peak kinetic energy reaches 7.9e15 × the
//! reference).

use nalgebra::Vector3;
use tetpbd::constraints::{bounded_step, vertex_face_step_bound, VERTEX_FACE_MAX_STEP};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings};

/// Peak kinetic energy allowed, as a multiple of the reference `M · 9.81 m/s² · L` (L the rest
/// bounding-box diagonal; the stability matrix's reference). With the bound the peak is about
/// 20; without it 7.9e15.
const PEAK_KE_BOUND: f32 = 100.0;

/// Hard vertex–face alone on a 1 m × 1 mm × 1 m plate of one cell thickness (every
/// tetrahedron a sliver of aspect about 1000), one edge pinned, 2 s under gravity at the
/// default 10 substeps: every frame finite, no non-finite reset, peak kinetic energy
/// bounded.
#[test]
fn hard_vertex_face_sliver_plate_stays_bounded() {
    let mesh = box_grid(Vector3::new(1.0, 1e-3, 1.0), [3, 1, 3], CellSplit::Six).unwrap();
    let pinned: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].x < -0.49)
        .collect();
    let body = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .pinned(pinned)
        .vertex_face(0.0)
        .build()
        .unwrap();
    let (lo, hi) = body.particles.aabb();
    let reference = body.particles.total_mass() * 9.81 * (hi - lo).norm();
    let mut world = hecs::World::new();
    let e = body.spawn(&mut world);
    let mut solver = Solver::new(SolverSettings::default()).unwrap();
    let mut peak = 0.0f32;
    for frame in 1..=120 {
        let stats = solver.step(&mut world).unwrap();
        assert_eq!(stats.non_finite_resets, 0, "frame {frame}");
        let p = world.get::<&Particles>(e).unwrap();
        assert!(
            p.positions()
                .iter()
                .chain(p.velocities())
                .all(|x| x.iter().all(|c| c.is_finite())),
            "frame {frame}: non-finite state"
        );
        peak = peak.max(p.kinetic_energy() / reference);
    }
    assert!(
        peak <= PEAK_KE_BOUND,
        "peak kinetic energy {peak} × the reference (bound {PEAK_KE_BOUND})"
    );
}

/// The bound itself: small steps unchanged bit for bit, large ones scaled to the bound with
/// their sign kept, and the bound a fraction of the largest rest value.
#[test]
fn bounded_step_scales_only_large_steps() {
    // reach² = 4: a step of Δλ moves the farthest particle by 2 Δλ.
    assert_eq!(bounded_step(0.1f64, 4.0, 1.0), 0.1);
    assert_eq!(bounded_step(-0.5f64, 4.0, 1.0), -0.5);
    assert!((bounded_step(3.0f64, 4.0, 1.0) - 0.5).abs() < 1e-15);
    assert!((bounded_step(-3.0f64, 4.0, 1.0) + 0.5).abs() < 1e-15);
    // Overflowing products still give the bounded step, not zero or NaN.
    assert!((bounded_step(1e30f32, 1e30, 1.0) - 1e-15).abs() < 1e-20);
    assert_eq!(bounded_step(0.0f32, 0.0, 1.0), 0.0);
    let b = vertex_face_step_bound(&[0.1, -0.4, 0.2, 0.3]);
    assert!((b - VERTEX_FACE_MAX_STEP * 0.4).abs() < 1e-7);
}
