//! Bodies of the Neo-Hookean material in motion: inverted and crushed starts recover, the
//! energy never grows without gravity, the sag does not depend on the mesh resolution, the
//! damping's decay does not depend on the substeps, and a resting body falls asleep.

mod common;

use common::{cube, deform, top, Deformation};
use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    is_sleeping, Activation, Material, NeoHookeanMaterial, Particles, SoftBodyBuilder, Solver,
    SolverSettings, Tetrahedra,
};

/// The substeps (at least `at_least`) the body's material needs to be stable at 60 Hz.
fn substeps_for(world: &World, e: Entity, at_least: u32) -> u32 {
    let m = world.get::<&NeoHookeanMaterial>(e).unwrap();
    let h = m.max_stable_substep(
        &world.get::<&Tetrahedra>(e).unwrap(),
        &world.get::<&Particles>(e).unwrap(),
    );
    ((1.0 / 60.0 / h).ceil() as u32).max(at_least)
}

fn awake(world: &mut World, e: Entity) {
    *world.get::<&mut Activation>(e).unwrap() = Activation::never_sleeps();
}

/// Kinetic plus the material's elastic energy, J.
fn energy(world: &World, e: Entity) -> f64 {
    let p = world.get::<&Particles>(e).unwrap();
    let m = world.get::<&NeoHookeanMaterial>(e).unwrap();
    let t = world.get::<&Tetrahedra>(e).unwrap();
    f64::from(p.kinetic_energy()) + m.elastic_energy(&t, p.positions())
}

