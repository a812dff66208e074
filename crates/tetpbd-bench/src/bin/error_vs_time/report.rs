//! The rows of the report and the files written from them: results.csv, contacts.csv (see
//! [`crate::contacts`]), squash_volume.csv,
//! the plot (see [`crate::plot`]) and summary.md (see [`crate::summary`]).

use std::fmt::Write as _;
use std::fs;
use std::io;
use std::path::Path;

use tetpbd_bench::ContactScene;

use crate::contacts::{contacts_csv, ContactRow};
use crate::engines::Model;
use crate::metrics::{Deviation, RunResult};
use crate::reference::{Convergence, Reference};
use crate::scenes::{Scene, DT};

/// Largest last change (relative to the body size) of a numerical reference whose deviations
/// are quoted in the headline and drawn in the deviation panels.
pub const REFERENCE_TOLERANCE: f32 = 1e-3;

/// One model's reference on one scene, as the summary lists it.
#[derive(Clone, Copy, Debug)]
pub struct RefInfo {
    /// Scene name.
    pub scene: &'static str,
    /// The model.
    pub model: Model,
    /// How far the reference is from converged.
    pub conv: Convergence,
    /// Its answer next to the other engine's (material scenes only).
    pub answer: crate::answers::Answer,
}

/// One run of one configuration, summarised.
#[derive(Clone, Debug)]
pub struct Row {
    /// Scene name.
    pub scene: &'static str,
    /// The model.
    pub model: Model,
    /// Substeps per frame (rapier: `num_solver_iterations`).
    pub substeps: u32,
    /// Iterations per substep (rapier: always 1 here; its own PGS settings are left at default).
    pub iterations: u32,
    /// Median wall ms per frame after the warm-up.
    pub ms: f64,
    /// Median thread CPU ms per frame over the same frames.
    pub cpu_ms: f64,
    /// Spread of the wall-time medians of the pooled runs, `max / min − 1`.
    pub timing_spread: f64,
    /// ns per constraint projection (tetpbd).
    pub ns_per_projection: Option<f64>,
    /// Deviation from the model's converged reference.
    pub dev: Deviation,
    /// Volume error after the last frame, %.
    pub volume_err_pct: f32,
    /// Largest |volume error| over the second half of the run, %.
    pub late_volume_err_pct: f32,
    /// RMS edge strain after the last frame.
    pub edge_strain_rms: f32,
    /// Largest edge strain after the last frame.
    pub edge_strain_max: f32,
    /// Inverted tetrahedra after the last frame.
    pub inverted: usize,
    /// Most inverted tetrahedra in any frame.
    pub max_inverted: usize,
    /// tetpbd per-family `(rms, max)` of `|C|` after the last frame: edge (m), vertex–face (m),
    /// volume (m³).
    pub families: [Option<(f32, f32)>; 3],
    /// Squash: time to recover within 1 %, s.
    pub recover_s: Option<f32>,
    /// Largest particle speed at the end, m/s.
    pub final_speed: f32,
    /// No position became non-finite.
    pub finite: bool,
    /// Substeps of the reference.
    pub ref_substeps: u32,
    /// The last change of the reference's answer when its substeps were doubled (relative
    /// to size; see [`Convergence::change`]).
    pub ref_change: f32,
    /// The reference is Richardson-extrapolated (see [`crate::reference`]).
    pub ref_extrapolated: bool,
    /// Volume error after every frame, %.
    pub volume_series: Vec<f32>,
}

impl Row {
    /// Summarises a run.
    pub fn new(
        scene: &Scene,
        model: Model,
        substeps: u32,
        iterations: u32,
        res: &RunResult,
        dev: Deviation,
        reference: &Reference,
    ) -> Row {
        use tetpbd::Family;
        let fam = |f: Family| {
            let k = Family::ALL.iter().position(|g| *g == f).unwrap_or(0);
            res.families[k].map(|e| (e.rms, e.max))
        };
        let half = res.volume_series.len() / 2;
        Row {
            scene: scene.name,
            model,
            substeps,
            iterations,
            ms: res.ms_median,
            cpu_ms: res.cpu_ms_median,
            timing_spread: res.timing_spread(),
            ns_per_projection: res.ns_per_projection,
            dev,
            volume_err_pct: res.last.volume_err_pct,
            late_volume_err_pct: res.volume_series[half..]
                .iter()
                .map(|v| {
                    if v.is_finite() {
                        v.abs()
                    } else {
                        f32::INFINITY
                    }
                })
                .fold(0.0, f32::max),
            edge_strain_rms: res.last.edge_strain_rms,
            edge_strain_max: res.last.edge_strain_max,
            inverted: res.last.inverted,
            max_inverted: res.max_inverted,
            families: [
                fam(Family::Edge),
                fam(Family::VertexFace),
                fam(Family::Volume),
            ],
            recover_s: res.recover_s,
            final_speed: res.final_speed,
            finite: res.finite,
            ref_substeps: reference.conv.substeps,
            ref_change: reference.conv.change,
            ref_extrapolated: reference.conv.extrapolated,
            volume_series: res.volume_series.clone(),
        }
    }

