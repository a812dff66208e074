//! Plasticity: a body whose rest shape flows toward the shape it is held in.
//!
//! The model, its flow rule and its bounds are documented on [`Plasticity`].

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use nalgebra::{Matrix3, Vector3};

use crate::body::families::EdgeConstraints;
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::error::PlasticityError;

/// Largest relative change of a tetrahedron's rest volume under volume-preserving flow:
/// `|Vₜ / V⁰ₜ − 1| ≤ 1e-6` (the `f32` rounding of the stored volume, with margin).
pub const VOLUME_PRESERVING_TOLERANCE: f32 = 1e-6;

/// The settings of a body's plastic flow (see [`Plasticity`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct PlasticitySettings {
    /// Yield strain (dimensionless, `≥ 0`): the Frobenius norm of the elastic strain
    /// `ε = U − I` (its deviatoric part when volume-preserving) past which the rest shape
    /// flows. Default 0.05.
    pub yield_strain: f32,
    /// Flow (creep) rate, 1/s (`≥ 0`, `f32::INFINITY` allowed): the fraction of the strain in
    /// excess of the yield absorbed into the rest shape per second; at `rate · dt ≥ 1` all of it
    /// flows in one frame. Default 20 1/s.
    pub flow_rate: f32,
    /// Maximum plastic strain (dimensionless, `0 ≤ m < 1`): the bound on `‖P − I‖_F` for each
    /// tetrahedron's plastic stretch `P`. Default 0.5.
    pub max_plastic_strain: f32,
    /// Flow only the deviatoric (shape) part of the strain and keep `det P = 1`: every rest
    /// volume stays within [`VOLUME_PRESERVING_TOLERANCE`] of its built value, as in metals
    /// and clay, whose plastic flow keeps their volume. Default `true`.
    pub volume_preserving: bool,
}

impl Default for PlasticitySettings {
    fn default() -> Self {
        PlasticitySettings {
            yield_strain: 0.05,
            flow_rate: 20.0,
            max_plastic_strain: 0.5,
            volume_preserving: true,
        }
    }
}

impl PlasticitySettings {
    /// Checks every setting, naming the first bad one and its value.
    pub fn validate(&self) -> Result<(), PlasticityError> {
        let y = self.yield_strain;
        if !(y.is_finite() && y >= 0.0) {
            return Err(PlasticityError::BadYieldStrain { value: y });
        }
        let r = self.flow_rate;
        if r.is_nan() || r < 0.0 {
            return Err(PlasticityError::BadFlowRate { value: r });
        }
        let m = self.max_plastic_strain;
        if !(m.is_finite() && (0.0..1.0).contains(&m)) {
            return Err(PlasticityError::BadMaxPlasticStrain { value: m });
        }
        Ok(())
    }
}

