//! [`Attachments`]: soft particles held to rigid bodies or kinematic targets (a hecs
//! component).
//!
//! Each attachment is a zero-rest-length XPBD distance constraint `C = |p − a|` between a
//! particle `p` and an anchor `a`, with compliance `α` in m/N (0 = rigid pin). An anchor on a
//! dynamic rigid body takes part with the body's generalized inverse mass, so the soft body
//! pulls the rigid body and vice versa. A kinematic target is infinitely heavy; it moves
//! linearly from the previous frame's target to the current one across the substeps.

use nalgebra::Vector3;
use rapier3d::dynamics::{RigidBodyHandle, RigidBodySet};
use tetpbd::Particles;

use crate::convert::{finite3, pose_to_na};
use crate::error::{check_coefficient, CouplingError};

/// What a particle is attached to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AttachTarget {
    /// A point fixed in a rigid body's frame (body-local coordinates, m).
    Body {
        /// The rigid body.
        handle: RigidBodyHandle,
        /// The anchor in the body's local frame, m.
        local_point: Vector3<f32>,
    },
    /// A kinematic world-space target, m, moved by [`Attachments::set_target`].
    Point {
        /// Target at the end of the coming frame, m.
        position: Vector3<f32>,
        /// Target at the end of the previous frame, m.
        previous: Vector3<f32>,
    },
}

/// One attachment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attachment {
    /// The soft particle.
    pub particle: u32,
    /// Its anchor.
    pub target: AttachTarget,
    /// Compliance α, m/N (0 = rigid).
    pub compliance: f32,
}

/// The attachments of one soft body (a hecs component on its entity).
///
/// ```
/// use nalgebra::Vector3;
/// use tetpbd::{generators, SoftBodyBuilder};
/// use tetpbd_rapier::Attachments;
/// let mesh = generators::box_grid(Vector3::new(1.0, 1.0, 1.0), [1, 1, 1], generators::CellSplit::Six)?;
/// let body = SoftBodyBuilder::new(mesh).edges(0.0).build()?;
/// let mut att = Attachments::new();
/// let k = att.attach_to_point(&body.particles, 0, Vector3::zeros(), 0.0)?;
/// att.set_target(k, Vector3::new(0.0, 1.0, 0.0))?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Attachments {
    pub(crate) items: Vec<Attachment>,
}

impl Attachments {
    /// No attachments.
    pub fn new() -> Self {
        Self::default()
    }

    /// The attachments.
    pub fn items(&self) -> &[Attachment] {
        &self.items
    }

    /// Number of attachments.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// `true` when there is none.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Attaches `particle` to `body` at the particle's current position (so the constraint
    /// starts satisfied), compliance in m/N. Returns the attachment's index.
    pub fn attach_to_body(
        &mut self,
        particles: &Particles,
        particle: u32,
        bodies: &RigidBodySet,
        body: RigidBodyHandle,
        compliance: f32,
    ) -> Result<usize, CouplingError> {
        let p = particle_position(particles, particle)?;
        let rb = bodies
            .get(body)
            .ok_or(CouplingError::BodyNotFound { handle: body })?;
        let local = pose_to_na(rb.position()).inverse_transform_point(&p.into());
        self.push_body(particle, body, local.coords, compliance)
    }

    /// Attaches `particle` to a point given in `body`'s local frame (m), compliance in m/N.
    pub fn attach_to_body_point(
        &mut self,
        particles: &Particles,
        particle: u32,
        bodies: &RigidBodySet,
        body: RigidBodyHandle,
        local_point: Vector3<f32>,
        compliance: f32,
    ) -> Result<usize, CouplingError> {
        particle_position(particles, particle)?;
        if !bodies.contains(body) {
            return Err(CouplingError::BodyNotFound { handle: body });
        }
        if !finite3(&local_point) {
            return Err(CouplingError::NonFinite {
                what: "attachment point",
            });
        }
        self.push_body(particle, body, local_point, compliance)
    }

    fn push_body(
        &mut self,
        particle: u32,
        handle: RigidBodyHandle,
        local_point: Vector3<f32>,
        compliance: f32,
    ) -> Result<usize, CouplingError> {
        check_coefficient("attachment compliance (m/N)", compliance)?;
        self.items.push(Attachment {
            particle,
            target: AttachTarget::Body {
                handle,
                local_point,
            },
            compliance,
        });
        Ok(self.items.len() - 1)
    }

