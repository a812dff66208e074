//! How fast a soft body's constraints carry a contact's push through it within a substep.
//!
//! [`crate::ImpactReach`] resolves a contact locally up to a quarter of a cell per substep,
//! the rest by the whole body. That bounds how deep a *particle* goes; it does not bound how
//! fast the body *behind* a stopped surface keeps coming. With hard constraints a substep
//! carries the stop one cell or more into the body, so the body behind the surface meets
//! it within the substep. With compliant constraints and short substeps it does not:
//! `α̃ = α/h²` grows as `1/h²`, each substep's projection carries only a fraction of the
//! push, and a 0.5 m cube at 300 m/s (6 cm a substep at 80 substeps, a cell every two
//! substeps) runs through its own stopped bottom layer while no surface particle ever goes
//! deeper than the reach. More substeps made it worse.
//!
//! The speed at which the constraints carry a push is the body's longitudinal wave speed
//! `c = √(M/ρ)`, `M` the stiffest family's modulus and `ρ` the body's density
//! ([`wave_speed`]); within one substep no solver carries it faster than one cell, `L/h`.
//! A body meeting a wall at speed `v` is strained by `v/c` where the wall stops a whole
//! face at once. Where the contact first meets it on a small patch (a ball, an edge, a
//! tilted face), the stopped region is smaller than the body's cross-section and the strain
//! around it is larger: a soft ball (radius 0.4 m, 6³ cells) inverted tetrahedra thrown at
//! 0.38 `c` and none at 0.19 `c`, while a cube took 0.25 `c` at any size. So a body that
//! approaches a contact faster than [`APPROACH_STRAIN`] × `c` (an eighth of its wave speed)
//! or than its local reach a substep (a quarter cell) has the excess approach taken by the
//! whole body, as a contact's excess depth is ([`crate::ImpactReach::limit_approach`]).
//! With hard constraints (`c = ∞`) this is the quarter cell per substep the particle rule
//! already holds; with compliant ones it is less.

use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::particles::Particles;

/// The longitudinal wave speed of a body, m/s: `√(M/ρ)` with `ρ` its mass over its rest
/// volume and `M` the largest of its families' moduli (Pa): edge and vertex–face
/// constraints `1/(α L̄)` (α in m/N, `L̄` the mean rest edge length, m), volume constraints
/// `V̄/α` (α in m⁵/N, `V̄` the mean rest tetrahedron volume, m³), the material `λ + 2μ`.
/// `f32::INFINITY` for a family with α = 0 (rigid within a substep) or a body without any
/// family or with no volume or mass.
pub fn wave_speed(
    p: &Particles,
    tets: &Tetrahedra,
    edges: Option<&EdgeConstraints>,
    vertex_face: Option<&VertexFaceConstraints>,
    volume: Option<&VolumeConstraints>,
    material: Option<&NeoHookeanMaterial>,
) -> f32 {
    let rigid = edges.is_some_and(|e| e.compliance <= 0.0)
        || vertex_face.is_some_and(|v| v.compliance <= 0.0)
        || volume.is_some_and(|v| v.compliance <= 0.0);
    if rigid {
        return f32::INFINITY;
    }
    let total_volume: f64 = tets.rest_volumes.iter().map(|v| f64::from(v.abs())).sum();
    let mass: f64 = p.masses().iter().map(|&m| f64::from(m)).sum();
    if !(total_volume > 0.0 && mass > 0.0) || tets.is_empty() {
        return f32::INFINITY;
    }
    let mean_volume = total_volume / tets.len() as f64;
    // Mean rest edge length of the tetrahedra's cells: the cube root of the mean volume
    // scaled to a cell of five or six tetrahedra is within a factor of two; the edge
    // family's own rest lengths when present.
    let edge_length = edges
        .filter(|e| !e.rest_lengths.is_empty())
        .map_or((6.0 * mean_volume).cbrt(), |e| {
            e.rest_lengths.iter().map(|&l| f64::from(l)).sum::<f64>() / e.rest_lengths.len() as f64
        });
    let mut modulus = 0.0f64;
    let mut compliant = |alpha: f32, scale: f64| {
        modulus = modulus.max(scale / f64::from(alpha));
    };
    if let Some(e) = edges {
        compliant(e.compliance, 1.0 / edge_length);
    }
    if let Some(v) = vertex_face {
        compliant(v.compliance, 1.0 / edge_length);
    }
    if let Some(v) = volume {
        compliant(v.compliance, mean_volume);
    }
    if let Some(m) = material {
        let (mu, lambda) = m.material().lame();
        modulus = modulus.max(f64::from(lambda) + 2.0 * f64::from(mu));
    }
    if modulus <= 0.0 {
        return f32::INFINITY;
    }
    let c = (modulus * total_volume / mass).sqrt() as f32;
    if c.is_finite() && c > 0.0 {
        c
    } else {
        f32::INFINITY
    }
}