/// A body's plastic state (a hecs component): its [`PlasticitySettings`] and the plastic
/// stretch of each tetrahedron. A body without it never flows and pays nothing.
///
/// # Model
///
/// Each tetrahedron `t` carries a *plastic stretch* `Pₜ` (3 × 3, identity when built). Its
/// rest edge matrix is `Dₜ = Pₜ D⁰ₜ`, with `D⁰ₜ = [r₁ − r₀, r₂ − r₀, r₃ − r₀]` the columns of
/// its built rest corners ([`crate::Particles::rest_positions`], never changed). Every rest
/// value of every family the body has is read from the `Dₜ`:
///
/// - rest volume (in [`crate::Tetrahedra`]): `Vₜ = det(Dₜ) / 6 = det(Pₜ) V⁰ₜ`;
/// - vertex–face rest heights ([`crate::VertexFaceConstraints`]): each corner's signed height
///   above its opposite face, corners at `0` and the columns of `Dₜ`;
/// - edge rest lengths ([`crate::EdgeConstraints`]): the length of the edge in each incident
///   tetrahedron's rest shape, averaged over those tetrahedra;
/// - the material's inverse rest shapes ([`crate::NeoHookeanMaterial`]): `Dₜ⁻¹`.
///
/// # Flow rule
///
/// Once per frame (length `dt`, s) the solver reads each tetrahedron's deformation against its
/// current rest shape, `F = Dₛ Dₜ⁻¹` (`Dₛ`: current edge matrix), and its stretch
/// `U = √(FᵀF)` (rotation removed). The elastic strain is `ε = U − I` (dimensionless), or its
/// deviatoric part `ε − tr(ε)/3 · I` with [`PlasticitySettings::volume_preserving`]. When
/// `‖ε‖_F` exceeds the yield `y`, a fraction of the excess flows into the rest shape:
///
/// ```text
/// γ = min(1, rate · dt) · (‖ε‖ − y) / ‖ε‖,   P ← (I + γ ε) P
/// ```
///
/// so an infinite rate leaves exactly the yield strain, and a finite one creeps at `rate`
/// (1/s). An inverted tetrahedron (`det F ≤ 0`) does not flow.
///
/// # Bounds (the rest state stays valid)
///
/// The accumulated flow is capped: `‖P − I‖_F ≤ m` ([`PlasticitySettings::max_plastic_strain`],
/// `0 ≤ m < 1`), a flow past it is scaled back onto the bound. Since the spectral norm is at
/// most the Frobenius norm, every singular value of `P` lies in `[1 − m, 1 + m]`: a rest shape
/// is never inverted nor flattened, its volume stays within `[(1 − m)³, (1 + m)³]` of the built
/// one, and its condition number grows by at most `(1 + m)/(1 − m)`. With
/// [`PlasticitySettings::volume_preserving`], `P` is scaled to `det P = 1` after each flow
/// (a uniform scale, so the singular-value bound on the shape's condition number holds), and
/// every rest volume stays within [`VOLUME_PRESERVING_TOLERANCE`] of its built value.
///
/// The stretch is kept in `f64`, so the rounding of one flow never accumulates into the next.
///
/// Made by [`crate::SoftBodyBuilder::plasticity`], or by [`Plasticity::new`] for a body
/// already built. A `Plasticity` made for another body (another number of tetrahedra or
/// edges) is ignored by the solver; [`Plasticity::fits`] tells.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Plasticity {
    pub(crate) settings: PlasticitySettings,
    /// Plastic stretch `P` of each tetrahedron, in solver order (dimensionless).
    pub(crate) stretch: Vec<Matrix3<f64>>,
    /// `(P D⁰)⁻¹` of each tetrahedron, 1/m: the deformation gradient `F = Dₛ (P D⁰)⁻¹` in one
    /// product, for the flow pass's quick test of the yield.
    pub(crate) inv_rest: Vec<Matrix3<f32>>,
    /// For each edge of the body's [`EdgeConstraints`], in their order, the range of
    /// `edge_corners` that lists it; empty when the body has no edge family.
    pub(crate) edge_offsets: Vec<u32>,
    /// `(tetrahedron, corner a, corner b)` of each edge's occurrences.
    pub(crate) edge_corners: Vec<(u32, [u8; 2])>,
}

impl Plasticity {
    /// The plastic state of a body with these particles, tetrahedra and edge family, at its
    /// built rest shape (no flow yet). Errors: a bad setting ([`PlasticitySettings::validate`]).
    pub fn new(
        settings: PlasticitySettings,
        particles: &Particles,
        tetrahedra: &Tetrahedra,
        edges: Option<&EdgeConstraints>,
    ) -> Result<Plasticity, PlasticityError> {
        settings.validate()?;
        let (edge_offsets, edge_corners) = match edges {
            Some(e) => edge_incidence(&tetrahedra.indices, &e.edges),
            None => (Vec::new(), Vec::new()),
        };
        let mut plastic = Plasticity {
            settings,
            stretch: vec![Matrix3::identity(); tetrahedra.len()],
            inv_rest: vec![Matrix3::zeros(); tetrahedra.len()],
            edge_offsets,
            edge_corners,
        };
        for t in 0..tetrahedra.len() {
            plastic.set_stretch(
                t,
                Matrix3::identity(),
                tetrahedra,
                &particles.rest_positions,
            );
        }
        Ok(plastic)
    }

