//! A soft body stuck in a tangled, self-intersecting equilibrium stays at rest: without the
//! removal of the corrections' rigid rotation (`SafetySettings::conserve_angular_momentum`)
//! Gauss–Seidel's second-order torque spins it up (undamped, 22 kJ within 10 s on this 1 m cube).

use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::{Particles, SoftBodyBuilder, Solver, Tetrahedra};
use tetpbd_stability::{all_cases, Config, ConstraintSet, Start};

/// The matrix's `long / mirrored` case under soft edges + volume without the spin removal
/// and without the untangling, which lands in a tangled state within its first frames; returns it settled and at rest,
/// with the solver set to zero damping.
fn tangled() -> (World, Entity, Solver) {
    let case = all_cases(None)
        .into_iter()
        .find(|c| c.name == "mirrored, 1 min at 20 substeps")
        .expect("the matrix has the case");
    let config = Config {
        set: ConstraintSet::EdgesVolume,
        soft: true,
    };
    let builder = SoftBodyBuilder::new(case.scene.mesh.clone()).density(1000.0);
    let body = config.apply(builder, 1.0).build().unwrap();
    let (lo, hi) = body.particles.aabb();
    let mut world = World::new();
    let e = body.spawn(&mut world);
    // The scene needs the tangle kept: the untangling (on by default) would pull the calm
    // body back to its rest shape.
    world.get::<&mut tetpbd::Untangle>(e).unwrap().disabled = true;
    {
        let mut p = world.get::<&mut Particles>(e).unwrap();
        Start::Mirrored.apply(&mut p, (lo + hi) / 2.0).unwrap();
    }
    let mut settings = case.scene.settings.clone();
    settings.safety.conserve_angular_momentum = false;
    // Damped hard so the body settles into the tangle's equilibrium (spinning, which the
    // restart below stops).
    settings.damping = 5.0;
    let mut solver = Solver::new(settings).unwrap();
    for _ in 0..300 {
        solver.step(&mut world).unwrap();
    }
    {
        let mut p = world.get::<&mut Particles>(e).unwrap();
        let t = world.get::<&Tetrahedra>(e).unwrap();
        let ratio = t.volume_ratio(p.positions());
        assert!(
            ratio < 0.9 && t.count_inverted(p.positions()) == 0,
            "the scene no longer tangles (volume ratio {ratio}); pick another start"
        );
        for v in p.velocities_mut() {
            *v = Vector3::zeros();
        }
    }
    solver.settings.damping = 0.0;
    (world, e, solver)
}

/// Kinetic energy (J) and |L| (kg m²/s) after two undamped seconds from rest.
fn run(conserve: bool) -> (f32, f32) {
    let (mut world, e, mut solver) = tangled();
    solver.settings.safety.conserve_angular_momentum = conserve;
    let mut peak = 0.0f32;
    for _ in 0..120 {
        solver.step(&mut world).unwrap();
        peak = peak.max(world.get::<&Particles>(e).unwrap().kinetic_energy());
    }
    let p = world.get::<&Particles>(e).unwrap();
    assert!(p
        .positions()
        .iter()
        .all(|x| x.iter().all(|c| c.is_finite())));
    (peak, p.angular_momentum().norm())
}

#[test]
fn tangled_body_does_not_spin_itself_up() {
    let (ke, l) = run(true);
    eprintln!("with the spin removal: peak KE {ke:e} J, final |L| {l:e} kg m²/s");
    assert!(ke < 1e-2, "peak kinetic energy {ke} J");
    assert!(l < 1e-2, "angular momentum {l} kg m²/s");
}

/// The scene shows the spin-up when the removal is off (so the test above can fail).
#[test]
fn without_spin_removal_the_tangled_body_spins_up() {
    let (ke, l) = run(false);
    eprintln!("without the spin removal: peak KE {ke:e} J, final |L| {l:e} kg m²/s");
    assert!(ke > 100.0, "peak kinetic energy only {ke} J");
    assert!(l > 100.0, "angular momentum only {l} kg m²/s");
}
