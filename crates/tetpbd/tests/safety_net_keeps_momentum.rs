//! The correction-speed safety net (`SafetySettings::max_correction_speed`) never changes a
//! free body's linear or angular momentum: what the per-particle clamp removes is given back
//! as a rigid velocity change of the whole body. Where the net never acts, the result is
//! bit-identical to running without it.

mod common;

use common::{Deformation as Start, Rng};
use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::generators::{ball, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings};

/// Linear momentum, angular momentum about the centre of mass, and the scales they are
/// measured against (`Σ mᵢ|vᵢ|`, kg·m/s, and `Σ mᵢ|xᵢ − c||vᵢ|`, kg·m²/s), summed in f64.
fn momenta(p: &Particles) -> (Vector3<f64>, Vector3<f64>, f64, f64) {
    let m: f64 = p.masses().iter().map(|&m| f64::from(m)).sum();
    let c = p
        .positions()
        .iter()
        .zip(p.masses())
        .fold(Vector3::zeros(), |a, (x, &mi)| {
            a + x.cast::<f64>() * f64::from(mi)
        })
        / m;
    let (mut lin, mut ang, mut sp, mut sl) = (Vector3::zeros(), Vector3::zeros(), 0.0, 0.0);
    for ((x, v), &mi) in p.positions().iter().zip(p.velocities()).zip(p.masses()) {
        let (r, mv) = (x.cast::<f64>() - c, v.cast::<f64>() * f64::from(mi));
        lin += mv;
        ang += r.cross(&mv);
        sp += mv.norm();
        sl += r.norm() * mv.norm();
    }
    (lin, ang, sp, sl)
}

/// A 1 m box of 3³ cells (density 1000 kg/m³, edges + volume) at rest, its positions
/// mirrored, scrambled or strained.
fn deformed(world: &mut World, start: Start) -> Entity {
    let e = SoftBodyBuilder::new(common::cube(3, CellSplit::Six))
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .build()
        .unwrap()
        .spawn(world);
    common::deform(world, e, start);
    e
}

/// Largest linear and angular momentum over 60 frames of a deformed body released with the
/// net at `net` m/s and no gravity, relative to the largest `Σ mᵢ|vᵢ|` and
/// `Σ mᵢ|xᵢ − c||vᵢ|` of the run, and the clamps the net made.
fn released(start: Start, net: f32) -> (f64, f64, u64) {
    let mut world = World::new();
    let e = deformed(&mut world, start);
    let mut solver = Solver::new(SolverSettings {
        gravity: Vector3::zeros(),
        safety: tetpbd::SafetySettings {
            max_correction_speed: Some(net),
            limit_correction_energy: false,
            ..Default::default()
        },
        ..Default::default()
    })
    .unwrap();
    let (mut lin, mut ang, mut sp, mut sl, mut clamps) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0);
    for _ in 0..60 {
        clamps += solver.step(&mut world).unwrap().velocity_clamps;
        let p = world.get::<&Particles>(e).unwrap();
        assert!(p
            .velocities()
            .iter()
            .all(|v| v.iter().all(|c| c.is_finite())));
        let (l, a, s, t) = momenta(&p);
        (lin, ang, sp, sl) = (lin.max(l.norm()), ang.max(a.norm()), sp.max(s), sl.max(t));
    }
    let (dp, dl) = (lin / sp, ang / sl);
    eprintln!("{start:?}: linear {dp:e}, angular {dl:e} (relative), {clamps} clamps");
    (dp, dl, clamps)
}

/// A mirrored or scrambled body snapping back with the net at 10 m/s. Typical: linear
/// 1.0–1.4e-6 relative; with the per-particle clamp alone 0.54 (mirrored) and 0.3
/// (scrambled). Angular 1.0–1.5e-6 (the solver removes the projections' own spin and the
/// net gives back the angular momentum it removed); without either, 0.6 of the scale in
/// frame 1.
#[test]
fn released_tangled_body_keeps_zero_momentum() {
    for start in [Start::Mirrored, Start::Scrambled] {
        let (dp, dl, clamps) = released(start, 10.0);
        assert!(clamps > 0, "{start:?}: the net acts");
        assert!(dp < 1e-5, "{start:?}: linear momentum {dp:e} (relative)");
        assert!(dl < 1e-5, "{start:?}: angular momentum {dl:e} (relative)");
    }
}