#[test]
fn inverted_and_crushed_material_bodies_recover() {
    let starts = [
        Deformation::Mirrored,
        Deformation::Flattened,
        Deformation::Sheared,
        Deformation::Scrambled,
    ];
    for material in [
        Material::JELLY,
        Material::FOAM,
        Material::new(2e5, 0.45).unwrap(),
    ] {
        for (cells, split) in [(2, CellSplit::Six), (3, CellSplit::Five)] {
            for start in starts {
                let mut world = World::new();
                let body = SoftBodyBuilder::new(cube(cells, split)).material(material);
                let e = body.build().unwrap().spawn(&mut world);
                awake(&mut world, e);
                deform(&mut world, e, start);
                let substeps = substeps_for(&world, e, 10);
                let settings = SolverSettings {
                    gravity: Vector3::zeros(),
                    substeps,
                    diagnostics: tetpbd::DiagnosticSettings {
                        measure_error: true,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                let mut solver = Solver::new(settings).unwrap();
                let mut inverted = usize::MAX;
                let e0 = energy(&world, e);
                let mut highest = e0;
                for _ in 0..600 {
                    inverted = solver.step(&mut world).unwrap().inverted.unwrap();
                    highest = highest.max(energy(&world, e));
                }
                let p = world.get::<&Particles>(e).unwrap();
                let t = world.get::<&Tetrahedra>(e).unwrap();
                let volume: f32 = (0..t.len())
                    .map(|k| t.volume_at(k, p.positions()).abs())
                    .sum();
                let fastest = p.velocities().iter().map(|v| v.norm()).fold(0.0, f32::max);
                eprintln!("E {} {cells} cells {start:?}: {inverted} inverted, volume {volume:.4} m³, fastest {fastest:.2e} m/s", material.young_modulus());
                assert_eq!(inverted, 0, "{start:?}: tetrahedra still inverted");
                assert!((volume - 1.0).abs() < 0.1, "{start:?}: volume {volume}");
                // The start's elastic energy may become a wobble (the material's damping is
                // light), never more than it.
                assert!(
                    highest <= e0 * 1.001,
                    "{start:?}: energy grew from {e0} J to {highest} J"
                );
            }
        }
    }
}

#[test]
fn material_energy_never_grows_without_gravity() {
    let mut rng = common::Rng::new(272);
    for case in 0..6 {
        let material =
            Material::new(rng.range(2e3, 2e5) as f32, rng.range(0.0, 0.49) as f32).unwrap();
        let mut world = World::new();
        let cells = 2 + case % 2;
        let e = SoftBodyBuilder::new(cube(cells, CellSplit::Six))
            .material(material)
            .build()
            .unwrap()
            .spawn(&mut world);
        awake(&mut world, e);
        let start = [Deformation::Strained, Deformation::Sheared][case as usize % 2];
        deform(&mut world, e, start);
        // A spin and a vibration on top.
        {
            let mut p = world.get::<&mut Particles>(e).unwrap();
            for i in 0..p.len() {
                let x = p.positions()[i];
                let v = Vector3::new(0.3, -0.2, 1.0).cross(&x) + x * rng.range(-1.0, 1.0) as f32;
                p.set_velocity(i, v).unwrap();
            }
        }
        let substeps = substeps_for(&world, e, 10);
        let settings = SolverSettings {
            gravity: Vector3::zeros(),
            substeps,
            ..Default::default()
        };
        let mut solver = Solver::new(settings).unwrap();
        let e0 = energy(&world, e);
        let mut highest = e0;
        for _ in 0..300 {
            solver.step(&mut world).unwrap();
            highest = highest.max(energy(&world, e));
        }
        eprintln!(
            "case {case}: E {:.0} Pa ν {:.2}, energy {e0:.4} J, highest {highest:.4} J",
            material.young_modulus(),
            material.poisson_ratio()
        );
        assert!(
            highest <= e0 * 1.001,
            "case {case}: energy grew from {e0} J to {highest} J"
        );
    }
}

/// Hangs a block of `cells` by its top face and lets it settle: the centre of mass's drop, m.
fn sag(cells: u32, material: Material, seed_families: bool) -> f32 {
    let mesh = box_grid(Vector3::new(0.2, 0.2, 0.2), [cells; 3], CellSplit::Six).unwrap();
    let pins: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y > 0.099)
        .collect();
    let mut builder = SoftBodyBuilder::new(mesh).density(1000.0).pinned(pins);
    builder = if seed_families {
        builder.edges(1e-4).volume(0.0)
    } else {
        builder.material(material)
    };
    let mut world = World::new();
    let e = builder.build().unwrap().spawn(&mut world);
    awake(&mut world, e);
    world
        .insert_one(e, tetpbd::DeformationDamping::new(20.0).unwrap())
        .unwrap();
    let substeps = if seed_families {
        40
    } else {
        4 * substeps_for(&world, e, 10)
    };
    let mut solver = Solver::new(SolverSettings {
        substeps,
        ..Default::default()
    })
    .unwrap();
    let y0 = world.get::<&Particles>(e).unwrap().center_of_mass().y;
    for _ in 0..240 {
        solver.step(&mut world).unwrap();
    }
    let y1 = world.get::<&Particles>(e).unwrap().center_of_mass().y;
    y0 - y1
}

#[test]
fn sag_does_not_depend_on_the_resolution() {
    // ν ≤ 0.25: linear tetrahedra lock near incompressibility (ν → 0.5), where the coarse
    // meshes are stiffer than the fine ones (a property of the elements, not of the solver).
    for material in [
        Material::new(5e3, 0.25).unwrap(),
        Material::new(2e4, 0.1).unwrap(),
    ] {
        let sags: Vec<f32> = [4, 6, 8].iter().map(|&c| sag(c, material, false)).collect();
        let seed: Vec<f32> = [4, 6, 8].iter().map(|&c| sag(c, material, true)).collect();
        let (lo, hi) = sags
            .iter()
            .fold((f32::MAX, 0.0f32), |(l, h), &s| (l.min(s), h.max(s)));
        eprintln!(
            "E {} Pa: sag {sags:?} m (spread {:.2} %); seed edges 1e-4 m/N: {seed:?} m",
            material.young_modulus(),
            100.0 * (hi - lo) / hi
        );
        assert!(lo > 0.0 && (hi - lo) < 0.05 * hi, "sags {sags:?}");
    }
}

/// The vibration energy left after 0.5 s of a jelly cube released from a stretch, at `substeps`.
fn left_after_wobble(substeps: u32, material: Material) -> f64 {
    let mut world = World::new();
    let body = SoftBodyBuilder::new(cube(3, CellSplit::Six))
        .scale(0.2)
        .material(material);
    let e = body.build().unwrap().spawn(&mut world);
    awake(&mut world, e);
    common::deform_with(&mut world, e, |_, x| {
        Vector3::new(x.x * 1.2, x.y / 1.1, x.z / 1.1)
    });
    let settings = SolverSettings {
        gravity: Vector3::zeros(),
        substeps,
        ..Default::default()
    };
    let mut solver = Solver::new(settings).unwrap();
    let e0 = energy(&world, e);
    for _ in 0..30 {
        solver.step(&mut world).unwrap();
    }
    energy(&world, e) / e0
}

/// The material's damping takes the same share of the energy whatever the substeps: the
/// energy left with damping over the energy left without (which holds XPBD's own numerical
/// dissipation, smaller at more substeps). Near rest the damping acts along the constraints'
/// gradients, the volume change, so a wobble that is mostly shear keeps most of its energy:
/// combine with `DeformationDamping` for a dead jelly.
#[test]
fn jelly_settles_at_a_rate_independent_of_substeps() {
    let undamped = Material::JELLY.with_damping(0.0).unwrap();
    let damped = Material::JELLY.with_damping(0.02).unwrap();
    let mut shares = Vec::new();
    for substeps in [20, 40, 80] {
        let (with, without) = (
            left_after_wobble(substeps, damped),
            left_after_wobble(substeps, undamped),
        );
        eprintln!(
            "{substeps} substeps: energy left after 0.5 s {with:.4} damped, {without:.4} undamped"
        );
        shares.push(with / without);
    }
    eprintln!("damping's share {shares:?}");
    let (lo, hi) = shares
        .iter()
        .fold((f64::MAX, 0.0f64), |(l, h), &s| (l.min(s), h.max(s)));
    assert!(hi < 0.95, "the damping takes nothing: {shares:?}");
    assert!(
        hi - lo < 0.05,
        "the damping's share {shares:?} depends on the substeps"
    );
}

#[test]
fn resting_material_body_falls_asleep() {
    let mesh = cube(2, CellSplit::Six);
    let pins = top(&mesh);
    let mut world = World::new();
    let e = SoftBodyBuilder::new(mesh)
        .scale(0.2)
        .pinned(pins.clone())
        .material(Material::SOFT_TISSUE)
        .build()
        .unwrap()
        .spawn(&mut world);
    let mut solver = Solver::new(SolverSettings {
        substeps: substeps_for(&world, e, 10),
        ..Default::default()
    })
    .unwrap();
    let mut asleep_at = None;
    for frame in 0..600 {
        solver.step(&mut world).unwrap();
        if asleep_at.is_none() && is_sleeping(&world, e) {
            asleep_at = Some(frame);
        }
    }
    assert!(asleep_at.is_some(), "the hanging body never fell asleep");
    assert!(is_sleeping(&world, e));
}
