//! Every constraint's analytic gradient against central finite differences in f64.

mod common;

use common::Rng;
use nalgebra::Vector3;
use tetpbd::constraints::{
    edge, signed_volume, vertex_face, vertex_face_bounded, volume, Evaluated,
};

/// Central finite difference of `f` with respect to particle `i`, coordinate by coordinate.
fn fd<const N: usize>(
    p: &[Vector3<f64>; N],
    i: usize,
    eps: f64,
    f: &dyn Fn(&[Vector3<f64>; N]) -> f64,
) -> Vector3<f64> {
    let mut g = Vector3::zeros();
    for k in 0..3 {
        let mut a = *p;
        let mut b = *p;
        a[i][k] += eps;
        b[i][k] -= eps;
        g[k] = (f(&a) - f(&b)) / (2.0 * eps);
    }
    g
}

fn check<const N: usize>(
    p: &[Vector3<f64>; N],
    e: &Evaluated<f64, N>,
    f: &dyn Fn(&[Vector3<f64>; N]) -> f64,
    what: &str,
) {
    check_with_step(p, e, f, 1e-6, what)
}

/// `eps` is the finite-difference step, m; it must be small against the smallest feature
/// of the configuration (the squeeze of a near-degenerate face).
fn check_with_step<const N: usize>(
    p: &[Vector3<f64>; N],
    e: &Evaluated<f64, N>,
    f: &dyn Fn(&[Vector3<f64>; N]) -> f64,
    eps: f64,
    what: &str,
) {
    let gmax = e.grad.iter().map(|g| g.norm()).fold(1e-12, f64::max);
    for i in 0..N {
        let num = fd(p, i, eps, f);
        let err = (num - e.grad[i]).norm() / gmax;
        assert!(
            err < 1e-5,
            "{what}: ∇p{i} analytic {:?} vs finite difference {:?} (relative error {err:e}) at {p:?}",
            e.grad[i],
            num
        );
    }
    let sum: Vector3<f64> = e.grad.iter().sum();
    assert!(
        sum.norm() < 1e-9 * gmax.max(1.0),
        "{what}: gradients do not sum to zero: {sum:?}"
    );
}

#[test]
fn edge_gradient_matches_finite_differences() {
    let mut rng = Rng::new(1);
    for _ in 0..500 {
        let p = [rng.vec(2.0), rng.vec(2.0)];
        let d = rng.range(0.1, 2.0);
        let e = edge(&p[0], &p[1], d, None).expect("random points are distinct");
        assert!((e.c - ((p[0] - p[1]).norm() - d)).abs() < 1e-12);
        check(&p, &e, &|q| (q[0] - q[1]).norm() - d, "edge");
    }
}

#[test]
fn edge_zero_length_uses_fallback_or_reports_none() {
    let p = Vector3::new(1.0f64, 2.0, 3.0);
    assert!(edge(&p, &p, 1.0, None).is_none());
    let dir = Vector3::new(0.0, 1.0, 0.0);
    let e = edge(&p, &p, 1.0, Some(&dir)).expect("fallback given");
    assert_eq!(e.grad, [dir, -dir]);
    assert_eq!(e.c, -1.0);
}

fn random_tet(rng: &mut Rng) -> [Vector3<f64>; 4] {
    loop {
        let p = [rng.vec(1.0), rng.vec(1.0), rng.vec(1.0), rng.vec(1.0)];
        if signed_volume(&p[0], &p[1], &p[2], &p[3]).abs() > 1e-3 {
            return p;
        }
    }
}

fn height(q: &[Vector3<f64>; 4]) -> f64 {
    let n = (q[2] - q[0]).cross(&(q[3] - q[0]));
    (q[1] - q[0]).dot(&n) / n.norm()
}

#[test]
fn vertex_face_gradient_matches_finite_differences() {
    let mut rng = Rng::new(2);
    for _ in 0..500 {
        let p = random_tet(&mut rng);
        let d = rng.range(-0.5, 0.5);
        let e = vertex_face(&p[0], &p[1], &p[2], &p[3], d).expect("non-degenerate face");
        assert!((e.c - (height(&p) - d)).abs() < 1e-12);
        check(&p, &e, &|q| height(q) - d, "vertex-face");
    }
}

#[test]
fn vertex_face_gradient_near_degenerate_face() {
    // Face (p0, p2, p3) nearly collinear but still above the degeneracy threshold.
    let mut rng = Rng::new(3);
    for k in 0..200 {
        let squeeze = 10f64.powf(-(1.0 + (k % 5) as f64));
        let p0 = rng.vec(1.0);
        let dir = rng.vec(1.0).normalize();
        let p2 = p0 + dir;
        let p3 = p0 + dir * rng.range(0.3, 2.0) + rng.vec(1.0).cross(&dir).normalize() * squeeze;
        let p1 = rng.vec(1.0);
        let p = [p0, p1, p2, p3];
        let e = vertex_face(&p0, &p1, &p2, &p3, 0.1).expect("above the threshold");
        check_with_step(
            &p,
            &e,
            &|q| height(q) - 0.1,
            1e-4 * squeeze,
            "vertex-face near-degenerate",
        );
    }
}

