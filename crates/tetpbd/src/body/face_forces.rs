//! The force a body transmits across each face shared by two tetrahedra, from the constraint
//! multipliers of the frame's last substep: what tearing by force compares with its
//! threshold.
//!
//! # From multipliers to forces
//!
//! In a substep of length `h`, XPBD moves particle `i` by `Δxᵢ = wᵢ ∇ᵢC Δλ` per projection
//! of a constraint `C`; the accumulated multiplier `λ` of the substep is an impulse times `h`,
//! and the constraint's force on particle `i` is
//!
//! ```text
//! fᵢ = ∇ᵢC λ / h²        (N)
//! ```
//!
//! whatever `C`'s units: `α` has the units of `C²/J`, so `λ` (`−C h²/α` at convergence) has
//! those of `J·s²/C` and `∇ᵢC` those of `C/m`. At convergence `λ = −C h²/α`, so `fᵢ = −∇ᵢC C/α =
//! −∂U/∂xᵢ` with `U = C²/(2α)`: the elastic force; for a rigid family (`α = 0`) `λ/h²` is the
//! force that holds `C = 0`, which no energy would give.
//!
//! # Per tetrahedron
//!
//! Each tetrahedron `t` gets the forces `fᵢᵗ` its own constraints put on its four corners:
//! its four vertex–face constraints, its volume constraint, the Neo-Hookean material's two
//! constraints (multipliers per tetrahedron), and a share `1/nₑ` of each of its six edges'
//! forces, `nₑ` the number of tetrahedra sharing edge `e` (the edge's energy split equally
//! among them; the body's total force on every particle is unchanged). The four forces sum
//! to zero (every family is invariant under translation).
//!
//! # Across a face
//!
//! Four forces summing to zero are those of one constant first Piola stress `P` on the
//! tetrahedron: with `Dm` its rest edge matrix and `V₀` its rest volume,
//! `[f₁ f₂ f₃] = −V₀ P Dm⁻ᵀ`, which has one solution `P` for any `f₁, f₂, f₃`. For a linear
//! tetrahedron `fₐ = −V₀ P ∇N_a`, and the gradient of corner `a`'s shape function is
//! `∇N_a = −N A₀ / (3 V₀)` with `N` the outward rest normal and `A₀` the rest area of the
//! face opposite `a`. So
//!
//! ```text
//! 3 fₐ = P N A₀ = σ n A        (N; Nanson: the current normal n and area A)
//! ```
//!
//! is the force the neighbour across that face exerts on the tetrahedron: three times the
//! force on the opposite corner, for every family and no stress formula needed. The face's
//! opening force is its component along the face's current normal `n`, pointing out of
//! tetrahedron `t₁` (apex `a`) into `t₂` (apex `b`), averaged over both sides:
//!
//! ```text
//! T = (3/2) (fₐᵗ¹ − f_bᵗ²) · n        (N; > 0 pulled open, < 0 pressed shut)
//! ```
//!
//! Under a uniaxial stress `σ` along `e` (a bar of cross-section `S` carrying a load `W`,
//! `σ = W/S`) a face of area `A` and normal `n` carries `T = σ (n·e)² A`: the faces normal to
//! the load carry the most, `T = W A/S`. A face sheared in its plane only is not pulled
//! open; shear tears it through the faces its principal tension crosses.

use nalgebra::Vector3;

use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::tearing::{face_key, InteriorFace};
use crate::constraints::{self, VERTEX_FACE_KAPPA, VERTEX_FACE_ORDER};

/// The corner pairs of a tetrahedron's six edges.
const EDGE_PAIRS: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

/// No edge constraint on this edge of a tetrahedron.
const NO_EDGE: u32 = u32::MAX;

