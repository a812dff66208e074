//! The benchmarks' deterministic perturbation of a grid body.

use nalgebra::Vector3;
use tetpbd::{Particles, StateError};

/// Moves every particle by a pseudo-random offset of up to ±1 % of `cell` (m) per axis
/// (xorshift, the same sequence every run), so that every projection of a sweep does work.
pub fn perturb(p: &mut Particles, cell: f32) -> Result<(), StateError> {
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    for i in 0..p.len() {
        let mut r = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            ((s >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 0.02 * cell
        };
        let x = p.positions()[i] + Vector3::new(r(), r(), r());
        p.set_position(i, x)?;
    }
    Ok(())
}
