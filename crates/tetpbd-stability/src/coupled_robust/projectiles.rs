//! Projectiles: 1 kg rigid balls and boxes at 50–300 m/s straight down into a soft slab
//! (1 × 0.2 × 1 m, 8 × 8 cells across, 1–4 cells thick, 1000 kg/m³) on the ground, and a
//! soft cube at those speeds onto rigid bodies. Criterion: never through, never faster out
//! than in, the target not thrown.

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape};
use tetpbd::generators::{box_grid, CellSplit};

use super::body::{world, Engine, Soft};
use super::{ground, merge, run};
use crate::coupled::CoupledOutcome;

/// A rigid projectile of the scenes.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Projectile {
    /// A ball of this radius, m.
    Ball(f32),
    /// A cube of this edge, m.
    Cube(f32),
}

impl Projectile {
    fn shape(self) -> SharedShape {
        match self {
            Projectile::Ball(r) => SharedShape::ball(r),
            Projectile::Cube(a) => SharedShape::cuboid(a / 2.0, a / 2.0, a / 2.0),
        }
    }

    fn half(self) -> f32 {
        match self {
            Projectile::Ball(r) => r,
            Projectile::Cube(a) => a / 2.0,
        }
    }
}

/// The aim points, m (the slab spans ±0.5 m): off-centre, centred, on a cell corner, far.
const AIMS: [[f32; 2]; 4] = [[0.03, 0.02], [0.0, 0.0], [0.0625, 0.0625], [0.31, -0.17]];

/// One shot.
struct Shot {
    /// Lowest point of the projectile while over the slab, m (the ground is at 0).
    lowest: f32,
    /// Fastest the projectile moved after its first frame, m/s.
    out_speed: f32,
    /// How high the slab's centre rose, m.
    rise: f32,
    /// Fastest slab particle after the first frame, m/s.
    slab_peak: f32,
}

/// One shot of `p` at `speed` from 0.5 m at `aim` onto a slab of `layers` cells, 1 s.
fn shoot(
    engine: Engine,
    p: Projectile,
    speed: f32,
    layers: u32,
    aim: [f32; 2],
    ccd: bool,
    out: &mut CoupledOutcome,
) -> Result<Shot, String> {
    let mut s = world(engine)?;
    ground(&mut s);
    let size = Vector3::new(1.0, 0.2, 1.0);
    let mesh = box_grid(size, [8, layers, 8], CellSplit::Six).map_err(|e| e.to_string())?;
    let at = Vector3::new(0.0, 0.1, 0.0);
    let slab = Soft::spawn(&mut s, engine, mesh, at, Vector3::zeros(), 1000.0)?;
    let rest = slab.look(&s).centre.y;
    let (rb, _) = s.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(aim[0], 0.5, aim[1]))
            .linvel(Vector::new(0.0, -speed, 0.0))
            .ccd_enabled(ccd),
        ColliderBuilder::new(p.shape()).mass(1.0),
    );
    let mut shot = Shot {
        lowest: f32::INFINITY,
        out_speed: 0.0,
        rise: 0.0,
        slab_peak: 0.0,
    };
    let mut one = CoupledOutcome::default();
    run(&mut s, &slab, 60, &mut one, |s, f| {
        let look = slab.look(s);
        shot.rise = shot.rise.max(look.centre.y - rest);
        if f > 0 {
            shot.slab_peak = shot.slab_peak.max(look.fastest);
        }
        let Some(b) = s.physics.bodies.get(rb) else {
            return;
        };
        let t = b.translation();
        if !t.is_finite() {
            shot.lowest = f32::NEG_INFINITY;
        }
        if t.x.abs() < 0.5 && t.z.abs() < 0.5 {
            shot.lowest = shot.lowest.min(t.y - p.half());
        }
        if f > 0 {
            shot.out_speed = shot.out_speed.max(b.linvel().length());
        }
    });
    merge(out, &one);
    Ok(shot)
}

