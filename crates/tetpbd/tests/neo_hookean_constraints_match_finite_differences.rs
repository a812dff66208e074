//! The Neo-Hookean material's constraints against central finite differences in f64, on
//! random, near-degenerate and inverted tetrahedra, and its energy against the analytic stress.

mod common;

use common::Rng;
use nalgebra::{Matrix3, Vector3};
use tetpbd::constraints::{
    deformation_gradient, neo_hookean_deviatoric, neo_hookean_energy_density,
    neo_hookean_hydrostatic, neo_hookean_rest_offset, neo_hookean_stress, neo_hookean_update,
    rest_shape_inverse, Evaluated,
};

/// Central finite difference of `f` with respect to particle `i`.
fn fd(
    p: &[Vector3<f64>; 4],
    i: usize,
    eps: f64,
    f: &dyn Fn(&[Vector3<f64>; 4]) -> f64,
) -> Vector3<f64> {
    let mut g = Vector3::zeros();
    for k in 0..3 {
        let (mut a, mut b) = (*p, *p);
        a[i][k] += eps;
        b[i][k] -= eps;
        g[k] = (f(&a) - f(&b)) / (2.0 * eps);
    }
    g
}

/// Every particle gradient of `e` against the finite difference of `f`, and the gradients sum
/// to zero. The error is relative to the largest gradient, or to `floor` where the gradients
/// are smaller: the size of the terms that cancel in them (a needle's cofactor is the
/// difference of products of its long edges), below which f64 rounding is all there is.
fn check(
    p: &[Vector3<f64>; 4],
    e: &Evaluated<f64, 4>,
    f: &dyn Fn(&[Vector3<f64>; 4]) -> f64,
    eps: f64,
    floor: f64,
    what: &str,
) {
    assert!(
        (e.c - f(p)).abs() <= 1e-12 * (1.0 + e.c.abs()),
        "{what}: C {} vs {}",
        e.c,
        f(p)
    );
    let gmax = e.grad.iter().map(|g| g.norm()).fold(1e-12, f64::max);
    for i in 0..4 {
        let num = fd(p, i, eps, f);
        let err = (num - e.grad[i]).norm() / gmax.max(floor);
        assert!(
            err < 1e-6,
            "{what}: ∇p{i} {:?} vs finite difference {num:?} (relative {err:e}) at {p:?}",
            e.grad[i]
        );
    }
    let sum: Vector3<f64> = e.grad.iter().sum();
    assert!(
        sum.norm() < 1e-9 * gmax.max(floor),
        "{what}: gradients sum to {sum:?}"
    );
}

/// A random rest tetrahedron of edge about `size`, positively or negatively wound.
/// `rest` deformed by a random linear map plus a random perturbation of each corner.
fn deformed(rng: &mut Rng, rest: &[Vector3<f64>; 4], strain: f64, noise: f64) -> [Vector3<f64>; 4] {
    let a = Matrix3::identity() + Matrix3::from_fn(|_, _| rng.range(-strain, strain));
    let shift = rng.vec(1.0);
    rest.map(|x| a * x + shift + rng.vec(noise))
}

fn dev(dm: &Matrix3<f64>) -> impl Fn(&[Vector3<f64>; 4]) -> f64 + '_ {
    move |q| deformation_gradient(q, dm).norm()
}

fn hyd(dm: &Matrix3<f64>, gamma: f64) -> impl Fn(&[Vector3<f64>; 4]) -> f64 + '_ {
    move |q| deformation_gradient(q, dm).determinant() - gamma
}

/// Checks both constraints at `p`.
fn check_both(p: &[Vector3<f64>; 4], dm: &Matrix3<f64>, gamma: f64, eps: f64, what: &str) {
    // The cofactor's terms are products of two columns of F, times Dm⁻¹: 1e-3 of that is
    // where rounding of f64 differences (~1e-16 / eps of it) stays far below the tolerance.
    let f = deformation_gradient(p, dm);
    let floor = 1e-3 * f.norm_squared() * dm.norm();
    let d = neo_hookean_deviatoric(p, dm).expect("the points do not coincide");
    check(p, &d, &dev(dm), eps, 0.0, &format!("{what} deviatoric"));
    let h = neo_hookean_hydrostatic(p, dm, gamma);
    check(
        p,
        &h,
        &hyd(dm, gamma),
        eps,
        floor,
        &format!("{what} hydrostatic"),
    );
}

