//! [`UserForces`]: forces the user applies to a soft body — on the whole body, at a point,
//! in a sphere (an explosion) — integrated by the solver like gravity.
//!
//! The component holds one force per particle, N. Every substep of length `h`, before the
//! prediction, each free particle's velocity gains `h · wᵢ Fᵢ` (`wᵢ = 1/mᵢ`): the forces
//! are integrated exactly as gravity is, so over a frame of length `dt` the body's momentum
//! changes by `Σ Fᵢ · dt` and its angular momentum by `Σ xᵢ × Fᵢ · dt` (to f32 rounding,
//! with the positions of each substep). A pinned particle takes no share.
//!
//! **Forces persist until [`UserForces::reset_forces`]**, as rapier's user forces do: a
//! force added once acts on every following frame. A game that applies a force for one
//! frame resets it after the step; a thruster adds it once and leaves it. A force at a
//! point stays with the particles it was given to (the material point moves with the body;
//! the force's direction stays fixed in the world).
//!
//! A body without the component pays nothing: the solver's loop runs over the bodies that
//! have it.
//!
//! At a point `p` held by tetrahedron `t` with barycentric coordinates `bₖ`
//! ([`MaterialPoint`]), corner `k` takes `bₖ F`: `Σ bₖ F = F` and `Σ xₖ × bₖ F = p × F`, the
//! force and torque of a rigid body pushed at `p`. A radial force gives each free particle
//! within `R` of the centre the acceleration `a · (1 − r/R)` away from it (`r` its distance,
//! the falloff of [`Particles::apply_radial_impulse`]): the force `mᵢ a (1 − r/R)`.

use nalgebra::Vector3;

use crate::body::grab::Grab;
use crate::body::impulses::finite;
use crate::body::material_point::MaterialPoint;
use crate::body::mesh::Tetrahedra;
use crate::body::particles::{ExternalAcceleration, Particles};
use crate::error::StateError;

/// User forces on one soft body, one per particle, N (an optional hecs component; see the
/// module docs for how they act and that they persist until reset).
///
/// ```
/// use nalgebra::Vector3;
/// use tetpbd::{generators, Solver, SolverSettings, SoftBodyBuilder, UserForces};
/// let mesh = generators::box_grid(Vector3::repeat(1.0), [2, 2, 2], generators::CellSplit::Six)?;
/// let body = SoftBodyBuilder::new(mesh).edges(0.0).build()?;
/// let mut forces = UserForces::new(&body.particles);
/// forces.add_force_at_point(&body.particles, &body.tetrahedra, Vector3::x() * 10.0, Vector3::zeros())?;
/// let mut world = hecs::World::new();
/// let e = body.spawn(&mut world);
/// world.insert_one(e, forces)?;
/// Solver::new(SolverSettings::default())?.step(&mut world)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct UserForces {
    pub(crate) forces: Vec<Vector3<f32>>,
}

impl UserForces {
    /// No force, for a body with `particles`.
    pub fn new(particles: &Particles) -> UserForces {
        UserForces {
            forces: vec![Vector3::zeros(); particles.len()],
        }
    }

    /// The force on each particle, N.
    pub fn forces(&self) -> &[Vector3<f32>] {
        &self.forces
    }

    /// The total force, N.
    pub fn force(&self) -> Vector3<f32> {
        self.forces.iter().sum()
    }

    /// The total torque about `origin` (m) with the particles where they are now, N·m.
    pub fn torque(&self, particles: &Particles, origin: Vector3<f32>) -> Vector3<f32> {
        particles
            .positions()
            .iter()
            .zip(&self.forces)
            .fold(Vector3::zeros(), |acc, (x, f)| acc + (x - origin).cross(f))
    }

    /// Removes every force (rapier's `reset_forces`).
    pub fn reset_forces(&mut self) {
        self.forces.fill(Vector3::zeros());
    }

    /// Adds `force` (N) to the whole body, spread over its free particles in proportion to
    /// their masses: every free particle accelerates by `F / M_free`, and the body does not
    /// start to spin.
    pub fn add_force(
        &mut self,
        particles: &Particles,
        force: Vector3<f32>,
    ) -> Result<(), StateError> {
        self.check(particles)?;
        finite(&force, "force")?;
        let free: f64 = particles.free_masses().map(f64::from).sum();
        if free <= 0.0 {
            return Err(StateError::AllPinned);
        }
        let per_kg = force.cast::<f64>() / free;
        let shares = particles
            .masses()
            .iter()
            .zip(particles.inv_masses())
            .enumerate()
            .filter(|(_, (_, w))| **w > 0.0)
            .map(|(i, (m, _))| (i, (per_kg * f64::from(*m)).cast::<f32>()));
        self.commit(shares.collect())
    }

