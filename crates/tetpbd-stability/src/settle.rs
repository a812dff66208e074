//! Settling a body on the ground before its volume is compared.
//!
//! A body thrown at the ground is intact if it keeps the volume the same body keeps set
//! down at rest. A stiff body is at rest at the end of its run; a soft, barely damped one
//! (the soft tissue material: E = 10 kPa) is not, thrown or set down: both still sway on
//! the ground after 2 s, their volumes swinging by ±3 % around what they settle to under
//! their weight, so two volumes taken at one instant compare two phases of a swing, not two
//! states. So both runs end with a settling: [`SETTLE_FRAMES`] more frames with the linear
//! velocity damping [`SETTLE_DAMPING`], which only removes energy and leaves a folded,
//! inverted or stuck expanded body as it is; the volumes are compared after it. The
//! inverted tetrahedra count at the end of the run proper and after the settling, whichever
//! is more, and the energy and speed criteria stay those of the run proper.

use tetpbd::{hecs, Particles, Solver, Tetrahedra};

use crate::ground::Ground;
use crate::run::Outcome;

/// Frames (of the scene's frame length) a body on the ground settles for.
pub const SETTLE_FRAMES: usize = 60;

/// Linear velocity damping of the settling, 1/s: overdamps the soft tissue body's slowest
/// sway on the ground (a few rad/s) within a few tenths of a second.
pub const SETTLE_DAMPING: f32 = 20.0;

/// Settles body `e` on `ground` ([`SETTLE_FRAMES`] frames of `solver` with
/// [`SETTLE_DAMPING`]) and measures its volume and inverted tetrahedra into `out` (volume
/// error against `resting`, the settled volume ratio of the same body set down at rest).
pub fn settle(
    solver: &mut Solver,
    world: &mut hecs::World,
    e: hecs::Entity,
    ground: &mut Ground,
    out: &mut Outcome,
    resting: f32,
) {
    solver.settings.damping = SETTLE_DAMPING;
    for _ in 0..SETTLE_FRAMES {
        if solver.step_with(world, ground).is_err() {
            return;
        }
    }
    let (Ok(p), Ok(t)) = (world.get::<&Particles>(e), world.get::<&Tetrahedra>(e)) else {
        return;
    };
    out.final_inverted = out.final_inverted.max(t.count_inverted(p.positions()));
    out.final_volume_ratio = t.volume_ratio(p.positions());
    out.final_volume_error = (out.final_volume_ratio / resting - 1.0).abs();
}