    /// Sets tetrahedron `t`'s plastic stretch and the inverse of its rest edge matrix.
    pub(crate) fn set_stretch(
        &mut self,
        t: usize,
        stretch: Matrix3<f64>,
        tetrahedra: &Tetrahedra,
        rest_positions: &[Vector3<f32>],
    ) {
        self.stretch[t] = stretch;
        let dm = stretch * built_edge_matrix(tetrahedra.indices[t], rest_positions);
        // The builder rejects degenerate tetrahedra and the flow keeps `P` regular, so the
        // inverse exists; zeros would only make the quick test defer to the full one.
        self.inv_rest[t] = dm
            .try_inverse()
            .unwrap_or_else(Matrix3::zeros)
            .cast::<f32>();
    }

    /// The settings.
    pub fn settings(&self) -> &PlasticitySettings {
        &self.settings
    }

    /// Replaces the settings; rejects bad ones and keeps the old ones then.
    pub fn set_settings(&mut self, settings: PlasticitySettings) -> Result<(), PlasticityError> {
        settings.validate()?;
        self.settings = settings;
        Ok(())
    }

    /// Whether this state was made for a body with these tetrahedra and edge family (the
    /// solver skips a body it does not fit).
    pub fn fits(&self, tetrahedra: &Tetrahedra, edges: Option<&EdgeConstraints>) -> bool {
        let edge_count = edges.map_or(0, |e| e.len());
        let listed = self.edge_offsets.len().saturating_sub(1);
        self.stretch.len() == tetrahedra.len()
            && self.inv_rest.len() == tetrahedra.len()
            && listed == edge_count
    }

    /// Plastic stretch `P` of each tetrahedron (dimensionless), in the order of
    /// [`crate::Tetrahedra::indices`].
    pub fn stretches(&self) -> &[Matrix3<f64>] {
        &self.stretch
    }

    /// Plastic strain `‖P − I‖_F` of tetrahedron `t` (dimensionless; at most
    /// [`PlasticitySettings::max_plastic_strain`], or slightly more after the unit-determinant
    /// scaling of volume-preserving flow), or `None` if there is no tetrahedron `t`.
    pub fn plastic_strain(&self, t: usize) -> Option<f32> {
        let p = self.stretch.get(t)?;
        Some((p - Matrix3::identity()).norm() as f32)
    }

    /// The largest plastic strain of any tetrahedron (0 for a body that never flowed).
    pub fn max_plastic_strain(&self) -> f32 {
        self.stretch
            .iter()
            .map(|p| (p - Matrix3::identity()).norm() as f32)
            .fold(0.0, f32::max)
    }

    /// The current rest edge matrix `Dₜ = Pₜ D⁰ₜ` of tetrahedron `t` (columns `q₁ − q₀`,
    /// `q₂ − q₀`, `q₃ − q₀` of its rest corners, m) of the body with these particles and
    /// tetrahedra, or `None` if `t` is out of range or this state does not fit the body.
    pub fn rest_edge_matrix(
        &self,
        t: usize,
        particles: &Particles,
        tetrahedra: &Tetrahedra,
    ) -> Option<Matrix3<f64>> {
        let (p, tet) = (self.stretch.get(t)?, tetrahedra.indices.get(t)?);
        let rest = &particles.rest_positions;
        if tet.iter().any(|&i| i as usize >= rest.len()) {
            return None;
        }
        Some(p * built_edge_matrix(*tet, rest))
    }

    /// Puts every rest shape of the body back to the built one (`P = I`) and with it the
    /// rest values of every family it has, exactly as built; the particles stay where they
    /// are and spring back from there. Does nothing and returns `false` when this state
    /// does not [fit](Self::fits) the body.
    pub fn reset(
        &mut self,
        particles: &Particles,
        tetrahedra: &mut Tetrahedra,
        vertex_face: Option<&mut crate::VertexFaceConstraints>,
        edges: Option<&mut EdgeConstraints>,
        material: Option<&mut crate::NeoHookeanMaterial>,
    ) -> bool {
        let vf_fits = vertex_face
            .as_ref()
            .is_none_or(|v| v.rest_heights.len() == tetrahedra.len());
        if !(self.fits(tetrahedra, edges.as_deref()) && vf_fits) {
            return false;
        }
        let rest_positions = &particles.rest_positions;
        for t in 0..tetrahedra.len() {
            self.set_stretch(t, Matrix3::identity(), tetrahedra, rest_positions);
        }
        let rest = crate::body::plastic_rest::RestState {
            tetrahedra,
            vertex_face,
            edges,
            material,
        };
        rest.refresh_all(self, rest_positions);
        true
    }
}

