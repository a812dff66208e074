//! A rounded soft body dropped on fixed ground comes to rest instead of rocking on its
//! belly, at default settings and with rolling resistance.
//!
//! A blob stiff enough to roll like a rigid body rocks with sticking friction, which does no
//! work; deformation damping only damps deformation. On an immovable collider the passivity
//! of its contacts (`response::passivity` in `tetpbd-rapier`: they stop the rigid motion's
//! approach as an inelastic impact and never give it energy) takes the rocking energy out, so
//! the `bunny_blob` asset rests without rolling resistance; with a rolling resistance of 0.01
//! ([`tetpbd_rapier::SoftColliderBuilder::rolling_resistance`], off by default) it rests too.

mod asset_drop_common;

use asset_drop_common::{asset_drop, AssetDrop};
use tetpbd::{Activation, Particles, Tetrahedra};
use tetpbd_rapier::SoftColliderBuilder;

/// Cell size of the tetrahedralization, m (coarser than the example's 0.07 m for speed).
const CELL: f32 = 0.1;

/// What one drop measured over its last `WINDOW` frames.
struct Rest {
    /// Largest particle speed, m/s.
    speed: f32,
    /// Largest end-of-step penetration, m.
    penetration: f32,
    /// Most inverted tetrahedra.
    inverted: usize,
}

/// Frames of the final window (0.5 s).
const WINDOW: usize = 30;

/// Drops the blob from 0.4 m with the `asset_drop` example's settings (10 substeps, friction
/// 0.6, deformation damping 5/s), the given rolling resistance (`None`: the default), for
/// `frames` frames of 1/60 s.
fn drop_blob(rolling: Option<f32>, frames: usize) -> Rest {
    let mut collider = SoftColliderBuilder::new().friction(0.6);
    if let Some(c) = rolling {
        collider = collider.rolling_resistance(c);
    }
    let AssetDrop {
        mut scene, body: e, ..
    } = asset_drop(
        "bunny_blob.obj",
        CELL,
        3,
        0.4,
        collider.build().expect("collider"),
    );
    // Watched awake: the rest measured is the solver's, not sleeping's.
    *scene.soft.get::<&mut Activation>(e).expect("body") = Activation::never_sleeps();
    let mut rest = Rest {
        speed: 0.0,
        penetration: 0.0,
        inverted: 0,
    };
    for frame in 0..frames {
        let stats = scene.step().expect("step");
        if frame + WINDOW >= frames {
            let (p, t) = scene
                .soft
                .query_one_mut::<(&Particles, &Tetrahedra)>(e)
                .expect("body");
            rest.speed = rest.speed.max(p.max_speed());
            rest.penetration = rest.penetration.max(stats.max_penetration);
            rest.inverted = rest.inverted.max(t.count_inverted(p.positions()));
        }
    }
    println!(
        "rolling resistance {rolling:?}: over the last {WINDOW} of {frames} frames max|v| \
         {:.5} m/s, penetration {:.6} m, inverted {}",
        rest.speed, rest.penetration, rest.inverted
    );
    rest
}

/// Asserts that the blob is at rest over the final window, not sunk and not inverted.
fn assert_rest(r: &Rest) {
    assert!(r.speed < 0.01, "still moving at {} m/s", r.speed);
    assert!(
        r.penetration < 0.01 * CELL,
        "penetration {} m",
        r.penetration
    );
    assert_eq!(r.inverted, 0, "inverted tetrahedra at rest");
}

#[test]
fn blob_with_rolling_resistance_comes_to_rest() {
    // 7 s: the blob lands at 0.3 s and tumbles; it rests at about 6 s (0.0006 m/s).
    assert_rest(&drop_blob(Some(0.01), 420));
}

#[test]
fn blob_comes_to_rest_at_default_settings() {
    // Rolling resistance off (the default): the contacts with the fixed ground are passive.
    assert_rest(&drop_blob(None, 420));
}
