//! The compensated position update every pass uses.

use nalgebra::Vector3;

/// `x += d`, keeping the rounding error of the sum in `r` (Fast2Sum: exact while
/// `|x| ≥ |d|`, which holds for the small corrections of a substep).
///
/// Why: a substep's corrections are often a few ulps of the position (10+ substeps, stiff
/// constraints), and round-to-nearest then biases them. The velocity update adds the residual
/// back, `v = (x − x_prev + r)/h`, so velocities, and with them momentum, see the exact sum
/// of the corrections. Positions themselves stay rounded.
#[inline(always)]
pub fn add_compensated(x: &mut Vector3<f32>, r: &mut Vector3<f32>, d: Vector3<f32>) {
    let old = *x;
    let new = old + d;
    *r += d - (new - old);
    *x = new;
}
