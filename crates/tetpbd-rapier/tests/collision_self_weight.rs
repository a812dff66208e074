//! `StackingSettings::self_weight`: the stacking pass's ground-up sweep on a soft
//! body resting under its own weight. With one Gauss–Seidel iteration per substep a resting
//! body sags by a volume error that falls only as `h²`; the sweep must cut it, keep the body
//! at rest and leave bodies without a support alone.

mod coupling_common;

use coupling_common::{ground, inverted, scene, soft_box, step_checked, volume_ratio};
use nalgebra::Vector3;
use tetpbd_rapier::SoftCollider;

/// What a run measured.
struct Rest {
    /// Largest |volume ratio − 1| over the last 30 frames.
    volume_error: f32,
    /// Largest particle speed over the last 30 frames, m/s.
    late_speed: f32,
    /// Stacking passes over the whole run.
    passes: u64,
}

/// A 1 m cube of 8³ cells dropped 5 cm onto the ground, 10 substeps, 180 frames.
fn rest(self_weight: bool) -> Rest {
    let mut s = scene(10);
    s.coupling.settings_mut().stacking = Some(tetpbd_rapier::StackingSettings {
        self_weight,
        ..Default::default()
    });
    ground(&mut s);
    let cube = soft_box(
        &mut s,
        Vector3::repeat(1.0),
        [8; 3],
        Vector3::new(0.0, 0.55, 0.0),
        SoftCollider::default(),
    );
    let frames = 180;
    let mut r = Rest {
        volume_error: 0.0,
        late_speed: 0.0,
        passes: 0,
    };
    for f in 0..frames {
        let (stats, v) = step_checked(&mut s, cube, f);
        r.passes += stats.stacking_passes;
        if f + 30 >= frames {
            r.late_speed = r.late_speed.max(v);
            r.volume_error = r.volume_error.max((volume_ratio(&s, cube) - 1.0).abs());
        }
    }
    assert_eq!(inverted(&s, cube), 0, "inverted tetrahedra at the end");
    println!(
        "self-weight sweep {self_weight}: volume error {:.3e}, last 30 frames max speed \
         {:.2e} m/s, stacking passes {}",
        r.volume_error, r.late_speed, r.passes
    );
    r
}

/// The sweep cuts the resting sag of a cube at least threefold and the cube stays at rest.
#[test]
fn self_weight_sweep_cuts_the_resting_volume_error() {
    let off = rest(false);
    let on = rest(true);
    assert_eq!(
        off.passes, 0,
        "the pass ran without a heavy load or the setting"
    );
    assert!(on.passes > 0, "the setting did not run the sweep");
    assert!(
        on.volume_error * 3.0 < off.volume_error,
        "volume error {} with the sweep, {} without",
        on.volume_error,
        off.volume_error
    );
    assert!(
        on.late_speed < 1e-3,
        "the cube is not at rest with the sweep: {} m/s",
        on.late_speed
    );
}

/// A body without a support (falling, nothing pinned) has no roots: the sweep never runs.
#[test]
fn self_weight_sweep_leaves_a_falling_body_alone() {
    let mut s = scene(10);
    s.coupling.settings_mut().stacking = Some(tetpbd_rapier::StackingSettings {
        self_weight: true,
        ..Default::default()
    });
    soft_box(
        &mut s,
        Vector3::repeat(1.0),
        [4; 3],
        Vector3::new(0.0, 5.0, 0.0),
        SoftCollider::default(),
    );
    for _ in 0..30 {
        let stats = s.step().expect("step");
        assert_eq!(stats.stacking_passes, 0, "the sweep ran on a falling body");
    }
}
