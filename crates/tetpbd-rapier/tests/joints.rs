//! rapier joints of bodies that carry soft bodies keep rapier's own precision: a box hanging
//! on a joint with a soft beam attached stays on its anchor.

mod robust_common;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    FixedJointBuilder, GenericJoint, PrismaticJointBuilder, RevoluteJointBuilder,
    SphericalJointBuilder,
};
use robust_common::{attach_beam, ball, cube_on_box, hanging_box, hinge, scene, scene_substeps};
use tetpbd_rapier::CoupledWorld;

/// The joints tried: name, joint with anchors (0, 0, 0) on the fixed body and (0, 0.2, 0)
/// on the box, and which components of the anchor drift count (a prismatic joint slides
/// along x).
fn joints() -> Vec<(&'static str, GenericJoint, [bool; 3])> {
    let a1 = Vector::ZERO;
    let a2 = Vector::new(0.0, 0.2, 0.0);
    vec![
        (
            "spherical",
            SphericalJointBuilder::new()
                .local_anchor1(a1)
                .local_anchor2(a2)
                .build()
                .into(),
            [true; 3],
        ),
        (
            "revolute",
            RevoluteJointBuilder::new(Vector::Z)
                .local_anchor1(a1)
                .local_anchor2(a2)
                .build()
                .into(),
            [true; 3],
        ),
        (
            "fixed",
            FixedJointBuilder::new()
                .local_anchor1(a1)
                .local_anchor2(a2)
                .build()
                .into(),
            [true; 3],
        ),
        (
            "prismatic",
            PrismaticJointBuilder::new(Vector::X)
                .local_anchor1(a1)
                .local_anchor2(a2)
                .build()
                .into(),
            [false, true, true],
        ),
    ]
}

/// A 2 kg box of 0.2 m hanging 0.2 m below a fixed anchor at (0, 1, 0) on `joint` (impulse
/// or multibody), with a soft beam of `beam_mass` kg (0.6 m along x, 6 × 1 × 1 cells)
/// attached by its root face to the box's +x side. Returns the anchor drift (m) after each
/// second.
fn hang(
    joint: GenericJoint,
    counted: [bool; 3],
    beam_mass: f32,
    multibody: bool,
    seconds: usize,
) -> Vec<f32> {
    let mut s: CoupledWorld = scene();
    let bx = hanging_box(&mut s, joint, multibody);
    attach_beam(&mut s, bx, beam_mass);
    let mut drift = Vec::new();
    let mut worst = 0.0f32;
    for f in 0..60 * seconds {
        s.step().expect("step");
        let b = &s.physics.bodies[bx];
        let at = b.position().transform_point(Vector::new(0.0, 0.2, 0.0));
        let d = at - Vector::new(0.0, 1.0, 0.0);
        let d = Vector::new(
            if counted[0] { d.x } else { 0.0 },
            if counted[1] { d.y } else { 0.0 },
            if counted[2] { d.z } else { 0.0 },
        );
        worst = worst.max(d.length());
        if f % 60 == 59 {
            drift.push(worst);
        }
    }
    drift
}

fn check(what: &str, drift: &[f32]) {
    let end = *drift.last().expect("a second");
    assert!(
        end <= 0.001,
        "{what}: anchor drift {end} m (per second: {drift:?})"
    );
}

#[test]
fn a_jointed_box_carrying_a_soft_beam_stays_on_its_anchor() {
    for (name, joint, counted) in joints() {
        for beam_mass in [0.2f32, 2.0, 20.0] {
            let drift = hang(joint, counted, beam_mass, false, 3);
            check(&format!("impulse {name}, {beam_mass} kg beam"), &drift);
        }
    }
}

#[test]
fn a_multibody_link_carrying_a_soft_beam_stays_on_its_anchor() {
    for (name, joint, counted) in joints() {
        let drift = hang(joint, counted, 2.0, true, 3);
        check(&format!("multibody {name}"), &drift);
    }
}

#[test]
#[ignore = "long: 10 s per joint and beam (CI runs it in release)"]
fn anchors_hold_for_ten_seconds_without_growth() {
    for multibody in [false, true] {
        for (name, joint, counted) in joints() {
            for beam_mass in [0.2f32, 2.0, 20.0] {
                let drift = hang(joint, counted, beam_mass, multibody, 10);
                check(
                    &format!("{name} (multibody {multibody}), {beam_mass} kg beam"),
                    &drift,
                );
            }
        }
    }
}

