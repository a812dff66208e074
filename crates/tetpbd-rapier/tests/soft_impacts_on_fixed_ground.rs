//! A compliant soft body thrown at a fixed rapier ground at 100–300 m/s ends intact (no
//! inverted tetrahedron, the settled volume of the same body released at rest from the same
//! height) and rebounds far slower than it came, at any grid split and substep count, at
//! default coupling settings. Its constraints carry a push through it slower than a short
//! substep reaches (`tetpbd::impact_speed`): without the approach limit the body behind the
//! stopped bottom layer ran through it, up to every other tetrahedron inverted and the
//! volume gone. A hard body is the control: it ends as it did without the limit.

mod robust_common;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use robust_common::{ground, scene_substeps};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Material, Particles, SoftBodyBuilder, Tetrahedra};
use tetpbd_rapier::{CoupledWorld, SoftCollider};

/// The constraint configurations thrown.
#[derive(Clone, Copy, Debug)]
enum Body {
    /// Edges α 1e-6 m/N and volume α 1e-9 m⁵/N.
    SoftEdgesVolume,
    /// The Neo-Hookean soft tissue material (E = 10 kPa).
    SoftTissue,
    /// Edges and volume with α = 0.
    Hard,
}

impl Body {
    /// How far the settled volume may be from that of the same body released at rest from
    /// the same height (a fraction). 1 % for the constraint bodies. The soft tissue body
    /// (E = 10 kPa) on a frictional ground settles into a shape that depends on how it
    /// landed, whatever the speed: released from 2 mm above the ground or from 5 cm, its
    /// settled volumes differ by up to 5 %, so 5 % is what tells a crushed body from one
    /// that landed differently.
    fn tolerance(self) -> f32 {
        match self {
            Body::SoftTissue => 0.05,
            Body::SoftEdgesVolume | Body::Hard => 0.01,
        }
    }
}

const SPLITS: [CellSplit; 2] = [CellSplit::Five, CellSplit::Six];

/// Frames of the throw proper (60 Hz) and of the settling after it.
const FRAMES: usize = 120;
const SETTLE_FRAMES: usize = 60;
/// Linear damping of the settling, 1/s: stills the soft tissue body's slow sway on the
/// ground so that two volumes compare two states, not two phases of a swing; it only removes
/// energy and leaves a folded or inverted body as it is.
const SETTLE_DAMPING: f32 = 20.0;

/// What one throw measured.
#[derive(Debug, Clone, Copy)]
struct Landing {
    /// Inverted tetrahedra at the end of the throw or after the settling, whichever is more.
    inverted: usize,
    /// Volume over rest volume after the settling.
    volume: f32,
    /// Fastest upward speed of the centre of mass, m/s.
    rose: f32,
}

/// Throws a 0.5 m cube of 4³ cells, 1000 kg/m³, its bottom 5 cm above a fixed cuboid
/// ground, at `speed` m/s down (0: released at rest) with `substeps` substeps; 2 s, then
/// the settling.
fn throw(body: Body, split: CellSplit, speed: f32, substeps: u32) -> Landing {
    throw_into(body, split, speed, substeps, false)
}

/// [`throw`]; with `corner`, a fixed wall stands 10 cm to the cube's +x side and the cube
/// is thrown at `speed` down and towards it at 45°, into the corner it makes with the
/// ground.
fn throw_into(body: Body, split: CellSplit, speed: f32, substeps: u32, corner: bool) -> Landing {
    let mut s = scene_substeps(substeps);
    ground(&mut s);
    let velocity = if corner {
        s.physics.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.85, 1.0, 0.0)),
            ColliderBuilder::cuboid(0.5, 2.0, 5.0),
        );
        Vector3::new(1.0, -1.0, 0.0) * (speed / 2f32.sqrt())
    } else {
        Vector3::new(0.0, -speed, 0.0)
    };
    let mesh = box_grid(Vector3::repeat(0.5), [4; 3], split).expect("mesh");
    let b = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .translation(Vector3::new(0.0, 0.3, 0.0))
        .velocity(velocity);
    let b = match body {
        Body::SoftEdgesVolume => b.edges(1e-6).volume(1e-9),
        Body::SoftTissue => b.material(Material::SOFT_TISSUE),
        Body::Hard => b.edges(0.0).volume(0.0),
    };
    let e = b.build().expect("body").spawn(&mut s.soft);
    s.soft
        .insert_one(e, SoftCollider::default())
        .expect("entity");
    let mut out = Landing {
        inverted: 0,
        volume: 1.0,
        rose: f32::NEG_INFINITY,
    };
    for _ in 0..FRAMES {
        let stats = s.step().expect("step");
        assert_eq!(stats.soft.non_finite_resets, 0, "{body:?} at {speed} m/s");
        let p = particles(&s, e);
        out.rose = out.rose.max(p.linear_momentum().y / p.total_mass());
    }
    out.inverted = inverted(&s, e);
    s.coupling.solver_mut().settings.damping = SETTLE_DAMPING;
    for _ in 0..SETTLE_FRAMES {
        s.step().expect("step");
    }
    out.inverted = out.inverted.max(inverted(&s, e));
    let p = particles(&s, e);
    let t = s.soft.get::<&Tetrahedra>(e).expect("tetrahedra");
    out.volume = t.volume_ratio(p.positions());
    out
}

