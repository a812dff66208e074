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
    pub name: String,
    /// What it does.
    pub description: &'static str,
    /// Fast or long.
    pub kind: CaseKind,
    /// Part of the sweep over grid splits and substep counts: the report runs it without the
    /// safety net only (the defaults are what the sweep measures).
    pub sweep: bool,
    /// The scene.
    pub scene: Scene,
}

/// The substep counts the recovery and impact sweeps run at.
pub const SWEEP_SUBSTEPS: [u32; 6] = [1, 5, 10, 20, 40, 80];

/// The released starts of the recovery sweep, with their row labels.
fn released_starts() -> [(Start, &'static str); 5] {
    [
        (Start::Mirrored, "mirrored"),
        (Start::Flattened, "flattened"),
        (Start::Collapsed, "collapsed to a point"),
        (Start::Scrambled(0.5), "scrambled"),
        (
            Start::Dragged(0, Vector3::new(100.0 / 3.0, 0.0, 0.0)),
            "one vertex dragged 100 cells",
        ),
    ]
}

fn split_label(split: CellSplit) -> &'static str {
    match split {
        CellSplit::Five => "5 tets/cell",
        CellSplit::Six => "6 tets/cell",
    }
}

/// The impact rows' scene: a 0.5 m cube of 4³ cells (grid `split`), its bottom 5 cm above
/// immovable ground ([`crate::Ground`]), thrown down at `speed` (m/s), gravity on, default
/// settings with `substeps` substeps, 2 s.
pub fn impact(split: CellSplit, speed: f32, substeps: u32) -> Scene {
    let mut mesh = box_grid(Vector3::repeat(0.5), [4; 3], split).unwrap_or_default();
    for v in &mut mesh.vertices {
        v.y += 0.3;
    }
    let mut s = Scene::new(mesh);
    s.velocity = Vector3::new(0.0, -speed, 0.0);
    s.ground = true;
    s.settings.substeps = substeps;
    s.frames = 120;
    s
}

fn cube(size: f32, cells: u32) -> TetMesh {
    cube_split(size, cells, CellSplit::Six)
}

fn cube_split(size: f32, cells: u32, split: CellSplit) -> TetMesh {
    // Cannot fail for positive finite sizes and 1..=1024 cells.
    box_grid(Vector3::repeat(size), [cells; 3], split).unwrap_or_default()
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

fn released(start: Start, split: CellSplit, substeps: u32) -> Scene {
    let mut s = Scene::new(cube_split(1.0, 3, split));
    s.settings.substeps = substeps;
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
/// [`tetpbd::SafetySettings::max_correction_speed`] on every scene.
pub fn all_cases(safety_net: Option<f32>) -> Vec<Case> {
    let mut cases = Vec::new();
    let mut add_case = |group, name: String, description, kind, sweep, mut scene: Scene| {
        scene.settings.safety.max_correction_speed = safety_net;
        cases.push(Case {
            group,
            name,
            description,
            kind,
            sweep,
            scene,
        });
    };
    let mut add = |group, name: &str, description, kind, scene| {
        add_case(group, name.to_string(), description, kind, false, scene)
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

    for (start, label) in released_starts() {
        add(
            "initial state",
            label,
            "1 m cube of 3³ cells, 6 tetrahedra per cell, released at rest, zero gravity, 5 s",
            Fast,
            released(start, CellSplit::Six, 10),
        );
    }
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

    let slab = box_grid(Vector3::new(10.0, 0.01, 1.0), [10, 1, 1], CellSplit::Six);
    let mut s = Scene::new(slab.unwrap_or_default());
    s.pinned = (0..s.mesh.vertices.len() as u32)
        .filter(|&i| s.mesh.vertices[i as usize].x < -4.99)
        .collect();
    s.frames = 180;
    add(
        "mesh",
        "cantilever slab, aspect 100",
        "10 m × 1 cm × 1 m slab of 10 × 1 × 1 cells, one end pinned, bending under gravity, 3 s",
        Fast,
        s,
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

    for split in [CellSplit::Six, CellSplit::Five] {
        for (start, label) in released_starts() {
            for substeps in SWEEP_SUBSTEPS {
                if split == CellSplit::Six && substeps == 10 {
                    continue; // the "initial state" rows
                }
                add_case(
                    "recovery",
                    format!("{label}, {}, {substeps} substeps", split_label(split)),
                    "as the initial state rows, on this grid split and substep count",
                    if substeps == 10 { Fast } else { Long },
                    true,
                    released(start.clone(), split, substeps),
                );
            }
        }
    }
    for split in [CellSplit::Six, CellSplit::Five] {
        for speed in [100.0, 300.0] {
            for substeps in SWEEP_SUBSTEPS {
                add_case(
                    "impact",
                    format!("{speed} m/s, {}, {substeps} substeps", split_label(split)),
                    "0.5 m cube of 4³ cells thrown at immovable ground (restitution 0), gravity on, 2 s: ends intact, never rises faster than it came",
                    if substeps == 10 && speed == 300.0 { Fast } else { Long },
                    true,
                    impact(split, speed, substeps),
                );
            }
        }
    }
    cases
}