#[test]
fn neo_hookean_gradients_match_finite_differences_on_random_tetrahedra() {
    let mut rng = Rng::new(27);
    for _ in 0..400 {
        let size = rng.range(0.01, 2.0);
        let rest = rng.tet(size);
        let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
        let p = deformed(&mut rng, &rest, 0.6, 0.2 * size);
        let gamma = 1.0 + rng.range(0.0, 1.0);
        check_both(&p, &dm, gamma, 1e-6 * size, "random");
    }
}

#[test]
fn neo_hookean_gradients_match_finite_differences_on_inverted_tetrahedra() {
    let mut rng = Rng::new(28);
    for _ in 0..300 {
        let size = rng.range(0.05, 1.0);
        let rest = rng.tet(size);
        let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
        // Mirror corner 3 through the plane of the other three: det F < 0.
        let mut p = deformed(&mut rng, &rest, 0.2, 0.02 * size);
        let n = (p[1] - p[0]).cross(&(p[2] - p[0])).normalize();
        p[3] -= n * (2.0 * (p[3] - p[0]).dot(&n));
        let f = deformation_gradient(&p, &dm);
        assert!(f.determinant() < 0.0);
        check_both(&p, &dm, 1.5, 1e-6 * size, "inverted");
        // A small step against the hydrostatic violation raises det F: back towards
        // positive volume.
        let h = neo_hookean_hydrostatic(&p, &dm, 1.5);
        assert!(h.c < -1.5);
        let step: Vec<Vector3<f64>> = h.grad.iter().map(|g| -g * h.c * 1e-4).collect();
        let q: [Vector3<f64>; 4] = std::array::from_fn(|i| p[i] + step[i]);
        assert!(deformation_gradient(&q, &dm).determinant() > f.determinant());
    }
}

#[test]
fn neo_hookean_gradients_match_finite_differences_on_near_degenerate_tetrahedra() {
    let mut rng = Rng::new(29);
    for squeeze in [1e-2, 1e-4, 1e-6] {
        for _ in 0..100 {
            let rest = rng.tet(1.0);
            let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
            // Corner 3 squeezed to within `squeeze` of the plane of the other three (flat),
            // or all four squeezed onto a line (needle).
            let mut p = deformed(&mut rng, &rest, 0.3, 0.0);
            let n = (p[1] - p[0]).cross(&(p[2] - p[0])).normalize();
            p[3] -= n * ((p[3] - p[0]).dot(&n) - squeeze);
            check_both(&p, &dm, 1.2, 1e-3 * squeeze, "flat");
            let axis = rng.vec(1.0).normalize();
            let needle = p.map(|x| axis * x.dot(&axis) + rng.vec(squeeze));
            check_both(&needle, &dm, 1.2, 1e-6, "needle");
        }
    }
    // All four corners at one point: the deviatoric direction is undefined (None), the
    // hydrostatic constraint finite with zero gradients.
    let rest = rng.tet(1.0);
    let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
    let point = [Vector3::new(0.3, 0.2, 0.1); 4];
    assert!(neo_hookean_deviatoric(&point, &dm).is_none());
    let h = neo_hookean_hydrostatic(&point, &dm, 1.2);
    assert!(h.c.is_finite() && h.grad.iter().all(|g| g.norm() == 0.0));
}

/// `Σ C²/(2α)` of the two constraints is `V₀ Ψ` plus a constant, so its particle gradient is
/// the nodal force of the analytic stress, `V₀ P Dm⁻ᵀ`; and `P` is `∂Ψ/∂F`.
#[test]
fn constraint_energy_is_the_neo_hookean_energy() {
    let mut rng = Rng::new(30);
    for _ in 0..200 {
        let (mu, lp) = (rng.range(1e3, 1e6), 0.0);
        let lp = lp + mu * rng.range(1.0, 50.0);
        let gamma = neo_hookean_rest_offset(mu, lp);
        let rest = rng.tet(0.5);
        let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
        let v0 = dm.determinant().abs().recip() / 6.0;
        let p = deformed(&mut rng, &rest, 0.5, 0.05);
        let f = deformation_gradient(&p, &dm);
        let d = neo_hookean_deviatoric(&p, &dm).unwrap();
        let h = neo_hookean_hydrostatic(&p, &dm, gamma);
        let stress = neo_hookean_stress(&f, mu, lp);
        let nodal = stress * dm.transpose() * v0;
        for i in 1..4 {
            let from_constraints = d.grad[i] * (d.c * mu * v0) + h.grad[i] * (h.c * lp * v0);
            let analytic = nodal.column(i - 1).into_owned();
            let err = (from_constraints - analytic).norm() / analytic.norm().max(1e-12);
            assert!(
                err < 1e-9,
                "corner {i}: {from_constraints:?} vs {analytic:?}"
            );
        }
        // P = ∂Ψ/∂F by central differences over the nine entries of F.
        for r in 0..3 {
            for c in 0..3 {
                let eps = 1e-6;
                let (mut a, mut b) = (f, f);
                a[(r, c)] += eps;
                b[(r, c)] -= eps;
                let num = (neo_hookean_energy_density(&a, mu, lp)
                    - neo_hookean_energy_density(&b, mu, lp))
                    / (2.0 * eps);
                assert!(
                    (num - stress[(r, c)]).abs() < 1e-6 * stress.norm().max(mu),
                    "P[{r},{c}] {} vs {num}",
                    stress[(r, c)]
                );
            }
        }
        assert!(neo_hookean_energy_density(&Matrix3::identity(), mu, lp).abs() < 1e-9 * mu);
        assert!(neo_hookean_stress(&Matrix3::identity(), mu, lp).norm() < 1e-9 * mu);
    }
}

