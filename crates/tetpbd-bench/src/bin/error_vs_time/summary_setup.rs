//! The set-up part of summary.md: scenes, configurations, references, metric definitions,
//! where the two engines' models differ, and per-model detail tables.

use std::fmt::Write as _;

use crate::engines::Model;
use crate::pareto::median;
use crate::report::Row;
use crate::scenes::{Scene, SceneKind, DT};

/// Appends the set-up sections to `s`.
pub fn setup(
    s: &mut String,
    scenes: &[Scene],
    rows: &[Row],
    references: &[(&'static str, Model, u32, f32)],
) {
    let _ = writeln!(s, "## Scenes (one mesh each, handed to both engines)\n");
    for sc in scenes {
        let what = match sc.kind {
            SceneKind::HangingBeam => "2 m × 0.2 m × 0.2 m beam (`tetpbd::generators::beam`, 20×2×2 cells, six tetrahedra per cell), the vertices at x = 0 pinned, gravity −9.81 m/s², started straight and at rest; compared after the last frame (static equilibrium)",
            SceneKind::Squash => "1 m cube (`generators::box_grid`, 4×4×4 cells, six tetrahedra per cell), every vertex's y halved about the centre (50 % height, x and z unchanged), released at rest without gravity; compared over every frame",
        };
        let _ = writeln!(
            s,
            "- **{}**: {what}. {} vertices, {} tetrahedra, {} edges; density {} kg/m³ with the same lumped masses in both engines (ρ·|V|/4 per tetrahedron corner); linear damping {} 1/s in both; {} frames of {:.4} s, the first {} excluded from the timing median.",
            sc.name,
            sc.mesh.vertices.len(),
            sc.mesh.tets.len(),
            sc.edges.len(),
            sc.density,
            sc.damping,
            sc.frames,
            DT,
            sc.warmup
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(s, "## Configurations\n");
    let _ = writeln!(s, "| model | set-up | budgets (substeps×iterations) | reference substeps (last change / size), per scene |\n|---|---|---|---|");
    let mut models: Vec<Model> = Vec::new();
    for r in rows {
        if !models.contains(&r.model) {
            models.push(r.model);
        }
    }
    for m in &models {
        let mut budgets: Vec<String> = Vec::new();
        for r in rows.iter().filter(|r| r.model == *m) {
            if !budgets.contains(&r.budget()) {
                budgets.push(r.budget());
            }
        }
        let refs: Vec<String> = references
            .iter()
            .filter(|(_, rm, _, _)| rm == m)
            .map(|(sc, _, n, c)| match n {
                0 => format!("{sc}: exact (rest shape)"),
                _ => format!("{sc}: {n} ({c:.1e})"),
            })
            .collect();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} |",
            m.label(),
            m.setup(),
            budgets.join(", "),
            refs.join("; ")
        );
    }
    let _ = writeln!(s, "\nAll runs at a frame dt of 1/60 s. tetpbd: `Solver` with `substeps` substeps of `iterations` Gauss–Seidel sweeps, families in the default order (volume, vertex–face, edge), per-family |C| and inverted tetrahedra evaluated after each timed step by `tetpbd::systems::measure` (the evaluation `SolverSettings::measure_error` runs, kept out of the time). rapier: `PhysicsWorld::step` with `integration_parameters.num_solver_iterations` = substeps (its soft-body substep count), every other integration and soft-body setting at its default (one internal PGS iteration plus the soft body's 3 additional ones, impact-adaptive substeps allowed, re-sweep of strained constraints at 0.75), no collider on the body, sleeping off, built from the same vertices, tetrahedra (`cells`), masses and pinned vertices; the volume model also gets the same edge list (`unique_edges`). The `Fem` solver runs with rapier's default `SoftFemParameters` (CG tolerance 1e-5, at most 20 CG iterations, direct factorisation up to 600 degrees of freedom, which covers both meshes). rapier has no separate iteration count in this sweep. tetpbd's `max_correction_speed` safety net is off (its default).\n");
    let settings = tetpbd::SolverSettings {
        dt: DT,
        ..Default::default()
    };
    let _ = writeln!(s, "tetpbd's solver settings in every run, apart from substeps, iterations, gravity and damping set per run and scene: `{settings:?}`.\n");
    convergence(s, references);
    let _ = writeln!(s, "## Metrics\n");
    let _ = writeln!(s, "- **deviation from converged reference**: for the hard models the exact answer, the rest shape (every edge, height and volume held; rapier's 1e6 Hz springs sag by about g/ω² ≈ 2.5e-13 m); for the soft models the same model and mesh run by the same solver with one iteration and doubled substeps until the answer changes by < 1e-6 of the body size or the cap is reached (the table gives the substeps kept and the last change, which bounds how far the reference itself is from converged). Reported as the largest particle distance to the reference divided by the body size (beam length 2 m, cube 1 m): after the last frame for the beam; over every frame for the squash, after the best rigid alignment (Kabsch) of each frame onto the reference, so that the shape is compared and not where the free block drifted or turned. A beam that has not settled by the last frame (see `final_speed_m_s` in results.csv) counts its remaining motion as error. Each engine is compared with its own reference, because the two engines' soft models are not the same material.\n- **RMS edge strain** `|l/l₀ − 1|` over the mesh edges, and **total-volume error** (Σ signed volumes / Σ rest volumes − 1), computed from positions in the same way for both engines. For the hard models (tetpbd α = 0; rapier's volume model at {:e} Hz) the exact answer keeps every edge and volume at rest, so every strain and volume error is solver error: this is the like-for-like comparison.\n- tetpbd's own per-family RMS and max |C| (`systems::measure`, as `StepStats` with `measure_error` reports it), inverted tetrahedra, ns per projection: in results.csv.\n- **time to recover** (squash): the first time after which the total volume stays within 1 % of rest and the RMS edge strain below 1 %.\n- **time**: median wall ms per frame over the measured frames of two runs of each configuration (pooled); the median thread CPU ms per frame over the same frames is in results.csv and in the last two headline columns.\n", tetpbd_bench::RAPIER_HARD_HZ);
    let _ = writeln!(s, "## Where the models differ\n");
    let _ = writeln!(s, "tetpbd's soft compliances (α per constraint, XPBD) and rapier's materials (frequency-normalised softness for the volume model, Young's modulus for the corotational and Neo-Hookean cells) are different materials: a soft tetpbd beam and a rapier corotational beam do not sag the same amount, so their errors are measured against their own references and only the shared observables (volume kept, edge stretch, shape against the reference) are compared. rapier's 'hard' volume model is a 1e6 Hz spring, which rapier saturates at the substep rate rather than treating as rigid.\n");
    let _ = writeln!(s, "## Per model\n");
    let _ = writeln!(s, "| scene | model | ns/projection (median over budgets) | cheapest budget: ms, deviation, recover s | largest budget: ms, deviation, recover s, inverted (max), final speed m/s |\n|---|---|---:|---|---|");
    for sc in scenes {
        for m in &models {
            let mine: Vec<&Row> = rows
                .iter()
                .filter(|r| r.scene == sc.name && r.model == *m)
                .collect();
            let (Some(lo), Some(hi)) = (
                mine.iter().min_by(|a, b| a.ms.total_cmp(&b.ms)),
                mine.iter().max_by(|a, b| a.ms.total_cmp(&b.ms)),
            ) else {
                continue;
            };
            let ns = median(mine.iter().filter_map(|r| r.ns_per_projection).collect())
                .map(|n| format!("{n:.1}"))
                .unwrap_or_else(|| "—".into());
            let rec = |r: &Row| {
                r.recover_s
                    .map(|t| format!("{t:.2}"))
                    .unwrap_or_else(|| "—".into())
            };
            let _ = writeln!(
                s,
                "| {} | {} | {ns} | {}: {:.3}, {:.2e}, {} | {}: {:.3}, {:.2e}, {}, {}, {:.2e} |",
                sc.name,
                m.label(),
                lo.budget(),
                lo.ms,
                lo.dev.max,
                rec(lo),
                hi.budget(),
                hi.ms,
                hi.dev.max,
                rec(hi),
                hi.max_inverted,
                hi.final_speed
            );
        }
    }
}

/// How far the numerical references got towards the issue's "until the answer stops changing
/// at 1e-6", from the references themselves.
fn convergence(s: &mut String, references: &[(&'static str, Model, u32, f32)]) {
    let numeric: Vec<&(&'static str, Model, u32, f32)> =
        references.iter().filter(|r| r.2 > 0).collect();
    let exact = references.len() - numeric.len();
    let reached = numeric.iter().filter(|r| r.3 < 1e-6).count();
    let quoted = numeric
        .iter()
        .filter(|r| r.3 <= crate::report::REFERENCE_TOLERANCE)
        .count();
    let _ = writeln!(s, "### Convergence of the references\n");
    let _ = writeln!(
        s,
        "The issue asks for references run \"until the answer stops changing at 1e-6\". Of the {} references, {exact} are exact (hard models: the rest shape) and {} are numerical; {reached} of those reached a change below 1e-6 of the body size when their substeps were last doubled, {quoted} a change of at most {:e} (the tolerance under which their deviations are quoted in the headline and drawn), the rest are left out of the deviation comparisons and named there.",
        references.len(),
        numeric.len(),
        crate::report::REFERENCE_TOLERANCE
    );
    if let (Some(lo), Some(hi)) = (
        numeric.iter().min_by(|a, b| a.3.total_cmp(&b.3)),
        numeric.iter().max_by(|a, b| a.3.total_cmp(&b.3)),
    ) {
        let _ = writeln!(
            s,
            "Closest: {} on {} ({:.1e} at {} substeps); farthest: {} on {} ({:.1e} at {} substeps).",
            lo.1.label(),
            lo.0,
            lo.3,
            lo.2,
            hi.1.label(),
            hi.0,
            hi.3,
            hi.2
        );
    }
    let _ = writeln!(s, "\nWhy 1e-6 is not reached: both engines compute in f32, whose spacing at 1 m is 1.2e-7 m (2.4e-7 m at the beam's 2 m), so 1e-6 of the body size is a handful of ulps; doubling the substeps changes every rounding of a run of thousands of substeps, and the sums of those roundings alone move the answer by about that much. A change near 1e-6 therefore cannot be told apart from rounding. Dynamic runs drift further than static ones, because a released soft block's oscillation phase keeps moving with the substep count (XPBD's discretisation error shrinks only like 1/substeps), and the doubling stops at its cap; the per-scene ranges below come from this run. The hard models need no numerical reference: their exact answer is known.\n");
    let mut scenes: Vec<&str> = Vec::new();
    for r in &numeric {
        if !scenes.contains(&r.0) {
            scenes.push(r.0);
        }
    }
    for sc in scenes {
        let c: Vec<f32> = numeric.iter().filter(|r| r.0 == sc).map(|r| r.3).collect();
        let lo = c.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = c.iter().copied().fold(0.0, f32::max);
        let _ = writeln!(
            s,
            "- {sc}: last change of the {} numerical references between {lo:.1e} and {hi:.1e} of the body size.",
            c.len()
        );
    }
    let _ = writeln!(s);
}
