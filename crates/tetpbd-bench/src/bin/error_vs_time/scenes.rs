//! The scenes of the report: one fixed tetrahedral mesh each, handed to both engines.

use nalgebra::Vector3;
use tetpbd::constraint::signed_volume;
use tetpbd::generators::{self, CellSplit};
use tetpbd::{unique_edges, Material, TetMesh};

/// Young's modulus of the material scenes, Pa (both engines): a soft rubber.
pub const MATERIAL_YOUNG: f32 = 1e6;
/// Poisson's ratio of the material scenes (both engines).
pub const MATERIAL_POISSON: f32 = 0.3;

/// The material of the material scenes: [`MATERIAL_YOUNG`], [`MATERIAL_POISSON`], no material
/// damping (the scene's linear damping settles both engines alike).
pub fn scene_material() -> Material {
    Material::new(MATERIAL_YOUNG, MATERIAL_POISSON).expect("valid material constants")
}

/// Which scene of the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    /// a) A beam pinned at one end, sagging under gravity to static equilibrium.
    HangingBeam,
    /// b) A block squashed to 50 % height, released without gravity.
    Squash,
}

/// One scene: the mesh both engines get, and how it is run.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Which scene.
    pub kind: SceneKind,
    /// Short name used in the CSV and the plot.
    pub name: &'static str,
    /// The rest mesh (both engines build their rest state from it).
    pub mesh: TetMesh,
    /// Pinned vertices.
    pub pinned: Vec<u32>,
    /// Start positions (the rest mesh, or the squashed one).
    pub start: Vec<Vector3<f32>>,
    /// Gravity along y, m/s².
    pub gravity: f32,
    /// Linear velocity damping of every particle, 1/s (same in both engines).
    pub damping: f32,
    /// Frames run at 1/60 s.
    pub frames: usize,
    /// Frames excluded from the timing median.
    pub warmup: usize,
    /// Body size used to make displacements relative, m.
    pub size: f32,
    /// Density, kg/m³ (masses are lumped per tetrahedron corner, the same in both engines).
    pub density: f32,
    /// A material scene: both engines model the body as this elastic material (tetpbd's
    /// Neo-Hookean material, rapier's Neo-Hookean and corotational cells with the same E and
    /// ν) instead of the constraint models of scenes a and b.
    pub material: Option<Material>,
    /// Unique edges of the mesh with their rest lengths.
    pub edges: Vec<[u32; 2]>,
    /// Rest length of each edge, m.
    pub rest_lengths: Vec<f32>,
    /// Signed rest volume of each tetrahedron, m³.
    pub rest_volumes: Vec<f32>,
}

pub use tetpbd_bench::DT;

impl Scene {
    /// a) A 2 m × 0.2 m × 0.2 m beam, 20 × 2 × 2 cells of six tetrahedra, pinned at x = 0,
    /// damped so that it settles within the run.
    pub fn hanging_beam(quick: bool) -> Scene {
        let mesh =
            generators::beam(2.0, 0.2, 20, 2, CellSplit::Six).expect("valid beam parameters");
        let pinned = generators::beam_root(&mesh);
        let start = mesh.vertices.clone();
        Scene::new(
            SceneKind::HangingBeam,
            "a_hanging_beam",
            mesh,
            pinned,
            start,
            -9.81,
            10.0,
            if quick { 60 } else { 180 },
            2.0,
        )
    }

    /// A 1 m × 0.1 m beam, 10 × 1 × 1 cells, otherwise as [`Scene::hanging_beam`] (full
    /// length run): small enough for tests to run it at many substeps.
    #[cfg(test)]
    pub fn small_hanging_beam() -> Scene {
        let mesh =
            generators::beam(1.0, 0.1, 10, 1, CellSplit::Six).expect("valid beam parameters");
        let pinned = generators::beam_root(&mesh);
        let start = mesh.vertices.clone();
        Scene::new(
            SceneKind::HangingBeam,
            "small_hanging_beam",
            mesh,
            pinned,
            start,
            -9.81,
            10.0,
            180,
            1.0,
        )
    }

    /// b) A 1 m cube, 4 × 4 × 4 cells of six tetrahedra, squashed to 50 % height about its
    /// centre (x and z unchanged, so half its volume) and released at rest, without gravity.
    pub fn squash(quick: bool) -> Scene {
        let mesh = generators::box_grid(Vector3::repeat(1.0), [4, 4, 4], CellSplit::Six)
            .expect("valid box parameters");
        let start = mesh
            .vertices
            .iter()
            .map(|v| Vector3::new(v.x, 0.5 * v.y, v.z))
            .collect();
        Scene::new(
            SceneKind::Squash,
            "b_squash_release",
            mesh,
            Vec::new(),
            start,
            0.0,
            2.0,
            if quick { 60 } else { 120 },
            1.0,
        )
    }

    /// e) The beam of [`Scene::hanging_beam`] made of [`scene_material`] in both engines.
    pub fn material_beam(quick: bool) -> Scene {
        Scene {
            name: "e_material_beam",
            material: Some(scene_material()),
            ..Scene::hanging_beam(quick)
        }
    }

    /// f) The squashed cube of [`Scene::squash`] made of [`scene_material`] in both engines,
    /// damped at 10 1/s instead of 2 (the elastic wobble is fast and its trajectory sensitive:
    /// the stronger damping brings the references nearer to convergence).
    pub fn material_squash(quick: bool) -> Scene {
        Scene {
            name: "f_material_squash",
            material: Some(scene_material()),
            damping: 10.0,
            ..Scene::squash(quick)
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn new(
        kind: SceneKind,
        name: &'static str,
        mesh: TetMesh,
        pinned: Vec<u32>,
        start: Vec<Vector3<f32>>,
        gravity: f32,
        damping: f32,
        frames: usize,
        size: f32,
    ) -> Scene {
        let edges = unique_edges(&mesh.tets);
        let rest_lengths = edges
            .iter()
            .map(|[a, b]| (mesh.vertices[*a as usize] - mesh.vertices[*b as usize]).norm())
            .collect();
        let rest_volumes = mesh
            .tets
            .iter()
            .map(|t| tet_volume(t, &mesh.vertices))
            .collect();
        Scene {
            kind,
            name,
            mesh,
            pinned,
            start,
            gravity,
            damping,
            frames,
            warmup: 10.min(frames / 4),
            size,
            density: 1000.0,
            material: None,
            edges,
            rest_lengths,
            rest_volumes,
        }
    }
}

/// Signed volume of tetrahedron `t` at `x`, m³.
pub fn tet_volume(t: &[u32; 4], x: &[Vector3<f32>]) -> f32 {
    let [a, b, c, d] = t.map(|i| x[i as usize]);
    signed_volume(&a, &b, &c, &d)
}
