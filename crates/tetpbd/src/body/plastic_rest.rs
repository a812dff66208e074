//! The rest values of a body's families, read from its tetrahedra's plastic rest shapes
//! (see [`crate::Plasticity`]).
//!
//! [`RestState`] borrows the rest data of every family a body has; each family gets one
//! refresh, from the rest edge matrix `Dₜ` of a tetrahedron that flowed (a per-tetrahedron
//! family) or from all of them (the edges, shared between tetrahedra). A further family with
//! rest data plugs in as one more optional field and one more refresh.

use nalgebra::{Matrix3, Vector3};

use crate::body::families::{EdgeConstraints, VertexFaceConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::plasticity::{built_edge_matrix, Plasticity};
use crate::constraints::{bounded_height, signed_volume, VERTEX_FACE_KAPPA, VERTEX_FACE_ORDER};

/// The rest data of one body's families, borrowed for a refresh.
pub(crate) struct RestState<'a> {
    /// Rest volumes (and the indices the others read).
    pub tetrahedra: &'a mut Tetrahedra,
    /// Vertex–face rest heights, if the body has the family.
    pub vertex_face: Option<&'a mut VertexFaceConstraints>,
    /// Edge rest lengths, if the body has the family.
    pub edges: Option<&'a mut EdgeConstraints>,
    /// The material's inverse rest shapes `Dₜ⁻¹`, if the body has one.
    pub material: Option<&'a mut NeoHookeanMaterial>,
}

impl RestState<'_> {
    /// Sets the rest values of tetrahedron `t`'s own constraints (its rest volume, its
    /// four vertex–face rest heights and the material's `Dₜ⁻¹`) to its rest shape `stretch · D⁰ₜ` (see
    /// [`crate::Plasticity`]); an identity stretch gives back the built values bit for bit.
    pub fn refresh_tetrahedron(
        &mut self,
        t: usize,
        stretch: &Matrix3<f64>,
        rest_positions: &[Vector3<f32>],
    ) {
        let tet = self.tetrahedra.indices[t];
        let built = tet.map(|i| rest_positions[i as usize]);
        // det(P D⁰)/6 = det(P) V⁰, with V⁰ computed as the builder did.
        let v0 = signed_volume(&built[0], &built[1], &built[2], &built[3]);
        let identity = *stretch == Matrix3::identity();
        self.tetrahedra.rest_volumes[t] = if identity {
            v0
        } else {
            (stretch.determinant() * f64::from(v0)) as f32
        };
        let dm = stretch * built_edge_matrix(tet, rest_positions);
        if let Some(m) = self.material.as_deref_mut() {
            m.set_rest_shape(t, tet, &dm, identity, rest_positions);
        }
        let Some(vf) = self.vertex_face.as_deref_mut() else {
            return;
        };
        let q = [
            Vector3::zeros(),
            dm.column(0).into_owned(),
            dm.column(1).into_owned(),
            dm.column(2).into_owned(),
        ];
        for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
            // A rest shape whose singular values are bounded away from 0 (see
            // `crate::Plasticity`) is never degenerate; a `None` keeps the old value.
            let h = if identity {
                let [a, b, c, d] = order.map(|o| built[o]);
                bounded_height(&a, &b, &c, &d, VERTEX_FACE_KAPPA, 0.0)
            } else {
                let [a, b, c, d] = order.map(|o| q[o]);
                let kappa = f64::from(VERTEX_FACE_KAPPA);
                bounded_height(&a, &b, &c, &d, kappa, 0.0).map(|h| h as f32)
            };
            if let Some(h) = h {
                vf.rest_heights[t][k] = h;
            }
        }
    }

    /// Sets every edge's rest length to the mean of its lengths in the rest shapes of the
    /// tetrahedra it belongs to (its built length where all of them are unflowed).
    pub fn refresh_edges(&mut self, plastic: &Plasticity, rest_positions: &[Vector3<f32>]) {
        let Some(e) = self.edges.as_deref_mut() else {
            return;
        };
        let tets = &self.tetrahedra.indices;
        let identity = Matrix3::<f64>::identity();
        for (k, &[i, j]) in e.edges.iter().enumerate() {
            let r = plastic.edge_offsets[k] as usize..plastic.edge_offsets[k + 1] as usize;
            let occurrences = &plastic.edge_corners[r];
            if occurrences
                .iter()
                .all(|&(t, _)| plastic.stretch[t as usize] == identity)
            {
                e.rest_lengths[k] =
                    (rest_positions[i as usize] - rest_positions[j as usize]).norm();
                continue;
            }
            let mut sum = 0.0f64;
            for &(t, [a, b]) in occurrences {
                let t = t as usize;
                let d0 = built_edge_matrix(tets[t], rest_positions);
                let corner = |c: u8| -> Vector3<f64> {
                    if c == 0 {
                        Vector3::zeros()
                    } else {
                        d0.column(c as usize - 1).into_owned()
                    }
                };
                sum += (plastic.stretch[t] * (corner(b) - corner(a))).norm();
            }
            e.rest_lengths[k] = (sum / occurrences.len() as f64) as f32;
        }
    }

    /// Sets every rest value of every family from `plastic`'s rest shapes.
    pub fn refresh_all(mut self, plastic: &Plasticity, rest_positions: &[Vector3<f32>]) {
        for t in 0..self.tetrahedra.len() {
            self.refresh_tetrahedron(t, &plastic.stretch[t], rest_positions);
        }
        self.refresh_edges(plastic, rest_positions);
    }
}
