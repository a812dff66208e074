//! The summary's section on the material scenes e and f: what both engines are given, which
//! reference the errors are measured against, and the converged answers side by side.

use std::fmt::Write as _;

use tetpbd::{NeoHookeanMaterial, Particles, Tetrahedra};

use crate::answers::euler_bernoulli_tip;
use crate::engines::{material_body, Model};
use crate::report::RefInfo;
use crate::scenes::{Scene, DT};

/// tetpbd's largest stable substep for the scene's body, s (see
/// [`NeoHookeanMaterial::max_stable_substep`]).
fn stable_substep(scene: &Scene) -> Option<f32> {
    let mut world = tetpbd::hecs::World::new();
    let e = material_body(scene).spawn(&mut world);
    let m = world.get::<&NeoHookeanMaterial>(e).ok()?;
    let t = world.get::<&Tetrahedra>(e).ok()?;
    let p = world.get::<&Particles>(e).ok()?;
    Some(m.max_stable_substep(&t, &p))
}

/// Appends the section to `s` (nothing when no scene has a material).
pub fn section(s: &mut String, scenes: &[Scene], references: &[RefInfo]) {
    let material: Vec<&Scene> = scenes.iter().filter(|sc| sc.material.is_some()).collect();
    let Some(first) = material.first() else {
        return;
    };
    let m = first.material.expect("filtered on material");
    let _ = writeln!(
        s,
        "## Material scenes e) and f)\n\n![material scenes](materials.png)\n"
    );
    let _ = writeln!(s, "Scenes e and f are scenes a and b (same mesh, pins, start, gravity, density and lumped masses, and the beam's linear damping; the squash's linear damping is raised from 2 to 10 1/s, in both engines, so that its references settle nearer to convergence) with the body made of one elastic material, the same in both engines: Young's modulus E = {:e} Pa, Poisson's ratio ν = {}, density {} kg/m³. tetpbd: `SoftBodyBuilder::material(Material::new(E, ν))`, the stable Neo-Hookean material (two coupled XPBD constraints per tetrahedron, see `docs/decisions/neo-hookean-material.md`), no material damping and no other constraint family, `substeps × iterations` as in scenes a and b. rapier: its `NeoHookean` and `Corotational` cell models with the same E and ν (`SoftBodyMaterial::young_modulus`, `poisson_ratio`; elastic damping ratio 1, rapier's default), on its `Constraints` and `Fem` solvers, `num_solver_iterations` = substeps. The two engines' Neo-Hookean energies are not the same formula (tetpbd's is the stable Neo-Hookean of Macklin & Müller with λ' = λ + μ, chosen so that both share linear elasticity with E and ν at small strain), and their damping differs (none in tetpbd's material, rapier's elastic damping ratio 1); the beam's static answer does not depend on damping.\n", m.young_modulus(), m.poisson_ratio(), first.density);
    let _ = writeln!(s, "**Reference and error.** Each model is measured against its own converged reference: the same engine, model and mesh at one iteration per substep with the substeps doubled until the answer stops changing (tetpbd's material: its own f32 solver from 32 up to 2048 substeps, there is no f64 stepper for it; rapier: its own f32 solver up to 128), as for the soft models of scenes a and b (see 'Convergence of the references'). The error is the same metric as in scenes a and b: the largest particle distance to the reference relative to the body size, after the last frame for the beam and over every frame after rigid alignment for the squash. The Euler–Bernoulli deflection is not used as the reference: it is linear theory for a slender beam, while this beam of linear tetrahedra with two cells through its thickness is far stiffer in bending than the continuum (see the tip deflections below) and sags beyond the small-deflection range; an error against it would measure the mesh, not the time stepping.\n");
    if let Some(h) = stable_substep(first) {
        let _ = writeln!(s, "tetpbd's `NeoHookeanMaterial::max_stable_substep` for this material on these meshes (0.1 L/c, L from the smallest rest altitude): {:.2e} s, i.e. {} substeps per 1/60 s frame; runs with fewer substeps than about a third of that vibrate by themselves (the material's shear stiffness is integrated explicitly, see the decision record), which is where tetpbd's low-substep points lose.\n", h, (DT / h).ceil());
    }
    let _ = writeln!(s, "**Converged answers side by side** (how far the two engines' materials agree once the time-stepping error is gone):\n");
    let _ = writeln!(s, "| scene | model | reference | beam tip drop, m | deviation from tetpbd's reference / size |\n|---|---|---|---:|---:|");
    for sc in &material {
        for r in references.iter().filter(|r| r.scene == sc.name) {
            let tip = r
                .answer
                .tip_drop
                .map(|t| format!("{t:.4}"))
                .unwrap_or_else(|| "—".into());
            let gap = match (r.model, r.answer.vs_material) {
                (Model::Material, _) => "0 (itself)".to_string(),
                (_, Some(d)) => format!("{d:.2e}"),
                (_, None) => "—".into(),
            };
            let _ = writeln!(
                s,
                "| {} | {} | f32, {} substeps ({:.1e}) | {tip} | {gap} |",
                sc.name,
                r.model.label(),
                r.conv.substeps,
                r.conv.change
            );
        }
    }
    if let Some(eb) = material.iter().find_map(|sc| euler_bernoulli_tip(sc)) {
        let _ = writeln!(s, "\nEuler–Bernoulli tip deflection of the beam under its own weight at this E (linear theory, `1.5 ρ g L⁴ / (E a²)`): {eb:.3} m. With two cells of linear tetrahedra through the thickness, the tetrahedral beams of both engines are several times stiffer than that (the 1 m cantilever of the decision record, at the same aspect ratio and resolution: −79 %).\n");
    }
}