    /// Adds `force` (N) at `point` (m), spread over the corners of the tetrahedron holding
    /// it by their barycentric coordinates (module docs). Returns the material point that
    /// took it.
    pub fn add_force_at_point(
        &mut self,
        particles: &Particles,
        tetrahedra: &Tetrahedra,
        force: Vector3<f32>,
        point: Vector3<f32>,
    ) -> Result<MaterialPoint, StateError> {
        self.check(particles)?;
        finite(&force, "force")?;
        let (at, _) = MaterialPoint::locate(particles, tetrahedra, point)?;
        let (corners, shares) = at.free_shares(particles, tetrahedra)?;
        let updates = corners
            .iter()
            .zip(&shares)
            .filter(|(_, s)| **s > 0.0)
            .map(|(i, s)| (*i, force * *s))
            .collect();
        self.commit(updates)?;
        Ok(at)
    }

    /// An explosion's push at `centre` (m): every free particle within `radius` (m) gains
    /// the force `mᵢ · acceleration · (1 − r/R)` (N; `acceleration` in m/s²) away from the
    /// centre. Returns the total force added, N.
    pub fn add_radial_force(
        &mut self,
        particles: &Particles,
        centre: Vector3<f32>,
        radius: f32,
        acceleration: f32,
    ) -> Result<Vector3<f32>, StateError> {
        self.check(particles)?;
        finite(&centre, "centre")?;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(StateError::BadParameter {
                what: "radius",
                value: radius,
            });
        }
        if !acceleration.is_finite() {
            return Err(StateError::BadParameter {
                what: "acceleration",
                value: acceleration,
            });
        }
        let mut updates = Vec::new();
        let (x, m, w) = (
            particles.positions(),
            particles.masses(),
            particles.inv_masses(),
        );
        for i in 0..x.len() {
            let d = x[i] - centre;
            let r = d.norm();
            if w[i] == 0.0 || r >= radius || r == 0.0 {
                continue;
            }
            updates.push((i, d * (m[i] * acceleration * (1.0 - r / radius) / r)));
        }
        let total = updates.iter().map(|(_, f)| f).sum();
        self.commit(updates)?;
        Ok(total)
    }

    fn check(&self, particles: &Particles) -> Result<(), StateError> {
        if self.forces.len() == particles.len() {
            Ok(())
        } else {
            Err(StateError::LengthMismatch {
                what: "UserForces",
                len: self.forces.len(),
                particles: particles.len(),
            })
        }
    }

    /// Adds every `(particle, force)` or, if one sum would not be finite, none.
    fn commit(&mut self, updates: Vec<(usize, Vector3<f32>)>) -> Result<(), StateError> {
        if let Some((i, _)) = updates
            .iter()
            .find(|(i, f)| !(self.forces[*i] + f).iter().all(|c| c.is_finite()))
        {
            return Err(StateError::NonFinite {
                what: "force",
                index: *i,
            });
        }
        for (i, f) in updates {
            self.forces[i] += f;
        }
        Ok(())
    }
}

/// Every body's [`UserForces`] over a substep of length `h` (s): `vᵢ ← vᵢ + h wᵢ Fᵢ` for
/// every free particle. [`crate::systems::predict`] runs it first, so the forces are
/// integrated as gravity is.
pub fn integrate_user_forces(world: &mut hecs::World, h: f32) {
    for (p, f) in world
        .query_mut::<(&mut Particles, &UserForces)>()
        .without::<&crate::Asleep>()
    {
        let Particles {
            velocities,
            inv_masses,
            ..
        } = p;
        for ((v, w), f) in velocities.iter_mut().zip(inv_masses.iter()).zip(&f.forces) {
            *v += f * (h * *w);
        }
    }
}

/// The acceleration (m/s²) that the loads applied to a body besides gravity give the centre
/// of mass of its free particles: its [`UserForces`] on free particles, its [`Grab`]'s force
/// over the last substep ([`Grab::force`]) and its [`ExternalAcceleration`],
///
/// ```text
/// a = (Σ_free Fᵢ + F_grab) / Σ_free mᵢ + a_ext
/// ```
///
/// Zero for a body without free particles or when a load is not finite. Contact responses
/// use it to tell a pull the user applies from the body's own elastic recoil.
pub fn applied_acceleration(
    particles: &Particles,
    forces: Option<&UserForces>,
    grab: Option<&Grab>,
    external: Option<&ExternalAcceleration>,
) -> Vector3<f32> {
    let mut mass = 0.0f32;
    let mut force = grab.map_or(Vector3::zeros(), Grab::force);
    for (i, &m) in particles.masses.iter().enumerate() {
        if particles.inv_masses[i] > 0.0 {
            mass += m;
            if let Some(f) = forces.and_then(|f| f.forces.get(i)) {
                force += f;
            }
        }
    }
    if mass <= 0.0 {
        return Vector3::zeros();
    }
    let total = force / mass + external.map_or(Vector3::zeros(), ExternalAcceleration::get);
    if total.iter().all(|c| c.is_finite()) {
        total
    } else {
        Vector3::zeros()
    }
}