#[test]
fn vertex_face_degenerate_face_is_none_not_nan() {
    let o = Vector3::new(0.0f64, 0.0, 0.0);
    let x = Vector3::new(1.0, 0.0, 0.0);
    let y = Vector3::new(0.0, 1.0, 0.0);
    // Collinear face points, coincident face points, everything at one point.
    assert!(vertex_face(&o, &y, &x, &(x * 2.0), 0.5).is_none());
    assert!(vertex_face(&o, &y, &o, &x, 0.5).is_none());
    assert!(vertex_face(&o, &o, &o, &o, 0.5).is_none());
    let o32 = Vector3::new(0.0f32, 0.0, 0.0);
    assert!(vertex_face(&o32, &o32, &o32, &o32, 0.5).is_none());
}

#[test]
fn volume_gradient_matches_finite_differences() {
    let mut rng = Rng::new(4);
    for _ in 0..500 {
        let p = random_tet(&mut rng);
        let v0 = rng.range(-0.2, 0.2);
        let e = volume(&p[0], &p[1], &p[2], &p[3], v0);
        let f = |q: &[Vector3<f64>; 4]| {
            (q[1] - q[0]).dot(&(q[2] - q[0]).cross(&(q[3] - q[0]))) / 6.0 - v0
        };
        assert!((e.c - f(&p)).abs() < 1e-12);
        check(&p, &e, &f, "volume");
    }
}

#[test]
fn volume_gradient_has_the_one_sixth() {
    // Unit right tetrahedron: ∇p1 C = (1/6) e2 × e3 = (1/6, 0, 0), not (1, 0, 0).
    let z = Vector3::zeros();
    let e = volume(&z, &Vector3::x(), &Vector3::y(), &Vector3::z(), 0.0f64);
    assert!((e.grad[1] - Vector3::new(1.0 / 6.0, 0.0, 0.0)).norm() < 1e-15);
    assert!((e.c - 1.0 / 6.0).abs() < 1e-15);
}

#[test]
fn collapsed_tetrahedron_volume_is_finite() {
    let p = Vector3::new(0.3f32, -0.2, 0.1);
    let e = volume(&p, &p, &p, &p, 0.1);
    assert!(e.c.is_finite() && e.grad.iter().all(|g| g.norm() == 0.0));
    assert!(tetpbd::constraints::xpbd_delta_lambda(e.c, 0.0, 0.0, 0.0f32).is_none());
}

#[test]
fn f32_matches_f64() {
    let mut rng = Rng::new(5);
    for _ in 0..200 {
        let p = random_tet(&mut rng);
        let q = p.map(|v| v.cast::<f32>());
        let a = vertex_face(&p[0], &p[1], &p[2], &p[3], 0.1).unwrap();
        let b = vertex_face(&q[0], &q[1], &q[2], &q[3], 0.1).unwrap();
        let gmax = a.grad.iter().map(|g| g.norm()).fold(1.0, f64::max);
        for i in 0..4 {
            assert!((a.grad[i] - b.grad[i].cast::<f64>()).norm() < 1e-3 * gmax);
        }
        let a = volume(&p[0], &p[1], &p[2], &p[3], 0.0);
        let b = volume(&q[0], &q[1], &q[2], &q[3], 0.0);
        assert!((a.c - f64::from(b.c)).abs() < 1e-5);
    }
}

/// `f/D` of the degeneracy-aware vertex–face constraint, written out independently.
fn bounded(q: &[Vector3<f64>; 4], kappa: f64) -> f64 {
    let (a, b, c) = (q[1] - q[0], q[2] - q[0], q[3] - q[0]);
    let m = b.cross(&c);
    let s = m.norm();
    let k = kappa * (b.norm_squared() + c.norm_squared()) / 2.0;
    let d = if s >= k {
        s
    } else {
        (s * s + k * k) / (2.0 * k)
    };
    a.dot(&m) / d
}

/// `|b × c| / (κ (|b|² + |c|²)/2)`: ≥ 1 on the exact-height branch.
fn thinness(q: &[Vector3<f64>; 4], kappa: f64) -> f64 {
    let (b, c) = (q[2] - q[0], q[3] - q[0]);
    b.cross(&c).norm() / (kappa * (b.norm_squared() + c.norm_squared()) / 2.0)
}

