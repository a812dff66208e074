//! The hydrostatic Neo-Hookean constraint's recovery direction: the exact gradient (against
//! central finite differences, f64) wherever the cofactor is not weak, continuous across the
//! threshold, and a direction out of a tetrahedron collapsed to a point or a line, where the
//! gradient vanishes.

mod common;

use common::Rng;
use nalgebra::{Matrix3, Vector3};
use tetpbd::constraints::{
    cofactor, deformation_gradient, neo_hookean_collapse_threshold, neo_hookean_hydrostatic,
    neo_hookean_hydrostatic_recovering, recovery_weight, rest_shape_inverse,
};
use tetpbd::Material;

fn det_at(p: &[Vector3<f64>; 4], dm: &Matrix3<f64>) -> f64 {
    deformation_gradient(p, dm).determinant()
}

/// The thresholds of the presets: twice the barrier `μ/(λ' + μ)`, squared.
fn thresholds() -> Vec<f64> {
    [
        Material::RUBBER,
        Material::SOFT_TISSUE,
        Material::JELLY,
        Material::FOAM,
    ]
    .iter()
    .map(|m| {
        let (mu, lambda) = m.lame();
        neo_hookean_collapse_threshold(f64::from(mu), f64::from(lambda + mu))
    })
    .collect()
}

#[test]
fn collapse_threshold_is_twice_the_barrier_squared_and_capped() {
    let (mu, lp) = (4.0e5, 2.0e7);
    let s = mu / (lp + mu);
    let tau: f64 = neo_hookean_collapse_threshold(mu, lp);
    assert!((tau - 4.0 * s * s).abs() < 1e-15);
    // ν = 0: λ' = μ, barrier 1/2, capped at 0.01.
    assert_eq!(neo_hookean_collapse_threshold(1.0f64, 1.0), 0.01);
    for tau in thresholds() {
        assert!(tau > 0.0 && tau <= 0.01, "{tau}");
    }
}

/// Outside the weak-cofactor region the recovering form is the hydrostatic constraint,
/// whose gradients match central finite differences; the region is only crushed states.
#[test]
fn recovering_hydrostatic_is_the_exact_gradient_outside_collapse() {
    let mut rng = Rng::new(41);
    let taus = thresholds();
    let mut outside = 0;
    for n in 0..400 {
        let size = rng.range(0.05, 2.0);
        let rest = rng.tet(size);
        let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
        let a = Matrix3::identity() + Matrix3::from_fn(|_, _| rng.range(-0.6, 0.6));
        let p = rest.map(|x| a * x + rng.vec(0.05 * size));
        let tau = taus[n % taus.len()];
        let cof = cofactor(&deformation_gradient(&p, &dm));
        if cof.norm() < 3.0f64.sqrt() * tau {
            continue;
        }
        outside += 1;
        let exact = neo_hookean_hydrostatic(&p, &dm, 1.1);
        let rec = neo_hookean_hydrostatic_recovering(&p, &dm, 1.1, tau);
        assert_eq!(rec.c, exact.c);
        let eps = 1e-6 * size;
        let gmax = exact.grad.iter().map(|g| g.norm()).fold(1e-12, f64::max);
        for i in 0..4 {
            assert_eq!(rec.grad[i], exact.grad[i]);
            let mut fd = Vector3::zeros();
            for k in 0..3 {
                let (mut u, mut d) = (p, p);
                u[i][k] += eps;
                d[i][k] -= eps;
                fd[k] = (det_at(&u, &dm) - det_at(&d, &dm)) / (2.0 * eps);
            }
            let err = (fd - rec.grad[i]).norm() / gmax;
            assert!(err < 1e-6, "∇p{i}: {:?} vs {fd:?}", rec.grad[i]);
        }
    }
    assert!(outside > 300, "only {outside} states outside the region");
}

/// The direction is continuous in the positions: across the threshold, and inside it.
#[test]
fn recovery_direction_is_continuous() {
    let mut rng = Rng::new(42);
    for tau in thresholds() {
        for _ in 0..50 {
            let rest = rng.tet(1.0);
            let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
            let centre = rng.vec(1.0);
            // Shrink the rest shape towards its centre through the threshold.
            let mut last: Option<[Vector3<f64>; 4]> = None;
            for k in 0..=2000 {
                let s = 1.5 * tau.sqrt() * (1.0 - f64::from(k) / 2000.0);
                let p = rest.map(|x| centre + x * s);
                let g = neo_hookean_hydrostatic_recovering(&p, &dm, 1.1, tau).grad;
                if let Some(prev) = last {
                    let scale = dm.norm();
                    for i in 0..4 {
                        assert!(
                            (g[i] - prev[i]).norm() < 5e-3 * scale,
                            "jump at s = {s}: {:?} → {:?}",
                            prev[i],
                            g[i]
                        );
                    }
                }
                last = Some(g);
            }
        }
    }
}

/// At a point and on a line the gradient of `det F` vanishes; the recovery direction does
/// not, sums to zero (momentum), and a step along it gives the tetrahedron positive volume
/// (with equal masses the step's `ΔF = Dm⁻ᵀ(I + 11ᵀ)Dm⁻¹` is symmetric positive definite,
/// so `det(r a aᵀ + ΔF) = det ΔF (1 + r aᵀΔF⁻¹a) > 0`).
#[test]
fn collapsed_tetrahedron_gets_a_direction_to_positive_volume() {
    let mut rng = Rng::new(43);
    for tau in thresholds() {
        for _ in 0..100 {
            let size = rng.range(0.05, 2.0);
            let rest = rng.tet(size);
            let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
            let centre = rng.vec(1.0);
            let axis = rng.vec(1.0).normalize();
            let point = [centre; 4];
            // Squeezed onto a line by a linear map, `F = r a aᵀ`.
            let r = rng.range(0.0, 1.0);
            let line = rest.map(|x| centre + axis * (axis.dot(&x) * r));
            for p in [point, line] {
                let exact = neo_hookean_hydrostatic(&p, &dm, 1.1);
                assert!(exact.grad.iter().all(|g| g.norm() < 1e-12 * dm.norm()));
                let rec = neo_hookean_hydrostatic_recovering(&p, &dm, 1.1, tau);
                let sum: Vector3<f64> = rec.grad.iter().sum();
                let gmax = rec.grad.iter().map(|g| g.norm()).fold(0.0, f64::max);
                assert!(gmax > 0.1 * dm.norm(), "no direction: {gmax}");
                assert!(sum.norm() < 1e-12 * gmax);
                // A step of a tenth of the rest size along it (equal masses).
                let step = 0.1 * size / gmax;
                let q: [Vector3<f64>; 4] = std::array::from_fn(|i| p[i] + rec.grad[i] * step);
                assert!(det_at(&q, &dm) > 0.0, "det {}", det_at(&q, &dm));
            }
            let f = deformation_gradient(&point, &dm);
            assert_eq!(recovery_weight(&cofactor(&f), tau), 1.0);
        }
    }
}
