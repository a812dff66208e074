//! Cases with rigid bodies (through `tetpbd-rapier`): mass ratios, a fast impact, an
//! overlapping start, and the long resting run.

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings, Tetrahedra};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, SoftCollider};

use crate::cases::CaseKind;
use crate::config::Config;

/// What a coupled case measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CoupledOutcome {
    /// A setup error (a clean outcome if typed).
    pub error: Option<String>,
    /// Every particle and rigid body finite at every frame.
    pub finite: bool,
    /// Largest soft particle speed over the run, m/s.
    pub peak_speed: f32,
    /// Largest soft particle speed at the end, m/s.
    pub final_speed: f32,
    /// Largest penetration over the last second, m.
    pub penetration: f32,
    /// Inverted tetrahedra at the end.
    pub inverted: usize,
    /// The case's own criterion (see each case), with its figure.
    pub criterion: (bool, String),
}

impl CoupledOutcome {
    /// Finite, no inverted tetrahedron at the end, and the case's own criterion.
    pub fn pass(&self) -> bool {
        self.error.is_none() && self.finite && self.inverted == 0 && self.criterion.0
    }
}

/// One coupled case.
pub struct CoupledCase {
    /// Row label.
    pub name: &'static str,
    /// What it does and what it asserts.
    pub description: &'static str,
    /// Fast or long.
    pub kind: CaseKind,
    /// Runs the case under a configuration.
    pub run: fn(&Config) -> CoupledOutcome,
    /// Runs the same scene with rapier 0.36's own soft bodies instead, where they apply.
    pub rapier: Option<fn() -> CoupledOutcome>,
}

fn scene(substeps: u32) -> Result<CoupledWorld, String> {
    scene_with(substeps, 1)
}

fn scene_with(substeps: u32, iterations: u32) -> Result<CoupledWorld, String> {
    scene_net(substeps, iterations, None)
}

fn scene_net(substeps: u32, iterations: u32, net: Option<f32>) -> Result<CoupledWorld, String> {
    let solver = SolverSettings {
        substeps,
        iterations,
        safety: tetpbd::SafetySettings {
            max_correction_speed: net,
            ..Default::default()
        },
        ..SolverSettings::default()
    };
    CoupledWorld::new(solver, CouplingSettings::default()).map_err(|e| e.to_string())
}

/// A fixed ground slab whose top is at y = 0, `depth` m thick.
fn ground_of(s: &mut CoupledWorld, depth: f32) {
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -depth / 2.0, 0.0)),
        ColliderBuilder::cuboid(20.0, depth / 2.0, 20.0),
    );
}

fn ground(s: &mut CoupledWorld) {
    ground_of(s, 1.0);
}

fn soft_box(
    s: &mut CoupledWorld,
    config: &Config,
    size: Vector3<f32>,
    cells: [u32; 3],
    at: Vector3<f32>,
    density: f32,
) -> Result<hecs::Entity, String> {
    let mesh = box_grid(size, cells, CellSplit::Six).map_err(|e| e.to_string())?;
    let b = SoftBodyBuilder::new(mesh).density(density).translation(at);
    let body = config.apply(b, 1.0).build().map_err(|e| e.to_string())?;
    let e = body.spawn(&mut s.soft);
    s.soft
        .insert_one(e, SoftCollider::default())
        .map_err(|e| e.to_string())?;
    Ok(e)
}

/// Steps `frames`, tracking the soft body `e` and the rigid body `rb` (if any).
fn run(
    s: &mut CoupledWorld,
    e: hecs::Entity,
    rb: Option<RigidBodyHandle>,
    frames: usize,
    out: &mut CoupledOutcome,
    mut each: impl FnMut(&CoupledWorld),
) {
    out.finite = true;
    for f in 0..frames {
        let Ok(stats) = s.step() else {
            out.finite = false;
            return;
        };
        let Ok(p) = s.soft.get::<&Particles>(e) else {
            return;
        };
        out.finite &= stats.soft.non_finite_resets == 0
            && p.positions()
                .iter()
                .all(|x| x.iter().all(|c| c.is_finite()));
        if let Some(h) = rb {
            out.finite &= s
                .physics
                .bodies
                .get(h)
                .is_some_and(|b| b.translation().is_finite());
        }
        out.peak_speed = out.peak_speed.max(p.max_speed());
        out.final_speed = p.max_speed();
        if f + 60 >= frames {
            out.penetration = out.penetration.max(stats.max_penetration);
        }
        drop(p);
        each(s);
    }
    if let (Ok(p), Ok(t)) = (s.soft.get::<&Particles>(e), s.soft.get::<&Tetrahedra>(e)) {
        out.inverted = t.count_inverted(p.positions());
    }
}

/// A case's outcome, or its setup error as a clean outcome.
pub(crate) fn guarded(r: Result<CoupledOutcome, String>) -> CoupledOutcome {
    r.unwrap_or_else(|e| CoupledOutcome {
        error: Some(e),
        ..CoupledOutcome::default()
    })
}