/// A face `(p0, p2, p3)` squeezed towards a segment: `p3` at `squeeze` off the line `p0 p2`.
fn thin_face(rng: &mut Rng, squeeze: f64, apex: f64) -> [Vector3<f64>; 4] {
    let p0 = rng.vec(1.0);
    let dir = rng.vec(1.0).normalize();
    let side = rng.vec(1.0).cross(&dir).normalize();
    let p2 = p0 + dir * rng.range(0.5, 1.5);
    let p3 = p0 + dir * rng.range(-0.5, 1.5) + side * squeeze;
    let p1 = p0 + rng.vec(apex);
    [p0, p1, p2, p3]
}

#[test]
fn bounded_vertex_face_is_the_height_on_healthy_faces() {
    let kappa = 0.1;
    let mut rng = Rng::new(6);
    let mut tested = 0;
    for _ in 0..2000 {
        let p = random_tet(&mut rng);
        if thinness(&p, kappa) < 1.01 {
            continue;
        }
        tested += 1;
        let d = rng.range(-0.5, 0.5);
        let e = vertex_face_bounded(&p[0], &p[1], &p[2], &p[3], d, kappa).unwrap();
        let seed = vertex_face(&p[0], &p[1], &p[2], &p[3], d).unwrap();
        assert!((e.c - seed.c).abs() < 1e-12, "value {} vs {}", e.c, seed.c);
        for i in 0..4 {
            assert!((e.grad[i] - seed.grad[i]).norm() < 1e-9 * seed.grad[i].norm().max(1.0));
        }
        check(
            &p,
            &e,
            &|q| bounded(q, kappa) - d,
            "bounded vertex-face, healthy",
        );
    }
    assert!(tested > 500, "{tested}");
}

#[test]
fn bounded_vertex_face_gradient_matches_finite_differences_on_thin_faces() {
    let kappa = 0.1;
    let mut rng = Rng::new(7);
    let (mut thin, mut weak) = (0, 0);
    for k in 0..1000 {
        let squeeze = 10f64.powf(-(1.0 + (k % 6) as f64));
        let p = thin_face(&mut rng, squeeze, 3.0);
        if thinness(&p, kappa) > 0.99 {
            continue;
        }
        let d = rng.range(-0.5, 0.5);
        let e = vertex_face_bounded(&p[0], &p[1], &p[2], &p[3], d, kappa).unwrap();
        let strength: f64 = e.grad.iter().map(|g| g.norm_squared()).sum();
        if (e.c - (bounded(&p, kappa) - d)).abs() < 1e-12 {
            thin += 1;
            assert!(strength >= 1.0, "{strength}");
            check_with_step(
                &p,
                &e,
                &|q| bounded(q, kappa) - d,
                1e-4 * squeeze,
                "bounded vertex-face, thin",
            );
        } else {
            // Thin branch too weak: the seed's height.
            weak += 1;
            let seed = vertex_face(&p[0], &p[1], &p[2], &p[3], d).unwrap();
            assert!((e.c - seed.c).abs() < 1e-12);
        }
    }
    assert!(thin > 500, "thin {thin}, weak {weak}");
    // Nearly collapsed onto a line: the thin branch's gradients vanish, the seed's height
    // takes over (its apex gradient is the unit normal).
    let p = [
        Vector3::zeros(),
        Vector3::new(0.5, 1e-4, 1e-4),
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(2.0, 1e-4, 0.0),
    ];
    let e = vertex_face_bounded(&p[0], &p[1], &p[2], &p[3], 0.2, kappa).unwrap();
    let seed = vertex_face(&p[0], &p[1], &p[2], &p[3], 0.2).unwrap();
    assert_eq!(e, seed);
}

#[test]
fn bounded_vertex_face_is_c1_across_the_switch() {
    // p3 moved off the line p0 p2 until |b × c| crosses κQ: value and gradients continuous.
    let kappa = 0.1;
    let mut rng = Rng::new(8);
    let mut tested = 0;
    for _ in 0..200 {
        let base = thin_face(&mut rng, 0.0, 1.0);
        let side = (base[1] - base[0])
            .cross(&(base[2] - base[0]))
            .cross(&(base[2] - base[0]))
            .normalize();
        let at = |t: f64| {
            let mut q = base;
            q[3] += side * t;
            q
        };
        // Bisect the switch point t* (thinness 1).
        let (mut lo, mut hi) = (0.0, 1.0);
        if thinness(&at(hi), kappa) < 1.0 {
            continue;
        }
        tested += 1;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if thinness(&at(mid), kappa) < 1.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let (below, above) = (at(lo - 1e-9), at(hi + 1e-9));
        let eb = vertex_face_bounded(&below[0], &below[1], &below[2], &below[3], 0.0, kappa);
        let ea = vertex_face_bounded(&above[0], &above[1], &above[2], &above[3], 0.0, kappa);
        let (eb, ea) = (eb.unwrap(), ea.unwrap());
        let gmax = ea.grad.iter().map(|g| g.norm()).fold(1.0, f64::max);
        assert!((eb.c - ea.c).abs() < 1e-6 * gmax, "{} vs {}", eb.c, ea.c);
        for i in 0..4 {
            assert!(
                (eb.grad[i] - ea.grad[i]).norm() < 1e-5 * gmax,
                "∇p{i}: {:?} below vs {:?} above the switch",
                eb.grad[i],
                ea.grad[i]
            );
        }
    }
    assert!(tested > 50, "{tested}");
}