/// `p` at 50, 150 and 300 m/s onto slabs of 1, 2 and 4 cells, each at two of [`AIMS`] in
/// turn (`speeds` overrides the speeds).
pub(crate) fn into_slabs(
    engine: Engine,
    p: Projectile,
    speeds: &[f32],
    ccd: bool,
) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome {
        finite: true,
        ..CoupledOutcome::default()
    };
    let (mut lowest, mut worst_out, mut worst_rise) = (f32::INFINITY, 0.0f32, 0.0f32);
    let mut failed = Vec::new();
    let mut k = 0usize;
    for &speed in speeds {
        for layers in [1u32, 2, 4] {
            for _ in 0..2 {
                let aim = AIMS[k % AIMS.len()];
                k += 1;
                let shot = shoot(engine, p, speed, layers, aim, ccd, &mut out)?;
                // The 200 kg slab cannot rise higher than the shot's whole energy lifts it.
                let bound = 0.5 * speed * speed / (200.0 * 9.81);
                let ok = shot.lowest > -0.01
                    && shot.out_speed < speed
                    && shot.slab_peak < speed
                    && shot.rise < bound;
                if !ok {
                    failed.push(format!("{speed} m/s, {layers} cells at {aim:?}"));
                }
                lowest = lowest.min(shot.lowest);
                worst_out = worst_out.max(shot.out_speed / speed);
                worst_rise = worst_rise.max(shot.rise / bound);
            }
        }
    }
    out.criterion = (
        failed.is_empty(),
        format!(
            "lowest {lowest:.3} m, out ≤ {:.0} % of in, slab rise ≤ {:.0} % of the bound{}",
            worst_out * 100.0,
            worst_rise * 100.0,
            if failed.is_empty() {
                String::new()
            } else {
                format!("; failed: {}", failed.join("; "))
            }
        ),
    );
    Ok(out)
}

/// A 0.3 m soft cube (3³ cells, 27 kg) at 50, 150 and 300 m/s straight down onto `target`:
/// the ground, a fixed 2 cm plate 0.3 m above it, or a 30 kg dynamic box 0.6 × 0.3 × 0.6 m
/// on it; 1 s each.
pub(crate) fn soft_into_rigid(
    engine: Engine,
    target: &str,
    speeds: &[f32],
) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome {
        finite: true,
        ..CoupledOutcome::default()
    };
    let (mut lowest, mut worst_out, mut thrown) = (f32::INFINITY, 0.0f32, 0.0f32);
    let mut failed = Vec::new();
    for &speed in speeds {
        let mut s = world(engine)?;
        ground(&mut s);
        let body = match target {
            "plate" => {
                s.physics.insert(
                    RigidBodyBuilder::fixed().translation(Vector::new(0.0, 0.3, 0.0)),
                    ColliderBuilder::cuboid(1.0, 0.01, 1.0),
                );
                None
            }
            "box" => Some(
                s.physics
                    .insert(
                        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.15, 0.0)),
                        ColliderBuilder::cuboid(0.3, 0.15, 0.3).mass(30.0),
                    )
                    .0,
            ),
            _ => None,
        };
        let top = if target == "ground" { 0.0 } else { 0.3 };
        let mesh =
            box_grid(Vector3::repeat(0.3), [3; 3], CellSplit::Six).map_err(|e| e.to_string())?;
        let at = Vector3::new(0.02, top + 0.6, -0.01);
        let v = Vector3::new(0.0, -speed, 0.0);
        let soft = Soft::spawn(&mut s, engine, mesh, at, v, 1000.0)?;
        let (mut low, mut fast, mut target_fast) = (f32::INFINITY, 0.0f32, 0.0f32);
        let mut one = CoupledOutcome::default();
        run(&mut s, &soft, 60, &mut one, |s, f| {
            let look = soft.look(s);
            low = low.min(look.lowest - top);
            if f > 0 {
                fast = fast.max(look.fastest);
                if let Some(b) = body.and_then(|h| s.physics.bodies.get(h)) {
                    target_fast = target_fast.max(b.linvel().length());
                }
            }
        });
        merge(&mut out, &one);
        if !(low > -0.02 && fast < speed && target_fast < speed) {
            failed.push(format!("{speed} m/s"));
        }
        lowest = lowest.min(low);
        worst_out = worst_out.max(fast / speed);
        thrown = thrown.max(target_fast);
    }
    out.criterion = (
        failed.is_empty(),
        format!(
            "lowest particle {lowest:.3} m from the top, out ≤ {:.0} % of in, target ≤ {thrown:.1} m/s{}",
            worst_out * 100.0,
            if failed.is_empty() {
                String::new()
            } else {
                format!("; failed: {}", failed.join(", "))
            }
        ),
    );
    Ok(out)
}
