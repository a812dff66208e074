//! Coupled cases of the scene families next to the coupling's simple ones, each also run with
//! rapier 0.36's own soft bodies in the same scene: loads both ways at mass ratios 1:1 to
//! 1000:1 (`loads`), jointed bodies carrying soft bodies (`joints`), fast projectiles both
//! ways (`projectiles`), triangle-mesh ground of either winding (`trimesh`), a slab pulled
//! apart until it tears (`tearing`).

mod body;
mod joints;
mod loads;
mod projectiles;
mod tearing;
mod trimesh;

use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd_rapier::CoupledWorld;

use crate::cases::CaseKind;
use crate::coupled::{guarded, CoupledCase, CoupledOutcome};
use body::{Engine, Soft};
use joints::{jointed, Joint};
use loads::{rigid_on_soft, soft_on_box};
use projectiles::{into_slabs, soft_into_rigid, Projectile};
use tearing::pulled_apart;
pub use tearing::{
    pull_apart, pull_apart_in, PullFigures, BLOWN_UP_SPEED, FRAGMENT_SPEED_MARGIN, PULL_SPEEDS,
};
use trimesh::{onto, Ground};

/// A fixed ground cuboid (40 × 1 × 40 m) whose top is at y = 0.
fn ground(s: &mut CoupledWorld) {
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(20.0, 0.5, 20.0),
    );
}

/// Steps `frames`, tracking `soft` into `out` (finite, peak and final speed, penetration over
/// the last second, inverted tetrahedra at the end); `each(world, frame)` after every frame.
fn run(
    s: &mut CoupledWorld,
    soft: &Soft,
    frames: usize,
    out: &mut CoupledOutcome,
    mut each: impl FnMut(&CoupledWorld, usize),
) {
    out.finite = true;
    for f in 0..frames {
        let Ok(stats) = s.step() else {
            out.finite = false;
            return;
        };
        let look = soft.look(s);
        out.finite &= stats.soft.non_finite_resets == 0 && look.finite;
        out.peak_speed = out.peak_speed.max(look.fastest);
        out.final_speed = look.fastest;
        if f + 60 >= frames {
            out.penetration = out.penetration.max(stats.max_penetration);
        }
        each(s, f);
    }
    out.inverted = soft.inverted(s);
}

/// Folds one run's outcome into a sweep's: finite only if every run was, worst figures.
fn merge(out: &mut CoupledOutcome, one: &CoupledOutcome) {
    out.finite &= one.finite;
    out.peak_speed = out.peak_speed.max(one.peak_speed);
    out.final_speed = out.final_speed.max(one.final_speed);
    out.penetration = out.penetration.max(one.penetration);
    out.inverted = out.inverted.max(one.inverted);
}

/// One case: its row and how it runs in either engine.
macro_rules! case {
    ($name:expr, $description:expr, |$e:ident| $body:expr) => {
        CoupledCase {
            name: $name,
            description: $description,
            kind: CaseKind::Fast,
            run: |c| {
                let $e = Engine::Tetpbd(c);
                guarded($body)
            },
            rapier: Some(|| {
                let $e = Engine::Rapier;
                guarded($body)
            }),
        }
    };
}

