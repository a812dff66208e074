//! The rest volumes and lumped masses of a tetrahedral mesh, and the inverse masses with
//! pinned vertices.

use crate::body::builder::TetMesh;
use crate::constraints::signed_volume;
use crate::error::BuildError;

/// The signed rest volume of every tetrahedron (in input order) and the lumped mass of every
/// vertex (a quarter of each incident tetrahedron's mass), checking indices and degeneracy.
pub(crate) fn rest_volumes_and_masses(
    mesh: &TetMesh,
    density: f32,
    epsilon: f32,
) -> Result<(Vec<f32>, Vec<f32>), BuildError> {
    let n = mesh.vertices.len();
    let mut rest_volumes = Vec::with_capacity(mesh.tets.len());
    let mut masses = vec![0.0f32; n];
    for (t, tet) in mesh.tets.iter().enumerate() {
        for (k, &i) in tet.iter().enumerate() {
            if i as usize >= n {
                return Err(BuildError::IndexOutOfRange {
                    tet: t,
                    index: i,
                    vertex_count: n,
                });
            }
            if tet[..k].contains(&i) {
                return Err(BuildError::RepeatedVertex { tet: t, index: i });
            }
        }
        let p = tet.map(|i| mesh.vertices[i as usize]);
        let vol = signed_volume(&p[0], &p[1], &p[2], &p[3]);
        let mut longest = 0.0f32;
        for a in 0..4 {
            for b in a + 1..4 {
                longest = longest.max((p[a] - p[b]).norm());
            }
        }
        let threshold = epsilon * longest * longest * longest;
        // NaN-safe: anything not strictly above the threshold (overflow included) is rejected.
        if vol.abs().partial_cmp(&threshold) != Some(std::cmp::Ordering::Greater) || vol == 0.0 {
            return Err(BuildError::DegenerateTetrahedron {
                tet: t,
                volume: vol,
                threshold,
            });
        }
        rest_volumes.push(vol);
        for &i in tet {
            masses[i as usize] += density * vol.abs() / 4.0;
        }
    }
    if let Some(vertex) = masses.iter().position(|m| *m <= 0.0) {
        return Err(BuildError::UnreferencedVertex { vertex });
    }
    Ok((rest_volumes, masses))
}

/// Inverse masses, 0 for the pinned vertices.
pub(crate) fn pinned_inverse_masses(
    masses: &[f32],
    pinned: &[u32],
) -> Result<Vec<f32>, BuildError> {
    let mut inv_masses: Vec<f32> = masses.iter().map(|m| 1.0 / m).collect();
    for &i in pinned {
        match inv_masses.get_mut(i as usize) {
            Some(w) => *w = 0.0,
            None => {
                return Err(BuildError::PinnedOutOfRange {
                    index: i,
                    vertex_count: masses.len(),
                })
            }
        }
    }
    Ok(inv_masses)
}