/// A soft cube (0.2 m, 3³ cells) of `ratio` × the box's 2 kg resting on the box of 0.2 m
/// that hangs on `joint` 0.2 m below a fixed anchor (impulse or multibody joint):
/// `(largest horizontal move of the cube's centre on the box, largest particle speed
/// relative to the box over the last second, largest anchor drift)`, m and m/s, over `frames` frames at `substeps`.
fn cube_on_jointed_box(
    (joint, counted): (GenericJoint, [bool; 3]),
    ratio: f32,
    substeps: u32,
    vertex_face: bool,
    multibody: bool,
    frames: usize,
) -> (f32, f32, f32) {
    let mut s: CoupledWorld = scene_substeps(substeps);
    let bx = hanging_box(&mut s, joint, multibody);
    let e = cube_on_box(&mut s, ratio, vertex_face);
    let centre = |s: &CoupledWorld| {
        let p = s.soft.get::<&tetpbd::Particles>(e).expect("particles");
        p.positions().iter().sum::<Vector3<f32>>() / p.len() as f32
    };
    // The cube relative to the box (a slider lets both drift along its axis together).
    let box_at = |s: &CoupledWorld| {
        let t = s.physics.bodies[bx].translation();
        Vector3::new(t.x, t.y, t.z)
    };
    let c0 = centre(&s) - box_at(&s);
    let (mut moved, mut late_speed, mut drift) = (0.0f32, 0.0f32, 0.0f32);
    for f in 0..frames {
        s.step().expect("step");
        let d = centre(&s) - box_at(&s) - c0;
        moved = moved.max(Vector3::new(d.x, 0.0, d.z).norm());
        if f + 60 >= frames {
            let w = s.physics.bodies[bx].linvel();
            let w = Vector3::new(w.x, w.y, w.z);
            let p = s.soft.get::<&tetpbd::Particles>(e).expect("particles");
            let v = p
                .velocities()
                .iter()
                .map(|v| (v - w).norm())
                .fold(0.0, f32::max);
            late_speed = late_speed.max(v);
        }
        let at = s.physics.bodies[bx]
            .position()
            .transform_point(Vector::new(0.0, 0.2, 0.0));
        let d = at - Vector::new(0.0, 1.0, 0.0);
        let d =
            Vector3::new(d.x, d.y, d.z).zip_map(
                &Vector3::from(counted),
                |x, c| {
                    if c {
                        x
                    } else {
                        0.0
                    }
                },
            );
        drift = drift.max(d.norm());
    }
    (moved, late_speed, drift)
}

/// Every run of the sweep holds the loads' bounds: the cube slides less than 1 cm on the box,
/// its particles end below 0.01 m/s relative to the box, the anchor drifts at most 1 mm
/// along the joint's locked axes.
fn check_welded(
    joint: (GenericJoint, [bool; 3]),
    multibodies: &[bool],
    ratios: &[f32],
    substeps: &[u32],
    frames: usize,
) {
    let mut failed = Vec::new();
    for &ratio in ratios {
        for &n in substeps {
            for vertex_face in [false, true] {
                for &multibody in multibodies {
                    let (moved, speed, drift) =
                        cube_on_jointed_box(joint, ratio, n, vertex_face, multibody, frames);
                    if moved >= 0.01 || speed >= 0.01 || drift > 0.001 {
                        failed.push(format!(
                            "{ratio}:1, {n} substeps, vertex-face {vertex_face}, multibody \
                             {multibody}: cube slid {moved} m, still at {speed} m/s, anchor \
                             drifted {drift} m"
                        ));
                    }
                }
            }
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
fn a_heavy_soft_cube_on_a_welded_box_stays_put() {
    check_welded(welded(), &[false, true], &[10.0], &[10], 180);
}

#[test]
fn a_heavy_soft_cube_on_a_box_on_a_slider_stays_put() {
    check_welded(slider(), &[false, true], &[10.0], &[10], 180);
}

#[test]
#[ignore = "long: mass ratios and substep counts (CI runs it in release)"]
fn soft_cubes_of_any_weight_stay_put_on_welded_boxes() {
    let (ratios, substeps) = ([1.0, 10.0, 100.0, 1000.0], [5, 10, 20, 40]);
    check_welded(welded(), &[false, true], &ratios, &substeps, 300);
    // Impulse sliders only: a multibody slider under a load of 100:1 or more, or at 5
    // substeps, keeps its load jiggling at 0.02–0.5 m/s (a known limit, in the joints module
    // docs).
    check_welded(slider(), &[false], &ratios, &substeps, 300);
}

/// A fixed joint from the anchor at (0, 1, 0) to the top of the box (its centre 0.2 m
/// below), with the components of the anchor's drift that count.
fn welded() -> (GenericJoint, [bool; 3]) {
    let joint = FixedJointBuilder::new()
        .local_anchor2(Vector::new(0.0, 0.2, 0.0))
        .build()
        .into();
    (joint, [true; 3])
}

/// A prismatic joint along x from the anchor at (0, 1, 0) to the top of the box (the drift
/// along x is free).
fn slider() -> (GenericJoint, [bool; 3]) {
    let joint = PrismaticJointBuilder::new(Vector::X)
        .local_anchor2(Vector::new(0.0, 0.2, 0.0))
        .build()
        .into();
    (joint, [false, true, true])
}

/// The rotation (rad) of the box of [`hang`]'s rig after each frame for `frames` frames,
/// with a 2 kg beam attached and `joint` an impulse or a multibody joint.
fn swing(joint: GenericJoint, multibody: bool, frames: usize) -> Vec<Vector3<f32>> {
    let mut s: CoupledWorld = scene();
    let bx = hanging_box(&mut s, joint, multibody);
    attach_beam(&mut s, bx, 2.0);
    (0..frames)
        .map(|_| {
            s.step().expect("step");
            let r = s.physics.bodies[bx].rotation().to_scaled_axis();
            Vector3::new(r.x, r.y, r.z)
        })
        .collect()
}

#[test]
fn a_soft_beam_swings_a_multibody_link_like_an_impulse_jointed_box() {
    for (name, joint) in [("hinge", hinge()), ("ball", ball())] {
        let impulse = swing(joint.0, false, 60);
        let multibody = swing(joint.0, true, 60);
        let peak = impulse.iter().map(|r| r.norm()).fold(0.0, f32::max);
        let apart = impulse
            .iter()
            .zip(&multibody)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f32::max);
        println!("{name}: peak {peak} rad, apart {apart} rad");
        assert!(peak > 0.1, "{name}: the beam swings the box ({peak} rad)");
        assert!(
            apart < 0.2 * peak,
            "{name}: multibody link {apart} rad from the impulse-jointed box (peak {peak} rad)"
        );
    }
}
