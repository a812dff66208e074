//! The systems of the Neo-Hookean material ([`NeoHookeanMaterial`]): its sweep, the reset
//! of its multipliers, and its share of the energy limit's budget. Plain loops over one
//! query each, like [`crate::systems`].

use hecs::World;

use crate::body::activation::Asleep;
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::particles::Particles;
use crate::kernels::count::ProjectionCount;
use crate::kernels::neo_hookean::{sweep, MaterialStep};
use crate::kernels::working_copy::{self, CopyMode};

/// One Gauss–Seidel sweep over every awake body's [`NeoHookeanMaterial`], tetrahedra in
/// solver (colour) order, on the scalar kernel: the two constraints of each tetrahedron
/// projected together ([`crate::constraints::neo_hookean_delta_lambdas`]), with the
/// material's damping. A tetrahedron collapsed to a point (no deviatoric direction) is
/// skipped and counted as degenerate.
pub fn project_neo_hookean(world: &mut World, h: f32) -> ProjectionCount {
    project_neo_hookean_in(world, h, CopyMode::PerSweep)
}

/// [`project_neo_hookean`], reaching the particles as `mode` says.
pub(crate) fn project_neo_hookean_in(world: &mut World, h: f32, mode: CopyMode) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    let q = world.query_mut::<(&mut Particles, &Tetrahedra, &mut NeoHookeanMaterial)>();
    for (p, tets, m) in q.without::<&Asleep>() {
        let k = MaterialStep::new(&m.material, h);
        if mode == CopyMode::PerSweep {
            working_copy::load(p);
        }
        let (c, released) = sweep(
            &mut p.work.0,
            &p.prev_positions,
            &tets.indices,
            &tets.rest_volumes,
            &m.rest_inverse,
            &mut m.lambdas,
            &k,
        );
        m.released += released;
        if mode == CopyMode::PerSweep {
            working_copy::store(p);
        }
        count += c;
    }
    count
}

/// Sets the material's multipliers and released energy to zero (start of a substep).
pub fn reset_neo_hookean(world: &mut World) {
    for m in world
        .query_mut::<&mut NeoHookeanMaterial>()
        .without::<&Asleep>()
    {
        m.lambdas.fill([0.0; 2]);
        m.released = 0.0;
    }
}

/// The material's share of the energy limit's budget for one body (J): the elastic energy its
/// projections released in the substep, plus `(1 + W̄/α̃_H)|A|` for the energy the prediction
/// moved in or out of it (`A` the work term, J; `W̄ = w_max Σ|∇C_H|²` at the rest shape of a
/// regular tetrahedron of the body's mean rest volume `V`, `Σ|∇ det F|² = L⁴/(12 V²)`),
/// as the seed's families' budget in `stabilisation::correction_energy`.
pub(crate) fn energy_budget(
    m: &NeoHookeanMaterial,
    tets: &Tetrahedra,
    h: f32,
    w_max: f32,
    work: f64,
) -> f64 {
    let (mu, lambda) = m.material.lame();
    let lp = f64::from(lambda) + f64::from(mu);
    let n = tets.rest_volumes.len().max(1) as f64;
    let v = tets
        .rest_volumes
        .iter()
        .map(|v| f64::from(v.abs()))
        .sum::<f64>()
        / n;
    let l4 = (6.0 * std::f64::consts::SQRT_2 * v).cbrt().powi(4);
    let wbar = f64::from(w_max) * l4 / (12.0 * v * v);
    let alpha_tilde = 1.0 / (lp * v * f64::from(h) * f64::from(h));
    let moved = (1.0 + wbar / alpha_tilde) * work.abs();
    if moved.is_finite() {
        moved + m.released
    } else {
        m.released
    }
}