/// The load cases.
fn load_cases() -> Vec<CoupledCase> {
    vec![
        case!(
            "soft 125 kg on box 1 kg",
            "a 125 kg soft cube (0.5 m, 4³ cells) on a 1 kg box of 0.5 m on the ground, 3 s: the box moves < 1 cm, turns < 1°, never faster than 1 m/s, and the box and the cube end below 0.05 m/s",
            |e| soft_on_box(e, 125.0, false)
        ),
        case!("soft 1:1 on a box on the ground", "the same with a 1 kg cube", |e| soft_on_box(e, 1.0, false)),
        case!("soft 10:1 on a box on the ground", "the same with a 10 kg cube", |e| soft_on_box(e, 10.0, false)),
        case!("soft 100:1 on a box on the ground", "the same with a 100 kg cube", |e| soft_on_box(e, 100.0, false)),
        case!("soft 1000:1 on a box on the ground", "the same with a 1000 kg cube", |e| soft_on_box(e, 1000.0, false)),
        case!("soft 1:1 on a box on a box", "a 1 kg soft cube on the 1 kg box standing on another 1 kg box of 0.5 m, the upper box watched", |e| soft_on_box(e, 1.0, true)),
        case!("soft 10:1 on a box on a box", "the same with a 10 kg cube", |e| soft_on_box(e, 10.0, true)),
        case!("soft 100:1 on a box on a box", "the same with a 100 kg cube", |e| soft_on_box(e, 100.0, true)),
        case!("soft 1000:1 on a box on a box", "the same with a 1000 kg cube", |e| soft_on_box(e, 1000.0, true)),
        case!(
            "rigid 1:1 on a soft slab on the ground",
            "a 1 kg rigid box of 0.3 m on a 1 kg soft slab (0.6 × 0.2 × 0.6 m, 4 × 2 × 4 cells) on the ground, 3 s: the slab's centre moves < 1 cm, the box turns < 1° and is never faster than 1 m/s, both end below 0.05 m/s",
            |e| rigid_on_soft(e, 1.0, false)
        ),
        case!("rigid 10:1 on a soft slab on the ground", "the same with a 10 kg box", |e| rigid_on_soft(e, 10.0, false)),
        case!("rigid 100:1 on a soft slab on the ground", "the same with a 100 kg box", |e| rigid_on_soft(e, 100.0, false)),
        case!("rigid 1000:1 on a soft slab on the ground", "the same with a 1000 kg box", |e| rigid_on_soft(e, 1000.0, false)),
        case!("rigid 1:1 on a soft slab on a box", "the 1 kg box on the slab resting on a 1 kg dynamic box (0.8 × 0.2 × 0.8 m) on the ground", |e| rigid_on_soft(e, 1.0, true)),
        case!("rigid 10:1 on a soft slab on a box", "the same with a 10 kg box", |e| rigid_on_soft(e, 10.0, true)),
        case!("rigid 100:1 on a soft slab on a box", "the same with a 100 kg box", |e| rigid_on_soft(e, 100.0, true)),
        case!("rigid 1000:1 on a soft slab on a box", "the same with a 1000 kg box", |e| rigid_on_soft(e, 1000.0, true)),
    ]
}

/// The joint cases.
fn joint_cases() -> Vec<CoupledCase> {
    vec![
        case!(
            "spherical joint carrying a soft beam",
            "a 2 kg box of 0.2 m hanging 0.2 m below a fixed anchor on a spherical impulse joint, a 2 kg soft beam (0.6 m, 6 × 1 × 1 cells) attached to its side, 10 s: the joint's anchor drifts ≤ 1 mm, in the last 5 s ≤ 0.1 mm beyond the first 5 s",
            |e| jointed(e, Joint::Spherical, false, 1.0, false)
        ),
        case!("fixed joint carrying a soft beam", "the same on a fixed joint", |e| jointed(e, Joint::Fixed, false, 1.0, false)),
        case!("spherical joint, beam 10×", "the spherical impulse joint with a 20 kg beam", |e| jointed(e, Joint::Spherical, false, 10.0, false)),
        case!("revolute joint, beam 10×", "the same on a revolute impulse joint (about z)", |e| jointed(e, Joint::Revolute, false, 10.0, false)),
        case!("fixed joint, beam 10×", "the same on a fixed impulse joint", |e| jointed(e, Joint::Fixed, false, 10.0, false)),
        case!("prismatic joint, beam 10×", "the same on a prismatic impulse joint (along x; the drift along x is free)", |e| jointed(e, Joint::Prismatic, false, 10.0, false)),
        case!("multibody spherical, beam 10×", "the 20 kg beam with the box on a spherical multibody joint", |e| jointed(e, Joint::Spherical, true, 10.0, false)),
        case!("multibody revolute, beam 10×", "the same on a revolute multibody joint", |e| jointed(e, Joint::Revolute, true, 10.0, false)),
        case!("multibody fixed, beam 10×", "the same on a fixed multibody joint", |e| jointed(e, Joint::Fixed, true, 10.0, false)),
        case!("multibody prismatic, beam 10×", "the same on a prismatic multibody joint", |e| jointed(e, Joint::Prismatic, true, 10.0, false)),
        case!("fixed joint, soft cube 10× resting", "a 20 kg soft cube (0.2 m, 3³ cells) resting on the box on a fixed impulse joint", |e| jointed(e, Joint::Fixed, false, 10.0, true)),
        case!("multibody fixed, soft cube 10× resting", "the same on a fixed multibody joint", |e| jointed(e, Joint::Fixed, true, 10.0, true)),
        case!("revolute joint, soft cube 10× resting", "the same on a revolute impulse joint (about z): the box pivots", |e| jointed(e, Joint::Revolute, false, 10.0, true)),
        case!("multibody revolute, soft cube 10× resting", "the same on a revolute multibody joint", |e| jointed(e, Joint::Revolute, true, 10.0, true)),
        case!("spherical joint, soft cube 3× resting", "a 6 kg soft cube resting on the box on a spherical impulse joint", |e| jointed(e, Joint::Spherical, false, 3.0, true)),
        case!("multibody spherical, soft cube 3× resting", "the same on a spherical multibody joint", |e| jointed(e, Joint::Spherical, true, 3.0, true)),
    ]
}

