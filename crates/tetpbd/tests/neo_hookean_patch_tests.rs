//! The Neo-Hookean material against its analytic response: a body at rest stays there, a
//! bar under uniform tension stretches as the Neo-Hookean law says and contracts laterally by
//! Poisson's ratio, a cube under shear tractions shears as the law says, and homogeneous
//! stretch and shear are reproduced inside a patch.

mod common;

use common::Rng;
use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    Activation, DeformationDamping, Material, NeoHookeanMaterial, Particles, SoftBodyBuilder,
    Solver, SolverSettings, Surface, Tetrahedra, UserForces,
};

fn no_gravity() -> SolverSettings {
    SolverSettings {
        gravity: Vector3::zeros(),
        ..Default::default()
    }
}

/// Spawns a body awake for good (these tests watch its motion).
fn spawn(world: &mut World, builder: SoftBodyBuilder, damping: f32) -> Entity {
    let e = builder.build().unwrap().spawn(world);
    *world.get::<&mut Activation>(e).unwrap() = Activation::never_sleeps();
    if damping > 0.0 {
        world
            .insert_one(e, DeformationDamping::new(damping).unwrap())
            .unwrap();
    }
    e
}

/// The substeps (at least `at_least`) the body's material needs to be stable at 60 Hz
/// ([`NeoHookeanMaterial::max_stable_substep`]).
fn substeps_for(world: &World, e: Entity, at_least: u32) -> u32 {
    let m = world.get::<&NeoHookeanMaterial>(e).unwrap();
    let h = m.max_stable_substep(
        &world.get::<&Tetrahedra>(e).unwrap(),
        &world.get::<&Particles>(e).unwrap(),
    );
    ((1.0 / 60.0 / h).ceil() as u32).max(at_least)
}

/// Largest distance of any particle from where it started.
fn largest_move(p: &Particles, start: &[Vector3<f32>]) -> f32 {
    p.positions()
        .iter()
        .zip(start)
        .map(|(x, s)| (x - s).norm())
        .fold(0.0, f32::max)
}

/// Rubber on a 1 cm mesh moves by rounding (f32 positions, amplified by its stiffness)
/// well below 0.1 % of its size.
#[test]
fn material_body_at_rest_stays_at_rest() {
    let presets = [
        Material::RUBBER,
        Material::JELLY,
        Material::SOFT_TISSUE,
        Material::FOAM,
    ];
    for (k, material) in presets.into_iter().enumerate() {
        for (cells, split, size) in [
            (1, CellSplit::Six, 0.1),
            (3, CellSplit::Five, 1.0),
            (2, CellSplit::Six, 0.02),
        ] {
            let mesh = box_grid(
                Vector3::new(size, size * 0.7, size * 1.3),
                [cells, cells, cells + 1],
                split,
            )
            .unwrap();
            let mut world = World::new();
            let e = spawn(
                &mut world,
                SoftBodyBuilder::new(mesh).material(material),
                0.0,
            );
            let start = world.get::<&Particles>(e).unwrap().positions().to_vec();
            let substeps = substeps_for(&world, e, 10);
            let mut solver = Solver::new(SolverSettings {
                substeps,
                ..no_gravity()
            })
            .unwrap();
            for _ in 0..30 {
                solver.step(&mut world).unwrap();
            }
            let p = world.get::<&Particles>(e).unwrap();
            let moved = largest_move(&p, &start);
            assert!(
                moved < 1e-3 * size,
                "preset {k}, {cells} cells of {size} m: moved {moved} m at rest"
            );
        }
    }
}

/// The axial first Piola–Kirchhoff stress (Pa) of a Neo-Hookean bar stretched by `s` with
/// free lateral faces, and its lateral stretch: `P₂₂ = 0` gives `t² = (γ − μ/(λ' s))/s`, and
/// then `P₁₁ = μ (s − t²/s)`.
fn uniaxial(material: &Material, s: f64) -> (f64, f64) {
    let (mu, lambda) = material.lame();
    let (mu, lp) = (f64::from(mu), f64::from(lambda) + f64::from(mu));
    let gamma = 1.0 + mu / lp;
    let t2 = (gamma - mu / (lp * s)) / s;
    (mu * (s - t2 / s), t2.sqrt())
}