fn heavy_rigid_on_light_soft(config: &Config) -> CoupledOutcome {
    guarded(heavy_rigid_on_light_soft_with(config, 10, 1))
}

fn heavy_rigid_on_light_soft_20x5(config: &Config) -> CoupledOutcome {
    guarded(heavy_rigid_on_light_soft_with(config, 20, 5))
}

fn heavy_rigid_on_light_soft_with(
    config: &Config,
    substeps: u32,
    iterations: u32,
) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome::default();
    let mut s = scene_with(substeps, iterations)?;
    ground(&mut s);
    // 1 kg soft slab (2 × 0.2 × 2 m at 1.25 kg/m³) under a 1000 kg rigid box.
    let e = soft_box(
        &mut s,
        config,
        Vector3::new(2.0, 0.2, 2.0),
        [4, 1, 4],
        Vector3::new(0.0, 0.1, 0.0),
        1.25,
    )?;
    let (rb, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.45, 0.0)),
        ColliderBuilder::cuboid(0.25, 0.25, 0.25).mass(1000.0),
    );
    run(&mut s, e, Some(rb), 180, &mut out, |_| {});
    let (y, v) = s.physics.bodies.get(rb).map_or((f32::NAN, f32::NAN), |b| {
        (b.translation().y, b.linvel().length())
    });
    // The box's bottom stays above the ground (it did not sink through the slab) and below
    // 5 cm above the slab's top (it was not thrown off), the box comes to rest, and the slab
    // never moves faster than 5 m/s (no explosion).
    let bottom = y - 0.25;
    out.criterion = (
        bottom > -0.01 && bottom < 0.25 && v < 0.05 && out.peak_speed < 5.0,
        format!("box bottom {bottom:.3} m, box |v| {v:.3} m/s"),
    );
    Ok(out)
}

fn light_soft_on_heavy_plank(config: &Config) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome::default();
    let mut s = scene(10)?;
    ground(&mut s);
    let (rb, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.1, 0.0)),
        ColliderBuilder::cuboid(1.5, 0.1, 1.5).mass(1000.0),
    );
    // 1 kg soft cube (0.5 m at 8 kg/m³) on a free 1000 kg plank.
    let e = soft_box(
        &mut s,
        config,
        Vector3::repeat(0.5),
        [3, 3, 3],
        Vector3::new(0.0, 0.46, 0.0),
        8.0,
    )?;
    run(&mut s, e, Some(rb), 180, &mut out, |_| {});
    let min_y = s
        .soft
        .get::<&Particles>(e)
        .map_or(f32::NAN, |p| p.aabb().0.y);
    out.criterion = (
        min_y > 0.2 - 0.01 && out.final_speed < 0.05,
        format!(
            "lowest particle {min_y:.3} m, final {:.3} m/s",
            out.final_speed
        ),
    );
    Ok(out)
}

fn ball_at(config: &Config, speed: f32) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome::default();
    let mut s = scene(10)?;
    ground(&mut s);
    // A soft slab one cell thick (0.2 m) on the ground; a 0.1 m rigid ball at 100 m/s onto it.
    let e = soft_box(
        &mut s,
        config,
        Vector3::new(2.0, 0.2, 2.0),
        [8, 1, 8],
        Vector3::new(0.0, 0.1, 0.0),
        1000.0,
    )?;
    let (rb, _) = s.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.05, 1.0, 0.05))
            .linvel(Vector::new(0.0, -speed, 0.0))
            .ccd_enabled(true),
        ColliderBuilder::ball(0.1).density(1000.0),
    );
    let mut lowest = f32::INFINITY;
    run(&mut s, e, Some(rb), 120, &mut out, |s| {
        if let Some(b) = s.physics.bodies.get(rb) {
            let t = b.translation();
            // Over the slab (the impact may set the ball rolling off its edge).
            if t.x.abs() < 1.0 && t.z.abs() < 1.0 {
                lowest = lowest.min(t.y);
            }
        }
    });
    // No tunnelling: the ball's centre never reaches the slab's lower half.
    out.criterion = (
        lowest > 0.1,
        format!("ball centre lowest over the slab {lowest:.3} m"),
    );
    Ok(out)
}

fn created_in_the_ground(config: &Config) -> CoupledOutcome {
    guarded(created_in_the_ground_with(config, None))
}

fn created_in_the_ground_net(config: &Config) -> CoupledOutcome {
    guarded(created_in_the_ground_with(config, Some(5.0)))
}