/// The projectile and triangle-mesh cases.
fn impact_and_mesh_cases() -> Vec<CoupledCase> {
    const SPEEDS: &[f32] = &[50.0, 150.0, 300.0];
    vec![
        case!(
            "ball at 200 m/s into a slab",
            "a 1 kg ball (r 0.05 m) at 200 m/s straight down onto a 1 × 0.2 × 1 m slab of 8 × 8 cells across and 1, 2 and 4 cells thick on the ground, two aim points each, 1 s: the ball's bottom never below the ground while over the slab, the ball never out faster than in, the slab never faster than the ball after the first frame and never lifted higher than the ball's whole energy lifts it",
            |e| into_slabs(e, Projectile::Ball(0.05), &[200.0], false)
        ),
        case!("ball r 0.05 m at 50–300 m/s", "the same at 50, 150 and 300 m/s", |e| into_slabs(e, Projectile::Ball(0.05), SPEEDS, false)),
        case!("ball r 0.1 m at 50–300 m/s", "the same with a ball of r 0.1 m", |e| into_slabs(e, Projectile::Ball(0.1), SPEEDS, false)),
        case!("ball r 0.1 m at 200 m/s, CCD on", "a ball of r 0.1 m at 200 m/s with rapier's CCD on", |e| into_slabs(e, Projectile::Ball(0.1), &[200.0], true)),
        case!("box 0.08 m at 50–300 m/s", "a 1 kg cube of 0.08 m at 50, 150 and 300 m/s", |e| into_slabs(e, Projectile::Cube(0.08), SPEEDS, false)),
        case!("box 0.2 m at 50–300 m/s", "a 1 kg cube of 0.2 m at 50, 150 and 300 m/s", |e| into_slabs(e, Projectile::Cube(0.2), SPEEDS, false)),
        case!(
            "soft cube at 50–300 m/s onto the ground",
            "a 0.3 m soft cube (3³ cells, 27 kg) at 50, 150 and 300 m/s straight down onto the ground, 1 s each: no particle more than 2 cm below the target's top, none faster than the cube came after the first frame",
            |e| soft_into_rigid(e, "ground", SPEEDS)
        ),
        case!("soft cube at 50–300 m/s onto a plate", "the same onto a fixed 2 cm plate 0.3 m above the ground", |e| soft_into_rigid(e, "plate", SPEEDS)),
        case!("soft cube at 50–300 m/s onto a box", "the same onto a 30 kg dynamic box (0.6 × 0.3 × 0.6 m) on the ground, which must not leave faster than the cube came", |e| soft_into_rigid(e, "box", SPEEDS)),
        case!(
            "onto an open mesh, counter-clockwise",
            "soft cubes of 0.3, 0.5 and 1 m at 0.5, 2 and 5 m/s onto a 10 m square of two triangles wound counter-clockwise seen from above, without flags and with `FIX_INTERNAL_EDGES`, 2 s: the lowest particle within −1 to 2 cm of the mesh and the fastest below 0.2 m/s; the cell notes under which flags a rigid 0.5 m cube falls through",
            |e| onto(e, Ground::Square(false))
        ),
        case!("onto an open mesh, clockwise", "the same wound clockwise seen from above (normal down)", |e| onto(e, Ground::Square(true))),
        case!("onto a closed mesh, outwards", "the same onto a closed 10 × 1 × 10 m slab wound outwards", |e| onto(e, Ground::Slab(false))),
        case!("onto a closed mesh, inwards", "the same wound inwards", |e| onto(e, Ground::Slab(true))),
    ]
}

/// The tearing case.
fn tearing_cases() -> Vec<CoupledCase> {
    vec![case!(
        "slab pulled apart at 1–20 m/s",
        "a 1 × 0.1 × 0.4 m slab (10 × 1 × 4 cells, 40 kg) on the ground, its end faces held by two kinematic boxes moving apart at 1, 5 and 20 m/s for 0.6 m each, tearing past a strain of 0.3 smoothed over 0.05 s, then 2 s: more than one piece, every mass positive, no inverted rest shape or tetrahedron, up to 5 m/s no particle over the ground more than 5 cm below it at the end, and no fragment over the ground faster than the boxes plus the slab's recoil at the tearing strain (strain × wave speed; 0 for hard constraints) plus 1 m/s; the cell lists per speed the pieces, the fastest fragment's centre of mass (the peak, over the ground, and the limit) and the lowest particle over the run and at the end",
        |e| pulled_apart(e)
    )]
}

/// The cases of this module, in report order.
pub(crate) fn robust_cases() -> Vec<CoupledCase> {
    let mut v = load_cases();
    v.extend(joint_cases());
    v.extend(impact_and_mesh_cases());
    v.extend(tearing_cases());
    v
}