    /// `true` when the row's reference is exact or changed by at most
    /// [`REFERENCE_TOLERANCE`] when its substeps were last doubled, so that a deviation from it
    /// is an error that can be quoted.
    pub fn reference_ok(&self) -> bool {
        self.ref_change <= REFERENCE_TOLERANCE
    }

    /// `substeps×iterations`.
    pub fn budget(&self) -> String {
        format!("{}x{}", self.substeps, self.iterations)
    }
}

fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

/// The CSV of every run.
pub fn results_csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "scene,engine,model,hard,substeps,iterations,ms_per_frame_median,cpu_ms_per_frame_median,\
         timing_spread,\
         ns_per_projection,\
         dev_max_rel,dev_rms_rel,volume_err_pct,late_volume_err_pct_max,edge_strain_rms,\
         edge_strain_max,inverted,inverted_max,edge_c_rms_m,edge_c_max_m,vertex_face_c_rms_m,\
         vertex_face_c_max_m,volume_c_rms_m3,volume_c_max_m3,recover_s,final_speed_m_s,finite,\
         ref_substeps,ref_change_rel,ref_extrapolated\n",
    );
    for r in rows {
        let f = |k: usize| {
            r.families[k]
                .map(|(rms, max)| format!("{rms:e},{max:e}"))
                .unwrap_or_else(|| ",".to_string())
        };
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{:.6},{:.6},{:.4},{},{:e},{:e},{:e},{:e},{:e},{:e},{},{},{},{},{},{},{:e},{},{},{:e},{}",
            r.scene,
            r.model.engine(),
            r.model.label(),
            r.model.is_hard(),
            r.substeps,
            r.iterations,
            r.ms,
            r.cpu_ms,
            r.timing_spread,
            opt(r.ns_per_projection.map(|n| format!("{n:.2}"))),
            r.dev.max,
            r.dev.rms,
            r.volume_err_pct,
            r.late_volume_err_pct,
            r.edge_strain_rms,
            r.edge_strain_max,
            r.inverted,
            r.max_inverted,
            f(0),
            f(1),
            f(2),
            opt(r.recover_s.map(|t| format!("{t:.4}"))),
            r.final_speed,
            r.finite,
            r.ref_substeps,
            r.ref_change,
            r.ref_extrapolated,
        );
    }
    s
}

/// Volume error over time of every squash run (long format).
pub fn squash_volume_csv(rows: &[Row], squash: &str) -> String {
    let mut s = String::from("model,substeps,iterations,frame,t_s,volume_err_pct\n");
    for r in rows.iter().filter(|r| r.scene == squash) {
        for (f, v) in r.volume_series.iter().enumerate() {
            let _ = writeln!(
                s,
                "{},{},{},{},{:.4},{:.5}",
                r.model.label(),
                r.substeps,
                r.iterations,
                f + 1,
                (f + 1) as f32 * DT,
                v
            );
        }
    }
    s
}

/// How the run went, for the summary.
#[derive(Clone, Debug)]
pub struct RunInfo {
    /// `--quick` smoke run.
    pub quick: bool,
    /// Wall time of the whole command, s.
    pub elapsed_s: f64,
    /// `/proc/loadavg` (1, 5, 15 min) when the sweep started.
    pub load_start: String,
    /// `/proc/loadavg` when the sweep ended.
    pub load_end: String,
}

/// The 1, 5 and 15 minute load averages, or "unknown".
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".to_string())
}

/// Writes every file of the report into `out`.
pub fn write_all(
    out: &Path,
    scenes: &[Scene],
    rows: &[Row],
    references: &[RefInfo],
    contacts: (&[ContactScene], &[ContactRow]),
    info: &RunInfo,
) -> io::Result<()> {
    fs::create_dir_all(out)?;
    fs::write(out.join("results.csv"), results_csv(rows))?;
    fs::write(out.join("contacts.csv"), contacts_csv(contacts.1))?;
    let squash = scenes
        .iter()
        .find(|s| s.kind == crate::scenes::SceneKind::Squash)
        .map(|s| s.name)
        .unwrap_or("");
    fs::write(
        out.join("squash_volume.csv"),
        squash_volume_csv(rows, squash),
    )?;
    crate::plot::draw(out, scenes, rows).map_err(io::Error::other)?;
    crate::plot_volume::draw(out, rows, squash).map_err(io::Error::other)?;
    crate::plot_contacts::draw(out, contacts.0, contacts.1).map_err(io::Error::other)?;
    let md = crate::summary::markdown(scenes, rows, references, contacts, info);
    fs::write(out.join("summary.md"), md)
}
