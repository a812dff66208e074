//! rapier joints of bodies that carry soft bodies: a 2 kg box hanging 0.2 m below a fixed
//! anchor on a spherical, revolute, fixed or prismatic joint (impulse or multibody), with a
//! soft beam attached to its side or a soft cube resting on it. Criterion: the joint's anchor
//! drifts ≤ 1 mm over 10 s, in the last 5 s no more than 0.1 mm beyond the first 5 s; a
//! resting cube's centre moves < 1 cm across the box (in the box's frame).

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    ColliderBuilder, FixedJointBuilder, GenericJoint, PrismaticJointBuilder, RevoluteJointBuilder,
    RigidBodyBuilder, RigidBodyHandle, SphericalJointBuilder,
};
use tetpbd::generators::{self, box_grid, CellSplit};
use tetpbd_rapier::{Attachments, CoupledWorld};

use super::body::{world, Engine, Soft};
use super::run;
use crate::coupled::CoupledOutcome;

/// The joint types of the scenes.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Joint {
    /// Ball joint.
    Spherical,
    /// Hinge about z.
    Revolute,
    /// Welded.
    Fixed,
    /// Slider along x (the anchor's drift along x is free).
    Prismatic,
}

/// Where the joint's anchor is on the box, m (box frame).
const ANCHOR: Vector = Vector::new(0.0, 0.2, 0.0);
/// The fixed anchor, m.
const PIVOT: Vector = Vector::new(0.0, 1.0, 0.0);

impl Joint {
    fn build(self) -> GenericJoint {
        match self {
            Joint::Spherical => SphericalJointBuilder::new()
                .local_anchor2(ANCHOR)
                .build()
                .into(),
            Joint::Revolute => RevoluteJointBuilder::new(Vector::Z)
                .local_anchor2(ANCHOR)
                .build()
                .into(),
            Joint::Fixed => FixedJointBuilder::new()
                .local_anchor2(ANCHOR)
                .build()
                .into(),
            Joint::Prismatic => PrismaticJointBuilder::new(Vector::X)
                .local_anchor2(ANCHOR)
                .build()
                .into(),
        }
    }

    /// The anchor's drift that the joint forbids, m.
    fn drift(self, d: Vector) -> f32 {
        match self {
            Joint::Prismatic => Vector::new(0.0, d.y, d.z).length(),
            _ => d.length(),
        }
    }
}

/// The hanging 2 kg box of 0.2 m at (0, 0.8, 0) on `joint` from a fixed body at (0, 1, 0).
fn hanging_box(s: &mut CoupledWorld, joint: Joint, multibody: bool) -> RigidBodyHandle {
    let anchor = s
        .physics
        .bodies
        .insert(RigidBodyBuilder::fixed().translation(PIVOT));
    let (bx, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.8, 0.0)),
        ColliderBuilder::cuboid(0.1, 0.1, 0.1).mass(2.0),
    );
    if multibody {
        s.physics
            .multibody_joints
            .insert(anchor, bx, joint.build(), true);
    } else {
        s.physics
            .impulse_joints
            .insert(anchor, bx, joint.build(), true);
    }
    bx
}

/// A soft beam of `mass` kg (0.6 m along x, 6 × 1 × 1 cells) whose root face is attached to
/// the box's +x side.
fn attach_beam(
    s: &mut CoupledWorld,
    engine: Engine,
    bx: RigidBodyHandle,
    mass: f32,
) -> Result<Soft, String> {
    let mesh = generators::beam(0.6, 0.1, 6, 1, CellSplit::Six).map_err(|e| e.to_string())?;
    let roots = generators::beam_root(&mesh);
    let at = Vector3::new(0.1, 0.75, -0.05);
    let soft = Soft::spawn(s, engine, mesh, at, Vector3::zeros(), mass / 0.006)?;
    if let Some(e) = soft.entity() {
        let mut att = Attachments::new();
        {
            let p = s
                .soft
                .get::<&tetpbd::Particles>(e)
                .map_err(|e| e.to_string())?;
            for &i in &roots {
                att.attach_to_body(&p, i, &s.physics.bodies, bx, 0.0)
                    .map_err(|e| e.to_string())?;
            }
        }
        s.soft.insert_one(e, att).map_err(|e| e.to_string())?;
    }
    if let Some(h) = soft.rapier() {
        let body = &mut s.physics.soft_bodies[h];
        for &i in &roots {
            body.attach_particle(i as usize, bx, &s.physics.bodies);
        }
    }
    Ok(soft)
}

/// The box on `joint` carrying a soft body of `ratio` × its mass: a beam attached to its side
/// (`resting` false) or a 0.2 m cube (3³ cells) resting on its top; 10 s.
pub(crate) fn jointed(
    engine: Engine,
    joint: Joint,
    multibody: bool,
    ratio: f32,
    resting: bool,
) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome::default();
    let mut s = world(engine)?;
    let bx = hanging_box(&mut s, joint, multibody);
    let mass = 2.0 * ratio;
    let soft = if resting {
        let mesh =
            box_grid(Vector3::repeat(0.2), [3; 3], CellSplit::Six).map_err(|e| e.to_string())?;
        let at = Vector3::new(0.0, 1.003, 0.0);
        Soft::spawn(&mut s, engine, mesh, at, Vector3::zeros(), mass / 0.008)?
    } else {
        attach_beam(&mut s, engine, bx, mass)?
    };
    let (mut first, mut last) = (0.0f32, 0.0f32);
    // A resting cube's centre in the box's frame: it may not slide 1 cm or more.
    let on_box = |s: &CoupledWorld| {
        let c = soft.look(s).centre;
        s.physics
            .bodies
            .get(bx)
            .map_or(Vector::splat(f32::INFINITY), |b| {
                b.position()
                    .inverse_transform_point(Vector::new(c.x, c.y, c.z))
            })
    };
    let start = on_box(&s);
    let mut slid = 0.0f32;
    run(&mut s, &soft, 600, &mut out, |s, f| {
        if resting {
            let d = on_box(s) - start;
            slid = slid.max(Vector::new(d.x, 0.0, d.z).length());
        }
        let d = s.physics.bodies.get(bx).map_or(f32::INFINITY, |b| {
            joint.drift(b.position().transform_point(ANCHOR) - PIVOT)
        });
        if f < 300 {
            first = first.max(d);
        } else {
            last = last.max(d);
        }
    });
    let held = first.max(last) <= 1e-3 && last <= first + 1e-4;
    let drift = format!(
        "anchor drift ≤ {:.2} mm (0–5 s), ≤ {:.2} mm (5–10 s)",
        first * 1e3,
        last * 1e3
    );
    out.criterion = if resting {
        (
            held && slid < 0.01,
            format!("{drift}; cube slid {:.1} mm on the box", slid * 1e3),
        )
    } else {
        (held, drift)
    };
    Ok(out)
}
