//! Render interpolation of the soft surfaces: what a renderer uploads each displayed frame.
//!
//! The physics steps at a fixed rate; the display runs at its own. After each physics step
//! the surface particles' positions are kept (`current`, the step before in `previous`);
//! each displayed frame draws `previous + α (current − previous)`, `α` the fraction of a
//! step left in the accumulator. The drawn surface lags the physics by up to one step and
//! moves smoothly at any display rate.

use nalgebra::Vector3;
use tetpbd_rapier::prelude::{Particles, Surface};

/// One soft body's surface buffers.
struct SurfaceBuffer {
    entity: hecs::Entity,
    /// The surface's particles (`Surface::vertices`); the triangles index particles too.
    vertices: Vec<u32>,
    previous: Vec<Vector3<f32>>,
    current: Vec<Vector3<f32>>,
    /// What the renderer draws this frame.
    drawn: Vec<Vector3<f32>>,
}

/// The surfaces of every soft body of a world.
pub struct Surfaces {
    bodies: Vec<SurfaceBuffer>,
}

impl Surfaces {
    /// Buffers for every soft body of `soft`, at its current positions.
    pub fn new(soft: &hecs::World) -> Surfaces {
        let mut bodies = Vec::new();
        for (entity, p, s) in soft.query::<(hecs::Entity, &Particles, &Surface)>().iter() {
            let vertices = s.vertices().to_vec();
            let now: Vec<_> = vertices
                .iter()
                .map(|i| p.positions()[*i as usize])
                .collect();
            bodies.push(SurfaceBuffer {
                entity,
                vertices,
                previous: now.clone(),
                current: now.clone(),
                drawn: now,
            });
        }
        Surfaces { bodies }
    }

    /// After a physics step: the step's positions become `current`.
    pub fn after_step(&mut self, soft: &hecs::World) {
        for b in &mut self.bodies {
            let Ok(p) = soft.get::<&Particles>(b.entity) else {
                continue;
            };
            std::mem::swap(&mut b.previous, &mut b.current);
            for (c, i) in b.current.iter_mut().zip(&b.vertices) {
                *c = p.positions()[*i as usize];
            }
        }
    }

    /// Before drawing: the surfaces at `alpha` (0–1) of the way from the previous step to
    /// the last one.
    pub fn interpolate(&mut self, alpha: f32) {
        for b in &mut self.bodies {
            for ((d, p), c) in b.drawn.iter_mut().zip(&b.previous).zip(&b.current) {
                *d = p.lerp(c, alpha);
            }
        }
    }

    /// The mean of `entity`'s drawn surface points, m.
    pub fn drawn_centre(&self, entity: hecs::Entity) -> Option<Vector3<f32>> {
        let b = self.bodies.iter().find(|b| b.entity == entity)?;
        let n = b.drawn.len().max(1) as f32;
        Some(b.drawn.iter().sum::<Vector3<f32>>() / n)
    }
}