impl Plasticity {
    /// The plastic state of a piece of this body (after a split): tetrahedron `k` of the
    /// piece is tetrahedron `from[k]` of this body and keeps its plastic stretch; the edge
    /// incidence is that of the piece's `tets` and `edges`.
    pub(crate) fn for_piece(
        &self,
        from: &[u32],
        tets: &[[u32; 4]],
        edges: Option<&EdgeConstraints>,
    ) -> Plasticity {
        let (edge_offsets, edge_corners) = match edges {
            Some(e) => edge_incidence(tets, &e.edges),
            None => (Vec::new(), Vec::new()),
        };
        Plasticity {
            settings: self.settings,
            stretch: from.iter().map(|&t| self.stretch[t as usize]).collect(),
            inv_rest: from.iter().map(|&t| self.inv_rest[t as usize]).collect(),
            edge_offsets,
            edge_corners,
        }
    }
}

/// `[r₁ − r₀, r₂ − r₀, r₃ − r₀]` of tetrahedron `tet` at `positions`, in `f64`, m.
pub(crate) fn built_edge_matrix(tet: [u32; 4], positions: &[Vector3<f32>]) -> Matrix3<f64> {
    let p = tet.map(|i| positions[i as usize].cast::<f64>());
    Matrix3::from_columns(&[p[1] - p[0], p[2] - p[0], p[3] - p[0]])
}

/// For each edge of `edges` (in their order), where it occurs in `tets`: CSR offsets and
/// `(tetrahedron, corner a, corner b)` entries, with `edges[k] = [tet[a], tet[b]]` up to order.
/// Sorted, no hash maps (deterministic).
fn edge_incidence(tets: &[[u32; 4]], edges: &[[u32; 2]]) -> (Vec<u32>, Vec<(u32, [u8; 2])>) {
    let mut occurrences: Vec<([u32; 2], u32, [u8; 2])> = Vec::with_capacity(tets.len() * 6);
    for (t, tet) in tets.iter().enumerate() {
        for a in 0..4u8 {
            for b in a + 1..4u8 {
                let (i, j) = (tet[a as usize], tet[b as usize]);
                occurrences.push(([i.min(j), i.max(j)], t as u32, [a, b]));
            }
        }
    }
    occurrences.sort_unstable();
    let mut offsets = Vec::with_capacity(edges.len() + 1);
    let mut corners = Vec::with_capacity(occurrences.len());
    offsets.push(0);
    for &[i, j] in edges {
        let key = [i.min(j), i.max(j)];
        let start = occurrences.partition_point(|o| o.0 < key);
        for o in occurrences[start..].iter().take_while(|o| o.0 == key) {
            corners.push((o.1, o.2));
        }
        offsets.push(corners.len() as u32);
    }
    (offsets, corners)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generators::{box_grid, CellSplit};
    use crate::SoftBodyBuilder;

    /// Every edge occurs in at least one tetrahedron, with corners naming its two particles.
    #[test]
    fn every_edge_is_found_in_its_tetrahedra() {
        let mesh = box_grid(Vector3::new(2.0, 1.0, 1.0), [3, 2, 2], CellSplit::Five).unwrap();
        let body = SoftBodyBuilder::new(mesh).edges(0.0).build().unwrap();
        let e = body.edges.as_ref().unwrap();
        let (particles, tets) = (&body.particles, &body.tetrahedra);
        let p = Plasticity::new(Default::default(), particles, tets, Some(e)).unwrap();
        assert!(p.fits(&body.tetrahedra, Some(e)));
        assert!(!p.fits(&body.tetrahedra, None));
        for (k, &[i, j]) in e.edges.iter().enumerate() {
            let r = p.edge_offsets[k] as usize..p.edge_offsets[k + 1] as usize;
            assert!(!r.is_empty(), "edge {k} in no tetrahedron");
            for &(t, [a, b]) in &p.edge_corners[r] {
                let tet = body.tetrahedra.indices[t as usize];
                let pair = [tet[a as usize], tet[b as usize]];
                assert!(pair == [i, j] || pair == [j, i]);
            }
        }
    }
}