#[test]
fn bounded_vertex_face_gradients_stay_bounded_where_the_seed_blows_up() {
    let kappa = 0.1;
    let mut rng = Rng::new(9);
    // Largest gradient × κ / (1 + |a|/√Q) on the thin branch: documented as about 4 at most.
    // Where the thin branch is too weak (nearly on a line) the seed's height is used and
    // compared with the seed's step bound instead.
    let (mut bounded_max, mut seed_max, mut thin) = (0.0f64, 0.0f64, 0);
    for k in 0..5000 {
        // Faces from healthy to squeezed 1e-6, apexes from 1e-3 to 1e3 face sizes away.
        let squeeze = 10f64.powf(-((k % 7) as f64));
        let apex = 10f64.powf(((k / 7) % 7) as f64 - 3.0);
        let p = thin_face(&mut rng, squeeze, apex);
        let (a, b, c) = (p[1] - p[0], p[2] - p[0], p[3] - p[0]);
        let norm = kappa / (1.0 + a.norm() / ((b.norm_squared() + c.norm_squared()) / 2.0).sqrt());
        let largest = |g: &[Vector3<f64>; 4]| g.iter().map(|g| g.norm()).fold(0.0, f64::max);
        let e = vertex_face_bounded(&p[0], &p[1], &p[2], &p[3], 0.3, kappa).unwrap();
        let s = vertex_face(&p[0], &p[1], &p[2], &p[3], 0.3).unwrap();
        let on_thin = (e.c - (bounded(&p, kappa) - 0.3)).abs() < 1e-9 * e.c.abs().max(1.0);
        if thinness(&p, kappa) < 1.0 && on_thin {
            thin += 1;
            bounded_max = bounded_max.max(largest(&e.grad) * norm);
            seed_max = seed_max.max(largest(&s.grad) * norm);
        }
    }
    assert!(thin > 1000, "{thin}");
    assert!(bounded_max < 5.0, "bounded gradients reach {bounded_max}");
    assert!(seed_max > 1e3, "the seed's gradients only reach {seed_max}");
}

#[test]
fn bounded_vertex_face_collapsed_to_a_point_is_none_and_f32_matches_f64() {
    let o = Vector3::new(0.5f64, -0.2, 0.1);
    assert!(vertex_face_bounded(&o, &o, &o, &o, 0.3, 0.1).is_none());
    let o32 = o.cast::<f32>();
    assert!(vertex_face_bounded(&o32, &o32, &o32, &o32, 0.3, 0.1).is_none());
    // A face collapsed to a segment is not degenerate here: the thin branch is finite.
    let x = Vector3::new(1.0, 0.0, 0.0);
    let e = vertex_face_bounded(&o, &(o + Vector3::y()), &(o + x), &(o + x * 2.0), 0.3, 0.1);
    let e = e.expect("thin branch");
    // The apex has no direction (zero gradient); the face's points are pushed apart.
    assert!(e.c.is_finite() && e.grad[1].norm() == 0.0);
    assert!(
        e.grad[2].norm() > 0.1 && e.grad[3].norm() > 0.1,
        "{:?}",
        e.grad
    );
    let mut rng = Rng::new(10);
    for k in 0..400 {
        let p = if k % 2 == 0 {
            random_tet(&mut rng)
        } else {
            thin_face(&mut rng, 1e-3, 1.0)
        };
        let q = p.map(|v| v.cast::<f32>());
        let a = vertex_face_bounded(&p[0], &p[1], &p[2], &p[3], 0.1, 0.1).unwrap();
        let b = vertex_face_bounded(&q[0], &q[1], &q[2], &q[3], 0.1, 0.1).unwrap();
        let gmax = a.grad.iter().map(|g| g.norm()).fold(1.0, f64::max);
        assert!((a.c - f64::from(b.c)).abs() < 1e-4 * gmax);
        for i in 0..4 {
            assert!((a.grad[i] - b.grad[i].cast::<f64>()).norm() < 1e-3 * gmax);
        }
    }
}
