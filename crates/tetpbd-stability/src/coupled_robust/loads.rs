//! Loads both ways: soft bodies resting on light rigid boxes and rigid boxes resting on
//! light soft slabs, at mass ratios 1:1 to 1000:1, the rigid box on fixed ground or on another
//! dynamic box. Criterion: everything at rest within 3 s, no body launched, the light body
//! moved < 1 cm and turned < 1°.

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd_rapier::CoupledWorld;

use super::body::{world, Engine, Soft};
use super::{ground, run};
use crate::coupled::CoupledOutcome;

/// What 3 s of a resting scene measured.
struct Rest {
    /// How far the watched rigid body's centre moved, m.
    moved: f32,
    /// How far it turned, rad.
    turned: f32,
    /// Its fastest speed, m/s.
    rigid_fastest: f32,
    /// Its fastest speed over the last 0.5 s, m/s.
    rigid_settled: f32,
    /// Fastest soft particle over the last 0.5 s, m/s.
    soft_settled: f32,
    /// How far the soft body's centre moved, m.
    soft_moved: f32,
}

fn watch(s: &mut CoupledWorld, soft: &Soft, rb: RigidBodyHandle, out: &mut CoupledOutcome) -> Rest {
    let start = s.physics.bodies.get(rb).map(|b| *b.position());
    let soft_start = soft.look(s).centre;
    let mut r = Rest {
        moved: 0.0,
        turned: 0.0,
        rigid_fastest: 0.0,
        rigid_settled: 0.0,
        soft_settled: 0.0,
        soft_moved: 0.0,
    };
    run(s, soft, 180, out, |s, f| {
        let look = soft.look(s);
        r.soft_moved = r.soft_moved.max((look.centre - soft_start).norm());
        if f >= 150 {
            r.soft_settled = r.soft_settled.max(look.fastest);
        }
        let (Some(b), Some(start)) = (s.physics.bodies.get(rb), start) else {
            r.moved = f32::INFINITY;
            return;
        };
        let v = b.linvel().length();
        r.rigid_fastest = r.rigid_fastest.max(v);
        r.moved = r.moved.max((b.translation() - start.translation).length());
        r.turned = r.turned.max(b.rotation().angle_between(start.rotation));
        if f >= 150 {
            r.rigid_settled = r.rigid_settled.max(v);
        }
    });
    r
}

/// A 0.5 m soft cube (4³ cells) of `ratio` kg on a 1 kg box of 0.5 m, on the ground or on
/// another 1 kg box (`stacked`).
pub(crate) fn soft_on_box(
    engine: Engine,
    ratio: f32,
    stacked: bool,
) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome::default();
    let mut s = world(engine)?;
    ground(&mut s);
    let mut top = 0.0;
    let mut rb = None;
    for _ in 0..=usize::from(stacked) {
        let (b, _) = s.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(0.0, top + 0.25, 0.0)),
            ColliderBuilder::cuboid(0.25, 0.25, 0.25).mass(1.0),
        );
        rb = Some(b);
        top += 0.5;
    }
    let rb = rb.ok_or("no box")?;
    let mesh = box_grid(Vector3::repeat(0.5), [4; 3], CellSplit::Six).map_err(|e| e.to_string())?;
    let at = Vector3::new(0.0, top + 0.253, 0.0);
    let soft = Soft::spawn(&mut s, engine, mesh, at, Vector3::zeros(), ratio / 0.125)?;
    let r = watch(&mut s, &soft, rb, &mut out);
    out.criterion = (
        r.moved < 0.01
            && r.turned < 1f32.to_radians()
            && r.rigid_fastest < 1.0
            && r.rigid_settled < 0.05
            && r.soft_settled < 0.05,
        format!(
            "box moved {:.1} mm, turned {:.2}°, fastest {:.2} m/s; at rest: box {:.3}, soft {:.3} m/s",
            r.moved * 1e3,
            r.turned.to_degrees(),
            r.rigid_fastest,
            r.rigid_settled,
            r.soft_settled
        ),
    );
    Ok(out)
}

/// A 0.3 m rigid box of `ratio` kg on a 1 kg soft slab (0.6 × 0.2 × 0.6 m, 4 × 2 × 4 cells)
/// on the ground, or on a 1 kg dynamic box 0.8 × 0.2 × 0.8 m on the ground (`on_box`).
pub(crate) fn rigid_on_soft(
    engine: Engine,
    ratio: f32,
    on_box: bool,
) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome::default();
    let mut s = world(engine)?;
    ground(&mut s);
    let base = if on_box {
        s.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.1, 0.0)),
            ColliderBuilder::cuboid(0.4, 0.1, 0.4).mass(1.0),
        );
        0.2
    } else {
        0.0
    };
    let size = Vector3::new(0.6, 0.2, 0.6);
    let mesh = box_grid(size, [4, 2, 4], CellSplit::Six).map_err(|e| e.to_string())?;
    let at = Vector3::new(0.0, base + 0.103, 0.0);
    let soft = Soft::spawn(&mut s, engine, mesh, at, Vector3::zeros(), 1.0 / 0.072)?;
    let (rb, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, base + 0.353, 0.0)),
        ColliderBuilder::cuboid(0.15, 0.15, 0.15).mass(ratio),
    );
    let r = watch(&mut s, &soft, rb, &mut out);
    // The light body: the slab (its centre moves as it is pressed; the box may sink into a
    // compliant slab, so the box's own move is not bounded, its turn is).
    let light_moved = if ratio >= 1.0 { r.soft_moved } else { r.moved };
    out.criterion = (
        light_moved < 0.01
            && r.turned < 1f32.to_radians()
            && r.rigid_fastest < 1.0
            && r.rigid_settled < 0.05
            && r.soft_settled < 0.05,
        format!(
            "slab moved {:.1} mm; box moved {:.1} mm, turned {:.2}°, fastest {:.2} m/s; at rest: box {:.3}, soft {:.3} m/s",
            r.soft_moved * 1e3,
            r.moved * 1e3,
            r.turned.to_degrees(),
            r.rigid_fastest,
            r.rigid_settled,
            r.soft_settled
        ),
    );
    Ok(out)
}
