//! [`NeoHookeanMaterial`]: the stable Neo-Hookean material of a body's tetrahedra, an optional
//! hecs component like the constraint families (a body without it pays nothing).

use nalgebra::Matrix3;

use crate::body::material::{Material, MaterialError};
use crate::body::mesh::Tetrahedra;
use crate::constraints::rest_shape_inverse;

/// The stable Neo-Hookean material of every tetrahedron of a body (two constraints each,
/// solved together; theory in [`crate::constraints::neo_hookean_deviatoric`] and
/// [`crate::constraints::neo_hookean_update`]), with the rest shape of each
/// tetrahedron. Compliances follow from the [`Material`] and each rest volume:
/// `α_D = 1/(μ V₀)`, `α_H = 1/(λ' V₀)` (1/J), `λ' = λ + μ`.
///
/// Combines with the seed's families: a body may have this component alone or with
/// [`crate::EdgeConstraints`], [`crate::VertexFaceConstraints`] and
/// [`crate::VolumeConstraints`]; the solver projects the material first in each iteration.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct NeoHookeanMaterial {
    pub(crate) material: Material,
    /// `Dm⁻¹` of each tetrahedron (solver order, as [`Tetrahedra`]), 1/m.
    pub(crate) rest_inverse: Vec<Matrix3<f32>>,
    /// `[λ_D, λ_H]` of each tetrahedron, J·s² (dimensionless `C` over `α̃`; reset every substep).
    pub(crate) lambdas: Vec<[f32; 2]>,
    /// Elastic energy released by the material's projections in the current substep, J (the
    /// energy limit's budget; reset every substep).
    pub(crate) released: f64,
    /// The energy each tetrahedron's last projection released, J (scratch of the sweep,
    /// summed into `released` in tetrahedron order, so the sum does not depend on how the
    /// sweep was split among threads).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) tet_released: ReleasedScratch,
}

/// The per-tetrahedron released energies of the last sweep: scratch, not state (never
/// serialized, equal whatever it holds, sized by the sweep on first use).
#[derive(Clone, Debug, Default)]
pub(crate) struct ReleasedScratch(pub(crate) Vec<f32>);

impl PartialEq for ReleasedScratch {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl NeoHookeanMaterial {
    /// The material of `tets` at the rest positions `rest` (m, indexed like the tetrahedra).
    /// Tetrahedra were checked non-degenerate by the builder; a singular rest shape gets a zero
    /// `Dm⁻¹` (no force).
    pub(crate) fn new(
        material: Material,
        tets: &Tetrahedra,
        rest: &[nalgebra::Vector3<f32>],
    ) -> Self {
        let rest_inverse = tets
            .indices
            .iter()
            .map(|t| {
                let [a, b, c, d] = t.map(|i| rest[i as usize].cast::<f64>());
                rest_shape_inverse(&a, &b, &c, &d).map_or(Matrix3::zeros(), |m| m.cast::<f32>())
            })
            .collect();
        NeoHookeanMaterial {
            material,
            rest_inverse,
            lambdas: vec![[0.0; 2]; tets.indices.len()],
            released: 0.0,
            tet_released: ReleasedScratch(vec![0.0; tets.indices.len()]),
        }
    }

    /// Sets tetrahedron `t`'s rest shape to the edge matrix `dm` (m), as the plastic flow
    /// moves it; `built` gives back the builder's `Dm⁻¹` of `tet` at `rest` bit for bit.
    pub(crate) fn set_rest_shape(
        &mut self,
        t: usize,
        tet: [u32; 4],
        dm: &Matrix3<f64>,
        built: bool,
        rest: &[nalgebra::Vector3<f32>],
    ) {
        let inverse = if built {
            let [a, b, c, d] = tet.map(|i| rest[i as usize].cast::<f64>());
            rest_shape_inverse(&a, &b, &c, &d)
        } else {
            dm.try_inverse()
        };
        if let (Some(slot), Some(m)) = (self.rest_inverse.get_mut(t), inverse) {
            *slot = m.cast::<f32>();
        }
    }

    /// The material's parameters.
    pub fn material(&self) -> Material {
        self.material
    }

    /// Changes the material (E, ν, damping) of the body; the rest shape stays.
    pub fn set_material(&mut self, material: Material) {
        self.material = material;
    }