fn particles(s: &CoupledWorld, e: hecs::Entity) -> Particles {
    robust_common::particles(s, e)
}

fn inverted(s: &CoupledWorld, e: hecs::Entity) -> usize {
    let p = particles(s, e);
    let t = s.soft.get::<&Tetrahedra>(e).expect("tetrahedra");
    t.count_inverted(p.positions())
}

/// Throws `bodies` at every `speeds` × split × `substeps`; returns the failing cells: an
/// inverted tetrahedron, a settled volume off that of the same body released at rest by
/// more than [`Body::tolerance`], or a rebound faster than `rebound` × the speed it came at.
fn failures(bodies: &[Body], speeds: &[f32], substeps: &[u32], rebound: f32) -> Vec<String> {
    let mut failed = Vec::new();
    for &body in bodies {
        for split in SPLITS {
            for &n in substeps {
                let rest = throw(body, split, 0.0, n);
                for &speed in speeds {
                    let l = throw(body, split, speed, n);
                    let off = (l.volume / rest.volume - 1.0).abs();
                    let line = format!(
                        "{body:?} at {speed} m/s, {split:?}, {n} substeps: {} inverted, \
                         volume {:.4} (released {:.4}, {:.2} % off), rose {:.2} m/s",
                        l.inverted,
                        l.volume,
                        rest.volume,
                        100.0 * off,
                        l.rose
                    );
                    eprintln!("{line}");
                    if l.inverted > 0 || off > body.tolerance() || l.rose >= rebound * speed {
                        failed.push(line);
                    }
                }
            }
        }
    }
    failed
}

#[test]
fn compliant_cubes_thrown_at_a_fixed_ground_end_intact_and_barely_rebound() {
    let failed = failures(
        &[Body::SoftEdgesVolume, Body::SoftTissue],
        &[100.0, 300.0],
        &[20, 80],
        0.1,
    );
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
#[ignore = "long: compliant and hard cubes at 100–300 m/s, both splits, 1–80 substeps (CI runs it in release)"]
fn cubes_thrown_at_a_fixed_ground_end_intact_at_every_substep_count() {
    let failed = failures(
        &[Body::SoftEdgesVolume, Body::SoftTissue, Body::Hard],
        &[100.0, 300.0],
        &[1, 5, 10, 20, 40, 80],
        0.1,
    );
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// A compliant cube thrown at 45° into the corner of the ground and a wall at many
/// substeps ends intact: its surface layer, stopped tangentially by friction on the ground and
/// then by the wall, is held to the approach limit of an eighth of the body's wave speed
/// per substep (at a quarter it ended crushed; docs/decisions/impact-approach-speed.md).
#[test]
fn a_compliant_cube_thrown_into_a_corner_at_many_substeps_ends_intact() {
    let mut failed = Vec::new();
    for split in SPLITS {
        let rest = throw_into(Body::SoftEdgesVolume, split, 0.0, 80, true);
        for speed in [100.0f32, 300.0] {
            let l = throw_into(Body::SoftEdgesVolume, split, speed, 80, true);
            let off = (l.volume / rest.volume - 1.0).abs();
            eprintln!(
                "into the corner at {speed} m/s, {split:?}, 80 substeps: {} inverted, {:.2} % off",
                l.inverted,
                100.0 * off
            );
            if l.inverted > 0 || off > Body::SoftEdgesVolume.tolerance() {
                failed.push((split, speed));
            }
        }
    }
    assert!(failed.is_empty(), "crushed in the corner: {failed:?}");
}
