//! Shared by the tests: a tiny seeded generator (no extra dependency, deterministic), the
//! test bodies and their deformed starts.
#![allow(dead_code)]

pub mod plastic;
pub mod tearing;

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, TetMesh};

/// xorshift64* — good enough for test configurations.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }

    pub fn vec(&mut self, half: f64) -> Vector3<f64> {
        Vector3::new(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        )
    }

    /// A tetrahedron of four points within `size` of the origin, not near degenerate:
    /// `|det [x₁−x₀, x₂−x₀, x₃−x₀]| > 0.05 size³` (either orientation).
    pub fn tet(&mut self, size: f64) -> [Vector3<f64>; 4] {
        loop {
            let t = [
                self.vec(size),
                self.vec(size),
                self.vec(size),
                self.vec(size),
            ];
            let d = nalgebra::Matrix3::from_columns(&[t[1] - t[0], t[2] - t[0], t[3] - t[0]])
                .determinant();
            if d.abs() > 0.05 * size.powi(3) {
                return t;
            }
        }
    }
}

/// One tetrahedron: the origin and the three unit points of the axes.
pub fn unit_tet() -> TetMesh {
    TetMesh {
        vertices: vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
        ],
        tets: vec![[0, 1, 2, 3]],
    }
}

/// A 1 m cube centred on the origin, of `cells³` cells split by `split`.
pub fn cube(cells: u32, split: CellSplit) -> TetMesh {
    box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], split).unwrap()
}

/// The vertices of `mesh` on the top face of [`cube`] (y > 0.49 m).
pub fn top(mesh: &TetMesh) -> Vec<u32> {
    (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y > 0.49)
        .collect()
}

/// A deformed start of a body: where each particle is moved from its position `x`.
#[derive(Clone, Copy, Debug)]
pub enum Deformation {
    /// Mirrored through the plane x = 0: every tetrahedron of [`cube`] inverted.
    Mirrored,
    /// Flattened onto the plane y = 0.
    Flattened,
    /// Every particle at a pseudo-random point of the cube of half size 0.5 m ([`Rng`]
    /// seeded 42, drawn in particle order).
    Scrambled,
    /// The top half (y > 0) twisted about the vertical axis by 0.03 rad/m and stretched by
    /// 0.9 %: a small, one-sided strain whose snap-back exceeds 1 m/s only at the top.
    Strained,
    /// Sheared and squashed to 60 %: large corrections, no inversion.
    Sheared,
}

/// Moves every particle of `e` from its position `x` to `f(i, x)` (checked writes, which
/// also reset the substep start: the move is not a velocity).
pub fn deform_with(
    world: &mut hecs::World,
    e: hecs::Entity,
    mut f: impl FnMut(usize, Vector3<f32>) -> Vector3<f32>,
) {
    let mut p = world.get::<&mut Particles>(e).unwrap();
    for i in 0..p.len() {
        let x = p.positions()[i];
        p.set_position(i, f(i, x)).unwrap();
    }
}

/// Moves every particle of `e` to where `deformation` takes it.
pub fn deform(world: &mut hecs::World, e: hecs::Entity, deformation: Deformation) {
    let mut rng = Rng::new(42);
    deform_with(world, e, |_, x| match deformation {
        Deformation::Mirrored => Vector3::new(-x.x, x.y, x.z),
        Deformation::Flattened => Vector3::new(x.x, 0.0, x.z),
        Deformation::Scrambled => rng.vec(0.5).cast(),
        Deformation::Strained if x.y > 0.0 => {
            let (s, c) = (0.03 * x.y).sin_cos();
            Vector3::new(x.x * c - x.z * s, 1.009 * x.y, x.x * s + x.z * c)
        }
        Deformation::Strained => x,
        Deformation::Sheared => Vector3::new(x.x + 0.1 * x.y, 0.6 * x.y, x.z - 0.05 * x.x),
    });
}

/// A cube of `cells³` cells (six tetrahedra each) with its top face pinned and all three
/// families, spawned into `world`: the body of the parallel tests.
pub fn hanging_cube(world: &mut hecs::World, cells: u32) -> hecs::Entity {
    hanging_cube_parts(world, cells, 0)
}

/// [`hanging_cube`] cut into `parts` slabs for the sweep order (0: the builder's choice).
#[allow(dead_code)]
pub fn hanging_cube_parts(world: &mut hecs::World, cells: u32, parts: usize) -> hecs::Entity {
    let mesh = cube(cells, CellSplit::Six);
    let top = top(&mesh);
    tetpbd::SoftBodyBuilder::new(mesh)
        .edges(1e-6)
        .volume(0.0)
        .vertex_face(1e-5)
        .pinned(top)
        .parts(parts)
        .build()
        .unwrap()
        .spawn(world)
}

/// Positions, then velocities, of a body as bits (for bit-identity comparisons).
pub fn state_bits(p: &tetpbd::Particles) -> Vec<[u32; 3]> {
    p.positions()
        .iter()
        .chain(p.velocities())
        .map(|x| x.map(f32::to_bits).into())
        .collect()
}

/// Kinetic + gravitational energy (g = 9.81 m/s² along −y) of the particles, J, in `f64`.
pub fn mechanical_energy(p: &Particles) -> f64 {
    p.positions()
        .iter()
        .zip(p.velocities())
        .zip(p.masses())
        .map(|((x, v), &m)| {
            let m = f64::from(m);
            m * 9.81 * f64::from(x.y) + 0.5 * m * v.cast::<f64>().norm_squared()
        })
        .sum()
}