/// A free bar of `cells` along x, 1 m × 0.2 m × 0.2 m, pulled at both ends by a uniform
/// traction `traction` (Pa; consistent nodal forces of the end faces' triangles), settled with
/// the material's damping and deformation damping. Returns the axial stretch between the
/// planes x = ∓0.2 m and the lateral stretch at x = 0, measured once the bar is at rest.
fn pulled_bar(material: Material, cells: [u32; 3], traction: f32, substeps: u32) -> (f64, f64) {
    let size = Vector3::new(1.0, 0.2, 0.2);
    let mesh = box_grid(size, cells, CellSplit::Six).unwrap();
    let mut world = World::new();
    let e = spawn(
        &mut world,
        SoftBodyBuilder::new(mesh)
            .density(1000.0)
            .material(material),
        20.0,
    );
    {
        let p = world.get::<&Particles>(e).unwrap();
        let surface = world.get::<&Surface>(e).unwrap();
        let tets = world.get::<&tetpbd::Tetrahedra>(e).unwrap();
        let mut forces = UserForces::new(&p);
        for tri in surface.triangles() {
            let x = tri.map(|i| p.positions()[i as usize]);
            let end = x[0].x;
            if x.iter()
                .all(|v| (v.x - end).abs() < 1e-6 && (end.abs() - 0.5).abs() < 1e-6)
            {
                let area = 0.5 * (x[1] - x[0]).cross(&(x[2] - x[0])).norm();
                let f = Vector3::new(end.signum() * traction * area / 3.0, 0.0, 0.0);
                for (&i, v) in tri.iter().zip(&x) {
                    forces
                        .add_force_at_point(&p, &tets, f, *v)
                        .unwrap_or_else(|_| panic!("corner {i}"));
                }
            }
        }
        drop((p, surface, tets));
        world.insert_one(e, forces).unwrap();
    }
    let mut solver = Solver::new(SolverSettings {
        substeps,
        ..no_gravity()
    })
    .unwrap();
    let measure = |p: &Particles| {
        let x = p.positions();
        let r = p.rest_positions();
        let plane = |px: f32| (0..x.len()).filter(move |&i| (r[i].x - px).abs() < 1e-4);
        let mean_x =
            |px: f32| plane(px).map(|i| f64::from(x[i].x)).sum::<f64>() / plane(px).count() as f64;
        let axial = (mean_x(0.2) - mean_x(-0.2)) / 0.4;
        let side = |sign: f32| {
            let n = plane(0.0).filter(|&i| r[i].y * sign > 0.099).count() as f64;
            plane(0.0)
                .filter(|&i| r[i].y * sign > 0.099)
                .map(|i| f64::from(x[i].y))
                .sum::<f64>()
                / n
        };
        (axial, (side(1.0) - side(-1.0)) / 0.2)
    };
    let mut last = (0.0, 0.0);
    for frame in 0..600 {
        solver.step(&mut world).unwrap();
        if frame % 60 == 59 {
            let now = measure(&world.get::<&Particles>(e).unwrap());
            if (now.0 - last.0).abs() < 1e-6 && (now.1 - last.1).abs() < 1e-6 {
                return now;
            }
            last = now;
        }
    }
    last
}

#[test]
fn bar_under_uniform_tension_stretches_as_neo_hookean() {
    let mut rng = Rng::new(270);
    for _ in 0..4 {
        let poisson = rng.range(0.0, 0.45) as f32;
        let material = Material::new(rng.range(2e4, 2e5) as f32, poisson).unwrap();
        // A traction giving a stretch between 5 and 30 %.
        let strain = rng.range(0.05, 0.3);
        let (traction, _) = uniaxial(&material, 1.0 + strain);
        let (s, t) = pulled_bar(material, [10, 2, 2], traction as f32, 40);
        let (expected, lateral) = uniaxial(&material, s);
        let err = (expected - traction).abs() / traction;
        eprintln!("ν {poisson:.3}, strain {strain:.3}: stretch {s:.5}, stress at it {expected:.1} Pa vs {traction:.1} Pa ({:.3} %), lateral {t:.5} vs {lateral:.5}", 100.0 * err);
        assert!(
            err < 0.01,
            "stress {expected} Pa at the measured stretch {s}, traction {traction} Pa"
        );
        assert!(
            (t - lateral).abs() < 0.01 * (1.0 - lateral).abs().max(0.01),
            "lateral stretch {t} vs {lateral}"
        );
    }
}

#[test]
fn bar_in_small_tension_contracts_laterally_by_poisson_ratio() {
    for poisson in [0.1f32, 0.25, 0.35, 0.45, 0.49] {
        let material = Material::new(1e5, poisson).unwrap();
        let (traction, _) = uniaxial(&material, 1.005);
        let (s, t) = pulled_bar(material, [10, 2, 2], traction as f32, 40);
        let measured = (1.0 - t) / (s - 1.0);
        eprintln!(
            "ν {poisson}: axial strain {:.5}, lateral {:.5}, ratio {measured:.4}",
            s - 1.0,
            1.0 - t
        );
        assert!(
            (measured - f64::from(poisson)).abs() < 0.05 * f64::from(poisson),
            "ν {poisson}: measured {measured}"
        );
    }
}