/// The scratch of the force estimate: per tetrahedron the forces of its own constraints on
/// its corners and the index of each of its edges' constraint, per edge constraint its share
/// per tetrahedron. Not state (never serialized, equal whatever it holds).
#[derive(Clone, Debug, Default)]
pub(crate) struct FaceForceScratch {
    /// `fᵢᵗ` of each tetrahedron's four corners, N.
    pub corner: Vec<[Vector3<f32>; 4]>,
    /// The [`EdgeConstraints`] index of each tetrahedron's edges ([`EDGE_PAIRS`] order),
    /// [`NO_EDGE`] where there is none.
    pub tet_edges: Vec<[u32; 6]>,
    /// `1/nₑ` of each edge constraint: one over the number of tetrahedra sharing it.
    pub edge_share: Vec<f32>,
}

impl PartialEq for FaceForceScratch {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The constraint families of one body, borrowed for the force estimate.
pub(crate) struct BodyFamilies<'a> {
    pub edges: Option<&'a EdgeConstraints>,
    pub vertex_face: Option<&'a VertexFaceConstraints>,
    pub volume: Option<&'a VolumeConstraints>,
    pub material: Option<&'a NeoHookeanMaterial>,
}

impl FaceForceScratch {
    /// The scratch of a body with tetrahedra `tets` and `edges` (allocates).
    pub fn new(tets: &[[u32; 4]], edges: Option<&EdgeConstraints>) -> Self {
        let mut tet_edges = vec![[NO_EDGE; 6]; tets.len()];
        let mut edge_share = Vec::new();
        if let Some(e) = edges {
            let mut sorted: Vec<([u32; 2], u32)> = e
                .edges
                .iter()
                .enumerate()
                .map(|(k, &[a, b])| ([a.min(b), a.max(b)], k as u32))
                .collect();
            sorted.sort_unstable();
            let mut count = vec![0u32; e.edges.len()];
            for (tet, slots) in tets.iter().zip(&mut tet_edges) {
                for (slot, [i, j]) in slots.iter_mut().zip(EDGE_PAIRS) {
                    let key = [tet[i].min(tet[j]), tet[i].max(tet[j])];
                    if let Ok(k) = sorted.binary_search_by_key(&key, |s| s.0) {
                        *slot = sorted[k].1;
                        count[sorted[k].1 as usize] += 1;
                    }
                }
            }
            edge_share = count
                .iter()
                .map(|&n| if n > 0 { 1.0 / n as f32 } else { 0.0 })
                .collect();
        }
        FaceForceScratch {
            corner: vec![[Vector3::zeros(); 4]; tets.len()],
            tet_edges,
            edge_share,
        }
    }

    /// Whether the scratch was made for these tetrahedra and edges.
    pub fn fits(&self, tets: usize, edges: Option<&EdgeConstraints>) -> bool {
        self.corner.len() == tets
            && self.tet_edges.len() == tets
            && self.edge_share.len() == edges.map_or(0, |e| e.edges.len())
    }

    /// Sets `fᵢᵗ` (N) of every tetrahedron from the families' multipliers at positions `x`
    /// (m), after a substep of length `h` (s). Allocates nothing.
    pub fn measure(
        &mut self,
        tets: &[[u32; 4]],
        rest_volumes: &[f32],
        x: &[Vector3<f32>],
        rest: &[Vector3<f32>],
        families: &BodyFamilies,
        h: f32,
    ) {
        let inv_h2 = 1.0 / (h * h);
        for (t, tet) in tets.iter().enumerate() {
            let p = tet.map(|i| x[i as usize]);
            let mut f = [Vector3::zeros(); 4];
            if let Some(vf) = families.vertex_face {
                vertex_face_forces(&mut f, tet, &p, rest, &vf.rest_heights[t], &vf.lambdas[t]);
            }
            if let Some(v) = families.volume {
                let e = constraints::volume(&p[0], &p[1], &p[2], &p[3], rest_volumes[t]);
                add(&mut f, &e.grad, v.lambdas[t]);
            }
            if let Some(m) = families.material {
                let [ld, lh] = m.lambdas[t];
                let dm_inv = &m.rest_inverse[t];
                if let Some(e) = constraints::neo_hookean_deviatoric(&p, dm_inv) {
                    add(&mut f, &e.grad, ld);
                }
                let e = constraints::neo_hookean_hydrostatic(&p, dm_inv, 0.0);
                add(&mut f, &e.grad, lh);
            }
            if let Some(e) = families.edges {
                self.edge_forces(&mut f, t, &p, e);
            }
            self.corner[t] = f.map(|v| v * inv_h2);
        }
    }

