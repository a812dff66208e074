//! The contact scenes' part of summary.md: headline lines (Pareto fronts on each shared
//! observable, and the speed-up at equal or better error on all of them at once), the set-up,
//! where the engines' contact models differ, and every run.

use std::fmt::Write as _;

use tetpbd_bench::{ContactKind, ContactScene, GROUND_HALF_EXTENTS, SETTLED_SPEED};

use crate::contacts::ContactRow;
use crate::pareto::{compare, median, Point};
use crate::summary::{brief_row, pareto_text, selection, sig, Brief};

/// A named error observable of a contact run.
struct Metric {
    name: &'static str,
    f: fn(&ContactRow) -> f64,
}

const SPEED: Metric = Metric {
    name: "settled max \\|v\\| (m/s, last 0.5 s)",
    f: |r| f64::from(r.res.settled_speed),
};
const VOLUME: Metric = Metric {
    name: "largest \\|volume error\\| of a body at rest (%)",
    f: |r| f64::from(r.res.rest_volume_err_pct),
};
const INTER: Metric = Metric {
    name: "largest interpenetration of two bodies at rest (m)",
    f: |r| f64::from(r.res.interpenetration.unwrap_or(0.0)),
};

fn points(rows: &[ContactRow], idx: &[usize], m: &Metric, cpu: bool) -> Vec<Point> {
    idx.iter()
        .map(|&i| Point {
            ms: if cpu {
                rows[i].res.cpu_ms_median
            } else {
                rows[i].res.ms_median
            },
            err: (m.f)(&rows[i]),
            row: i,
        })
        .collect()
}

/// Rows of `scene` and `engine` that came to rest ([`tetpbd_bench::ContactResult::came_to_rest`]:
/// the unstable ones are listed apart, see [`unsettled`]), one thread (the parallel runs are
/// compared separately), hard models only when `hard`.
fn select(rows: &[ContactRow], scene: &str, engine: &str, hard: bool) -> Vec<usize> {
    (0..rows.len())
        .filter(|&i| {
            let r = &rows[i];
            r.scene == scene
                && r.engine.engine() == engine
                && r.res.came_to_rest()
                && r.threads == 1
                && (!hard || r.is_hard())
        })
        .collect()
}

fn one(
    details: &mut String,
    rows: &[ContactRow],
    scene: &str,
    m: &Metric,
    hard: bool,
    cpu: bool,
) -> Brief {
    let matches = compare(
        &points(rows, &select(rows, scene, "tetpbd", hard), m, cpu),
        &points(rows, &select(rows, scene, "rapier", hard), m, cpu),
    );
    let which = if hard {
        "hard models only"
    } else {
        "all models"
    };
    let _ = writeln!(details, "**{scene}, {which}, error = {}.** ", m.name);
    pareto_text(details, &matches, &|i| rows[i].describe())
}

/// The headline table lines (same columns as scenes a and b) and the detail paragraphs.
pub fn headlines(
    details: &mut String,
    scenes: &[ContactScene],
    rows: &[ContactRow],
) -> Vec<String> {
    let mut out = Vec::new();
    for sc in scenes {
        let metrics: &[&Metric] = match sc.kind {
            ContactKind::Drop => &[&SPEED, &VOLUME],
            ContactKind::Pile => &[&SPEED, &VOLUME, &INTER],
        };
        for m in metrics {
            for hard in [true, false] {
                let has_soft = rows.iter().any(|r| r.scene == sc.name && !r.is_hard());
                if !hard && !has_soft {
                    continue;
                }
                let b = one(details, rows, sc.name, m, hard, false);
                let c = one(&mut String::new(), rows, sc.name, m, hard, true);
                out.push(brief_row(sc.name, selection(hard, false), m.name, &b, &c));
            }
        }
    }
    out
}

