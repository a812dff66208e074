//! The volume constraint's recovery direction: the exact gradient (against central finite
//! differences, f64) wherever the cofactor is not weak, and a direction out of a
//! tetrahedron collapsed onto a line or a point, where the gradient vanishes.

mod common;

use common::Rng;
use nalgebra::{Matrix3, Vector3};
use tetpbd::constraints::{
    rest_shape_inverse, signed_volume, volume, volume_recovering, VOLUME_GATE,
};

fn vol(p: &[Vector3<f64>; 4]) -> f64 {
    signed_volume(&p[0], &p[1], &p[2], &p[3])
}

/// Outside the gate the recovering form is the volume constraint, bit for bit, and matches
/// central finite differences.
#[test]
fn recovering_volume_is_the_exact_gradient_outside_collapse() {
    let mut rng = Rng::new(7);
    for _ in 0..300 {
        let size = rng.range(0.01, 10.0);
        let rest = rng.tet(size);
        let v0 = vol(&rest);
        let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
        let a = Matrix3::identity() + Matrix3::from_fn(|_, _| rng.range(-0.6, 0.6));
        let p = rest.map(|x| a * x + rng.vec(0.05 * size));
        let exact = volume(&p[0], &p[1], &p[2], &p[3], v0);
        let q: f64 = exact.grad.iter().map(|g| g.norm_squared()).sum();
        if q.powi(3) < VOLUME_GATE * v0.powi(4) {
            continue;
        }
        let rec = volume_recovering(&p, &dm, v0);
        assert!((rec.c - exact.c).abs() <= 1e-12 * v0.abs());
        let gmax = exact.grad.iter().map(|g| g.norm()).fold(1e-300, f64::max);
        let eps = 1e-6 * size;
        for i in 0..4 {
            assert!((rec.grad[i] - exact.grad[i]).norm() <= 1e-9 * gmax);
            let mut fd = Vector3::zeros();
            for k in 0..3 {
                let (mut u, mut d) = (p, p);
                u[i][k] += eps;
                d[i][k] -= eps;
                fd[k] = (vol(&u) - vol(&d)) / (2.0 * eps);
            }
            assert!((fd - rec.grad[i]).norm() < 1e-6 * gmax, "∇p{i}");
        }
    }
}

/// On a line or at a point the volume gradient is zero; the recovery direction is the rest
/// gradient there, its directions sum to zero (momentum kept), and projections along it
/// bring the tetrahedron back to its rest volume (the way out).
#[test]
fn collapsed_tetrahedron_has_a_direction_that_restores_volume() {
    let mut rng = Rng::new(8);
    for n in 0..200 {
        let size = rng.range(0.01, 10.0);
        let mut rest = rng.tet(size);
        if vol(&rest) < 0.0 {
            rest.swap(2, 3);
        }
        let v0 = vol(&rest);
        let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
        let origin = rng.vec(size);
        let dir = rng.vec(1.0).normalize();
        // Every point on a line (n odd) or at one point (n even).
        let p = [0.0, 0.3, -0.7, 1.1].map(|t| origin + dir * (t * size * f64::from(n % 2)));
        let exact = volume(&p[0], &p[1], &p[2], &p[3], v0);
        assert!(exact.grad.iter().all(|g| g.norm() <= 1e-12 * size * size));
        let rec = volume_recovering(&p, &dm, v0);
        let sum: Vector3<f64> = rec.grad.iter().sum();
        assert!(sum.norm() <= 1e-12 * size * size);
        // Hard XPBD projections with equal masses: out of the collapse, then to the rest
        // volume.
        let mut x = p;
        for _ in 0..30 {
            let e = volume_recovering(&x, &dm, v0);
            let q: f64 = e.grad.iter().map(|g| g.norm_squared()).sum();
            let dl = -e.c / q;
            x = std::array::from_fn(|i| x[i] + e.grad[i] * dl);
        }
        assert!((vol(&x) - v0).abs() < 1e-6 * v0, "{n}: {} of {v0}", vol(&x));
    }
}