    /// Adds tetrahedron `t`'s share of its edges' `∇C λ` to `f` (corners at `p`).
    fn edge_forces(
        &self,
        f: &mut [Vector3<f32>; 4],
        t: usize,
        p: &[Vector3<f32>; 4],
        edges: &EdgeConstraints,
    ) {
        for (&k, [i, j]) in self.tet_edges[t].iter().zip(EDGE_PAIRS) {
            if k == NO_EDGE {
                continue;
            }
            let k = k as usize;
            let d = p[i] - p[j];
            let len = d.norm();
            if len <= 0.0 {
                continue;
            }
            // C = |xᵢ − xⱼ| − d: ∇ᵢC = (xᵢ − xⱼ)/|xᵢ − xⱼ|, whichever end the edge lists first.
            let g = d * (edges.lambdas[k] * self.edge_share[k] / len);
            f[i] += g;
            f[j] -= g;
        }
    }

    /// The force pulling `face` open, N (`T` of the module docs; > 0 pulled open), at
    /// positions `x`; `None` when the face has collapsed (no normal) or is not finite.
    pub fn face_force(
        &self,
        face: &InteriorFace,
        tets: &[[u32; 4]],
        x: &[Vector3<f32>],
    ) -> Option<f32> {
        let [t1, t2] = face.tets.map(|t| t as usize);
        let [a, b] = face.apex;
        let ca = tets[t1].iter().position(|&i| i == a)?;
        let cb = tets[t2].iter().position(|&i| i == b)?;
        let q = face_key(&tets[t1], ca).map(|i| x[i as usize]);
        let mut n = (q[1] - q[0]).cross(&(q[2] - q[0]));
        let len = n.norm();
        if len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        n /= len;
        // Out of t₁: away from its apex a.
        if n.dot(&(x[a as usize] - q[0])) > 0.0 {
            n = -n;
        }
        let t = 1.5 * (self.corner[t1][ca] - self.corner[t2][cb]).dot(&n);
        t.is_finite().then_some(t)
    }
}

/// `f += ∇C λ` for one constraint's four gradients.
#[inline]
fn add(f: &mut [Vector3<f32>; 4], grad: &[Vector3<f32>; 4], lambda: f32) {
    if lambda != 0.0 {
        for (fi, g) in f.iter_mut().zip(grad) {
            *fi += g * lambda;
        }
    }
}

/// Adds `∇C λ` of a tetrahedron's four vertex–face constraints (corners `tet` at `p`) to `f`,
/// each evaluated as the solver evaluates it ([`constraints::vertex_face_bounded`], a face
/// collapsed to a point holding the vertex along the rest normal).
fn vertex_face_forces(
    f: &mut [Vector3<f32>; 4],
    tet: &[u32; 4],
    p: &[Vector3<f32>; 4],
    rest: &[Vector3<f32>],
    heights: &[f32; 4],
    lambdas: &[f32; 4],
) {
    for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
        let lambda = lambdas[k];
        if lambda == 0.0 {
            continue;
        }
        let q = order.map(|o| p[o]);
        let grad = match constraints::vertex_face_bounded(
            &q[0],
            &q[1],
            &q[2],
            &q[3],
            heights[k],
            VERTEX_FACE_KAPPA,
        ) {
            Some(e) => e.grad,
            None => {
                let r = order.map(|o| rest[tet[o] as usize]);
                let n = (r[2] - r[0]).cross(&(r[3] - r[0]));
                let n = n / n.norm().max(f32::MIN_POSITIVE);
                [-n, n, Vector3::zeros(), Vector3::zeros()]
            }
        };
        for (j, &o) in order.iter().enumerate() {
            f[o] += grad[j] * lambda;
        }
    }
}
