//! User forces ([`UserForces`]) are integrated as gravity is: over a frame the body's
//! momentum changes by exactly `F · dt`, its angular momentum about the centre of mass by
//! `r × F · dt`, forces persist until reset, and bad input is a typed error. Seeded sweeps
//! over sizes, densities, substeps and points.

use nalgebra::{UnitQuaternion, Vector3};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    MaterialPoint, Particles, SoftBody, SoftBodyBuilder, Solver, SolverSettings, StateError,
    UserForces,
};

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }

    fn vector(&mut self, scale: f32) -> Vector3<f32> {
        Vector3::new(self.next(), self.next(), self.next()) * scale
    }
}

/// A body of the sweep's `case`: size, cells, split and density vary; it starts at rest
/// (so its positions move by O(F dt²/m) in the frame) and is compliant enough to deform.
fn body(rng: &mut Rng, case: usize) -> SoftBody {
    body_with(rng, case, 1e-6)
}

/// [`body`] with edge compliance `edges` (m/N; volume 0.1 of it, m⁵/N).
fn body_with(rng: &mut Rng, case: usize, edges: f32) -> SoftBody {
    let split = if case.is_multiple_of(2) {
        CellSplit::Five
    } else {
        CellSplit::Six
    };
    let cells = [2 + case as u32 % 3, 2, 1 + case as u32 % 2];
    let size = Vector3::new(1.0, 0.5, 0.3) * (0.1 + 2.0 * rng.next().abs());
    let mesh = box_grid(size, cells, split).unwrap();
    SoftBodyBuilder::new(mesh)
        .density(10f32.powf(1.0 + 3.0 * rng.next().abs()))
        .edges(edges)
        .volume(edges * 0.1)
        .rotation(UnitQuaternion::from_scaled_axis(rng.vector(2.0)))
        .translation(rng.vector(0.5))
        .build()
        .unwrap()
}

fn settings(substeps: u32) -> SolverSettings {
    SolverSettings {
        gravity: Vector3::zeros(),
        substeps,
        ..SolverSettings::default()
    }
}

fn momenta(p: &Particles, about: Vector3<f32>) -> (Vector3<f64>, Vector3<f64>) {
    let (mut lin, mut ang) = (Vector3::zeros(), Vector3::zeros());
    let about = about.cast::<f64>();
    for ((x, v), m) in p.positions().iter().zip(p.velocities()).zip(p.masses()) {
        let mv = v.cast::<f64>() * f64::from(*m);
        lin += mv;
        ang += (x.cast::<f64>() - about).cross(&mv);
    }
    (lin, ang)
}

/// A point inside tetrahedron `t`: a random convex combination of its corners.
fn inside(rng: &mut Rng, b: &SoftBody) -> Vector3<f32> {
    let tets = b.tetrahedra.indices();
    let t = (rng.next().abs() * tets.len() as f32) as usize % tets.len();
    let w = [0; 4].map(|_| rng.next().abs() + 0.05);
    let s: f32 = w.iter().sum();
    (0..4)
        .map(|k| b.particles.positions()[tets[t][k] as usize] * (w[k] / s))
        .sum()
}

#[test]
fn force_at_a_point_changes_momentum_by_force_times_dt_and_spins_as_r_cross_f() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for case in 0..36 {
        let substeps = [1, 4, 10, 25][case % 4];
        let b = body_with(&mut rng, case, 0.0);
        let point = inside(&mut rng, &b);
        // A small force on a stiff body: it turns by a tiny angle over the frame, so its
        // torque stays the start's r × F.
        let force = rng.vector(1.0) * b.particles.total_mass();
        let mut forces = UserForces::new(&b.particles);
        forces
            .add_force_at_point(&b.particles, &b.tetrahedra, force, point)
            .unwrap();
        let com = b.particles.center_of_mass();
        let torque = forces.torque(&b.particles, com);
        let expected_torque = (point - com).cross(&force);
        assert!(
            (torque - expected_torque).norm() <= 1e-5 * expected_torque.norm().max(1e-3),
            "case {case}: torque {torque:?}, r × F {expected_torque:?}"
        );
        assert!((forces.force() - force).norm() <= 1e-5 * force.norm());

        let mut world = hecs::World::new();
        let e = b.spawn(&mut world);
        world.insert_one(e, forces).unwrap();
        let mut solver = Solver::new(settings(substeps)).unwrap();
        let dt = solver.settings.dt;
        let before = momenta(&world.get::<&Particles>(e).unwrap(), com);
        solver.step(&mut world).unwrap();
        let after = momenta(&world.get::<&Particles>(e).unwrap(), com);
        let dp = after.0 - before.0;
        let want = force.cast::<f64>() * f64::from(dt);
        assert!(
            (dp - want).norm() <= 1e-5 * want.norm(),
            "case {case} ({substeps} substeps): Δp {dp:?}, F·dt {want:?}"
        );
        let dl = after.1 - before.1;
        let want_l = expected_torque.cast::<f64>() * f64::from(dt);
        let size = b_size(&world, e);
        assert!(
            (dl - want_l).norm() <= 1e-3 * force.norm() as f64 * size * f64::from(dt),
            "case {case} ({substeps} substeps): ΔL {dl:?}, r×F·dt {want_l:?}"
        );
    }
}