/// The section on scenes c and d: set-up, model differences, every-observable comparison and
/// every run.
pub fn section(s: &mut String, scenes: &[ContactScene], rows: &[ContactRow]) {
    let _ = writeln!(
        s,
        "## Contact scenes c) and d)\n\n![contact scenes](contacts.png)\n"
    );
    for sc in scenes {
        let what = match sc.kind {
            ContactKind::Drop => format!("one 1 m cube (`generators::box_grid`, {c}×{c}×{c} cells, six tetrahedra per cell), its bottom 5 cm above a fixed rigid ground cuboid (top face at y = 0), released at rest under gravity −9.81 m/s²", c = sc.cells),
            ContactKind::Pile => "nine 1 m cubes (4×4×4 cells, six tetrahedra each) in the layout of rapier's own `fem_bench` \"jelly pile\": a 3 × 3 grid of 1 m pitch (neighbours touch face to face), cube i centred at height 0.55 + 1.05·i m, so they land one after another next to and along the ones already down (lateral soft–soft contacts all the way), on the same rigid ground".to_string(),
        };
        let _ = writeln!(
            s,
            "- **{}**: {what}. {} tetrahedra in all; density {} kg/m³, the same lumped masses in both engines; {} frames of 1/60 s, resting phase from frame {} ({:.1} s) on: the timing median and the 'at rest' observables are taken over it.",
            sc.name,
            sc.tets(),
            sc.density,
            sc.frames,
            sc.rest_from,
            sc.rest_from as f32 / 60.0
        );
    }
    let _ = writeln!(s, "\n**Set-up.** tetpbd: `tetpbd_rapier::CoupledWorld` (the rigid ground is a rapier collider, particles collide with it through the coupling, `SoftCollider` default: thickness 2 mm), edges and volumes at α = 0, with `DeformationDamping` 5/s, undamped, or undamped with `StackingSettings::self_weight` (the ground-up sweep from the particles on the ground in every substep, opt-in); the pile's soft–soft contacts are the coupling's own (`CouplingSettings::soft_contacts`, default settings: vertex–triangle contacts with each body's `SoftCollider`, 2 mm + 2 mm = 4 mm between two bodies, friction 0.5, body-level restitution 0). rapier: `PhysicsWorld` with the same ground collider, each cube a `SoftBodyBuilder` on the same vertices, tetrahedra, masses (and edge list for the volume model) with rapier's default surface collider (the body's boundary mesh as a collider, particle radius 1 cm as its contact skin, self contacts off), sleeping off, `num_solver_iterations` = substeps. Timing: one run per configuration (no pooling), wall and thread CPU median over the resting phase.\n");
    let _ = writeln!(s, "**Where the contact models differ.** rapier's soft bodies collide through their surface colliders: rigid contacts and soft–soft contacts (vertex–surface and edge–edge pairs, plus a volume-overlap correction) are velocity constraints solved with rapier's rigid bodies, with a 1 cm skin; tetpbd's are positional XPBD inequalities re-evaluated every substep (particle against collider by parry point projection, 2 mm; particle against the other body's surface triangles, 4 mm; no edge–edge test). So the resting gap differs by design (column `rest min y`), and neither engine lets a particle below the ground's top face once settled: ground penetration is compared as depth below y = 0, interpenetration as the depth of a surface particle of one body inside another body's tetrahedra (distance to that body's surface), computed from positions in the same way for both engines. Friction coefficients are each engine's defaults.\n");
    let _ = writeln!(s, "**Reference and error of the contact scenes.** Scenes c and d have no converged trajectory reference: their errors are observables of the resting state whose exact values are known for the hard models of both engines, so each is an error against that exact answer: settled max |v| (exact: 0), ground penetration and interpenetration at rest (exact: 0), volume error at rest (exact: 0 for hard edges and volumes). There is no f64 path here as there is for scenes a and b: tetpbd's contacts run through `tetpbd-rapier` (rapier colliders and parry queries, f32) and rapier's soft bodies through rapier itself, which this workspace builds for f32 only; and where the cubes of the pile end up changes with the substep count (see the fastest-body column under 'Runs that did not come to rest'), so a trajectory reference would not converge anyway.\n");
    same_budget(s, scenes, rows);
    all_at_once(s, scenes, rows);
    parallel(s, rows);
    let _ = writeln!(s, "### Every contact run\n\nSettled max |v|: largest particle speed (displacement over a frame / dt) over the last 30 frames; settle s: the first time after which it stays below {SETTLED_SPEED} m/s. Data: [contacts.csv](contacts.csv).\n");
    let _ = writeln!(s, "| scene | run | ms/frame | CPU ms | settled max\\|v\\| m/s | settle s | ground pen. at rest m | peak ground pen. m | interpen. at rest m | vol. err. at rest % | rest min y m | inverted (max) |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in rows {
        let x = &r.res;
        let _ =
            writeln!(
            s,
            "| {} | {} | {:.3} | {:.3} | {:.2e} | {} | {:.2e} | {:.2e} | {} | {:.4} | {:.4} | {} |",
            r.scene,
            r.describe(),
            x.ms_median,
            x.cpu_ms_median,
            x.settled_speed,
            x.settle_s.map(|t| format!("{t:.2}")).unwrap_or_else(|| "—".into()),
            x.rest_penetration,
            x.peak_penetration,
            x.interpenetration
                .map(|d| format!("{d:.2e}"))
                .unwrap_or_else(|| "—".into()),
            x.rest_volume_err_pct,
            x.rest_min_y,
            x.max_inverted
        );
    }
    let _ = writeln!(s);
}