/// The first Piola–Kirchhoff stress (Pa) of the material at `f`:
/// `P = μ F + λ' (det F − γ) cof F`, `λ' = λ + μ`, `γ = 1 + μ/λ'`.
fn piola(material: &Material, f: &nalgebra::Matrix3<f64>) -> nalgebra::Matrix3<f64> {
    let (mu, lambda) = material.lame();
    let (mu, lp) = (f64::from(mu), f64::from(lambda) + f64::from(mu));
    let j = f.determinant();
    let cof = j * f.try_inverse().unwrap().transpose();
    f * mu + cof * (lp * (j - (1.0 + mu / lp)))
}

/// A cube held by its mid-plane `y = 0` (which simple shear along x leaves in place) and
/// loaded on its faces by the tractions `P N` of simple shear `F = I + g eₓ e_yᵀ` (consistent
/// nodal forces of each face triangle): it settles on that shear, so the stress at the
/// measured deformation (its least-squares fit over every particle) is the traction applied,
/// as the Neo-Hookean law says, within 1 %.
#[test]
fn cube_under_shear_tractions_shears_as_neo_hookean() {
    let mut rng = Rng::new(272);
    for _ in 0..3 {
        let material =
            Material::new(rng.range(2e4, 2e5) as f32, rng.range(0.0, 0.45) as f32).unwrap();
        let g = rng.range(0.05, 0.25);
        let mut target = nalgebra::Matrix3::<f64>::identity();
        target[(0, 1)] = g;
        let traction = piola(&material, &target);
        let mesh = box_grid(Vector3::new(0.4, 0.4, 0.4), [4, 4, 4], CellSplit::Six).unwrap();
        let mid: Vec<u32> = (0..mesh.vertices.len() as u32)
            .filter(|&i| mesh.vertices[i as usize].y.abs() < 1e-4)
            .collect();
        let mut world = World::new();
        let e = spawn(
            &mut world,
            SoftBodyBuilder::new(mesh)
                .density(1000.0)
                .material(material)
                .pinned(mid),
            20.0,
        );
        {
            let p = world.get::<&Particles>(e).unwrap();
            let surface = world.get::<&Surface>(e).unwrap();
            let tets = world.get::<&Tetrahedra>(e).unwrap();
            let mut forces = UserForces::new(&p);
            for tri in surface.triangles() {
                let x = tri.map(|i| p.positions()[i as usize]);
                let n = (x[1] - x[0]).cross(&(x[2] - x[0]));
                let area = 0.5 * n.norm();
                let f = (traction * n.normalize().cast::<f64>() * f64::from(area) / 3.0).cast();
                for v in &x {
                    // A corner on the held mid-plane passes its share to the hold.
                    match forces.add_force_at_point(&p, &tets, f, *v) {
                        Ok(_) | Err(tetpbd::StateError::AllPinned) => {}
                        Err(e) => panic!("{e}"),
                    }
                }
            }
            drop((p, surface, tets));
            world.insert_one(e, forces).unwrap();
        }
        let substeps = 2 * substeps_for(&world, e, 20);
        let mut solver = Solver::new(SolverSettings {
            substeps,
            ..no_gravity()
        })
        .unwrap();
        // The least-squares deformation gradient of every particle about the centre.
        let fit = |p: &Particles| {
            let n = p.len() as f64;
            let c = p
                .positions()
                .iter()
                .map(|x| x.cast::<f64>())
                .sum::<Vector3<f64>>()
                / n;
            let c0 = p
                .rest_positions()
                .iter()
                .map(|x| x.cast::<f64>())
                .sum::<Vector3<f64>>()
                / n;
            let (mut a, mut b) = (nalgebra::Matrix3::zeros(), nalgebra::Matrix3::zeros());
            for (x, r) in p.positions().iter().zip(p.rest_positions()) {
                let (x, r) = (x.cast::<f64>() - c, r.cast::<f64>() - c0);
                a += x * r.transpose();
                b += r * r.transpose();
            }
            a * b.try_inverse().unwrap()
        };
        let mut last = nalgebra::Matrix3::zeros();
        for frame in 0..900 {
            solver.step(&mut world).unwrap();
            if frame % 60 == 59 {
                let now = fit(&world.get::<&Particles>(e).unwrap());
                if (now - last).norm() < 1e-7 {
                    break;
                }
                last = now;
            }
        }
        let measured = fit(&world.get::<&Particles>(e).unwrap());
        let stress = piola(&material, &measured);
        let err = (stress - traction).norm() / traction.norm();
        let off = (measured - target).norm() / g;
        eprintln!(
            "E {:.0} Pa, ν {:.3}, shear {g:.3}: stress at the measured F off the traction by {:.3} %, F off by {:.3} % of the shear",
            material.young_modulus(),
            material.poisson_ratio(),
            100.0 * err,
            100.0 * off
        );
        assert!(
            err < 0.01,
            "stress {stress} at the measured {measured}, traction {traction}"
        );
    }
}