    /// Changes the damping time, s (finite, ≥ 0).
    pub fn set_damping(&mut self, beta: f32) -> Result<(), MaterialError> {
        self.material = self.material.with_damping(beta)?;
        Ok(())
    }

    /// Number of tetrahedra (two constraints each).
    pub fn len(&self) -> usize {
        self.lambdas.len()
    }

    /// `true` when there is no tetrahedron.
    pub fn is_empty(&self) -> bool {
        self.lambdas.is_empty()
    }

    /// The inverse rest edge matrix `Dm⁻¹` of each tetrahedron, 1/m.
    pub fn rest_inverse(&self) -> &[Matrix3<f32>] {
        &self.rest_inverse
    }

    /// The longest substep (s) at which this material is stable on this body:
    /// `0.1 L/c`, with `c = √(μ/ρ)` the shear wave speed (`ρ` the body's mean density, from
    /// `particles`' masses and the rest volumes) and `L = √(3/2) a` the edge of the regular
    /// tetrahedron whose altitude `a` is the smallest rest altitude of the body's tetrahedra
    /// (`3V/A` of the largest face: the thinnest direction a wave crosses).
    ///
    /// Why there is a bound: the two constraints are isotropic invariants of `F`, whose
    /// gradients at rest are both along the volume change, so the material's shear stiffness
    /// lives entirely in their curvature times their (non-zero) rest multipliers, and XPBD
    /// integrates that part explicitly. Shear waves then need the explicit (CFL) condition
    /// `h ≲ 0.3 L / c`; past it a body at rest starts to vibrate by itself. The wave crosses a
    /// sliver in its thin direction, so `L` comes from the smallest altitude, not the smallest
    /// volume (a 1 m × 1 mm × 1 m sliver has the volume of a regular tetrahedron of 5 cm edge).
    /// Choose `substeps ≥ dt / max_stable_substep` (`SolverSettings::substeps`).
    pub fn max_stable_substep(&self, tets: &Tetrahedra, particles: &crate::Particles) -> f32 {
        let volume: f64 = tets.rest_volumes.iter().map(|v| f64::from(v.abs())).sum();
        let mass: f64 = particles.masses().iter().map(|&m| f64::from(m)).sum();
        let altitude = smallest_rest_altitude(tets, particles.rest_positions());
        let (mu, _) = self.material.lame();
        let c = (f64::from(mu) * volume / mass).sqrt();
        let l = 1.5f64.sqrt() * altitude;
        (0.1 * l / c) as f32
    }

    /// The material's elastic energy `Σ V₀ Ψ(F)` at `positions` (J; zero at rest), with the
    /// body's tetrahedra.
    pub fn elastic_energy(&self, tets: &Tetrahedra, positions: &[nalgebra::Vector3<f32>]) -> f64 {
        let (mu, lambda) = self.material.lame();
        let (mu, lp) = (f64::from(mu), f64::from(lambda) + f64::from(mu));
        tets.indices
            .iter()
            .zip(&self.rest_inverse)
            .zip(&tets.rest_volumes)
            .map(|((t, dm), v0)| {
                let p = t.map(|i| positions[i as usize].cast::<f64>());
                let f = crate::constraints::deformation_gradient(&p, &dm.cast::<f64>());
                f64::from(v0.abs()) * crate::constraints::neo_hookean_energy_density(&f, mu, lp)
            })
            .sum()
    }
}

/// The smallest altitude `3|V|/A_max` of the tetrahedra of `tets` at the rest positions
/// `rest`, m (f64; `f64::INFINITY` for no tetrahedron or indices past `rest`).
fn smallest_rest_altitude(tets: &Tetrahedra, rest: &[nalgebra::Vector3<f32>]) -> f64 {
    let mut smallest = f64::INFINITY;
    for (t, v0) in tets.indices.iter().zip(&tets.rest_volumes) {
        let corners = t.map(|i| rest.get(i as usize).map(|v| v.cast::<f64>()));
        let [Some(a), Some(b), Some(c), Some(d)] = corners else {
            continue;
        };
        let x = [a, b, c, d];
        let largest_face = crate::stabilisation::sliver_orientation::largest_face(&x);
        if largest_face > 0.0 {
            smallest = smallest.min(3.0 * f64::from(v0.abs()) / largest_face);
        }
    }
    smallest
}
