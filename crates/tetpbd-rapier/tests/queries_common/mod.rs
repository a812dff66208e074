//! Shared helpers of the scene-query tests (`tests/queries_*.rs`): a seeded generator,
//! placed cubes and balls, and the analytic answers for a box.
#![allow(dead_code)]

use hecs::{Entity, World};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rapier3d::math::Vector;
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder};
use tetpbd_rapier::SoftLocation;

/// A small deterministic generator (xorshift64*).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let r = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (r >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in `[-1, 1)³`.
    pub fn cube(&mut self) -> Vector3<f32> {
        Vector3::new(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        )
    }

    /// A random rotation (uniform axis in the cube, angle up to π).
    pub fn rotation(&mut self) -> UnitQuaternion<f32> {
        let axis = self.cube() + Vector3::new(1e-3, 0.0, 0.0);
        UnitQuaternion::from_scaled_axis(axis.normalize() * self.range(0.0, std::f32::consts::PI))
    }

    /// A random pose: rotation as above, translation within `reach` m of the origin.
    pub fn pose(&mut self, reach: f32) -> Isometry3<f32> {
        Isometry3::from_parts(Translation3::from(self.cube() * reach), self.rotation())
    }
}

/// Spawns a cube of half extent `h` (m), `cells` cells per axis, at `pose`.
pub fn spawn_cube(world: &mut World, h: f32, cells: u32, pose: Isometry3<f32>) -> Entity {
    let mesh = generators::box_grid(Vector3::repeat(2.0 * h), [cells; 3], CellSplit::Six)
        .expect("cube mesh");
    SoftBodyBuilder::new(mesh)
        .pose(pose)
        .build()
        .expect("cube body")
        .spawn(world)
}

/// Spawns a ball of radius `r` (m), `cells` cells per axis, centred at `c`.
pub fn spawn_ball(world: &mut World, r: f32, cells: u32, c: Vector3<f32>) -> Entity {
    let mesh = generators::ball(r, cells, CellSplit::Six).expect("ball mesh");
    SoftBodyBuilder::new(mesh)
        .translation(c)
        .build()
        .expect("ball body")
        .spawn(world)
}

pub fn na(v: Vector) -> Vector3<f32> {
    Vector3::new(v.x, v.y, v.z)
}

pub fn glam(v: &Vector3<f32>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// The point a location names, from the body's current positions.
pub fn location_point(world: &World, e: Entity, loc: &SoftLocation) -> Vector3<f32> {
    let p = world.get::<&Particles>(e).expect("particles");
    loc.weights()
        .map(|(i, w)| p.positions()[i as usize] * w)
        .sum()
}

/// The point of the box `[-h, h]³` nearest to the local point `q`, and `q`'s distance to
/// the box surface (from either side).
pub fn box_surface_nearest(q: &Vector3<f32>, h: f32) -> (Vector3<f32>, f32) {
    let inside = q.iter().all(|c| c.abs() <= h);
    if !inside {
        let n = q.map(|c| c.clamp(-h, h));
        return (n, (q - n).norm());
    }
    // Inside: the nearest face.
    let (axis, _) = q
        .iter()
        .enumerate()
        .map(|(i, c)| (i, h - c.abs()))
        .fold((0, f32::MAX), |a, b| if b.1 < a.1 { b } else { a });
    let mut n = *q;
    n[axis] = h * q[axis].signum();
    (n, h - q[axis].abs())
}
