//! A tiny seeded generator shared by the tests (no extra dependency, deterministic).
#![allow(dead_code)]

use nalgebra::Vector3;

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
}

/// A cube of `cells³` cells (six tetrahedra each) with its top face pinned and all three
/// families, spawned into `world`: the body of the parallel tests.
pub fn hanging_cube(world: &mut hecs::World, cells: u32) -> hecs::Entity {
    hanging_cube_parts(world, cells, 0)
}

/// [`hanging_cube`] cut into `parts` slabs for the sweep order (0: the builder's choice).
#[allow(dead_code)]
pub fn hanging_cube_parts(world: &mut hecs::World, cells: u32, parts: usize) -> hecs::Entity {
    use tetpbd::generators::{box_grid, CellSplit};
    let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Six).unwrap();
    let top: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y > 0.49)
        .collect();
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