fn created_in_the_ground_with(config: &Config, net: Option<f32>) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome::default();
    let mut s = scene_net(10, 1, net)?;
    // Ground 4 m thick, so the nearest face of every overlapping particle is the top.
    ground_of(&mut s, 4.0);
    // A 1 m cube created half inside the ground.
    let e = soft_box(
        &mut s,
        config,
        Vector3::repeat(1.0),
        [3, 3, 3],
        Vector3::zeros(),
        1000.0,
    )?;
    run(&mut s, e, None, 180, &mut out, |_| {});
    let min_y = s
        .soft
        .get::<&Particles>(e)
        .map_or(f32::NAN, |p| p.aabb().0.y);
    out.criterion = (
        min_y > -0.02 && out.peak_speed < 20.0,
        format!(
            "peak {:.1} m/s, lowest particle {min_y:.3} m",
            out.peak_speed
        ),
    );
    Ok(out)
}

fn resting_100k_frames(config: &Config) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome::default();
    let mut s = scene(10)?;
    ground(&mut s);
    let e = soft_box(
        &mut s,
        config,
        Vector3::repeat(0.5),
        [2, 2, 2],
        Vector3::new(0.0, 0.3, 0.0),
        1000.0,
    )?;
    let mut settled = None;
    let mut ke_settled = 0.0f32;
    let mut ke_max_after = 0.0f32;
    let mut frame = 0usize;
    run(&mut s, e, None, 100_000, &mut out, |s| {
        frame += 1;
        if let Ok(p) = s.soft.get::<&Particles>(e) {
            if frame == 600 {
                settled = Some(p.center_of_mass());
                ke_settled = p.kinetic_energy();
            } else if frame > 600 {
                ke_max_after = ke_max_after.max(p.kinetic_energy());
            }
        }
    });
    let com = s
        .soft
        .get::<&Particles>(e)
        .map_or(Vector3::repeat(f32::NAN), |p| p.center_of_mass());
    let drift = settled.map_or(f32::NAN, |c| (com - c).norm());
    out.criterion = (
        out.final_speed < 1e-3
            && drift < 1e-3
            && ke_max_after <= ke_settled.max(1e-9) * 10.0 + 1e-6,
        format!(
            "final {:.1e} m/s, drift {drift:.1e} m, KE after settling ≤ {ke_max_after:.1e} J",
            out.final_speed
        ),
    );
    Ok(out)
}

/// Every coupled case, in report order.
pub fn coupled_cases() -> Vec<CoupledCase> {
    vec![
        CoupledCase {
            name: "rigid 1000 kg on soft 1 kg",
            description: "a 1000 kg rigid box on a 1 kg soft slab (2 × 0.2 × 2 m, one cell thick, top at 0.2 m) on the ground, 3 s: the box's bottom stays between the ground and 0.25 m, the box ends below 0.05 m/s and the slab's peak speed stays below 5 m/s",
            kind: CaseKind::Fast,
            run: heavy_rigid_on_light_soft,
            rapier: None,
        },
        CoupledCase {
            name: "rigid 1000 kg on soft 1 kg, 20 × 5",
            description: "the same with 20 substeps of 5 iterations",
            kind: CaseKind::Fast,
            run: heavy_rigid_on_light_soft_20x5,
            rapier: None,
        },
        CoupledCase {
            name: "soft 1 kg on rigid 1000 kg",
            description: "a 1 kg soft cube on a free 1000 kg plank on the ground, 3 s: rests on it (lowest particle on the plank, final speed < 0.05 m/s)",
            kind: CaseKind::Fast,
            run: |c| guarded(light_soft_on_heavy_plank(c)),
            rapier: None,
        },
        CoupledCase {
            name: "rigid ball at 100 m/s",
            description: "a 0.1 m rigid ball (CCD on) at 100 m/s onto a soft slab one cell (0.2 m) thick on the ground, 2 s: the ball's centre never reaches the slab's lower half while over the slab",
            kind: CaseKind::Fast,
            run: |c| guarded(ball_at(c, 100.0)),
            rapier: None,
        },
        CoupledCase {
            name: "rigid ball at 30 m/s",
            description: "the same at 30 m/s",
            kind: CaseKind::Fast,
            run: |c| guarded(ball_at(c, 30.0)),
            rapier: None,
        },
        CoupledCase {
            name: "created half in the ground",
            description: "a 1 m soft cube created half inside the ground, 3 s: pushed out (lowest particle above −2 cm) with peak speed < 20 m/s",
            kind: CaseKind::Fast,
            run: created_in_the_ground,
            rapier: None,
        },
        CoupledCase {
            name: "created half in the ground, safety net 5 m/s",
            description: "the same with `max_correction_speed = 5 m/s`",
            kind: CaseKind::Fast,
            run: created_in_the_ground_net,
            rapier: None,
        },
        CoupledCase {
            name: "resting, 100,000 frames",
            description: "a 0.5 m soft cube resting on the ground for 100,000 frames (28 min simulated): final speed < 1 mm/s, centre-of-mass drift < 1 mm after settling, kinetic energy never above 10 × its settled value",
            kind: CaseKind::Long,
            run: |c| guarded(resting_100k_frames(c)),
            rapier: None,
        },
    ]
    .into_iter()
    .chain(crate::coupled_robust::robust_cases())
    .collect()
}
