//! The cases of the suite.

use nalgebra::Vector3;
use tetpbd::generators::{beam, beam_root, box_grid, CellSplit};
use tetpbd::TetMesh;

use crate::run::{Scene, Start};

/// Whether a case belongs in the default test suite.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaseKind {
    /// Seconds in a debug build: run by the default tests.
    Fast,
    /// Long: `#[ignore]`d, run in release by CI.
    Long,
}

/// One row of the matrix.
#[derive(Clone, Debug)]
pub struct Case {
    /// Group ("stiff", "large steps", …).
    pub group: &'static str,
    /// Row label.
    pub name: &'static str,
    /// What it does.
    pub description: &'static str,
    /// Fast or long.
    pub kind: CaseKind,
    /// The scene.
    pub scene: Scene,
}

fn cube(size: f32, cells: u32) -> TetMesh {
    // Cannot fail for positive finite sizes and 1..=1024 cells.
    box_grid(Vector3::repeat(size), [cells; 3], CellSplit::Six).unwrap_or_default()
}

fn top(mesh: &TetMesh) -> Vec<u32> {
    let max = mesh
        .vertices
        .iter()
        .map(|v| v.y)
        .fold(f32::NEG_INFINITY, f32::max);
    (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y >= max - 1e-6 * max.abs().max(1e-6))
        .collect()
}

fn hanging(size: f32, substeps: u32, frames: usize) -> Scene {
    let mesh = cube(size, 3);
    let mut s = Scene::new(mesh.clone());
    s.pinned = top(&mesh);
    s.settings.substeps = substeps;
    s.frames = frames;
    s
}

fn released(start: Start) -> Scene {
    let mut s = Scene::new(cube(1.0, 3));
    s.start = start;
    s.settings.gravity = Vector3::zeros();
    s.settings.damping = 1.0;
    s.frames = 300;
    s.require_recovery = true;
    s
}

fn single_tet(apex_height: f32) -> TetMesh {
    TetMesh {
        vertices: vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
            Vector3::new(0.3, apex_height, 0.3),
        ],
        tets: vec![[0, 1, 2, 3]],
    }
}

/// Every case, in report order. `safety_net` sets
/// [`tetpbd::SolverSettings::max_correction_speed`] on every scene.
pub fn all_cases(safety_net: Option<f32>) -> Vec<Case> {
    let mut cases = Vec::new();
    let mut add = |group, name, description, kind, mut scene: Scene| {
        scene.settings.max_correction_speed = safety_net;
        cases.push(Case {
            group,
            name,
            description,
            kind,
            scene,
        });
    };
    use CaseKind::{Fast, Long};

    add(
        "stiff",
        "hanging cube, 1 substep",
        "1 m cube, 3³ cells, top face pinned, 2 s",
        Fast,
        hanging(1.0, 1, 120),
    );
    add(
        "stiff",
        "hanging cube, 20 substeps",
        "as above with 20 substeps",
        Fast,
        hanging(1.0, 20, 120),
    );
    let mut s = hanging(1.0, 1, 120);
    s.compliance_scale = 1e-6;
    add(
        "stiff",
        "stiffest finite α, 1 substep",
        "soft columns at 10⁻⁶ × their compliance (α = 10⁻¹² m/N)",
        Fast,
        s,
    );
    let mut s = hanging(1.0, 20, 120);
    s.compliance_scale = 1e-6;
    add(
        "stiff",
        "stiffest finite α, 20 substeps",
        "as above with 20 substeps",
        Fast,
        s,
    );
    let mesh = beam(2.0, 0.1, 20, 1, CellSplit::Five).unwrap_or_default();
    let mut s = Scene::new(mesh.clone());
    s.pinned = beam_root(&mesh);
    s.frames = 180;
    add(
        "stiff",
        "thin beam, 100 tetrahedra",
        "2 m × 0.1 m beam, 20 × 1 × 1 cells of 5 tetrahedra, root pinned, 3 s",
        Fast,
        s,
    );

    let mut s = hanging(1.0, 1, 60);
    s.settings.dt = 1.0 / 15.0;
    add(
        "large steps",
        "dt 1/15 s, 1 substep",
        "hanging cube, 4 s",
        Fast,
        s,
    );
    let mut s = Scene::new(cube(1.0, 3));
    s.frames = 600;
    s.free_fall = true;
    add(
        "large steps",
        "falling 10 s",
        "free fall to 98 m/s",
        Fast,
        s,
    );

    add(
        "initial state",
        "mirrored",
        "every tetrahedron inverted, zero gravity, 5 s",
        Fast,
        released(Start::Mirrored),
    );
    add(
        "initial state",
        "flattened",
        "onto the plane y = 0",
        Fast,
        released(Start::Flattened),
    );
    add(
        "initial state",
        "collapsed to a point",
        "every vertex at the centre",
        Fast,
        released(Start::Collapsed),
    );
    add(
        "initial state",
        "scrambled",
        "vertices random in the cube",
        Fast,
        released(Start::Scrambled(0.5)),
    );
    add(
        "initial state",
        "one vertex dragged 100 cells",
        "vertex 0 moved 33 m (100 cell sizes) and released",
        Fast,
        released(Start::Dragged(0, Vector3::new(100.0 / 3.0, 0.0, 0.0))),
    );

    let mut s = Scene::new(
        box_grid(Vector3::new(1.0, 1e-3, 1.0), [3, 1, 3], CellSplit::Six).unwrap_or_default(),
    );
    s.pinned = (0..s.mesh.vertices.len() as u32)
        .filter(|&i| s.mesh.vertices[i as usize].x < -0.49)
        .collect();
    s.frames = 120;
    add(
        "mesh",
        "slivers, aspect 1000",
        "1 m × 1 mm × 1 m plate of 1 cell thickness, one edge pinned, 2 s",
        Fast,
        s,
    );
    // Volume 3.4e-5/6 m³ ≈ 2 × the builder's threshold 1e-6 · (√2 m)³.
    let mut s = Scene::new(single_tet(1.2e-5 * 2.0_f32.sqrt() * 2.0 * 3.0));
    s.pinned = vec![0, 1, 2];
    s.frames = 120;
    add(
        "mesh",
        "volume just above ε",
        "one tetrahedron at 2 × the builder's volume threshold, base pinned, apex under gravity",
        Fast,
        s,
    );
    let mut s = Scene::new(single_tet(1.0));
    s.start = Start::Mirrored;
    s.settings.gravity = Vector3::zeros();
    s.settings.damping = 1.0;
    s.frames = 120;
    s.require_recovery = true;
    add(
        "mesh",
        "single tetrahedron, inverted",
        "one free tetrahedron, mirrored",
        Fast,
        s,
    );

    add(
        "scale",
        "1 mm cube",
        "hanging cube at 1 mm",
        Fast,
        hanging(1e-3, 10, 120),
    );
    add(
        "scale",
        "100 m cube",
        "hanging cube at 100 m",
        Fast,
        hanging(100.0, 10, 120),
    );

    let mut s = Scene::new(cube(1.0, 3));
    s.start = Start::Mirrored;
    s.settings.gravity = Vector3::zeros();
    s.settings.damping = 1.0;
    s.settings.substeps = 20;
    s.frames = 3600;
    s.require_recovery = true;
    add(
        "long",
        "mirrored, 1 min at 20 substeps",
        "recovery, then 3600 frames at rest without drift",
        Long,
        s,
    );

    cases
}
