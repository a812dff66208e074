//! Scenes c) drop and d) pile: the sweep over engines, substeps and (with the `parallel`
//! feature) threads, and the CSV of its runs. Scene set-up, both engines and the observables
//! are `tetpbd_bench`'s, shared with the `vs_rapier` binary.

use std::fmt::Write as _;

use rapier3d::prelude::{SoftBodyCellModel, SoftBodySolver};
use tetpbd_bench::{
    build_contact, run_contact, ContactEngine, ContactKind, ContactResult, ContactScene,
};

/// One run of one contact configuration.
#[derive(Clone, Debug)]
pub struct ContactRow {
    /// Scene name.
    pub scene: &'static str,
    /// Engine set-up.
    pub engine: ContactEngine,
    /// Substeps per frame (rapier: `num_solver_iterations`).
    pub substeps: u32,
    /// Iterations per substep (rapier: 1).
    pub iterations: u32,
    /// Threads of the rayon pool tetpbd ran in (1 without the `parallel` feature).
    pub threads: usize,
    /// What the run gave.
    pub res: ContactResult,
}

impl ContactRow {
    /// `label substepsxiterations[, N threads]`.
    pub fn describe(&self) -> String {
        let t = match self.threads {
            1 => String::new(),
            n => format!(", {n} threads"),
        };
        format!(
            "{} {}x{}{t}",
            self.engine.label(),
            self.substeps,
            self.iterations
        )
    }

    /// rapier's hard volume models and tetpbd (always α = 0 here): the like-for-like set.
    pub fn is_hard(&self) -> bool {
        match self.engine {
            ContactEngine::Tetpbd { .. } => true,
            ContactEngine::Rapier { hard, cell, .. } => hard && cell == SoftBodyCellModel::Volume,
        }
    }
}

/// The contact scenes: c) at 4³ cells, d) the pile, and with the `parallel` feature c) again
/// at 12³ cells (10 368 tetrahedra, enough for tetpbd's parallel colour classes).
pub fn scenes(quick: bool) -> Result<Vec<ContactScene>, tetpbd::BuildError> {
    let mut v = vec![
        ContactScene::drop(4, if quick { 150 } else { 240 })?,
        ContactScene::pile(if quick { 210 } else { 300 })?,
    ];
    if cfg!(feature = "parallel") {
        let mut big = ContactScene::drop(12, if quick { 150 } else { 240 })?;
        big.name = "c_drop_12";
        v.push(big);
    }
    Ok(v)
}

/// Engine set-ups swept on `scene`.
fn engines(scene: &ContactScene, quick: bool) -> Vec<ContactEngine> {
    let mut e = vec![
        ContactEngine::Tetpbd {
            damping: 5.0,
            self_weight: false,
        },
        ContactEngine::Tetpbd {
            damping: 0.0,
            self_weight: false,
        },
        ContactEngine::Tetpbd {
            damping: 0.0,
            self_weight: true,
        },
        ContactEngine::Rapier {
            cell: SoftBodyCellModel::Volume,
            solver: SoftBodySolver::Constraints,
            hard: true,
        },
    ];
    if !quick && scene.cells == 4 {
        e.push(ContactEngine::Rapier {
            cell: SoftBodyCellModel::Volume,
            solver: SoftBodySolver::Fem,
            hard: true,
        });
        e.push(ContactEngine::Rapier {
            cell: SoftBodyCellModel::Volume,
            solver: SoftBodySolver::Constraints,
            hard: false,
        });
    }
    e
}

/// Substep counts swept (one iteration each).
fn budgets(engine: &ContactEngine, scene: &ContactScene, quick: bool) -> Vec<u32> {
    match (engine, quick, scene.cells) {
        (_, true, _) => vec![10],
        (ContactEngine::Tetpbd { .. }, false, 4) if scene.kind == ContactKind::Drop => {
            vec![5, 10, 20, 40, 80]
        }
        (ContactEngine::Tetpbd { .. }, false, 4) => vec![5, 10, 20, 40],
        (ContactEngine::Tetpbd { .. }, false, _) => vec![10, 20, 40],
        (ContactEngine::Rapier { .. }, false, 4) => vec![5, 10, 20],
        (ContactEngine::Rapier { .. }, false, _) => vec![10],
    }
}

