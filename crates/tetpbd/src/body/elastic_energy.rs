//! A body's elastic energy: what its compliant constraint families and its material store.
//!
//! A family with compliance `α > 0` stores `Σ C²/(2α)` (J; `C` in m for the edges and the
//! vertex–faces, α in m/N; `C` in m³ for the volumes, α in m⁵/N). Hard families (`α = 0`)
//! hold no defined energy and count as 0. The Neo-Hookean material stores
//! [`NeoHookeanMaterial::elastic_energy`]. A vertex–face constraint whose face collapsed to
//! a point has no height: its violation is its rest value.

use nalgebra::Vector3;

use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::constraints::{bounded_height, VERTEX_FACE_KAPPA, VERTEX_FACE_ORDER};

/// The families and material of one body whose elastic energy is measured (any may be
/// absent).
#[derive(Clone, Copy, Default)]
pub struct ElasticFamilies<'a> {
    /// Edge distance constraints.
    pub edges: Option<&'a EdgeConstraints>,
    /// Signed volume constraints.
    pub volume: Option<&'a VolumeConstraints>,
    /// Vertex–face constraints.
    pub vertex_face: Option<&'a VertexFaceConstraints>,
    /// The Neo-Hookean material.
    pub material: Option<&'a NeoHookeanMaterial>,
}

fn term(c: f32, alpha: f32) -> f64 {
    f64::from(c) * f64::from(c) / (2.0 * f64::from(alpha))
}

impl ElasticFamilies<'_> {
    /// The elastic energy stored at `x` (J), the body's tetrahedra `t`.
    pub fn energy(&self, t: &Tetrahedra, x: &[Vector3<f32>]) -> f64 {
        let mut u = 0.0f64;
        if let Some(f) = self.edges.filter(|f| f.compliance() > 0.0) {
            let alpha = f.compliance();
            for (&[a, b], &l) in f.edges().iter().zip(f.rest_lengths()) {
                u += term((x[a as usize] - x[b as usize]).norm() - l, alpha);
            }
        }
        if let Some(m) = self.material {
            u += m.elastic_energy(t, x);
        }
        if let Some(f) = self.volume.filter(|f| f.compliance() > 0.0) {
            let alpha = f.compliance();
            for (k, &v0) in t.rest_volumes().iter().enumerate() {
                u += term(t.volume_at(k, x) - v0, alpha);
            }
        }
        if let Some(f) = self.vertex_face.filter(|f| f.compliance() > 0.0) {
            let alpha = f.compliance();
            for (tet, rest) in t.indices().iter().zip(f.rest_heights()) {
                for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
                    let [a, b, c, d] = order.map(|o| x[tet[o] as usize]);
                    let h =
                        bounded_height(&a, &b, &c, &d, VERTEX_FACE_KAPPA, rest[k]).unwrap_or(0.0);
                    u += term(h - rest[k], alpha);
                }
            }
        }
        u
    }
}
