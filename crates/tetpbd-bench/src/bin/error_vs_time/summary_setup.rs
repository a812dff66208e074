//! The set-up part of summary.md: scenes, configurations, references, metric definitions,
//! where the two engines' models differ, and per-model detail tables.

use std::fmt::Write as _;

use crate::engines::Model;
use crate::pareto::median;
use crate::report::{RefInfo, Row};
use crate::scenes::{Scene, SceneKind, DT};

/// Appends the set-up sections to `s`.
pub fn setup(s: &mut String, scenes: &[Scene], rows: &[Row], references: &[RefInfo]) {
    let _ = writeln!(s, "## Scenes (one mesh each, handed to both engines)\n");
    for sc in scenes {
        let material = match sc.material {
            Some(m) => format!(" Made of one elastic material in both engines: E = {:e} Pa, ν = {} (see 'Material scenes e) and f)').", m.young_modulus(), m.poisson_ratio()),
            None => String::new(),
        };
        let what = match sc.kind {
            SceneKind::HangingBeam => "2 m × 0.2 m × 0.2 m beam (`tetpbd::generators::beam`, 20×2×2 cells, six tetrahedra per cell), the vertices at x = 0 pinned, gravity −9.81 m/s², started straight and at rest; compared after the last frame (static equilibrium)",
            SceneKind::Squash => "1 m cube (`generators::box_grid`, 4×4×4 cells, six tetrahedra per cell), every vertex's y halved about the centre (50 % height, x and z unchanged), released at rest without gravity; compared over every frame",
        };
        let _ = writeln!(
            s,
            "- **{}**: {what}.{material} {} vertices, {} tetrahedra, {} edges; density {} kg/m³ with the same lumped masses in both engines (ρ·|V|/4 per tetrahedron corner); linear damping {} 1/s in both; {} frames of {:.4} s, the first {} excluded from the timing median.",
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
    let _ = writeln!(s, "| model | set-up | budgets (substeps×iterations) | reference: precision, substeps (last change / size), per scene |\n|---|---|---|---|");
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
            .filter(|r| r.model == *m)
            .map(|r| match r.conv.substeps {
                0 => format!("{}: exact (rest shape)", r.scene),
                n => format!(
                    "{}: {} {n}{} ({:.1e})",
                    r.scene,
                    if r.conv.f64 { "f64" } else { "f32" },
                    if r.conv.extrapolated {
                        " Richardson-extrapolated"
                    } else {
                        ""
                    },
                    r.conv.change
                ),
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
    let _ = writeln!(s, "\nAll runs at a frame dt of 1/60 s. tetpbd: `Solver` with `substeps` substeps of `iterations` Gauss–Seidel sweeps, families in the default order (volume, vertex–face, edge), per-family |C| and inverted tetrahedra evaluated after each timed step by `tetpbd::systems::measure` (the evaluation `DiagnosticSettings::measure_error` runs, kept out of the time). rapier: `PhysicsWorld::step` with `integration_parameters.num_solver_iterations` = substeps (its soft-body substep count), every other integration and soft-body setting at its default (one internal PGS iteration plus the soft body's 3 additional ones, impact-adaptive substeps allowed, re-sweep of strained constraints at 0.75), no collider on the body, sleeping off, built from the same vertices, tetrahedra (`cells`), masses and pinned vertices; the volume model also gets the same edge list (`unique_edges`). The `Fem` solver runs with rapier's default `SoftFemParameters` (CG tolerance 1e-5, at most 20 CG iterations, direct factorisation up to 600 degrees of freedom, which covers both meshes). rapier has no separate iteration count in this sweep. tetpbd's `max_correction_speed` safety net is off (its default).\n");
    let settings = tetpbd::SolverSettings {
        dt: DT,
        ..Default::default()
    };
    let _ = writeln!(s, "tetpbd's solver settings in every run, apart from substeps, iterations, gravity and damping set per run and scene: `{settings:?}`.\n");
    convergence(s, references);
    let _ = writeln!(s, "## Metrics\n");
    let _ = writeln!(s, "- **deviation from converged reference**: for the hard models the exact answer, the rest shape (every edge, height and volume held; rapier's 1e6 Hz springs sag by about g/ω² ≈ 2.5e-13 m); for the soft models the same model and mesh run with one iteration and doubled substeps until the answer changes by < 1e-6 of the body size or the cap is reached, tetpbd's in f64 (Richardson-extrapolated where the runs converge at second order) and rapier's by rapier in f32 (see 'Convergence of the references'; the table gives the substeps of the finest run and the last change of the answer kept, the estimate of how far the reference itself is from converged). Reported as the largest particle distance to the reference divided by the body size (beam length 2 m, cube 1 m): after the last frame for the beam; over every frame for the squash, after the best rigid alignment (Kabsch) of each frame onto the reference, so that the shape is compared and not where the free block drifted or turned. A beam that has not settled by the last frame (see `final_speed_m_s` in results.csv) counts its remaining motion as error. Each engine is compared with its own reference, because the two engines' soft models are not the same material.\n- **RMS edge strain** `|l/l₀ − 1|` over the mesh edges, and **total-volume error** (Σ signed volumes / Σ rest volumes − 1), computed from positions in the same way for both engines. For the hard models (tetpbd α = 0; rapier's volume model at {:e} Hz) the exact answer keeps every edge and volume at rest, so every strain and volume error is solver error: this is the like-for-like comparison.\n- tetpbd's own per-family RMS and max |C| (`systems::measure`, as `StepStats` with `measure_error` reports it), inverted tetrahedra, ns per projection: in results.csv.\n- **time to recover** (squash): the first time after which the total volume stays within 1 % of rest and the RMS edge strain below 1 %.\n- **time**: median wall ms per frame over the measured frames of two runs of each configuration (pooled); the median thread CPU ms per frame over the same frames is in results.csv and in the last two headline columns.\n", tetpbd_bench::RAPIER_HARD_HZ);
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

/// Whether a reference belongs to a group of the convergence list.
type Belongs = fn(&RefInfo) -> bool;

/// How far the numerical references got towards the issue's "until the answer stops changing
/// at 1e-6", from the references themselves.
fn convergence(s: &mut String, references: &[RefInfo]) {
    let numeric: Vec<&RefInfo> = references.iter().filter(|r| r.conv.substeps > 0).collect();
    let exact = references.len() - numeric.len();
    let _ = writeln!(s, "### Convergence of the references\n");
    let _ = writeln!(
        s,
        "The issue asks for references run \"until the answer stops changing at 1e-6\". Of the {} references, {exact} are exact (hard models: the rest shape, every edge, height and volume held) and {} are numerical: the same model and mesh run with one iteration per substep and doubled substeps until the largest particle displacement between two doublings, relative to the body size, is below {:e}, or a cap is reached. For tetpbd's references (in f64), wherever three successive runs u(4h), u(2h), u(h) converge at second order (the ratio of their two changes between {} and {}, an observed order within about 0.2 of 2), the second-order error term is removed per particle and frame by Richardson extrapolation, E(h) = (4·u(h) − u(2h))/3, and the same criterion is applied to the extrapolated answers: their change is the largest displacement between E(h) and E(2h) (both from those three runs). The search stops when the change of the plain runs or of the extrapolated answers is below {:e}; at the cap it keeps whichever of the two answers changed less. Where the order check fails the plain last run is kept; rapier's references are never extrapolated (extrapolation amplifies rounding, and f32 rounding is near 1e-6 already). A numerical reference is quoted in the headline and drawn only when the last change of the answer kept is at most {:e}; the others are named where they are left out.\n",
        references.len(),
        numeric.len(),
        crate::reference::TARGET_CHANGE,
        crate::reference::SECOND_ORDER_RATIO.0,
        crate::reference::SECOND_ORDER_RATIO.1,
        crate::reference::TARGET_CHANGE,
        crate::report::REFERENCE_TOLERANCE
    );
    let groups: [(Belongs, &str); 3] = [
        (
            |r| r.conv.f64,
            "tetpbd's soft models, run in f64 by `tetpbd_bench::Xpbd64`",
        ),
        (
            |r| !r.conv.f64 && r.model.is_ours(),
            "tetpbd's Neo-Hookean material, run by tetpbd's own f32 solver (the f64 stepper has no material)",
        ),
        (
            |r| !r.model.is_ours(),
            "rapier's soft models, run by rapier's own f32 solver",
        ),
    ];
    for (belongs, who) in groups {
        let mine: Vec<&&RefInfo> = numeric.iter().filter(|r| belongs(r)).collect();
        if mine.is_empty() {
            continue;
        }
        let target = crate::reference::TARGET_CHANGE;
        let reached = mine.iter().filter(|r| r.conv.change < target).count();
        let ratio = |prev: f32, now: f32| {
            if prev.is_finite() {
                format!(", {:.1} times less than at the doubling before", prev / now)
            } else {
                String::new()
            }
        };
        let list: Vec<String> = mine
            .iter()
            .map(|r| {
                let plain = format!(
                    "{:.1e} at {} substeps{}",
                    r.conv.plain_change,
                    r.conv.substeps,
                    ratio(r.conv.plain_prev_change, r.conv.plain_change)
                );
                let kept = if r.conv.extrapolated {
                    format!(
                        "extrapolated from {} and {} substeps, changed {:.1e}{} (plain runs: {plain})",
                        r.conv.substeps / 2,
                        r.conv.substeps,
                        r.conv.change,
                        ratio(r.conv.prev_change, r.conv.change)
                    )
                } else {
                    format!("plain, {plain}")
                };
                format!("{} on {}: {kept}", r.model.label(), r.scene)
            })
            .collect();
        let _ = writeln!(
            s,
            "- {who}: {reached} of {} reached a change below {target:e} ({}).",
            mine.len(),
            list.join("; ")
        );
    }
    let _ = writeln!(s, "\n**tetpbd in f64.** tetpbd computes in f32, whose spacing at 1 m is 1.2e-7 m, so in f32 a change near 1e-6 of the body size cannot be told from the rounding of thousands of substeps. tetpbd's references are therefore run by a small f64 XPBD stepper in the bench crate (`tetpbd_bench::Xpbd64`): it takes the body the f32 solver gets (same particles, lumped masses, pins, constraint families in the same colour order, compliances; rest lengths, heights and volumes recomputed in f64 from the rest positions) and the same `SolverSettings` (gravity, damping, substeps, family order), and runs the core's constraint functions (`tetpbd::constraint`, generic over the scalar) in the solver's substep scheme. That it is the same model is a test (`xpbd64_matches_the_f32_solver` in `error_vs_time`): at 8 substeps over 30 frames the f64 stepper and tetpbd's f32 `Solver` agree to 1e-5 of the body size on both scenes and all three soft constraint sets, while the same comparison against a deliberately different model (damping off) differs by more than 100 times as much. Where an f64 reference still stops above 1e-6 it is the substep cap, not rounding. How fast the change falls per doubling is given with each reference: a factor near 4 is second-order convergence (the beam settling to static equilibrium: a plain run is then within about change/3 of the converged answer, and the extrapolation removes that leading term, so its answers change several times faster per doubling), near 2 first order (a dynamic run), near or below 1 no convergence at these substeps (a motion so sensitive that its trajectory keeps changing: such a reference is left out of the comparisons). That the extrapolated answer is the converged one is a test (`extrapolated_beam_reference_matches_a_plain_16384_substep_run` in `error_vs_time`, run in release with the ignored tests): on a 1 m beam of 10×1×1 cells, for each of the three soft constraint sets, the reference extrapolated from 512, 1024 and 2048 substeps agrees with a plain 16384-substep f64 run to better than 1e-6 of the beam's length, while the plain 2048-substep run is more than 10 times as far from it; a second test (`extrapolation_only_where_second_order_is_observed`) checks on synthetic sequences that a first-order sequence keeps the plain answer.\n");
    let _ = writeln!(s, "**rapier in f32.** rapier3d is built for f32 in this workspace (its f64 build is a separate crate, `rapier3d-f64`, which the project does not depend on), so rapier's references are its own f32 solver with the substeps doubled up to its cap (the substeps kept are in the configurations table); their last change is the figure listed, and a change near 1e-6 would be within f32 rounding. rapier's hard models need no numerical reference.\n");
}