/// `Σ wᵢ ∇ᵢa · ∇ᵢb`.
fn gram<T: nalgebra::RealField + Copy>(w: &[T; 4], a: &Evaluated<T, 4>, b: &Evaluated<T, 4>) -> T {
    (0..4).fold(T::zero(), |s, i| s + w[i] * a.grad[i].dot(&b.grad[i]))
}

/// A random material, substep, masses and rest tetrahedron: `(μ, λ', h, w, rest, Dm⁻¹, V₀)`.
#[allow(clippy::type_complexity)]
fn random_setup(
    rng: &mut Rng,
) -> (
    f64,
    f64,
    f64,
    [f64; 4],
    [Vector3<f64>; 4],
    Matrix3<f64>,
    f64,
) {
    let mu = rng.range(1e2, 1e7);
    let lp = mu * rng.range(1.0, 100.0);
    let size = rng.range(0.01, 1.0);
    let rest = rng.tet(size);
    let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
    let v0 = dm.determinant().abs().recip() / 6.0;
    let w: [f64; 4] = std::array::from_fn(|_| rng.range(0.1, 10.0));
    (mu, lp, rng.range(1e-4, 1e-2), w, rest, dm, v0)
}

/// The coupled update solves its 2×2 system, moves the particles by `wᵢ Σ ∇ᵢC Δλ` and
/// predicts `C + G Δλ`, on deformed tetrahedra with damping and running multipliers.
#[test]
fn coupled_update_solves_its_system() {
    let mut rng = Rng::new(31);
    for _ in 0..300 {
        let (mu, lp, h, w, rest, dm, v0) = random_setup(&mut rng);
        let gamma = neo_hookean_rest_offset(mu, lp);
        let p = deformed(&mut rng, &rest, 0.5, 0.1 * (v0 * 6.0).cbrt());
        let d = neo_hookean_deviatoric(&p, &dm).unwrap();
        let y = neo_hookean_hydrostatic(&p, &dm, gamma);
        let at = [1.0 / (mu * v0 * h * h), 1.0 / (lp * v0 * h * h)];
        let damping = rng.range(0.0, 0.05) / h;
        let lambda = [rng.range(-1.0, 1.0) / at[0], rng.range(-1.0, 1.0) / at[1]];
        let rate = [rng.range(-0.1, 0.1), rng.range(-0.1, 0.1)];
        let up = neo_hookean_update(&d, &y, w, lambda, at, damping, rate).unwrap();
        let dl = up.delta_lambda;
        let g = [
            [gram(&w, &d, &d), gram(&w, &d, &y)],
            [gram(&w, &d, &y), gram(&w, &y, &y)],
        ];
        let k = 1.0 + damping;
        let b = [
            -d.c - at[0] * lambda[0] - damping * rate[0],
            -y.c - at[1] * lambda[1] - damping * rate[1],
        ];
        let r0 = (k * g[0][0] + at[0]) * dl[0] + k * g[0][1] * dl[1] - b[0];
        let r1 = k * g[0][1] * dl[0] + (k * g[1][1] + at[1]) * dl[1] - b[1];
        let scale = b[0].abs() + b[1].abs();
        assert!(
            r0.abs() < 1e-8 * scale && r1.abs() < 1e-8 * scale,
            "residual {r0} {r1} of {b:?}"
        );
        for (i, (wi, moved)) in w.iter().zip(&up.moves).enumerate() {
            let dx = (d.grad[i] * dl[0] + y.grad[i] * dl[1]) * *wi;
            assert!(
                (dx - moved).norm() <= 1e-8 * dx.norm().max(1e-12),
                "move {i}"
            );
        }
        let c_after = [
            d.c + g[0][0] * dl[0] + g[0][1] * dl[1],
            y.c + g[0][1] * dl[0] + g[1][1] * dl[1],
        ];
        for (c, got) in c_after.iter().zip(&up.c_after) {
            assert!((c - got).abs() < 1e-8 * (1.0 + c.abs()));
        }
    }
}