/// rapier's Constraints hard run against tetpbd at the same substep count.
fn same_budget(s: &mut String, scenes: &[ContactScene], rows: &[ContactRow]) {
    let _ = writeln!(s, "### Same substeps\n\nrapier `Constraints` with the hard volume model against tetpbd at the same substep count (one thread): rapier ms / tetpbd ms per frame, and each engine's observables. A run marked † did not come to rest (see 'Runs that did not come to rest' above): its observables are those of a body still moving or blown up, not a resting error.\n\n| scene | substeps | tetpbd run | speed-up | settled max\\|v\\| tetpbd / rapier | vol. err. % tetpbd / rapier | interpen. m tetpbd / rapier |\n|---|---:|---|---:|---|---|---|");
    for sc in scenes {
        for t in rows
            .iter()
            .filter(|r| r.scene == sc.name && r.engine.label() == "rapier Constraints Volume hard")
        {
            for o in rows.iter().filter(|r| {
                r.scene == sc.name
                    && r.engine.engine() == "tetpbd"
                    && r.substeps == t.substeps
                    && r.threads == 1
            }) {
                let _ = writeln!(
                    s,
                    "| {} | {} | {}{} | {:.2}× | {:.2e}{} / {:.2e}{} | {:.4} / {:.4} | {} |",
                    sc.name,
                    t.substeps,
                    o.engine.label(),
                    dagger(o),
                    t.res.ms_median / o.res.ms_median,
                    o.res.settled_speed,
                    dagger(o),
                    t.res.settled_speed,
                    dagger(t),
                    o.res.rest_volume_err_pct,
                    t.res.rest_volume_err_pct,
                    match (o.res.interpenetration, t.res.interpenetration) {
                        (Some(a), Some(b)) => format!("{a:.2e} / {b:.2e}"),
                        _ => "—".into(),
                    }
                );
            }
        }
    }
    let _ = writeln!(s);
}

/// "†" for a run that did not come to rest.
fn dagger(r: &ContactRow) -> &'static str {
    if r.res.came_to_rest() {
        ""
    } else {
        "†"
    }
}

/// For each rapier hard run that came to rest, tetpbd's cheapest run that came to rest and is
/// at least as good on every observable.
fn all_at_once(s: &mut String, scenes: &[ContactScene], rows: &[ContactRow]) {
    let _ = writeln!(s, "### Equal or better on every observable at once\n\nFor each rapier run with a hard model that came to rest: tetpbd's cheapest one-thread run that came to rest and whose settled max |v|, ground penetration, interpenetration and volume error at rest are all at most rapier's, and rapier ms / tetpbd ms. Runs of either engine that did not come to rest are not compared (a blown-up run is no point to beat, and one still moving is no match); they are listed under 'Runs that did not come to rest'.\n\n| scene | rapier run | ms | tetpbd run | ms | speed-up |\n|---|---|---:|---|---:|---:|");
    for sc in scenes {
        let mut ratios = Vec::new();
        for t in rows.iter().filter(|r| stable_rapier_hard(r, sc.name)) {
            let best = rows
                .iter()
                .filter(|r| {
                    r.scene == sc.name
                        && r.engine.engine() == "tetpbd"
                        && r.threads == 1
                        && r.res.came_to_rest()
                        && r.res.at_least_as_accurate_as(&t.res)
                })
                .min_by(|a, b| a.res.ms_median.total_cmp(&b.res.ms_median));
            let (name, ms, ratio) = match best {
                Some(o) => {
                    let q = t.res.ms_median / o.res.ms_median;
                    ratios.push(q);
                    (
                        o.describe(),
                        format!("{:.3}", o.res.ms_median),
                        format!("{q:.2}×"),
                    )
                }
                None => (
                    "none in the sweep".to_string(),
                    String::new(),
                    String::new(),
                ),
            };
            let _ = writeln!(
                s,
                "| {} | {} | {:.3} | {name} | {ms} | {ratio} |",
                sc.name,
                t.describe(),
                t.res.ms_median
            );
        }
        let n = rows
            .iter()
            .filter(|r| stable_rapier_hard(r, sc.name))
            .count();
        let _ = writeln!(
            s,
            "| {} | **median over the {} of {n} resting rapier runs tetpbd matches** | | | | **{}** |",
            sc.name,
            ratios.len(),
            median(ratios).map(sig).unwrap_or_else(|| "n/a".into())
        );
    }
    let _ = writeln!(s);
}

/// A rapier run with a hard model on `scene` that came to rest.
fn stable_rapier_hard(r: &ContactRow, scene: &str) -> bool {
    r.scene == scene && r.engine.engine() == "rapier" && r.is_hard() && r.res.came_to_rest()
}

