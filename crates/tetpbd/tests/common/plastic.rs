//! Plastic bars for the plasticity tests: their families, a mould, the checks of a valid
//! rest state.

use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    EdgeConstraints, Material, NeoHookeanMaterial, Particles, PlasticitySettings, SoftBodyBuilder,
    Solver, SolverSettings, Tetrahedra, VertexFaceConstraints, VOLUME_PRESERVING_TOLERANCE,
};

/// Edge compliance of the bars, m/N: soft enough that a frame sees the held shape's strain.
pub const EDGE_COMPLIANCE: f32 = 1e-5;
/// Volume compliance, m⁵/N.
pub const VOLUME_COMPLIANCE: f32 = 1e-7;

#[derive(Clone, Copy, Debug)]
pub enum Families {
    EdgesVolume,
    EdgesVertexFace,
    /// No family: the Neo-Hookean material [`bar_material`] alone.
    Material,
}

/// The material of [`Families::Material`] bars: E = 5 MPa, ν = 0.3, damping 1 ms.
pub fn bar_material() -> Material {
    Material::new(5e6, 0.3).unwrap().with_damping(1e-3).unwrap()
}

#[derive(Clone, Copy, Debug)]
pub struct Bar {
    /// Length along x, m; the cross-section is `length / 5` square.
    pub length: f32,
    /// Cells along the length; `cells / 4` (at least 2) across.
    pub cells: u32,
    pub substeps: u32,
    pub families: Families,
}

pub fn spawn_bar(world: &mut World, bar: Bar, settings: Option<PlasticitySettings>) -> Entity {
    let width = bar.length / 5.0;
    let across = (bar.cells / 4).max(2);
    let size = Vector3::new(bar.length, width, width);
    let mesh = box_grid(size, [bar.cells, across, across], CellSplit::Six).unwrap();
    let b = SoftBodyBuilder::new(mesh).density(1000.0);
    let b = match bar.families {
        Families::EdgesVolume => b.edges(EDGE_COMPLIANCE).volume(VOLUME_COMPLIANCE),
        Families::EdgesVertexFace => b.edges(EDGE_COMPLIANCE).vertex_face(EDGE_COMPLIANCE),
        Families::Material => b.material(bar_material()),
    };
    let b = match settings {
        Some(s) => b.plasticity(s),
        None => b,
    };
    b.build().unwrap().spawn(world)
}

/// The substeps per 1/60 s frame a bar's material needs
/// ([`NeoHookeanMaterial::max_stable_substep`]), at least 5.
pub fn stable_substeps(bar: Bar) -> u32 {
    let mut world = World::new();
    let e = spawn_bar(&mut world, bar, None);
    let material = world.get::<&NeoHookeanMaterial>(e).unwrap();
    let (t, p) = (
        world.get::<&Tetrahedra>(e).unwrap(),
        world.get::<&Particles>(e).unwrap(),
    );
    let h = material.max_stable_substep(&t, &p);
    ((1.0 / 60.0 / h).ceil() as u32).max(5)
}

pub fn solver(substeps: u32, damping: f32) -> Solver {
    Solver::new(SolverSettings {
        gravity: Vector3::zeros(),
        substeps,
        damping,
        ..Default::default()
    })
    .unwrap()
}

/// The rest point `x` of a bar of `length` bent about z into an arc of total angle `angle`
/// (rad): the fibre at height `y` gets the strain `−y · angle / length`.
pub fn arc(x: Vector3<f32>, length: f32, angle: f32) -> Vector3<f32> {
    let r = length / angle;
    let phi = x.x / r;
    Vector3::new((r - x.y) * phi.sin(), r - (r - x.y) * phi.cos(), x.z)
}

/// Puts body `e` into a mould of shape `held` (every particle there, at rest, pinned), or
/// takes it out (`hold` false: every particle free again, where it is).
pub fn mould(world: &mut World, e: Entity, held: &[Vector3<f32>], hold: bool) {
    let mut p = world.get::<&mut Particles>(e).unwrap();
    for (i, x) in held.iter().enumerate() {
        if hold {
            p.set_position(i, *x).unwrap();
            p.set_velocity(i, Vector3::zeros()).unwrap();
        }
        p.set_pinned(i, hold).unwrap();
    }
}

/// Checks every rest value of body `e` is finite and valid: rest volumes of the built sign,
/// within the bounds of the maximum plastic strain (and of the volume-preserving tolerance),
/// positive edge rest lengths, vertex–face rest heights of the built sign. Returns the largest
/// relative change of a rest volume.
pub fn check_rest_state(world: &World, e: Entity, s: &PlasticitySettings) -> f32 {
    let p = world.get::<&Particles>(e).unwrap();
    let t = world.get::<&Tetrahedra>(e).unwrap();
    let m = s.max_plastic_strain;
    let mut worst = 0.0f32;
    for k in 0..t.len() {
        let built = t.volume_at(k, p.rest_positions());
        let ratio = t.rest_volumes()[k] / built;
        assert!(
            ratio.is_finite() && ratio > 0.0,
            "tet {k}: rest volume ratio {ratio}"
        );
        if s.volume_preserving {
            assert!(
                (ratio - 1.0).abs() <= VOLUME_PRESERVING_TOLERANCE,
                "tet {k}: {ratio}"
            );
        } else {
            let (lo, hi) = ((1.0 - m).powi(3), (1.0 + m).powi(3));
            assert!(
                ratio >= lo * 0.9999 && ratio <= hi * 1.0001,
                "tet {k}: {ratio}"
            );
        }
        worst = worst.max((ratio - 1.0).abs());
    }
    if let Ok(edges) = world.get::<&EdgeConstraints>(e) {
        assert!(edges
            .rest_lengths()
            .iter()
            .all(|l| l.is_finite() && *l > 0.0));
    }
    if let Ok(vf) = world.get::<&VertexFaceConstraints>(e) {
        for (k, h) in vf.rest_heights().iter().enumerate() {
            let sign = t.rest_volumes()[k].signum();
            assert!(
                h.iter().all(|h| h.is_finite() && h * sign > 0.0),
                "tet {k}: {h:?}"
            );
        }
    }
    worst
}