/// Thread counts tetpbd runs with.
fn threads(engine: &ContactEngine, scene: &ContactScene) -> Vec<usize> {
    match engine {
        ContactEngine::Tetpbd { .. } if cfg!(feature = "parallel") && scene.cells > 4 => {
            vec![1, 2]
        }
        _ => vec![1],
    }
}

/// One run, in a rayon pool of `threads` threads with the `parallel` feature.
fn run_one(
    engine: ContactEngine,
    scene: &ContactScene,
    substeps: u32,
    threads: usize,
) -> Result<ContactResult, String> {
    let go = || {
        build_contact(engine, scene, substeps, 1)
            .and_then(|mut sim| run_contact(sim.as_mut(), scene))
            .map_err(|e| e.to_string())
    };
    #[cfg(feature = "parallel")]
    {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| e.to_string())?;
        pool.install(go)
    }
    #[cfg(not(feature = "parallel"))]
    {
        let _ = threads;
        go()
    }
}

/// Runs the sweep over `scenes`, printing a line per run to stderr.
pub fn sweep(scenes: &[ContactScene], quick: bool) -> Result<Vec<ContactRow>, String> {
    let mut rows = Vec::new();
    for scene in scenes {
        for engine in engines(scene, quick) {
            for substeps in budgets(&engine, scene, quick) {
                for n in threads(&engine, scene) {
                    let res = run_one(engine, scene, substeps, n)
                        .map_err(|e| format!("{} {}: {e}", scene.name, engine.label()))?;
                    let row = ContactRow {
                        scene: scene.name,
                        engine,
                        substeps,
                        iterations: 1,
                        threads: n,
                        res,
                    };
                    let r = &row.res;
                    eprintln!(
                        "{:<18} {:<48} {:>9.3} ms  max|v| {:.2e}  pen {:.2e}  inter {:.2e}  vol {:.3}%",
                        scene.name,
                        row.describe(),
                        r.ms_median,
                        r.settled_speed,
                        r.rest_penetration,
                        r.interpenetration.unwrap_or(0.0),
                        r.rest_volume_err_pct
                    );
                    rows.push(row);
                }
            }
        }
    }
    Ok(rows)
}

fn opt(v: Option<f32>, f: impl Fn(f32) -> String) -> String {
    v.map(f).unwrap_or_default()
}

/// The CSV of every contact run.
pub fn contacts_csv(rows: &[ContactRow]) -> String {
    let mut s = String::from(
        "scene,engine,model,hard,substeps,iterations,threads,ms_per_frame_median_rest,\
         cpu_ms_per_frame_median_rest,ms_per_frame_median_all,settled_max_speed_m_s,settle_s,\
         rest_penetration_m,peak_penetration_m,rest_interpenetration_m,rest_volume_err_pct_max,\
         rest_min_y_m,inverted_max,finite\n",
    );
    for r in rows {
        let x = &r.res;
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{:.6},{:.6},{:.6},{:e},{},{:e},{:e},{},{:e},{:e},{},{}",
            r.scene,
            r.engine.engine(),
            r.engine.label(),
            r.is_hard(),
            r.substeps,
            r.iterations,
            r.threads,
            x.ms_median,
            x.cpu_ms_median,
            x.ms_median_all,
            x.settled_speed,
            opt(x.settle_s, |t| format!("{t:.4}")),
            x.rest_penetration,
            x.peak_penetration,
            opt(x.interpenetration, |d| format!("{d:e}")),
            x.rest_volume_err_pct,
            x.rest_min_y,
            x.max_inverted,
            x.finite
        );
    }
    s
}