/// tetpbd on 2 threads against 1 (with the `parallel` feature).
fn parallel(s: &mut String, rows: &[ContactRow]) {
    let pairs: Vec<(&ContactRow, &ContactRow)> = rows
        .iter()
        .filter(|r| r.threads == 2)
        .filter_map(|two| {
            rows.iter()
                .find(|one| {
                    one.threads == 1
                        && one.scene == two.scene
                        && one.engine == two.engine
                        && one.substeps == two.substeps
                })
                .map(|one| (one, two))
        })
        .collect();
    let _ = writeln!(s, "### Parallel (tetpbd's rayon Gauss–Seidel)\n");
    if pairs.is_empty() {
        let _ = writeln!(s, "Not measured in this run: build with `--features parallel` (`cargo run --release -p tetpbd-bench --features parallel --bin error_vs_time`) to add the 12³-cell drop with tetpbd on 1 and 2 threads.\n");
        return;
    }
    let _ = writeln!(s, "tetpbd's `parallel` feature runs a constraint family's colour classes in parallel when the body has at least 4096 constraints of that family; the 4³ cubes and the beam have fewer, so only the 12³-cell cube (c_drop_12, 10 368 tetrahedra) is run on 1 and 2 threads (a rayon pool of that size). Contacts and the coupling stay serial.\n\n| scene | run | 1 thread ms | 2 threads ms | speed-up | settled max\\|v\\| 1 / 2 threads |\n|---|---|---:|---:|---:|---|");
    for (one, two) in pairs {
        let _ = writeln!(
            s,
            "| {} | {} {}x{} | {:.3} | {:.3} | {:.2}× | {:.2e} / {:.2e} |",
            one.scene,
            one.engine.label(),
            one.substeps,
            one.iterations,
            one.res.ms_median,
            two.res.ms_median,
            one.res.ms_median / two.res.ms_median,
            one.res.settled_speed,
            two.res.settled_speed
        );
    }
    let _ = writeln!(s);
}

/// The contact runs that did not come to rest ([`tetpbd_bench::ContactResult::came_to_rest`]
/// is false: settled max |v| at or above [`SETTLED_SPEED`], a particle below the ground in the
/// resting phase, or a non-finite position), per engine. They are left out of the Pareto
/// fronts and of the every-observable comparison.
pub fn unsettled(s: &mut String, rows: &[ContactRow]) {
    let _ = writeln!(s, "\n### Runs that did not come to rest\n");
    let bad: Vec<&ContactRow> = rows.iter().filter(|r| !r.res.came_to_rest()).collect();
    if bad.is_empty() {
        let _ = writeln!(s, "Every contact run came to rest (settled max |v| below {SETTLED_SPEED} m/s, no particle below the ground, all positions finite).");
        return;
    }
    let _ = writeln!(
        s,
        "{} of {} contact runs did not come to rest (settled max |v| at or above {SETTLED_SPEED} m/s, a particle below the ground in the resting phase, or a non-finite position). They are left out of the contact Pareto fronts above and of the every-observable comparison below, on both sides: a blown-up run is no point to beat (the ratios against it would only measure how far it blew up) and a run still moving is no match. Listed here instead:\n",
        bad.len(),
        rows.len()
    );
    let _ = writeln!(s, "| scene | run | settled max\\|v\\| m/s | ground pen. at rest m | vol. err. at rest % | finite | fastest body at the end: index, speed m/s, centre (x, y, z) m |\n|---|---|---:|---:|---:|---|---|");
    for r in bad {
        let fastest = r
            .res
            .fastest_body
            .map(|(b, v, c)| {
                format!(
                    "{b}, {v:.2e}, ({:.2}, {:.2}, {:.2}){}",
                    c.x,
                    c.y,
                    c.z,
                    where_is(c)
                )
            })
            .unwrap_or_else(|| "—".into());
        let _ = writeln!(
            s,
            "| {} | {} | {:.2e} | {:.2e} | {:.3} | {} | {fastest} |",
            r.scene,
            r.describe(),
            r.res.settled_speed,
            r.res.rest_penetration,
            r.res.rest_volume_err_pct,
            if r.res.finite { "yes" } else { "no" }
        );
    }
    let _ = writeln!(s, "\nThe last column says which body keeps the run from resting and where it is: a 1 m cube whose centre is about 0.5 m up stands on the ground, one higher up lies on other cubes or is in the air, one whose centre is beyond the ground's half extent ({} m) has left the ground over its edge (its particles then fall below y = 0, which the ground-penetration column counts).\n", GROUND_HALF_EXTENTS[0]);
}

/// Where a cube's centre `c` is, in words, for the unsettled table.
fn where_is(c: nalgebra::Vector3<f32>) -> &'static str {
    let [hx, _, hz] = GROUND_HALF_EXTENTS;
    if c.x.abs() > hx || c.z.abs() > hz {
        ": beyond the ground's edge"
    } else if c.y > 0.8 {
        ": above a cube resting on the ground (on other cubes or in the air)"
    } else if c.y > 0.0 {
        ": on the ground"
    } else {
        ": below the ground"
    }
}
