//! The particle state of one soft body: one flat array per quantity.

use nalgebra::Vector3;

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

use crate::error::StateError;

/// Particle state of one soft body, one flat array per quantity (a hecs component).
///
/// All arrays have the same length, fixed when the body is built; the accessors hand out
/// slices so the length cannot change. Particle `i` is the `i`-th vertex the body was built
/// from, unless the builder renumbered the particles for locality
/// ([`crate::SoftBodyBuilder::spatial_order`]): then [`Particles::source`] and
/// [`Particles::particle_of`] map between particles and input vertices. A particle with inverse mass 0 is pinned: the solver never moves it (it can still be
/// moved by writing its position, e.g. to drive it kinematically).
///
/// Equality (`==`) and serialization cover the state: positions, substep starts,
/// velocities, masses and inverse masses, rest positions, rounding residuals and the
/// particle–vertex maps. The projections' working copy is scratch memory, rebuilt by every
/// sweep: it is neither compared nor serialized, so a body restored from a snapshot equals
/// the one it was taken from.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Particles {
    pub(crate) positions: Vec<Vector3<f32>>,
    pub(crate) prev_positions: Vec<Vector3<f32>>,
    pub(crate) velocities: Vec<Vector3<f32>>,
    pub(crate) inv_masses: Vec<f32>,
    pub(crate) masses: Vec<f32>,
    pub(crate) rest_positions: Vec<Vector3<f32>>,
    /// Rounding residual of the current substep's position updates (see
    /// [`crate::solver::systems::add_compensated`]); zeroed by prediction.
    pub(crate) residuals: Vec<Vector3<f32>>,
    /// Input vertex of each particle (see [`crate::SoftBodyBuilder::spatial_order`]).
    pub(crate) source: Vec<u32>,
    /// Particle of each input vertex (the inverse of `source`).
    pub(crate) vertex_to_particle: Vec<u32>,
    /// The projections' working copy (scratch, see [`crate::kernels::working_copy`]).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) work: crate::kernels::slots::WorkCopy,
    /// Whether the particles were written through a public accessor since the end of the
    /// last step (wakes a sleeping body, `body::activation` module docs). Not state: neither
    /// compared nor serialized.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) written: bool,
    /// The kinetic energy a hook's corrections handed the families' next pass (see
    /// [`crate::stabilisation::hook_work`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pub(crate) hook: crate::stabilisation::hook_work::HookWork,
}

impl PartialEq for Particles {
    fn eq(&self, o: &Particles) -> bool {
        // Every field but the working copy (`work`), which is scratch.
        let Particles {
            positions,
            prev_positions,
            velocities,
            inv_masses,
            masses,
            rest_positions,
            residuals,
            source,
            vertex_to_particle,
            work: _,
            written: _,
            hook,
        } = self;
        *positions == o.positions
            && *prev_positions == o.prev_positions
            && *velocities == o.velocities
            && *inv_masses == o.inv_masses
            && *masses == o.masses
            && *rest_positions == o.rest_positions
            && *residuals == o.residuals
            && *source == o.source
            && *vertex_to_particle == o.vertex_to_particle
            && *hook == o.hook
    }
}

impl Particles {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// `true` when the body has no particles.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Current positions, m.
    pub fn positions(&self) -> &[Vector3<f32>] {
        &self.positions
    }

    /// Current positions for writing, m. Writing a non-finite value is the caller's bug; use
    /// [`Particles::set_position`] for a checked write.
    ///
    /// Borrowing them wakes a sleeping body at the next step (as does every other write
    /// below: velocities, pinning, impulses).
    pub fn positions_mut(&mut self) -> &mut [Vector3<f32>] {
        self.written = true;
        &mut self.positions
    }

    /// Positions at the start of the current substep, m.
    pub fn prev_positions(&self) -> &[Vector3<f32>] {
        &self.prev_positions
    }

    /// Velocities, m/s.
    pub fn velocities(&self) -> &[Vector3<f32>] {
        &self.velocities
    }

    /// Velocities for writing, m/s.
    pub fn velocities_mut(&mut self) -> &mut [Vector3<f32>] {
        self.written = true;
        &mut self.velocities
    }

    /// Inverse masses, 1/kg; 0 for pinned particles.
    pub fn inv_masses(&self) -> &[f32] {
        &self.inv_masses
    }

    /// Lumped masses, kg (also for pinned particles).
    pub fn masses(&self) -> &[f32] {
        &self.masses
    }

    /// For each particle, the index of the input mesh vertex it was built from (the
    /// identity unless [`crate::SoftBodyBuilder::spatial_order`] renumbered the particles).
    pub fn source(&self) -> &[u32] {
        &self.source
    }

    /// The particle built from input mesh vertex `vertex`; `None` when the mesh had no such
    /// vertex. Use it to turn a mesh vertex index into the particle index that
    /// [`Particles::positions`], pinning and attachments take.
    pub fn particle_of(&self, vertex: u32) -> Option<u32> {
        // A piece of a split body lacks the vertices of the other pieces (`u32::MAX`).
        let p = *self.vertex_to_particle.get(vertex as usize)?;
        (p != u32::MAX).then_some(p)
    }

    /// Rest-pose positions the body was built from, m.
    pub fn rest_positions(&self) -> &[Vector3<f32>] {
        &self.rest_positions
    }

