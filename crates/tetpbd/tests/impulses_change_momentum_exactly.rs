//! Impulses on a soft body change its momentum by exactly what was given, and its angular
//! momentum as a rigid body's hit at the same point; an explosion pushes outwards only within
//! its radius. Seeded sweep over meshes, poses, points and impulses.

use nalgebra::{UnitQuaternion, Vector3};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBody, SoftBodyBuilder, StateError};

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

fn body(rng: &mut Rng, case: usize) -> SoftBody {
    let split = if case.is_multiple_of(2) {
        CellSplit::Five
    } else {
        CellSplit::Six
    };
    let cells = [2 + case as u32 % 3, 2, 1 + case as u32 % 2];
    let mesh = box_grid(
        Vector3::new(1.0, 0.5, 0.3) * (0.1 + 2.0 * rng.next().abs()),
        cells,
        split,
    )
    .unwrap();
    SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .volume(0.0)
        .rotation(UnitQuaternion::from_scaled_axis(rng.vector(2.0)))
        .translation(rng.vector(20.0))
        .velocity(rng.vector(3.0))
        .build()
        .unwrap()
}

fn momenta(p: &Particles) -> (Vector3<f64>, Vector3<f64>) {
    let (mut lin, mut ang) = (Vector3::zeros(), Vector3::zeros());
    for ((x, v), m) in p.positions().iter().zip(p.velocities()).zip(p.masses()) {
        let mv = v.cast::<f64>() * f64::from(*m);
        lin += mv;
        ang += x.cast::<f64>().cross(&mv);
    }
    (lin, ang)
}

#[test]
fn impulse_at_a_point_changes_momenta_as_on_a_rigid_body() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    for case in 0..40 {
        let mut b = body(&mut rng, case);
        let tets = b.tetrahedra.indices().to_vec();
        // Inside: a random convex combination of a random tetrahedron's corners. Outside:
        // far beside the body.
        let t = (rng.next().abs() * tets.len() as f32) as usize % tets.len();
        let w = [
            rng.next().abs() + 0.05,
            rng.next().abs() + 0.05,
            rng.next().abs() + 0.05,
            rng.next().abs() + 0.05,
        ];
        let s: f32 = w.iter().sum();
        let inside: Vector3<f32> = (0..4)
            .map(|k| b.particles.positions()[tets[t][k] as usize] * (w[k] / s))
            .sum();
        let outside = b.particles.center_of_mass() + rng.vector(1.0).normalize() * 50.0;
        for (point, expect_inside) in [(inside, true), (outside, false)] {
            let j = rng.vector(100.0);
            let before = momenta(&b.particles);
            let hit = b
                .particles
                .apply_impulse_at_point(&b.tetrahedra, j, point)
                .unwrap();
            let after = momenta(&b.particles);
            assert_eq!(hit.inside, expect_inside, "case {case}");
            assert!((hit.weights.iter().sum::<f32>() - 1.0).abs() < 1e-6);
            let dp = after.0 - before.0;
            let scale = f64::from(j.norm());
            assert!(
                (dp - j.cast::<f64>()).norm() <= 1e-5 * scale,
                "case {case}: Δp {dp:?} vs J {j:?}"
            );
            if expect_inside {
                let dl = after.1 - before.1;
                let expected = point.cast::<f64>().cross(&j.cast::<f64>());
                let tolerance = 1e-5 * scale * (1.0 + f64::from(point.norm()));
                assert!(
                    (dl - expected).norm() <= tolerance,
                    "case {case}: ΔL {dl:?} vs p × J {expected:?}"
                );
            }
        }
    }
}

#[test]
fn impulse_on_the_body_moves_its_centre_of_mass() {
    let mut rng = Rng(99);
    for case in 0..10 {
        let mut b = body(&mut rng, case);
        let j = rng.vector(10.0);
        let before = momenta(&b.particles);
        b.particles.apply_impulse(j).unwrap();
        let after = momenta(&b.particles);
        assert!((after.0 - before.0 - j.cast::<f64>()).norm() <= 1e-5 * f64::from(j.norm()));
    }
}

#[test]
fn explosion_pushes_outwards_within_its_radius_only() {
    let mut rng = Rng(5);
    for case in 0..10 {
        let mut b = body(&mut rng, case);
        let v0 = b.particles.velocities().to_vec();
        let centre = b.particles.center_of_mass() + rng.vector(0.2);
        let radius = 0.3 + rng.next().abs();
        let total = b
            .particles
            .apply_radial_impulse(centre, radius, 20.0)
            .unwrap();
        let mut sum = Vector3::<f64>::zeros();
        for (i, x) in b.particles.positions().iter().enumerate() {
            let dv = b.particles.velocities()[i] - v0[i];
            let r = (x - centre).norm();
            if r >= radius {
                assert_eq!(dv, Vector3::zeros(), "case {case}: particle {i} outside");
            } else {
                assert!(
                    dv.dot(&(x - centre)) >= 0.0,
                    "case {case}: particle {i} pulled in"
                );
                let expected = 20.0 * (1.0 - r / radius);
                assert!(
                    (dv.norm() - expected).abs() <= 1e-4 * 20.0,
                    "case {case}: falloff"
                );
            }
            sum += dv.cast::<f64>() * f64::from(b.particles.masses()[i]);
        }
        assert!((sum - total.cast::<f64>()).norm() <= 1e-4 * (1.0 + sum.norm()));
    }
}

#[test]
fn impulses_reject_bad_input_with_typed_errors() {
    let mesh = box_grid(Vector3::repeat(1.0), [1, 1, 1], CellSplit::Five).unwrap();
    let n = mesh.vertices.len() as u32;
    let mut pinned = SoftBodyBuilder::new(mesh.clone())
        .edges(0.0)
        .pinned(0..n)
        .build()
        .unwrap();
    let j = Vector3::new(1.0, 0.0, 0.0);
    assert_eq!(
        pinned.particles.apply_impulse(j),
        Err(StateError::AllPinned)
    );
    let at = pinned.particles.center_of_mass();
    assert_eq!(
        pinned
            .particles
            .apply_impulse_at_point(&pinned.tetrahedra, j, at),
        Err(StateError::AllPinned)
    );
    let mut b = SoftBodyBuilder::new(mesh).edges(0.0).build().unwrap();
    let nan = Vector3::new(f32::NAN, 0.0, 0.0);
    assert!(matches!(
        b.particles.apply_impulse(nan),
        Err(StateError::NonFinite {
            what: "impulse",
            ..
        })
    ));
    assert!(matches!(
        b.particles.apply_impulse_at_point(&b.tetrahedra, j, nan),
        Err(StateError::NonFinite { what: "point", .. })
    ));
    for r in [0.0, -1.0, f32::NAN] {
        assert!(matches!(
            b.particles.apply_radial_impulse(Vector3::zeros(), r, 1.0),
            Err(StateError::BadParameter { what: "radius", .. })
        ));
    }
    let v = b.particles.velocities().to_vec();
    assert!(b
        .particles
        .apply_radial_impulse(Vector3::zeros(), 1.0, f32::INFINITY)
        .is_err());
    assert_eq!(
        b.particles.velocities(),
        &v[..],
        "a rejected call changes nothing"
    );
}