/// A cube whose boundary particles are pinned on a homogeneous deformation `F` (stretch or
/// shear), its inside started off it: the inside settles onto `F`, the patch test of the
/// discretisation (a homogeneous stress has no divergence).
#[test]
fn pinned_patch_settles_on_homogeneous_stretch_and_shear() {
    let mut rng = Rng::new(271);
    let cases: [(&str, nalgebra::Matrix3<f32>); 3] = [
        (
            "stretch",
            nalgebra::Matrix3::from_diagonal(&Vector3::new(1.3, 0.9, 1.0)),
        ),
        (
            "shear",
            nalgebra::Matrix3::new(1.0, 0.4, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        ),
        (
            "compress and shear",
            nalgebra::Matrix3::new(0.8, 0.0, 0.2, 0.1, 0.9, 0.0, 0.0, 0.0, 0.85),
        ),
    ];
    for (what, f) in cases {
        for material in [
            Material::JELLY,
            Material::FOAM,
            Material::new(1e5, 0.3).unwrap(),
        ] {
            let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [4, 4, 4], CellSplit::Five).unwrap();
            let boundary: Vec<u32> = (0..mesh.vertices.len() as u32)
                .filter(|&i| mesh.vertices[i as usize].abs().max() > 0.49)
                .collect();
            let mut world = World::new();
            let e = spawn(
                &mut world,
                SoftBodyBuilder::new(mesh)
                    .material(material)
                    .pinned(boundary),
                20.0,
            );
            common::deform_with(&mut world, e, |_, x| {
                f * x + rng.vec(0.02).cast::<f32>() * (x.abs().max() < 0.49) as i32 as f32
            });
            // Converged: four times the substeps stability needs.
            let substeps = 4 * substeps_for(&world, e, 10);
            let mut solver = Solver::new(SolverSettings {
                substeps,
                ..no_gravity()
            })
            .unwrap();
            for _ in 0..300 {
                solver.step(&mut world).unwrap();
            }
            let p = world.get::<&Particles>(e).unwrap();
            let worst = (0..p.len())
                .map(|i| (p.positions()[i] - f * p.rest_positions()[i]).norm())
                .fold(0.0f32, f32::max);
            let scale = (f - nalgebra::Matrix3::identity()).norm() * 0.25;
            eprintln!("{what}, E {}: inside off the homogeneous field by {worst:.2e} m ({:.3} % of the deformation)", material.young_modulus(), 100.0 * worst / scale);
            assert!(worst < 0.01 * scale, "{what}: inside off by {worst} m");
        }
    }
}

#[test]
fn bad_materials_are_typed_errors_naming_the_value() {
    use tetpbd::MaterialError::*;
    for (e, nu) in [(1e5, 0.5), (1e5, 0.7), (1e5, -0.1), (1e5, f32::NAN)] {
        assert!(
            matches!(Material::new(e, nu), Err(BadPoissonRatio { value }) if value.to_bits() == nu.to_bits())
        );
    }
    for e in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert!(
            matches!(Material::new(e, 0.3), Err(BadYoungsModulus { value }) if value.to_bits() == e.to_bits())
        );
    }
    for b in [-1e-3, f32::NAN, f32::INFINITY] {
        assert!(
            matches!(Material::JELLY.with_damping(b), Err(BadDamping { value }) if value.to_bits() == b.to_bits())
        );
    }
    let msg = Material::new(1e5, 0.5).unwrap_err().to_string();
    assert!(msg.contains("0.5"), "{msg}");
}

/// A material and a body's material component round-trip through serde; a serialized
/// material out of range is rejected with the same typed error.
#[cfg(feature = "serde")]
#[test]
fn material_round_trips_through_serde_and_stays_validated() {
    let m = Material::JELLY;
    let json = serde_json::to_string(&m).unwrap();
    assert_eq!(serde_json::from_str::<Material>(&json).unwrap(), m);
    let bad = json.replace("0.45", "0.5");
    let err = serde_json::from_str::<Material>(&bad)
        .unwrap_err()
        .to_string();
    assert!(err.contains("Poisson"), "{err}");
    let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [2, 2, 2], CellSplit::Six).unwrap();
    let body = SoftBodyBuilder::new(mesh).material(m).build().unwrap();
    let c = body.material.unwrap();
    let back: NeoHookeanMaterial =
        serde_json::from_str(&serde_json::to_string(&c).unwrap()).unwrap();
    assert_eq!(back, c);
}
