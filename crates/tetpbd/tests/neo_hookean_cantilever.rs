//! A slender cantilever of the Neo-Hookean material against Euler–Bernoulli, under mesh
//! refinement (slow: `#[ignore]`, run with `--ignored` in release).

mod common;

use hecs::World;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    Activation, DeformationDamping, Material, NeoHookeanMaterial, Particles, SoftBodyBuilder,
    Solver, SolverSettings, Tetrahedra,
};

/// Beam: 1 m long along x, 0.1 m square, clamped (pinned) at x = −0.5 m, density 1000 kg/m³,
/// `E = 1e5 Pa`, `ν = 0.3`, under a gravity `g` small enough for the linear regime: the
/// Euler–Bernoulli tip deflection is `q L⁴ / (8 E I) = 1.5 ρ g L⁴ / (E a²)`.
const G: f32 = 0.01;

fn tip_deflection(cells: [u32; 3]) -> (f64, u32) {
    let mesh = box_grid(Vector3::new(1.0, 0.1, 0.1), cells, CellSplit::Six).unwrap();
    let clamped: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].x < -0.499)
        .collect();
    let tip: Vec<usize> = (0..mesh.vertices.len())
        .filter(|&i| mesh.vertices[i].x > 0.499)
        .collect();
    let material = Material::new(1e5, 0.3).unwrap();
    let body = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .material(material)
        .pinned(clamped);
    let mut world = World::new();
    let e = body.build().unwrap().spawn(&mut world);
    *world.get::<&mut Activation>(e).unwrap() = Activation::never_sleeps();
    world
        .insert_one(e, DeformationDamping::new(2.0).unwrap())
        .unwrap();
    // Four times the substeps stability needs: converged (the steady state's bias shrinks with h²).
    let h = world
        .get::<&NeoHookeanMaterial>(e)
        .unwrap()
        .max_stable_substep(
            &world.get::<&Tetrahedra>(e).unwrap(),
            &world.get::<&Particles>(e).unwrap(),
        );
    let substeps = 4 * ((1.0 / 60.0 / h).ceil() as u32).max(10);
    let settings = SolverSettings {
        gravity: Vector3::new(0.0, -G, 0.0),
        substeps,
        ..Default::default()
    };
    let mut solver = Solver::new(settings).unwrap();
    for _ in 0..1200 {
        solver.step(&mut world).unwrap();
    }
    let p = world.get::<&Particles>(e).unwrap();
    let drop = tip
        .iter()
        .map(|&i| f64::from(p.rest_positions()[i].y - p.positions()[i].y))
        .sum::<f64>()
        / tip.len() as f64;
    (drop, substeps)
}

/// Linear tetrahedra are far too stiff in bending with one or two cells through the
/// thickness (−94 %, −79 %); at four the tip is within 20 % of Euler–Bernoulli (measured
/// +16 %, softer: the XPBD steady-state bias and shear). The 3 % of a converged FEM beam is not
/// reached at these resolutions (docs/decisions/neo-hookean-material.md).
#[test]
#[ignore = "slow: run in release with --ignored"]
fn cantilever_tip_approaches_euler_bernoulli_under_refinement() {
    let (rho, l, a, e) = (1000.0, 1.0, 0.1, 1e5);
    let exact = 1.5 * rho * f64::from(G) * l * l * l * l / (e * a * a);
    let mut errors = Vec::new();
    for cells in [[10, 1, 1], [20, 2, 2], [40, 4, 4]] {
        let (tip, substeps) = tip_deflection(cells);
        let err = (tip - exact) / exact;
        eprintln!("{cells:?} ({substeps} substeps): tip {tip:.6} m, Euler–Bernoulli {exact:.6} m, error {:.2} %", 100.0 * err);
        errors.push(err.abs());
    }
    assert!(
        errors[2] < errors[1] && errors[1] < errors[0],
        "no convergence: {errors:?}"
    );
    assert!(errors[2] < 0.2, "finest error {:.2} %", 100.0 * errors[2]);
}