    /// Attaches `particle` to a kinematic world target (m), compliance in m/N. Returns the
    /// attachment's index.
    pub fn attach_to_point(
        &mut self,
        particles: &Particles,
        particle: u32,
        position: Vector3<f32>,
        compliance: f32,
    ) -> Result<usize, CouplingError> {
        particle_position(particles, particle)?;
        if !finite3(&position) {
            return Err(CouplingError::NonFinite {
                what: "attachment target",
            });
        }
        check_coefficient("attachment compliance (m/N)", compliance)?;
        self.items.push(Attachment {
            particle,
            target: AttachTarget::Point {
                position,
                previous: position,
            },
            compliance,
        });
        Ok(self.items.len() - 1)
    }

    /// Moves the kinematic target of attachment `index` to `position` (m) for the coming
    /// frame; the anchor sweeps from the previous target to it across the substeps.
    pub fn set_target(
        &mut self,
        index: usize,
        position: Vector3<f32>,
    ) -> Result<(), CouplingError> {
        if !finite3(&position) {
            return Err(CouplingError::NonFinite {
                what: "attachment target",
            });
        }
        let len = self.items.len();
        match self.items.get_mut(index).map(|a| &mut a.target) {
            Some(AttachTarget::Point { position: p, .. }) => {
                *p = position;
                Ok(())
            }
            Some(AttachTarget::Body { .. }) => Err(CouplingError::NotAPointTarget { index }),
            None => Err(CouplingError::AttachmentOutOfRange { index, len }),
        }
    }

    /// Removes every attachment of `particle`.
    pub fn detach(&mut self, particle: u32) {
        self.items.retain(|a| a.particle != particle);
    }

    /// After a frame: every point target's previous value becomes its current one.
    pub(crate) fn roll_targets(&mut self) {
        for a in &mut self.items {
            if let AttachTarget::Point { position, previous } = &mut a.target {
                *previous = *position;
            }
        }
    }
}

fn particle_position(particles: &Particles, particle: u32) -> Result<Vector3<f32>, CouplingError> {
    particles
        .positions()
        .get(particle as usize)
        .copied()
        .ok_or(CouplingError::ParticleOutOfRange {
            index: particle,
            len: particles.len(),
        })
}

/// An attachment in the frame.
#[derive(Clone, Debug)]
pub(crate) struct AttachRun {
    pub particle: u32,
    pub body: Option<usize>,
    pub local: Vector3<f32>,
    pub start: Vector3<f32>,
    pub end: Vector3<f32>,
    pub compliance: f32,
    pub lambda: f32,
}

/// One sweep over a soft body's attachments (see the module docs for the constraint).
/// `frac` is the current substep's end time as a fraction of the frame.
pub(crate) fn project_attachments(
    runs: &mut [AttachRun],
    p: &mut Particles,
    bodies: &mut [crate::rigid::body::BodyProxy],
    frac: f32,
    h: f32,
) {
    for a in runs {
        let i = a.particle as usize;
        let anchor = anchor_of(a, bodies, frac);
        let d = p.positions()[i] - anchor;
        let len = d.norm();
        if len.is_nan() || len <= 1e-9 {
            continue;
        }
        let n = d / len;
        let alpha = a.compliance / (h * h);
        let w_p = p.inv_masses()[i];
        // The body is pulled towards the particle unless the compliant spring pushes back.
        let push = if -len - alpha * a.lambda < 0.0 { n } else { -n };
        let w_b = a
            .body
            .map_or(0.0, |b| bodies[b].inv_mass_pushed(&anchor, &push));
        let denom = w_p + w_b + alpha;
        if denom.is_nan() || denom <= 0.0 {
            continue;
        }
        let dl = (-len - alpha * a.lambda) / denom;
        a.lambda += dl;
        p.positions_mut()[i] += n * (w_p * dl);
        if let Some(b) = a.body {
            bodies[b].apply_position_impulse(&(-n * dl), &anchor);
        }
    }
}

/// World anchor of an attachment at the current substep, m.
pub(crate) fn anchor_of(
    a: &AttachRun,
    bodies: &[crate::rigid::body::BodyProxy],
    frac: f32,
) -> Vector3<f32> {
    match a.body {
        Some(b) => (bodies[b].pose * nalgebra::Point3::from(a.local)).coords,
        None => a.start.lerp(&a.end, frac),
    }
}