/// The elastic strain `v/c` an impact may leave in a body's cells before the excess of its
/// approach speed `v` is taken by the whole body (dimensionless; module docs). An eighth: a
/// quarter holds on a flat face but inverted tetrahedra of balls
/// (`docs/decisions/impact-approach-speed.md`).
pub const APPROACH_STRAIN: f32 = 0.125;

/// How far a body may approach a contact within a substep of `h` (s) before the excess is
/// taken by the whole body, m: `min(APPROACH_STRAIN × c h, reach)` with `c` the body's
/// [`wave_speed`] (m/s) and `reach` its local reach ([`crate::local_reach`], m, a quarter
/// cell). `reach` itself for a rigid family (`c = ∞`).
pub fn approach_limit(reach: f32, c: f32, h: f32) -> f32 {
    let carried = APPROACH_STRAIN * c * h;
    if carried.is_nan() {
        reach
    } else {
        reach.min(carried)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generators::{box_grid, CellSplit};
    use crate::{Material, SoftBodyBuilder};
    use nalgebra::Vector3;

    fn speed(b: SoftBodyBuilder) -> f32 {
        let body = b.build().unwrap();
        wave_speed(
            &body.particles,
            &body.tetrahedra,
            body.edges.as_ref(),
            body.vertex_face.as_ref(),
            body.volume.as_ref(),
            body.material.as_ref(),
        )
    }

    fn mesh() -> crate::TetMesh {
        box_grid(Vector3::repeat(0.5), [4; 3], CellSplit::Five).unwrap()
    }

    #[test]
    fn hard_constraints_carry_a_push_at_any_speed() {
        let c = speed(
            SoftBodyBuilder::new(mesh())
                .density(1000.0)
                .edges(0.0)
                .volume(1e-9),
        );
        assert_eq!(c, f32::INFINITY);
    }

    #[test]
    fn the_wave_speed_grows_as_the_root_of_the_stiffness_and_falls_with_density() {
        let c =
            |alpha: f32, rho: f32| speed(SoftBodyBuilder::new(mesh()).density(rho).edges(alpha));
        let base = c(1e-6, 1000.0);
        assert!(base.is_finite() && base > 0.0);
        assert!((c(1e-6 / 4.0, 1000.0) / base - 2.0).abs() < 1e-3);
        assert!((c(1e-6, 4000.0) / base - 0.5).abs() < 1e-3);
    }

    #[test]
    fn the_material_wave_speed_is_the_longitudinal_one() {
        let m = Material::SOFT_TISSUE;
        let (mu, lambda) = m.lame();
        let c = speed(SoftBodyBuilder::new(mesh()).density(1000.0).material(m));
        let expected = ((lambda + 2.0 * mu) / 1000.0).sqrt();
        assert!((c / expected - 1.0).abs() < 1e-3, "{c} vs {expected}");
    }

    #[test]
    fn the_approach_limit_is_the_reach_when_the_constraints_keep_up_and_less_when_not() {
        assert_eq!(approach_limit(0.03, f32::INFINITY, 1e-3), 0.03);
        assert_eq!(approach_limit(0.03, 1e6, 1e-3), 0.03);
        let slow = approach_limit(0.03, 10.0, 1e-3);
        assert!((slow - APPROACH_STRAIN * 10.0 * 1e-3).abs() < 1e-9);
    }
}