fn b_size(world: &hecs::World, e: hecs::Entity) -> f64 {
    let (lo, hi) = world.get::<&Particles>(e).unwrap().aabb();
    f64::from((hi - lo).norm())
}

#[test]
fn forces_persist_until_reset() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for case in 0..8 {
        let b = body(&mut rng, case);
        let force = rng.vector(10.0) * b.particles.total_mass();
        let mut forces = UserForces::new(&b.particles);
        forces.add_force(&b.particles, force).unwrap();
        let mut world = hecs::World::new();
        let e = b.spawn(&mut world);
        world.insert_one(e, forces).unwrap();
        let mut solver = Solver::new(settings(5)).unwrap();
        let dt = f64::from(solver.settings.dt);
        let p0 = momenta(&world.get::<&Particles>(e).unwrap(), Vector3::zeros()).0;
        for _ in 0..3 {
            solver.step(&mut world).unwrap();
        }
        let p3 = momenta(&world.get::<&Particles>(e).unwrap(), Vector3::zeros()).0;
        let want = force.cast::<f64>() * 3.0 * dt;
        assert!((p3 - p0 - want).norm() <= 1e-5 * want.norm(), "case {case}");
        world.get::<&mut UserForces>(e).unwrap().reset_forces();
        solver.step(&mut world).unwrap();
        let p4 = momenta(&world.get::<&Particles>(e).unwrap(), Vector3::zeros()).0;
        assert!(
            (p4 - p3).norm() <= 1e-5 * want.norm(),
            "case {case}: moved after reset"
        );
    }
}

#[test]
fn whole_body_force_accelerates_without_spin() {
    let mut rng = Rng(0x5555_aaaa_1234_4321);
    for case in 0..8 {
        let b = body(&mut rng, case);
        let force = rng.vector(10.0) * b.particles.total_mass();
        let mut forces = UserForces::new(&b.particles);
        forces.add_force(&b.particles, force).unwrap();
        let com = b.particles.center_of_mass();
        let torque = forces.torque(&b.particles, com);
        assert!(
            torque.norm() <= 1e-5 * force.norm() * 3.0,
            "case {case}: {torque:?}"
        );
    }
}

#[test]
fn radial_force_pushes_outwards_within_its_radius_only() {
    let mut rng = Rng(0x0bad_cafe_dead_beef);
    for case in 0..12 {
        let b = body(&mut rng, case);
        let centre = b.particles.center_of_mass() + rng.vector(0.2);
        let radius = 0.05 + rng.next().abs();
        let mut forces = UserForces::new(&b.particles);
        forces
            .add_radial_force(&b.particles, centre, radius, 100.0)
            .unwrap();
        for (i, (x, f)) in b
            .particles
            .positions()
            .iter()
            .zip(forces.forces())
            .enumerate()
        {
            let d = x - centre;
            if d.norm() >= radius {
                assert_eq!(*f, Vector3::zeros(), "case {case}: particle {i} outside");
            } else {
                assert!(f.dot(&d) >= 0.0, "case {case}: particle {i} pulled inwards");
                assert!(f.cross(&d).norm() <= 1e-4 * f.norm() * d.norm());
            }
        }
    }
}

#[test]
fn bad_forces_are_typed_errors_and_change_nothing() {
    let mut rng = Rng(42);
    let b = body(&mut rng, 1);
    let mut forces = UserForces::new(&b.particles);
    let nan = Vector3::new(f32::NAN, 0.0, 0.0);
    assert!(matches!(
        forces.add_force_at_point(&b.particles, &b.tetrahedra, nan, Vector3::zeros()),
        Err(StateError::NonFinite { what: "force", .. })
    ));
    assert!(matches!(
        forces.add_force_at_point(&b.particles, &b.tetrahedra, Vector3::x(), nan),
        Err(StateError::NonFinite { what: "point", .. })
    ));
    assert!(matches!(
        forces.add_radial_force(&b.particles, Vector3::zeros(), -1.0, 1.0),
        Err(StateError::BadParameter { what: "radius", .. })
    ));
    // Adding the largest force again and again overflows one particle's sum at some point:
    // that add is rejected whole.
    let huge = Vector3::new(f32::MAX, 0.0, 0.0);
    let mut rejected = false;
    for _ in 0..10_000 {
        let kept = forces.clone();
        if let Err(e) = forces.add_force(&b.particles, huge) {
            assert!(matches!(e, StateError::NonFinite { what: "force", .. }));
            assert_eq!(
                forces, kept,
                "a rejected force leaves the others as they were"
            );
            rejected = true;
            break;
        }
    }
    assert!(rejected, "a sum beyond f32::MAX must be rejected");
    let other = body(&mut rng, 2);
    if other.particles.len() != b.particles.len() {
        let mut wrong = UserForces::new(&other.particles);
        assert!(matches!(
            wrong.add_force(&b.particles, Vector3::x()),
            Err(StateError::LengthMismatch { .. })
        ));
    }
    assert!(matches!(
        MaterialPoint::new(&b.tetrahedra, b.tetrahedra.len(), [0.25; 4]),
        Err(StateError::TetrahedronOutOfRange { .. })
    ));
    assert!(matches!(
        MaterialPoint::new(&b.tetrahedra, 0, [0.5, 0.5, 0.5, -0.5]),
        Err(StateError::BadBarycentric { .. })
    ));
}
