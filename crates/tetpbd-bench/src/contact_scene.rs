//! The contact scenes: soft cubes of one tetrahedral mesh dropped onto a fixed rigid ground
//! (c: one cube; d: a pile of nine), the same in both engines.

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{BuildError, Surface, TetMesh};

use crate::rapier_setup::lumped_masses;

/// Half extents of the fixed ground cuboid, m; its top face is at y = 0.
pub const GROUND_HALF_EXTENTS: [f32; 3] = [12.0, 0.5, 12.0];

/// Which contact scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactKind {
    /// c) One soft cube dropped onto the ground.
    Drop,
    /// d) Nine soft cubes dropped on each other and the ground.
    Pile,
}

/// One contact scene: the cube mesh every body is a copy of, where each starts, and how the
/// run is measured.
#[derive(Clone, Debug)]
pub struct ContactScene {
    /// Which scene.
    pub kind: ContactKind,
    /// Short name used in the CSV and the plot.
    pub name: &'static str,
    /// The rest mesh of one cube, centred at the origin, 1 m edge.
    pub cube: TetMesh,
    /// Cells per axis of the cube mesh.
    pub cells: u32,
    /// Boundary triangles of the cube mesh (interpenetration depth).
    pub surface: Surface,
    /// Centre of each cube at the start, m (all start at rest).
    pub placements: Vec<Vector3<f32>>,
    /// Density, kg/m³ (the same lumped masses in both engines).
    pub density: f32,
    /// Frames run at [`crate::DT`].
    pub frames: usize,
    /// First frame of the resting phase: the timing median and the "at rest" metrics are taken
    /// over the frames from here on.
    pub rest_from: usize,
    /// Rest volume of one cube, m³.
    pub rest_volume: f32,
}

impl ContactScene {
    /// c) A 1 m cube of `cells`³ cells (six tetrahedra each), its bottom 5 cm above the ground,
    /// run for `frames` frames; at rest from 2 s on.
    pub fn drop(cells: u32, frames: usize) -> Result<ContactScene, BuildError> {
        ContactScene::new(
            ContactKind::Drop,
            "c_drop",
            cells,
            vec![Vector3::new(0.0, 0.55, 0.0)],
            frames,
            120,
        )
    }

    /// d) Nine 1 m cubes of 4³ cells in the layout of rapier's `fem_bench` "jelly pile": a
    /// 3 × 3 grid of 1 m pitch (neighbours touch face to face), cube `i` centred at height
    /// 0.55 + 1.05 i m, so they land one after another and slide down along the ones already
    /// there; run for `frames` frames, at rest from 3 s on.
    pub fn pile(frames: usize) -> Result<ContactScene, BuildError> {
        let placements = (0..9)
            .map(|i| {
                Vector3::new(
                    (i % 3) as f32 - 1.0,
                    0.55 + i as f32 * 1.05,
                    (i / 3) as f32 - 1.0,
                )
            })
            .collect();
        ContactScene::new(ContactKind::Pile, "d_pile", 4, placements, frames, 180)
    }

    fn new(
        kind: ContactKind,
        name: &'static str,
        cells: u32,
        placements: Vec<Vector3<f32>>,
        frames: usize,
        rest_from: usize,
    ) -> Result<ContactScene, BuildError> {
        let cube = box_grid(Vector3::repeat(1.0), [cells; 3], CellSplit::Six)?;
        let surface = Surface::from_tetrahedra(&cube.tets, &cube.vertices);
        let density = 1000.0;
        let rest_volume = lumped_masses(&cube, 1.0).iter().sum();
        Ok(ContactScene {
            kind,
            name,
            cube,
            cells,
            surface,
            placements,
            density,
            frames,
            rest_from: rest_from.min(frames.saturating_sub(1)),
            rest_volume,
        })
    }

    /// Start positions of body `b`, m.
    pub fn start(&self, b: usize) -> Vec<Vector3<f32>> {
        self.cube
            .vertices
            .iter()
            .map(|v| v + self.placements[b])
            .collect()
    }

    /// Tetrahedra of all bodies together.
    pub fn tets(&self) -> usize {
        self.cube.tets.len() * self.placements.len()
    }
}
