//! `cargo run --release -p tetpbd-bench --bin error_vs_time [-- [--quick] [--out DIR]]`
//! (`-- --help` lists the options)
//!
//! Error against run time, tetpbd next to rapier 0.36's built-in soft bodies, on six scenes:
//! a) a hanging beam settling to static equilibrium, b) a block squashed to 50 % height and
//! released, c) a soft cube dropped onto rigid ground, d) a pile of nine cubes (soft–soft
//! contacts), and the material scenes e) and f): scenes a and b with the body made of one
//! elastic material (the same Young's modulus, Poisson's ratio and density in both engines:
//! tetpbd's Neo-Hookean material, rapier's Neo-Hookean and corotational cells). Writes
//! `docs/error-vs-time/` (results.csv, contacts.csv, squash_volume.csv, plot.png, plot.svg,
//! materials.png, materials.svg, contacts.png, contacts.svg, squash_volume.png,
//! squash_volume.svg, summary.md);
//! `--quick` (a smoke run) writes `target/error-vs-time-quick/`. With `--features parallel`
//! the references of scenes a, b, e and f (see [`mod@reference`]) are computed on rayon's threads
//! before the timed runs, and the contact sweep adds a 12³-cell drop run by tetpbd on 1 and 2
//! threads.

mod answers;
mod contacts;
mod engines;
mod metrics;
mod pareto;
mod plot;
mod plot_contacts;
mod plot_volume;
mod reference;
mod report;
mod scenes;
mod summary;
mod summary_contacts;
mod summary_materials;
mod summary_setup;

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use clap::Parser;
use rapier3d::prelude::{SoftBodyCellModel, SoftBodySolver};
use tetpbd_viz::Progress;

use engines::{build, ConstraintSet, Model};
use metrics::{deviation, run, widen};
use reference::{converged, exact_rest, Reference};
use report::Row;
use scenes::{Scene, SceneKind};

