//! A body built with a pose, a uniform scale and an initial spin starts where and how it was
//! asked to, with rest data of the scaled mesh, and moves as a rigid body when nothing acts
//! on it. Seeded sweep over rotations, scales, velocities and both grid splits.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{BuildError, Particles, SoftBodyBuilder, Solver, SolverSettings, Tetrahedra};

/// A small deterministic generator (xorshift), values in [-1, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }

    fn vector(&mut self, scale: f32) -> Vector3<f32> {
        Vector3::new(self.next(), self.next(), self.next()) * scale
    }
}

fn mesh(split: CellSplit) -> tetpbd::TetMesh {
    box_grid(Vector3::new(1.0, 0.6, 0.4), [3, 2, 2], split).unwrap()
}

#[test]
fn placed_body_starts_at_its_pose_with_scaled_rest_data() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for case in 0..24u32 {
        let split = if case.is_multiple_of(2) {
            CellSplit::Five
        } else {
            CellSplit::Six
        };
        let axis = rng.vector(1.0) + Vector3::new(0.0, 0.0, 1e-3);
        let rotation = UnitQuaternion::from_scaled_axis(axis.normalize() * rng.next() * 3.0);
        let translation = rng.vector(50.0);
        let scale = 10f32.powf(rng.next() * 2.0); // 0.01–100
        let plain = SoftBodyBuilder::new(mesh(split))
            .edges(0.0)
            .volume(0.0)
            .build()
            .unwrap();
        let placed = SoftBodyBuilder::new(mesh(split))
            .edges(0.0)
            .volume(0.0)
            .pose(Isometry3::from_parts(
                Translation3::from(translation),
                rotation,
            ))
            .scale(scale)
            .build()
            .unwrap();
        let (p0, p) = (&plain.particles, &placed.particles);
        let size = scale * 1.2;
        for (k, x) in p.positions().iter().enumerate() {
            let expected = rotation * (p0.positions()[k] * scale) + translation;
            let tolerance = 1e-6 * (size + translation.norm());
            assert!(
                (x - expected).norm() <= tolerance,
                "case {case}: particle {k}"
            );
            let rest = p0.rest_positions()[k] * scale;
            assert!((p.rest_positions()[k] - rest).norm() <= 1e-6 * size);
        }
        let s3 = scale * scale * scale;
        for (a, b) in plain
            .tetrahedra
            .rest_volumes()
            .iter()
            .zip(placed.tetrahedra.rest_volumes())
        {
            assert!(
                (b - a * s3).abs() <= 1e-5 * (a * s3).abs(),
                "case {case}: rest volume"
            );
        }
        let (m0, m) = (p0.total_mass(), p.total_mass());
        assert!(
            (m - m0 * s3).abs() <= 1e-5 * m0 * s3,
            "case {case}: mass {m} vs {}",
            m0 * s3
        );
        let edges = placed.edges.as_ref().unwrap().rest_lengths();
        for (a, b) in plain
            .edges
            .as_ref()
            .unwrap()
            .rest_lengths()
            .iter()
            .zip(edges)
        {
            assert!(
                (b - a * scale).abs() <= 1e-5 * a * scale,
                "case {case}: rest length"
            );
        }
    }
}

/// Linear momentum M v and angular momentum about the centre of mass I ω, where I is the
/// inertia tensor of the lumped masses.
fn momenta(p: &Particles) -> (Vector3<f64>, Vector3<f64>, f64) {
    let c = p.center_of_mass().cast::<f64>();
    let (mut lin, mut ang, mut m) = (Vector3::zeros(), Vector3::zeros(), 0.0);
    for ((x, v), mi) in p.positions().iter().zip(p.velocities()).zip(p.masses()) {
        let (r, v, mi) = ((x.cast::<f64>() - c), v.cast::<f64>(), f64::from(*mi));
        lin += v * mi;
        ang += r.cross(&v) * mi;
        m += mi;
    }
    (lin, ang, m)
}

