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
/// projected together ([`crate::constraints::neo_hookean_update`]), with the
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
        m.released = released;
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

/// The material's share of the energy limit's budget for one body (J): the elastic energy it
/// released since the substep start, `Σ V₀ (Ψ(F̄) − Ψ(F))` over its tetrahedra (each taken
/// exactly when the last sweep projected it; zero if the material stored energy). That is
/// the energy its corrections may turn into motion; a step that would add more (an
/// instability, a tangle) is limited.
pub(crate) fn energy_budget(m: &NeoHookeanMaterial) -> f64 {
    m.released.max(0.0)
}
