//! [`Grab`]: a material point of a soft body held to a moving target (mouse picking, a
//! hand), as a compliant XPBD constraint with a bounded force.
//!
//! The constraint is [`crate::constraints::grab`]: `C = |p − t|` (m) with
//! `p = Σ bₖ xₖ` the grabbed material point ([`MaterialPoint`]) and `t` the target,
//! `∇xₖ C = bₖ (p − t)/|p − t|`, compliance `α` in m/N (`1/α` is the spring rate, N/m;
//! 0 holds the point on the target as hard as the substeps allow). The accumulated multiplier of a
//! substep is kept in `[−F_max h², 0]`: the grab never pulls harder than `F_max` (N), so a
//! heavy body follows a fast target only as fast as `F_max` accelerates it
//! ([`crate::constraints::grab_delta_lambda`]).
//!
//! The solver projects it once per iteration after the body's own families, on every body
//! that has the component (a body without it pays nothing). The target moves linearly from
//! where it was at the end of the previous frame to where [`Grab::set_target`] put it, across
//! the substeps, so a target moving each frame pulls smoothly. Releasing is removing the
//! component: the grab keeps no state anywhere else.

use nalgebra::Vector3;

use crate::body::material_point::MaterialPoint;
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::constraints::{grab, grab_delta_lambda};
use crate::error::StateError;

/// A material point held to a target point (an optional hecs component; module docs).
///
/// ```
/// use nalgebra::Vector3;
/// use tetpbd::{generators, Grab, Solver, SolverSettings, SoftBodyBuilder};
/// let mesh = generators::box_grid(Vector3::repeat(1.0), [2, 2, 2], generators::CellSplit::Six)?;
/// let body = SoftBodyBuilder::new(mesh).edges(0.0).build()?;
/// // Grab the body at its centre with a 1e-3 m/N spring pulling at most 200 N.
/// let mut grab = Grab::at(&body.particles, &body.tetrahedra, Vector3::zeros(), 1e-3, 200.0)?;
/// grab.set_target(Vector3::new(0.0, 0.5, 0.0))?;
/// let mut world = hecs::World::new();
/// let e = body.spawn(&mut world);
/// world.insert_one(e, grab)?;
/// Solver::new(SolverSettings::default())?.step(&mut world)?;
/// world.remove_one::<Grab>(e)?; // release
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Grab {
    point: MaterialPoint,
    target: Vector3<f32>,
    previous: Vector3<f32>,
    compliance: f32,
    max_force: f32,
    lambda: f32,
    force: Vector3<f32>,
}

impl Grab {
    /// Grabs `point` (m; the nearest material point if it is outside the body), with the
    /// target where the point is now (the constraint starts satisfied). `compliance` in m/N
    /// (finite, ≥ 0), `max_force` in N (> 0; `f32::INFINITY` for no bound).
    pub fn at(
        particles: &Particles,
        tetrahedra: &Tetrahedra,
        point: Vector3<f32>,
        compliance: f32,
        max_force: f32,
    ) -> Result<Grab, StateError> {
        let (at, _) = MaterialPoint::locate(particles, tetrahedra, point)?;
        let target = at
            .position(particles, tetrahedra)
            .ok_or(StateError::NoTetrahedra)?;
        Grab::new(at, target, compliance, max_force)
    }

    /// Grabs the material point `point` and pulls it towards `target` (m).
    pub fn new(
        point: MaterialPoint,
        target: Vector3<f32>,
        compliance: f32,
        max_force: f32,
    ) -> Result<Grab, StateError> {
        check_target(&target)?;
        if !(compliance.is_finite() && compliance >= 0.0) {
            return Err(StateError::BadCompliance { value: compliance });
        }
        if max_force.is_nan() || max_force <= 0.0 {
            return Err(StateError::BadParameter {
                what: "max force (N)",
                value: max_force,
            });
        }
        Ok(Grab {
            point,
            target,
            previous: target,
            compliance,
            max_force,
            lambda: 0.0,
            force: Vector3::zeros(),
        })
    }

    /// Moves the target to `target` (m) for the coming frame; it sweeps there from the
    /// previous frame's target across the substeps.
    pub fn set_target(&mut self, target: Vector3<f32>) -> Result<(), StateError> {
        check_target(&target)?;
        self.target = target;
        Ok(())
    }

    /// The target, m.
    pub fn target(&self) -> Vector3<f32> {
        self.target
    }

    /// The grabbed material point.
    pub fn material_point(&self) -> MaterialPoint {
        self.point
    }

    /// The grab of the same material point with its tetrahedron renumbered to `t`.
    pub(crate) fn renumbered(mut self, t: usize) -> Grab {
        self.point = self.point.renumbered(t);
        self
    }

    /// Compliance, m/N.
    pub fn compliance(&self) -> f32 {
        self.compliance
    }

    /// Largest force, N.
    pub fn max_force(&self) -> f32 {
        self.max_force
    }

    /// The force the grab exerted on the body over the last substep, N (towards the target).
    pub fn force(&self) -> Vector3<f32> {
        self.force
    }

    /// Distance from the grabbed point to the target, m; `None` when the point's
    /// tetrahedron is not in the body.
    pub fn error(&self, particles: &Particles, tetrahedra: &Tetrahedra) -> Option<f32> {
        Some((self.point.position(particles, tetrahedra)? - self.target).norm())
    }
}

fn check_target(target: &Vector3<f32>) -> Result<(), StateError> {
    if target.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(StateError::NonFinite {
            what: "grab target",
            index: 0,
        })
    }
}

/// Zeroes every grab's multiplier and force (start of a substep).
pub fn reset_grabs(world: &mut hecs::World) {
    for g in world.query_mut::<&mut Grab>() {
        g.lambda = 0.0;
        g.force = Vector3::zeros();
    }
}

/// One projection of every body's [`Grab`] in a substep of length `h` (s) that ends at
/// `frac` of the frame (the target stands at `previous + frac (target − previous)`).
pub fn project_grabs(world: &mut hecs::World, h: f32, frac: f32) {
    for (p, tets, g) in world
        .query_mut::<(&mut Particles, &Tetrahedra, &mut Grab)>()
        .without::<&crate::Asleep>()
    {
        let Some(corners) = g.point.corners(p, tets) else {
            continue;
        };
        let target = g.previous.lerp(&g.target, frac);
        let x = corners.map(|i| &p.positions[i]);
        let b = g.point.coords();
        let Some(e) = grab(x, b, &target) else {
            continue;
        };
        let w = corners.map(|i| p.inv_masses[i]);
        let w_grad_sq: f32 = (0..4).map(|k| w[k] * e.grad[k].norm_squared()).sum();
        let alpha_tilde = g.compliance / (h * h);
        let Some(dl) = grab_delta_lambda(e.c, g.lambda, alpha_tilde, w_grad_sq, g.max_force, h)
        else {
            continue;
        };
        g.lambda += dl;
        for k in 0..4 {
            p.positions[corners[k]] += e.grad[k] * (w[k] * dl);
        }
        // The force over the substep is ∇C λ / h² summed over the corners: n λ / h².
        let n = e.grad.iter().sum::<Vector3<f32>>();
        g.force = n * (g.lambda / (h * h));
    }
}

/// End of a frame: every grab's previous target becomes its current one.
pub fn roll_grab_targets(world: &mut hecs::World) {
    for g in world.query_mut::<&mut Grab>() {
        g.previous = g.target;
    }
}
