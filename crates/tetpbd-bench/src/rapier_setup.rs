//! How rapier's built-in soft bodies are set up in every comparison: material per cell model,
//! lumped masses equal to tetpbd's, and the vector conversion.

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{SoftBodyCellModel, SoftBodyMaterial, SoftBodySolver, SpringCoefficients};
use tetpbd::TetMesh;

/// Young's modulus of rapier's elastic cell models, Pa.
pub const RAPIER_YOUNG: f32 = 1e8;
/// Poisson's ratio of rapier's elastic cell models.
pub const RAPIER_POISSON: f32 = 0.3;
/// Natural frequency standing for "hard" in rapier's frequency-based softness, Hz (rapier's own
/// default for joints; a frequency above the substep rate saturates instead of exploding).
pub const RAPIER_HARD_HZ: f32 = 1.0e6;

/// rapier's material for a cell model: for [`SoftBodyCellModel::Volume`], edges and cell
/// volumes at [`RAPIER_HARD_HZ`] (`hard`) or rapier's default 30 Hz softness, critically
/// damped; for the elastic models, [`RAPIER_YOUNG`], [`RAPIER_POISSON`] and elastic damping
/// ratio 1.
pub fn rapier_material(cell: SoftBodyCellModel, hard: bool) -> SoftBodyMaterial {
    match (cell, hard) {
        (SoftBodyCellModel::Volume, true) => {
            let k = SpringCoefficients::new(RAPIER_HARD_HZ, 1.0);
            SoftBodyMaterial {
                edge_softness: k,
                volume_softness: k,
                ..Default::default()
            }
        }
        (SoftBodyCellModel::Volume, false) => SoftBodyMaterial::default(),
        _ => SoftBodyMaterial {
            young_modulus: RAPIER_YOUNG,
            poisson_ratio: RAPIER_POISSON,
            elastic_damping_ratio: 1.0,
            ..Default::default()
        },
    }
}

/// Lumped particle masses of `mesh` at `density` (kg/m³): `density · |V| / 4` per tetrahedron
/// corner, kg — what tetpbd's `SoftBodyBuilder::density` gives, handed to rapier explicitly.
pub fn lumped_masses(mesh: &TetMesh, density: f32) -> Vec<f32> {
    let mut m = vec![0.0; mesh.vertices.len()];
    for t in &mesh.tets {
        let [a, b, c, d] = t.map(|i| mesh.vertices[i as usize]);
        let v = tetpbd::constraint::signed_volume(&a, &b, &c, &d).abs();
        for &i in t {
            m[i as usize] += density * v / 4.0;
        }
    }
    m
}

/// A nalgebra vector as rapier's.
pub fn to_rapier(v: &Vector3<f32>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// The label of a rapier set-up in every report: `rapier <solver> <cell model>`, with ` hard`
/// or ` 30Hz` for the volume model.
pub fn rapier_label(cell: SoftBodyCellModel, solver: SoftBodySolver, hard: bool) -> String {
    let c = match cell {
        SoftBodyCellModel::Volume => "Volume",
        SoftBodyCellModel::Corotational => "Corotational",
        SoftBodyCellModel::NeoHookean => "NeoHookean",
    };
    let s = match solver {
        SoftBodySolver::Constraints => "Constraints",
        SoftBodySolver::Fem => "Fem",
    };
    let k = match (cell, hard) {
        (SoftBodyCellModel::Volume, true) => " hard",
        (SoftBodyCellModel::Volume, false) => " 30Hz",
        _ => "",
    };
    format!("rapier {s} {c}{k}")
}
