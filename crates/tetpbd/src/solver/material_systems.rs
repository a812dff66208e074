//! The systems of the Neo-Hookean material ([`NeoHookeanMaterial`]): its sweep, the reset
//! of its multipliers, and its share of the energy limit's budget. Plain loops over one
//! query each, like [`crate::systems`].

use hecs::World;

use crate::body::activation::Asleep;
use crate::body::mesh::Tetrahedra;
use crate::body::neo_hookean::NeoHookeanMaterial;
use crate::body::particles::Particles;
use crate::kernels::count::{Kernel, ProjectionCount};
use crate::kernels::neo_hookean::{sweep, MaterialStep, TetRun};
use crate::kernels::slots::WorkAccess;
use crate::kernels::working_copy::{self, CopyMode};

/// One Gauss–Seidel sweep over every awake body's [`NeoHookeanMaterial`] with the default
/// kernel.
pub fn project_neo_hookean(world: &mut World, h: f32) -> ProjectionCount {
    project_neo_hookean_with(world, h, Kernel::default())
}

/// One Gauss–Seidel sweep over every awake body's [`NeoHookeanMaterial`], tetrahedra in
/// solver (colour) order: the two constraints of each tetrahedron projected together
/// ([`crate::constraints::neo_hookean_update`]), with the material's damping. A tetrahedron
/// collapsed towards a point or a line is moved apart along the hydrostatic constraint's
/// recovery direction ([`crate::constraints::neo_hookean_hydrostatic_recovering`]).
///
/// [`Kernel::Simd`] projects four or eight tetrahedra of a colour class at once and agrees
/// with [`Kernel::Scalar`] to rounding. With the `parallel` feature, the tetrahedra of one
/// colour class (which share no particle) are projected concurrently; the result is
/// bit-identical to the serial sweep.
pub fn project_neo_hookean_with(world: &mut World, h: f32, kernel: Kernel) -> ProjectionCount {
    project_neo_hookean_in(world, h, kernel, CopyMode::PerSweep)
}

/// [`project_neo_hookean_with`], reaching the particles as `mode` says.
pub(crate) fn project_neo_hookean_in(
    world: &mut World,
    h: f32,
    kernel: Kernel,
    mode: CopyMode,
) -> ProjectionCount {
    let mut count = ProjectionCount::default();
    let q = world.query_mut::<(&mut Particles, &Tetrahedra, &mut NeoHookeanMaterial)>();
    for (p, tets, m) in q.without::<&Asleep>() {
        let k = MaterialStep::new(&m.material, h);
        if mode == CopyMode::PerSweep {
            working_copy::load(p);
        }
        let released = &mut m.tet_released.0;
        released.resize(m.lambdas.len(), 0.0);
        let mut acc = WorkAccess {
            slots: &mut p.work.0,
            rest: &p.rest_positions,
        };
        let mut run = TetRun {
            rest_inverse: &m.rest_inverse,
            rest_volumes: &tets.rest_volumes,
            lambdas: &mut m.lambdas,
            released,
        };
        count += sweep_body(&mut acc, &p.prev_positions, tets, &mut run, &k, kernel);
        m.released = m.tet_released.0.iter().map(|&e| f64::from(e)).sum();
        if mode == CopyMode::PerSweep {
            working_copy::store(p);
        }
    }
    count
}

/// One sweep of one body's material: in parallel on a large body, serially otherwise (the
/// same bits either way).
fn sweep_body(
    acc: &mut WorkAccess<'_>,
    prev: &[nalgebra::Vector3<f32>],
    tets: &Tetrahedra,
    run: &mut TetRun<'_>,
    k: &MaterialStep,
    kernel: Kernel,
) -> ProjectionCount {
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::worth_it(tets.len()) {
        return crate::parallel::sweeps::material(acc, prev, tets, run, k, kernel);
    }
    sweep(acc, prev, &tets.indices, &tets.classes, run, k, kernel)
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