/// At rest the coupled update moves nothing, whatever the compliances and masses: the two
/// constraints' pulls cancel (a rest state that separate projections would not keep). The
/// moves stay at the rounding of the positions (ε |x|, in f64 and f32) times the stiffness
/// ratio `G/α̃` by which the rest multipliers amplify it: the solve itself cancels nothing
/// large (a plain 2×2 determinant moved rubber cubes at rest by 7 % of their size).
#[test]
fn coupled_update_keeps_the_rest_state() {
    let mut rng = Rng::new(33);
    for _ in 0..300 {
        let (mu, lp, h, w, rest, dm, v0) = random_setup(&mut rng);
        let gamma = neo_hookean_rest_offset(mu, lp);
        let size = (6.0 * v0).cbrt();
        let at = [1.0 / (mu * v0 * h * h), 1.0 / (lp * v0 * h * h)];
        let damping = rng.range(0.0, 0.1) / h;
        let d = neo_hookean_deviatoric(&rest, &dm).unwrap();
        let y = neo_hookean_hydrostatic(&rest, &dm, gamma);
        let up = neo_hookean_update(&d, &y, w, [0.0; 2], at, damping, [0.0; 2]).unwrap();
        let moved = up.moves.iter().map(|m| m.norm()).fold(0.0, f64::max);
        let stiffness = gram(&w, &y, &y) / at[1];
        assert!(
            moved < 4.0 * f64::EPSILON * size * (1.0 + stiffness),
            "f64 moves {moved} m at rest"
        );
        // The same tetrahedron in f32, placed away from the origin as a body would be.
        let shift = Vector3::new(1.0, -2.0, 0.5);
        let rest32 = rest.map(|x| (x + shift).cast::<f32>());
        let dm32 = rest_shape_inverse(&rest32[0], &rest32[1], &rest32[2], &rest32[3]).unwrap();
        let d32 = neo_hookean_deviatoric(&rest32, &dm32).unwrap();
        let y32 = neo_hookean_hydrostatic(&rest32, &dm32, gamma as f32);
        let w32 = w.map(|x| x as f32);
        let at32 = at.map(|x| x as f32);
        let up32 =
            neo_hookean_update(&d32, &y32, w32, [0.0; 2], at32, damping as f32, [0.0; 2]).unwrap();
        let moved = up32
            .moves
            .iter()
            .map(|m| f64::from(m.norm()))
            .fold(0.0, f64::max);
        let rounding = f64::from(f32::EPSILON) * (shift.norm() + size);
        assert!(
            moved < 4.0 * rounding * (1.0 + stiffness),
            "f32 moves {moved} m at rest, tetrahedron {size} m, G/α̃ {stiffness:e}"
        );
    }
}

#[test]
fn f32_matches_f64() {
    let mut rng = Rng::new(32);
    for _ in 0..100 {
        let rest = rng.tet(1.0);
        let dm = rest_shape_inverse(&rest[0], &rest[1], &rest[2], &rest[3]).unwrap();
        let p = deformed(&mut rng, &rest, 0.3, 0.05);
        let (d64, h64) = (
            neo_hookean_deviatoric(&p, &dm).unwrap(),
            neo_hookean_hydrostatic(&p, &dm, 1.1),
        );
        let p32 = p.map(|x| x.cast::<f32>());
        let dm32 = dm.cast::<f32>();
        let (d32, h32) = (
            neo_hookean_deviatoric(&p32, &dm32).unwrap(),
            neo_hookean_hydrostatic(&p32, &dm32, 1.1f32),
        );
        assert!((f64::from(d32.c) - d64.c).abs() < 1e-4 * d64.c);
        assert!((f64::from(h32.c) - h64.c).abs() < 1e-4 * (1.0 + h64.c.abs()));
        for i in 0..4 {
            assert!(
                (d32.grad[i].cast::<f64>() - d64.grad[i]).norm()
                    < 1e-4 * (1.0 + d64.grad[i].norm())
            );
            assert!(
                (h32.grad[i].cast::<f64>() - h64.grad[i]).norm()
                    < 1e-4 * (1.0 + h64.grad[i].norm())
            );
        }
    }
}