/// A one-sided strain snapping back with the net at 1 m/s: the clamp acts on the top only,
/// which clamped particle by particle would push the body and set it turning. Typical: linear
/// 0.9e-7 relative, angular 1.5e-7; with the per-particle clamp alone 0.45 and 0.34.
#[test]
fn released_strained_body_keeps_zero_momentum() {
    let (dp, dl, clamps) = released(Start::Strained, 1.0);
    assert!(clamps > 0, "the net acts");
    assert!(dp < 1e-5, "linear momentum {dp:e} (relative)");
    assert!(dl < 1e-5, "angular momentum {dl:e} (relative)");
}

/// Positions, velocities as bits after 100 frames of a ball with a random internal velocity
/// field (0.5 m/s), and the clamps made.
fn gentle(net: Option<f32>) -> (Vec<[u32; 3]>, u64) {
    let mut world = World::new();
    let mesh = ball(0.5, 3, CellSplit::Six).unwrap();
    let e = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(1e-6)
        .volume(0.0)
        .vertex_face(1e-5)
        .build()
        .unwrap()
        .spawn(&mut world);
    {
        let mut p = world.get::<&mut Particles>(e).unwrap();
        let mut rng = Rng::new(7);
        for i in 0..p.len() {
            p.set_velocity(i, rng.vec(0.5).cast()).unwrap();
        }
    }
    let mut solver = Solver::new(SolverSettings {
        safety: tetpbd::SafetySettings {
            max_correction_speed: net,
            ..Default::default()
        },
        ..Default::default()
    })
    .unwrap();
    let mut clamps = 0;
    for _ in 0..100 {
        clamps += solver.step(&mut world).unwrap().velocity_clamps;
    }
    let p = world.get::<&Particles>(e).unwrap();
    (common::state_bits(&p), clamps)
}

#[test]
fn net_that_never_acts_changes_nothing() {
    let (off, _) = gentle(None);
    let (on, clamps) = gentle(Some(10.0));
    assert_eq!(clamps, 0, "the net does not act on this body");
    assert!(off == on, "bit-identical with and without the net");
}

/// Every particle on one line with the net on (an inertia tensor of rank 2): nothing turns
/// non-finite and the momenta stay zero (to f32 rounding of the largest momentum of the run).
#[test]
fn collinear_body_stays_finite() {
    let mut world = World::new();
    let e = deformed(&mut world, Start::Mirrored);
    common::deform_with(&mut world, e, |i, _| {
        let t = (i as f32 * 0.37).sin() * 0.5;
        Vector3::new(t, 2.0 * t, -t)
    });
    let mut solver = Solver::new(SolverSettings {
        gravity: Vector3::zeros(),
        safety: tetpbd::SafetySettings {
            max_correction_speed: Some(1.0),
            limit_correction_energy: false,
            ..Default::default()
        },
        ..Default::default()
    })
    .unwrap();
    let mut clamps = 0;
    let (mut sp_max, mut sl_max) = (0.0f64, 0.0f64);
    for _ in 0..30 {
        let s = solver.step(&mut world).unwrap();
        assert_eq!(s.non_finite_resets, 0);
        clamps += s.velocity_clamps;
        let p = world.get::<&Particles>(e).unwrap();
        assert!(p
            .positions()
            .iter()
            .chain(p.velocities())
            .all(|v| v.iter().all(|c| c.is_finite())));
        let (lin, ang, sp, sl) = momenta(&p);
        // Relative to the largest of the run, as `released` takes them: the body leaves the
        // line (the volume constraints' recovery direction) and comes to rest.
        (sp_max, sl_max) = (sp_max.max(sp), sl_max.max(sl));
        assert!(lin.norm() <= 1e-5 * sp_max, "linear momentum {lin:?}");
        assert!(ang.norm() <= 1e-5 * sl_max, "angular momentum {ang:?}");
    }
    assert!(clamps > 0, "the net acts");
}