#[test]
fn initial_spin_is_a_rigid_rotation_about_the_centre_of_mass() {
    let mut rng = Rng(7);
    for case in 0..12u32 {
        let split = if case.is_multiple_of(2) {
            CellSplit::Five
        } else {
            CellSplit::Six
        };
        let v = rng.vector(20.0);
        let w = rng.vector(10.0);
        let rotation = UnitQuaternion::from_scaled_axis(rng.vector(2.0));
        let body = SoftBodyBuilder::new(mesh(split))
            .edges(0.0)
            .volume(0.0)
            .rotation(rotation)
            .translation(rng.vector(5.0))
            .velocity(v)
            .angular_velocity(w)
            .build()
            .unwrap();
        let p = &body.particles;
        let (lin, ang, m) = momenta(p);
        assert!((lin / m - v.cast::<f64>()).norm() <= 1e-5 * (1.0 + v.norm() as f64));
        let c = p.center_of_mass();
        let mut inertia = nalgebra::Matrix3::<f64>::zeros();
        for (x, mi) in p.positions().iter().zip(p.masses()) {
            let r = (x - c).cast::<f64>();
            inertia +=
                (nalgebra::Matrix3::identity() * r.dot(&r) - r * r.transpose()) * f64::from(*mi);
        }
        let expected = inertia * w.cast::<f64>();
        assert!(
            (ang - expected).norm() <= 1e-3 * expected.norm().max(1.0),
            "case {case}: L {ang:?} vs I ω {expected:?}"
        );
    }
}

#[test]
fn spinning_body_without_forces_keeps_its_shape_and_momenta() {
    for split in [CellSplit::Five, CellSplit::Six] {
        let mut world = hecs::World::new();
        let e = SoftBodyBuilder::new(mesh(split))
            .edges(0.0)
            .volume(0.0)
            .rotation(UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1))
            .velocity(Vector3::new(1.0, 2.0, -0.5))
            .angular_velocity(Vector3::new(0.5, 3.0, -1.0))
            .build()
            .unwrap()
            .spawn(&mut world);
        let (lin0, ang0, _) = momenta(&world.get::<&Particles>(e).unwrap());
        let mut solver = Solver::new(SolverSettings {
            gravity: Vector3::zeros(),
            ..Default::default()
        })
        .unwrap();
        for _ in 0..60 {
            solver.step(&mut world).unwrap();
        }
        let p = world.get::<&Particles>(e).unwrap();
        let t = world.get::<&Tetrahedra>(e).unwrap();
        let (lin, ang, _) = momenta(&p);
        assert!(
            (lin - lin0).norm() <= 1e-4 * lin0.norm(),
            "{split:?}: linear momentum"
        );
        // Hard constraints take a little rotational energy out of a spinning body (each
        // projection shortens the chord of a particle's arc); the momentum stays.
        assert!(
            (ang - ang0).norm() <= 2e-2 * ang0.norm(),
            "{split:?}: angular momentum {ang:?} vs {ang0:?}"
        );
        assert_eq!(t.count_inverted(p.positions()), 0);
        assert!((t.volume_ratio(p.positions()) - 1.0).abs() < 1e-2);
    }
}

#[test]
fn bad_placement_is_a_typed_error() {
    let build = |b: SoftBodyBuilder| b.edges(0.0).build().map(|_| ()).unwrap_err();
    let m = || SoftBodyBuilder::new(mesh(CellSplit::Six));
    for s in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert!(
            matches!(build(m().scale(s)), BuildError::BadScale { .. }),
            "scale {s}"
        );
    }
    let nan_rotation =
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(f32::NAN, 0.0, 0.0, 0.0));
    assert_eq!(build(m().rotation(nan_rotation)), BuildError::NonFinitePose);
    assert_eq!(
        build(m().translation(Vector3::new(0.0, f32::INFINITY, 0.0))),
        BuildError::NonFinitePose
    );
    assert_eq!(
        build(m().angular_velocity(Vector3::new(f32::NAN, 0.0, 0.0))),
        BuildError::NonFiniteVelocity
    );
    // A scale that overflows the coordinates names the vertex.
    let overflowing = m()
        .scale(f32::MAX)
        .translation(Vector3::new(f32::MAX, 0.0, 0.0));
    assert!(matches!(
        build(overflowing),
        BuildError::NonFiniteVertex { .. }
    ));
}