/// Error against run time, tetpbd next to rapier 0.36's built-in soft bodies: a hanging beam,
/// a squashed block, a soft cube dropped on rigid ground, a pile of nine cubes, and the beam
/// and the block again made of one elastic material in both engines. Writes the report's
/// tables, plots and summary.
#[derive(Debug, Parser)]
#[command(name = "error_vs_time")]
struct Args {
    /// A smoke run: fewer models, budgets and frames (seconds instead of minutes).
    #[arg(long)]
    quick: bool,
    /// Directory to write the report to (default: docs/error-vs-time, or
    /// target/error-vs-time-quick with --quick, so a smoke run never overwrites the committed
    /// report).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

impl Args {
    /// The output directory, its default resolved.
    fn out_dir(&self) -> PathBuf {
        self.out.clone().unwrap_or_else(|| {
            PathBuf::from(if self.quick {
                "target/error-vs-time-quick"
            } else {
                "docs/error-vs-time"
            })
        })
    }
}

/// The swept models of `scene`: on a material scene [`material_models`], otherwise every
/// tetpbd constraint set at α = 0 and soft, and rapier's cell models and solvers.
fn models(scene: &Scene, quick: bool) -> Vec<Model> {
    if scene.material.is_some() {
        return material_models(quick);
    }
    let mut m = Vec::new();
    for soft in [false, true] {
        for set in [
            ConstraintSet::EdgesVolume,
            ConstraintSet::VertexFace,
            ConstraintSet::VertexFaceEdges,
        ] {
            if quick && set != ConstraintSet::EdgesVolume {
                continue;
            }
            m.push(Model::Ours { set, soft });
        }
    }
    let rapier = [
        (SoftBodyCellModel::Volume, SoftBodySolver::Constraints, true),
        (
            SoftBodyCellModel::Volume,
            SoftBodySolver::Constraints,
            false,
        ),
        (
            SoftBodyCellModel::Corotational,
            SoftBodySolver::Constraints,
            false,
        ),
        (
            SoftBodyCellModel::NeoHookean,
            SoftBodySolver::Constraints,
            false,
        ),
        (SoftBodyCellModel::Volume, SoftBodySolver::Fem, true),
        (SoftBodyCellModel::Corotational, SoftBodySolver::Fem, false),
        (SoftBodyCellModel::NeoHookean, SoftBodySolver::Fem, false),
    ];
    for (k, (cell, solver, hard)) in rapier.into_iter().enumerate() {
        if quick && k > 2 {
            continue;
        }
        m.push(Model::Rapier { cell, solver, hard });
    }
    m
}

/// The models of a material scene, all with the same E, ν and density: tetpbd's Neo-Hookean
/// material, rapier's Neo-Hookean and corotational cells on both its solvers (the quick run:
/// Neo-Hookean on the constraints solver only).
fn material_models(quick: bool) -> Vec<Model> {
    let mut m = vec![Model::Material];
    for (cell, solver) in [
        (SoftBodyCellModel::NeoHookean, SoftBodySolver::Constraints),
        (SoftBodyCellModel::NeoHookean, SoftBodySolver::Fem),
        (SoftBodyCellModel::Corotational, SoftBodySolver::Constraints),
        (SoftBodyCellModel::Corotational, SoftBodySolver::Fem),
    ] {
        if quick && (cell, solver) != (SoftBodyCellModel::NeoHookean, SoftBodySolver::Constraints) {
            continue;
        }
        m.push(Model::RapierMaterial { cell, solver });
    }
    m
}

/// `(substeps, iterations)` swept for a model at the 1/60 s frame: substeps × 1 iteration
/// from 1 up to the point where tetpbd costs about as much per frame as rapier's most
/// expensive runs, plus a few iteration-heavy budgets.
fn budgets(model: &Model, quick: bool) -> Vec<(u32, u32)> {
    let top = match (model, quick) {
        (_, true) => 16,
        (
            Model::Ours {
                set: ConstraintSet::EdgesVolume,
                ..
            },
            false,
        ) => 256,
        (Model::Ours { .. }, false) => 128,
        (Model::Material, false) => 256,
        (Model::Rapier { .. } | Model::RapierMaterial { .. }, false) => 32,
    };
    let step = if quick { 4 } else { 2 };
    let mut b: Vec<(u32, u32)> = std::iter::successors(Some(1u32), |s| Some(s * step))
        .take_while(|s| *s <= top)
        .map(|s| (s, 1))
        .collect();
    if model.is_ours() {
        match quick {
            true => b.push((1, 4)),
            false => b.extend([(1, 4), (1, 16), (1, 32), (4, 4)]),
        }
    }
    b
}

/// Runs of each configuration whose measured frames are pooled for the timing median (the
/// error metrics come from the first; both engines are deterministic single-threaded).
fn repeats(quick: bool) -> usize {
    if quick {
        1
    } else {
        2
    }
}

/// Substeps at which the reference search starts and stops. tetpbd's references run in f64
/// (slower than the f32 solver, but not stopped by rounding). The beam's static answer
/// converges at second order (the plain change falls about 4 times per doubling, 1.2e-5 to
/// 4.2e-5 of its length at 2048 substeps), so its Richardson-extrapolated answer meets the
/// 1e-6 criterion by 2048 (see [`mod@reference`]); the squash does not converge at these substeps
/// and is capped lower. The quick run starts at 32 so that its three runs can be checked for
/// second order too. tetpbd's material has no `f64` stepper: its references run the `f32`
/// solver, like rapier's, up to 2048 substeps (cheap: one body of a few hundred
/// tetrahedra).
fn reference_range(model: &Model, scene: &Scene, quick: bool) -> (u32, u32) {
    match (model, quick) {
        (Model::Material, false) => (32, 2048),
        (Model::Ours { .. }, false) => match scene.kind {
            SceneKind::HangingBeam => (256, 2048),
            SceneKind::Squash => (128, 1024),
        },
        (Model::Ours { .. }, true) => (32, 128),
        (Model::Material, true) => (32, 128),
        (Model::Rapier { .. } | Model::RapierMaterial { .. }, false) => (32, 128),
        (Model::Rapier { .. } | Model::RapierMaterial { .. }, true) => (32, 64),
    }
}

/// Every `(scene, model)` pair of the sweep, scenes in order, each scene's models in
/// [`models`] order.
fn jobs(scenes: &[Scene], quick: bool) -> Vec<(&Scene, Model)> {
    scenes
        .iter()
        .flat_map(|sc| models(sc, quick).into_iter().map(move |m| (sc, m)))
        .collect()
}

/// The reference of every job (see [`jobs`]), computed before any timed run. With the
/// `parallel` feature they run on rayon's threads (nothing is timed meanwhile; each reference
/// is deterministic, so the answers are the same as one after the other), without it one
/// after the other.
fn all_references(jobs: &[(&Scene, Model)], quick: bool) -> Vec<Reference> {
    // A bar on a terminal, plain periodic lines otherwise (CI); the per-reference lines go
    // through `suspend` so they do not tear the bar.
    let progress = Mutex::new(Progress::new(
        "scenes a, b, e, f: references",
        jobs.len() as u64,
    ));
    let one = |&(scene, model): &(&Scene, Model)| {
        let (lo, hi) = reference_range(&model, scene, quick);
        let t = Instant::now();
        let r = if model.is_hard() {
            exact_rest(scene)
        } else {
            converged(model, scene, lo, hi)
        };
        let mut p = progress.lock().unwrap_or_else(|e| e.into_inner());
        p.suspend(|| {
            eprintln!(
                "{:<18} {:<36} reference {:>5} substeps{}, change {:.2e} ({:.1} s)",
                scene.name,
                model.label(),
                r.conv.substeps,
                match (r.conv.f64, r.conv.extrapolated) {
                    (true, true) => " (f64, extrapolated)",
                    (true, false) => " (f64)",
                    _ => "",
                },
                r.conv.change,
                t.elapsed().as_secs_f64()
            )
        });
        p.inc(1);
        r
    };
    #[cfg(feature = "parallel")]
    let refs = {
        use rayon::prelude::*;
        jobs.par_iter().map(one).collect()
    };
    #[cfg(not(feature = "parallel"))]
    let refs = jobs.iter().map(one).collect();
    progress.lock().unwrap_or_else(|e| e.into_inner()).finish();
    refs
}

/// Every timed run of scenes a, b, e and f against its reference, and the references as the
/// summary lists them.
fn sweep(scenes: &[Scene], quick: bool) -> (Vec<Row>, Vec<report::RefInfo>) {
    let mut rows = Vec::new();
    let mut references = Vec::new();
    let jobs = jobs(scenes, quick);
    let computed = all_references(&jobs, quick);
    let answers = answers::answers(&jobs, &computed);
    let mut progress = Progress::new("scenes a, b, e, f: budgets", jobs.len() as u64);
    for (k, &(scene, model)) in jobs.iter().enumerate() {
        let r = &computed[k];
        progress.suspend(|| eprintln!("{:<18} {}", scene.name, model.label()));
        for (substeps, iterations) in budgets(&model, quick) {
            let mut res = run(build(model, scene, substeps, iterations).as_mut(), scene);
            for _ in 1..repeats(quick) {
                let again = run(build(model, scene, substeps, iterations).as_mut(), scene);
                res.pool_timing(&again);
            }
            let dev = deviation(scene, &widen(&res.trajectory), &r.trajectory);
            progress.suspend(|| {
                eprintln!(
                    "    {substeps:>3}x{iterations:<3} {:>9.3} ms  dev max {:.2e} rms {:.2e}  vol {:+.3}%  strain {:.2e}",
                    res.ms_median, dev.max, dev.rms, res.last.volume_err_pct, res.last.edge_strain_rms
                )
            });
            rows.push(Row::new(scene, model, substeps, iterations, &res, dev, r));
        }
        references.push(report::RefInfo {
            scene: scene.name,
            model,
            conv: r.conv,
            answer: answers[k],
        });
        progress.inc(1);
    }
    progress.finish();
    (rows, references)
}

fn main() {
    let args = Args::parse();
    let out = args.out_dir();
    let started = Instant::now();
    let load_start = report::load_average();
    let scenes = [
        Scene::hanging_beam(args.quick),
        Scene::squash(args.quick),
        Scene::material_beam(args.quick),
        Scene::material_squash(args.quick),
    ];
    let (rows, references) = sweep(&scenes, args.quick);
    let contact_scenes = match contacts::scenes(args.quick) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("contact scenes: {e}");
            std::process::exit(1);
        }
    };
    let contact_rows = match contacts::sweep(&contact_scenes, args.quick) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("contact sweep: {e}");
            std::process::exit(1);
        }
    };
    let elapsed = started.elapsed().as_secs_f64();
    let info = report::RunInfo {
        quick: args.quick,
        elapsed_s: elapsed,
        load_start,
        load_end: report::load_average(),
    };
    if let Err(e) = report::write_all(
        &out,
        &scenes,
        &rows,
        &references,
        (&contact_scenes, &contact_rows),
        &info,
    ) {
        eprintln!("writing {}: {e}", out.display());
        std::process::exit(1);
    }
    eprintln!("wrote {} in {elapsed:.0} s", out.display());
}