    /// Pins (`true`) or frees particle `i`.
    pub fn set_pinned(&mut self, i: usize, pinned: bool) -> Result<(), StateError> {
        let n = self.len();
        let m = *self
            .masses
            .get(i)
            .ok_or(StateError::ParticleOutOfRange { index: i, len: n })?;
        self.written = true;
        self.inv_masses[i] = if pinned || m <= 0.0 { 0.0 } else { 1.0 / m };
        Ok(())
    }

    /// `true` when particle `i` exists and is pinned.
    pub fn is_pinned(&self, i: usize) -> bool {
        self.inv_masses.get(i).is_some_and(|w| *w == 0.0)
    }

    /// Checked write of one particle's position (m); also resets its substep start so the
    /// move does not turn into a velocity.
    pub fn set_position(&mut self, i: usize, p: Vector3<f32>) -> Result<(), StateError> {
        let n = self.len();
        if i >= n {
            return Err(StateError::ParticleOutOfRange { index: i, len: n });
        }
        if !p.iter().all(|x| x.is_finite()) {
            return Err(StateError::NonFinite {
                what: "position",
                index: i,
            });
        }
        self.written = true;
        self.positions[i] = p;
        self.prev_positions[i] = p;
        Ok(())
    }

    /// Checked write of one particle's velocity, m/s.
    pub fn set_velocity(&mut self, i: usize, v: Vector3<f32>) -> Result<(), StateError> {
        let n = self.len();
        if i >= n {
            return Err(StateError::ParticleOutOfRange { index: i, len: n });
        }
        if !v.iter().all(|x| x.is_finite()) {
            return Err(StateError::NonFinite {
                what: "velocity",
                index: i,
            });
        }
        self.written = true;
        self.velocities[i] = v;
        Ok(())
    }

    /// Whether the particles were written through a public accessor since the end of the
    /// last step (such a write wakes a sleeping body at the next step).
    pub fn written(&self) -> bool {
        self.written
    }

    /// Total mass of all particles, pinned ones included, kg.
    pub fn total_mass(&self) -> f32 {
        self.masses.iter().sum()
    }

    /// Mass-weighted centre of the particles, m.
    pub fn center_of_mass(&self) -> Vector3<f32> {
        let m = self.total_mass();
        if m <= 0.0 {
            return Vector3::zeros();
        }
        self.positions
            .iter()
            .zip(&self.masses)
            .fold(Vector3::zeros(), |acc, (p, mi)| acc + p * *mi)
            / m
    }

    /// Linear momentum Σ mᵢvᵢ, kg·m/s.
    pub fn linear_momentum(&self) -> Vector3<f32> {
        self.velocities
            .iter()
            .zip(&self.masses)
            .fold(Vector3::zeros(), |acc, (v, m)| acc + v * *m)
    }

    /// Angular momentum Σ xᵢ × mᵢvᵢ about the origin, kg·m²/s.
    pub fn angular_momentum(&self) -> Vector3<f32> {
        self.positions
            .iter()
            .zip(&self.velocities)
            .zip(&self.masses)
            .fold(Vector3::zeros(), |acc, ((x, v), m)| {
                acc + x.cross(&(v * *m))
            })
    }

    /// Kinetic energy ½ Σ mᵢ|vᵢ|², J.
    pub fn kinetic_energy(&self) -> f32 {
        0.5 * self
            .velocities
            .iter()
            .zip(&self.masses)
            .map(|(v, m)| m * v.norm_squared())
            .sum::<f32>()
    }

    /// Largest particle speed, m/s.
    pub fn max_speed(&self) -> f32 {
        self.velocities.iter().map(|v| v.norm()).fold(0.0, f32::max)
    }

    /// Axis-aligned bounds of the current positions, `(min, max)` in m.
    pub fn aabb(&self) -> (Vector3<f32>, Vector3<f32>) {
        let mut lo = Vector3::repeat(f32::INFINITY);
        let mut hi = Vector3::repeat(f32::NEG_INFINITY);
        for p in &self.positions {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        (lo, hi)
    }
}

/// A constant acceleration added to gravity for every free particle of a body, m/s²
/// (an optional hecs component; e.g. wind or buoyancy).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct ExternalAcceleration(pub(crate) Vector3<f32>);

impl ExternalAcceleration {
    /// Checks that `a` is finite.
    pub fn new(a: Vector3<f32>) -> Result<Self, StateError> {
        if a.iter().all(|c| c.is_finite()) {
            Ok(ExternalAcceleration(a))
        } else {
            Err(StateError::NonFinite {
                what: "acceleration",
                index: 0,
            })
        }
    }

    /// The acceleration, m/s².
    pub fn get(&self) -> Vector3<f32> {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use crate::generators::{box_grid, CellSplit};
    use crate::kernels::slots::Slot;
    use crate::SoftBodyBuilder;

    #[test]
    fn equality_compares_the_state_not_the_scratch() {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [2, 2, 2], CellSplit::Six).unwrap();
        let a = SoftBodyBuilder::new(mesh).build().unwrap().particles;
        let mut b = a.clone();
        b.work.0.clear();
        b.work.0.push(Slot::default());
        assert_eq!(a, b, "the working copy is scratch");
        b.positions[3].y += 1e-3;
        assert_ne!(a, b, "a moved particle is a different state");
        let mut c = a.clone();
        c.residuals[0].x = 1e-9;
        assert_ne!(a, c, "the rounding residual is state");
    }
}
