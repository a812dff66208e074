//! The plastic flow system: once per frame, each tetrahedron of a body with a
//! [`Plasticity`] strained past its yield moves its rest shape toward its current shape, and
//! the body's families take their rest values from the new rest shapes (the model, the rule and
//! its bounds are documented on [`crate::Plasticity`]).

use std::cmp::Ordering;

use hecs::World;
use nalgebra::Matrix3;

use crate::body::activation::Asleep;
use crate::body::families::{EdgeConstraints, VertexFaceConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::particles::Particles;
use crate::body::plastic_rest::RestState;
use crate::body::plasticity::{built_edge_matrix, Plasticity, PlasticitySettings};

/// Flows the rest shapes of every awake body with a [`Plasticity`] for a frame of length
/// `dt` (s), then refreshes the rest values of the families it has (rest volumes, vertex–face
/// rest heights, edge rest lengths). Returns the number of tetrahedra that flowed.
///
/// Bodies without the component are never visited; a body whose component does not fit it
/// ([`Plasticity::fits`]) is skipped. Allocates nothing.
pub fn flow_plastically(world: &mut World, dt: f32) -> usize {
    let mut flowed = 0;
    let q = world.query_mut::<(
        &Particles,
        &mut Tetrahedra,
        &mut Plasticity,
        Option<&mut VertexFaceConstraints>,
        Option<&mut EdgeConstraints>,
        Option<&mut NeoHookeanMaterial>,
    )>();
    for (p, tetrahedra, plastic, vertex_face, edges, material) in q.without::<&Asleep>() {
        if !plastic.fits(tetrahedra, edges.as_deref()) {
            continue;
        }
        let mut rest = RestState {
            tetrahedra,
            vertex_face,
            edges,
            material,
        };
        let settings = plastic.settings;
        let quick = quick_bound(settings.yield_strain);
        let quick_sq = if quick > 0.0 { quick * quick } else { -1.0 };
        let mut body_flowed = 0;
        for t in 0..rest.tetrahedra.len() {
            let tet = rest.tetrahedra.indices[t];
            // Quick test in f32 on the cached inverse rest matrix: 2‖E‖ = ‖FᵀF − I‖ bounds
            // the strain the full test reads (see `flow`).
            let x = tet.map(|i| p.positions[i as usize]);
            let ds = Matrix3::from_columns(&[x[1] - x[0], x[2] - x[0], x[3] - x[0]]);
            let f = ds * plastic.inv_rest[t];
            if green_norm_sq(&f) <= quick_sq {
                continue;
            }
            let d0 = built_edge_matrix(tet, &p.rest_positions);
            let ds = built_edge_matrix(tet, &p.positions);
            if let Some(next) = flow(&plastic.stretch[t], &d0, &ds, &settings, f64::from(dt)) {
                plastic.set_stretch(t, next, rest.tetrahedra, &p.rest_positions);
                rest.refresh_tetrahedron(t, &next, &p.rest_positions);
                body_flowed += 1;
            }
        }
        if body_flowed > 0 {
            rest.refresh_edges(plastic, &p.rest_positions);
        }
        flowed += body_flowed;
    }
    flowed
}

/// The flow rule of one tetrahedron over `dt` (s): its next plastic stretch, or `None` when it
/// does not flow (strain within the yield, inverted, or a rate of zero).
///
/// `stretch` is its plastic stretch `P`, `d0` its built edge matrix `D⁰` and `ds` its current
/// one, m. With `F = Dₛ (P D⁰)⁻¹` and `U = √(FᵀF)`, the strain `ε = U − I` (deviatoric when
/// volume-preserving) flows by `γ = min(1, rate·dt)(‖ε‖ − y)/‖ε‖`: `P ← (I + γε)P`, capped at
/// `‖P − I‖ ≤ m` and, when volume-preserving, scaled to `det P = 1`.
pub(crate) fn flow(
    stretch: &Matrix3<f64>,
    d0: &Matrix3<f64>,
    ds: &Matrix3<f64>,
    s: &PlasticitySettings,
    dt: f64,
) -> Option<Matrix3<f64>> {
    let identity = Matrix3::<f64>::identity();
    let y = f64::from(s.yield_strain);
    let f = ds * (stretch * d0).try_inverse()?;
    if f.determinant().partial_cmp(&0.0) != Some(Ordering::Greater) {
        return None;
    }
    let c = f.transpose() * f;
    // Cheap bound first: every principal Biot strain is at most twice the Green strain
    // `E = (FᵀF − I)/2` in magnitude (`|√(1 + 2e) − 1| ≤ 2|e|`), and taking the deviatoric
    // part only shrinks a norm, so `2‖E‖ ≤ y` means no flow.
    if (c - identity).norm() <= y {
        return None;
    }
    let eigen = c.symmetric_eigen();
    let root = eigen.eigenvalues.map(|l| l.max(0.0).sqrt());
    let u = eigen.eigenvectors * Matrix3::from_diagonal(&root) * eigen.eigenvectors.transpose();
    let mut strain = u - identity;
    if s.volume_preserving {
        strain -= identity * (strain.trace() / 3.0);
    }
    let norm = strain.norm();
    if norm.partial_cmp(&y) != Some(Ordering::Greater) {
        return None;
    }
    let gamma = (f64::from(s.flow_rate) * dt).min(1.0) * (norm - y) / norm;
    if gamma.partial_cmp(&0.0) != Some(Ordering::Greater) {
        return None;
    }
    let mut next = (identity + strain * gamma) * stretch;
    if s.volume_preserving {
        next = unit_determinant(next)?;
    }
    let m = f64::from(s.max_plastic_strain);
    let deviation = next - identity;
    let dn = deviation.norm();
    if dn > m {
        next = identity + deviation * (m / dn);
        if s.volume_preserving {
            next = unit_determinant(next)?;
        }
    }
    (next.iter().all(|x| x.is_finite()) && next.determinant() > 0.0).then_some(next)
}

/// The bound on the `f32` quick test's `‖FᵀF − I‖` below which a tetrahedron cannot reach
/// the yield `y`: `y` less a margin for the rounding of `f32` products of unit-sized
/// matrices (negative, so never met, for a yield below the margin).
fn quick_bound(y: f32) -> f32 {
    y - 1e-4 * (1.0 + y)
}

/// `‖FᵀF − I‖²_F` from the six distinct entries of the symmetric `FᵀF`.
#[inline]
fn green_norm_sq(f: &Matrix3<f32>) -> f32 {
    let [a, b, c] = [f.column(0), f.column(1), f.column(2)];
    let (caa, cbb, ccc) = (a.dot(&a) - 1.0, b.dot(&b) - 1.0, c.dot(&c) - 1.0);
    let (cab, cac, cbc) = (a.dot(&b), a.dot(&c), b.dot(&c));
    caa * caa + cbb * cbb + ccc * ccc + 2.0 * (cab * cab + cac * cac + cbc * cbc)
}

/// `p` scaled to determinant 1, or `None` if its determinant is not positive.
fn unit_determinant(p: Matrix3<f64>) -> Option<Matrix3<f64>> {
    let det = p.determinant();
    (det > 0.0).then(|| p / det.cbrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    fn settings(volume_preserving: bool) -> PlasticitySettings {
        PlasticitySettings {
            yield_strain: 0.05,
            flow_rate: f32::INFINITY,
            max_plastic_strain: 0.9,
            volume_preserving,
        }
    }

    /// A shear past the yield, seen through a rotation, flows until the yield strain is left.
    #[test]
    fn full_flow_leaves_the_yield_strain() {
        let d0 = Matrix3::identity();
        let rot = Rotation3::from_axis_angle(&Vector3::y_axis(), 0.7);
        let shear = Matrix3::new(1.0, 0.3, 0.0, 0.3, 1.0, 0.0, 0.0, 0.0, 1.0);
        for vp in [false, true] {
            let s = settings(vp);
            let ds = rot.matrix() * shear;
            let p = flow(&Matrix3::identity(), &d0, &ds, &s, 1.0 / 60.0).unwrap();
            if vp {
                assert!((p.determinant() - 1.0).abs() < 1e-12);
            }
            // The strain left against the new rest shape.
            let f = ds * p.try_inverse().unwrap();
            let eig = (f.transpose() * f).symmetric_eigen();
            let u = eig.eigenvectors
                * Matrix3::from_diagonal(&eig.eigenvalues.map(f64::sqrt))
                * eig.eigenvectors.transpose();
            let mut e = u - Matrix3::identity();
            if vp {
                e -= Matrix3::identity() * (e.trace() / 3.0);
            }
            // The linear update leaves the yield to first order in the strain.
            assert!((e.norm() - 0.05).abs() < 0.02, "left {}", e.norm());
        }
    }

    /// Strain within the yield, an inverted or non-finite shape and a zero rate never flow.
    #[test]
    fn nothing_flows_within_the_yield_or_inverted() {
        let d0 = Matrix3::identity();
        let s = settings(false);
        let small = Matrix3::new(1.0, 0.02, 0.0, 0.02, 1.0, 0.0, 0.0, 0.0, 1.0);
        assert!(flow(&Matrix3::identity(), &d0, &small, &s, 0.1).is_none());
        let mirrored = Matrix3::from_diagonal(&Vector3::new(-1.5, 1.0, 1.0));
        assert!(flow(&Matrix3::identity(), &d0, &mirrored, &s, 0.1).is_none());
        let stopped = PlasticitySettings {
            flow_rate: 0.0,
            ..s
        };
        let big = Matrix3::from_diagonal(&Vector3::new(2.0, 1.0, 1.0));
        assert!(flow(&Matrix3::identity(), &d0, &big, &stopped, 0.1).is_none());
        for bad in [f64::NAN, f64::INFINITY] {
            let ds = Matrix3::from_diagonal(&Vector3::new(bad, 1.0, 1.0));
            assert!(flow(&Matrix3::identity(), &d0, &ds, &s, 0.1).is_none());
        }
    }

    /// However far a tetrahedron is crushed, again and again, its plastic stretch stays
    /// within the cap and keeps a positive determinant.
    #[test]
    fn repeated_crushing_stays_within_the_cap() {
        let d0 = Matrix3::identity();
        for vp in [false, true] {
            let s = PlasticitySettings {
                max_plastic_strain: 0.6,
                ..settings(vp)
            };
            let mut p = Matrix3::identity();
            let crush = Matrix3::from_diagonal(&Vector3::new(0.05, 3.0, 1.0));
            for _ in 0..50 {
                if let Some(next) = flow(&p, &d0, &(crush * p), &s, 0.1) {
                    p = next;
                }
                let m = f64::from(s.max_plastic_strain);
                let svd = p.svd(false, false);
                assert!(svd.singular_values.min() >= (1.0 - m) / (1.0 + m) - 1e-12);
                assert!(p.determinant() > 0.0);
                if !vp {
                    let n = (p - Matrix3::identity()).norm();
                    assert!(n <= m + 1e-12, "{n}");
                }
            }
        }
    }

    /// The quick test's norm is the full one's `‖FᵀF − I‖²`.
    #[test]
    fn quick_norm_matches_the_matrix_norm() {
        let f = Matrix3::new(1.1f32, 0.2, -0.3, 0.05, 0.9, 0.4, -0.2, 0.1, 1.3);
        let full = (f.tr_mul(&f) - Matrix3::identity()).norm_squared();
        assert!((green_norm_sq(&f) - full).abs() < 1e-5 * full);
    }
}
