//! summary.md: machine, date, commit, set-up of every configuration, and the Pareto headline
//! in numbers, all from the rows of this run.

use std::fmt::Write as _;
use std::process::Command;

use tetpbd_bench::ContactScene;

use crate::contacts::ContactRow;
use crate::pareto::{compare, median, Match, Point};
use crate::report::{Row, RunInfo};
use crate::scenes::{Scene, SceneKind};

fn command_line(cmd: &str, args: &[&str]) -> Option<String> {
    let out = Command::new(cmd).args(args).output().ok()?;
    let s = String::from_utf8_lossy(&out.stdout).trim().to_string();
    (out.status.success() && !s.is_empty()).then_some(s)
}

fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|c| {
            c.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".to_string());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let os = std::fs::read_to_string("/etc/os-release")
        .ok()
        .and_then(|c| {
            c.lines().find(|l| l.starts_with("PRETTY_NAME=")).map(|l| {
                l.trim_start_matches("PRETTY_NAME=")
                    .trim_matches('"')
                    .to_string()
            })
        })
        .unwrap_or_else(|| std::env::consts::OS.to_string());
    let rustc = command_line("rustc", &["--version"]).unwrap_or_else(|| "rustc ?".to_string());
    format!("{cpu}, {cores} logical cores available, {os}, {rustc}")
}

fn commit() -> String {
    let head = command_line("git", &["rev-parse", "--short=12", "HEAD"])
        .unwrap_or_else(|| "unknown".to_string());
    let dirty = command_line(
        "git",
        &[
            "status",
            "--porcelain",
            "--",
            "crates/tetpbd",
            "crates/tetpbd-bench",
        ],
    )
    .is_some();
    if dirty {
        format!("{head} (with uncommitted changes in crates/tetpbd or crates/tetpbd-bench)")
    } else {
        head
    }
}

/// A named error metric.
struct Metric {
    name: &'static str,
    f: fn(&Row) -> f64,
    /// Only rows whose reference converged (see [`Row::reference_ok`]).
    needs_reference: bool,
}

const DEV: Metric = Metric {
    name: "max deviation from converged reference / body size",
    f: |r| f64::from(r.dev.max),
    needs_reference: true,
};
const STRAIN: Metric = Metric {
    name: "RMS edge strain",
    f: |r| f64::from(r.edge_strain_rms),
    needs_reference: false,
};
const LATE_VOLUME: Metric = Metric {
    name: "largest absolute volume error (%) over the second half",
    f: |r| f64::from(r.late_volume_err_pct),
    needs_reference: false,
};

/// Cost by wall time (`cpu == false`) or by thread CPU time.
fn points(rows: &[Row], idx: &[usize], m: &Metric, cpu: bool) -> Vec<Point> {
    idx.iter()
        .map(|&i| Point {
            ms: if cpu { rows[i].cpu_ms } else { rows[i].ms },
            err: (m.f)(&rows[i]),
            row: i,
        })
        .collect()
}

/// Three significant digits, without an exponent for ordinary ratios.
pub fn sig(x: f64) -> String {
    match x.abs() {
        a if a >= 1e5 || (a < 1e-2 && a > 0.0) => format!("{x:.2e}"),
        a if a >= 100.0 => format!("{x:.0}"),
        a if a >= 10.0 => format!("{x:.1}"),
        _ => format!("{x:.2}"),
    }
}

fn describe(r: &Row) -> String {
    format!("{} {}", r.model.label(), r.budget())
}

/// The medians of one headline comparison.
pub struct Brief {
    /// Median of rapier ms / tetpbd ms at equal error.
    pub speed: Option<f64>,
    /// Median of rapier error / tetpbd error at equal time.
    pub gain: Option<f64>,
    /// rapier Pareto points.
    pub points: usize,
}

/// Which models a headline compares: the hard ones, all of a constraint scene, or the
/// material models of a material scene.
pub fn selection(hard: bool, material: bool) -> &'static str {
    match (hard, material) {
        (true, _) => "hard",
        (false, false) => "all",
        (false, true) => "same E, ν",
    }
}

/// One line of the headline table: by wall time (`b`) and by CPU time (`c`); `models` says
/// which models are compared (see [`selection`]).
pub fn brief_row(scene: &str, models: &str, metric: &str, b: &Brief, c: &Brief) -> String {
    let f = |x: Option<f64>| x.map(sig).unwrap_or_else(|| "n/a".to_string());
    format!(
        "| {scene} | {models} | {metric} | **{}** | **{}** | {} | {} | {} |",
        f(b.speed),
        f(b.gain),
        b.points,
        f(c.speed),
        f(c.gain)
    )
}

/// The headline paragraph and table for one scene, one metric and one selection of rows.
fn headline(
    s: &mut String,
    rows: &[Row],
    scene: &str,
    m: &Metric,
    hard_only: bool,
    cpu: bool,
) -> Brief {
    let sel = |engine: &str| -> Vec<usize> {
        (0..rows.len())
            .filter(|&i| {
                let r = &rows[i];
                r.scene == scene
                    && r.model.engine() == engine
                    && r.finite
                    && (!hard_only || r.model.is_hard())
                    && (!m.needs_reference || r.reference_ok())
            })
            .collect()
    };
    let matches = compare(
        &points(rows, &sel("tetpbd"), m, cpu),
        &points(rows, &sel("rapier"), m, cpu),
    );
    let material = rows
        .iter()
        .any(|r| r.scene == scene && r.model == crate::engines::Model::Material);
    let which = match (hard_only, material) {
        (true, _) => "hard models only",
        (false, false) => "all models",
        (false, true) => "the material models (same E, ν and density in both engines)",
    };
    let _ = writeln!(s, "**{scene}, {which}, error = {}.** ", m.name);
    if m.needs_reference {
        let mut out: Vec<String> = Vec::new();
        for r in rows
            .iter()
            .filter(|r| r.scene == scene && !r.reference_ok())
        {
            let l = format!("{} ({:.1e})", r.model.label(), r.ref_change);
            if !out.contains(&l) && (!hard_only || r.model.is_hard()) {
                out.push(l);
            }
        }
        if !out.is_empty() {
            let _ = writeln!(
                s,
                "Left out because their reference still moved by more than {:e} of the body size when its substeps were doubled: {}. ",
                crate::report::REFERENCE_TOLERANCE,
                out.join(", ")
            );
        }
    }
    pareto_text(s, &matches, &|i| describe(&rows[i]))
}

/// The medians and the table of one comparison at rapier's Pareto points; `describe(i)` names
/// the run behind point row `i`.
pub fn pareto_text(s: &mut String, matches: &[Match], describe: &dyn Fn(usize) -> String) -> Brief {
    let speed: Vec<f64> = matches.iter().filter_map(|x| x.speedup()).collect();
    let gain: Vec<f64> = matches.iter().filter_map(|x| x.accuracy_gain()).collect();
    let range = |v: &[f64]| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        format!("{}–{}", sig(lo), sig(hi))
    };
    match median(speed.clone()) {
        Some(x) => {
            let _ = writeln!(
                s,
                "At equal error, rapier's time / tetpbd's time = **{}** (median over the {} of {} rapier Pareto points that tetpbd reaches; range {}; above 1 tetpbd is faster). ",
                sig(x),
                speed.len(),
                matches.len(),
                range(&speed)
            );
        }
        None => {
            let _ = writeln!(
                s,
                "At equal error: tetpbd reaches none of rapier's {} Pareto points. ",
                matches.len()
            );
        }
    }
    match median(gain.clone()) {
        Some(x) => {
            let _ = writeln!(
                s,
                "At equal time, rapier's error / tetpbd's error = **{}** (median over the {} of {} rapier Pareto points with a tetpbd run at most as costly; range {}; above 1 tetpbd is more accurate).\n",
                sig(x),
                gain.len(),
                matches.len(),
                range(&gain)
            );
        }
        None => {
            let _ = writeln!(
                s,
                "At equal time: no tetpbd run is as cheap as any rapier Pareto point.\n"
            );
        }
    }
    let _ = writeln!(s, "| rapier Pareto point | ms | error | tetpbd at equal error | ms | speed-up | tetpbd at equal time | error | gain |");
    let _ = writeln!(s, "|---|---:|---:|---|---:|---:|---|---:|---:|");
    for x in matches {
        let (ee, ee_ms, sp) = match x.at_equal_error {
            Some(p) => (
                describe(p.row),
                format!("{:.3}", p.ms),
                format!("{:.2}×", x.theirs.ms / p.ms),
            ),
            None => ("—".into(), String::new(), String::new()),
        };
        let (et, et_err, g) = match x.at_equal_time {
            Some(p) => (
                describe(p.row),
                format!("{:.2e}", p.err),
                format!("{}×", sig(x.accuracy_gain().unwrap_or(f64::NAN))),
            ),
            None => ("—".into(), String::new(), String::new()),
        };
        let _ = writeln!(
            s,
            "| {} | {:.3} | {:.2e} | {ee} | {ee_ms} | {sp} | {et} | {et_err} | {g} |",
            describe(x.theirs.row),
            x.theirs.ms,
            x.theirs.err
        );
    }
    let _ = writeln!(s);
    Brief {
        speed: median(speed),
        gain: median(gain),
        points: matches.len(),
    }
}

/// The whole summary.
pub fn markdown(
    scenes: &[Scene],
    rows: &[Row],
    references: &[crate::report::RefInfo],
    contacts: (&[ContactScene], &[ContactRow]),
    info: &RunInfo,
) -> String {
    let (quick, elapsed_s) = (info.quick, info.elapsed_s);
    let mut s = String::new();
    let date = command_line("date", &["-u", "+%Y-%m-%d %H:%M UTC"])
        .unwrap_or_else(|| "unknown".to_string());
    let _ = writeln!(
        s,
        "# Error against run time: tetpbd vs rapier 0.36 soft bodies\n"
    );
    let _ = writeln!(s, "Regenerate: `cargo run --release -p tetpbd-bench{} --bin error_vs_time{}` (this run took {elapsed_s:.0} s).\n", if cfg!(feature = "parallel") { " --features parallel" } else { "" }, if quick { " -- --quick" } else { "" });
    if quick {
        let _ = writeln!(s, "**This is a `--quick` smoke run: fewer models, budgets, frames and a cheaper reference. Do not quote it.**\n");
    }
    let _ = writeln!(s, "- Machine: {}\n- Date: {date}\n- Commit: {}\n- Load average (1/5/15 min) at start: {}, at end: {} (the machine is shared; a load above 1 on 2 cores inflates the times of both engines alike).\n- Every timed run one after the other, single-threaded unless marked '2 threads'{}. rapier is built without its `parallel` feature. tetpbd's `parallel` feature (colour-class Gauss–Seidel on rayon) only parallelises a family with at least 4096 constraints, more than the meshes of scenes a, b, c and d have (at most 1920 per family per body), so for those a parallel column would repeat the serial one; {}\n", machine(), commit(), info.load_start, info.load_end, if cfg!(feature = "parallel") { " (the references of scenes a, b, e and f, which are not timed, are computed first, on rayon's threads)" } else { "" }, if cfg!(feature = "parallel") { "this run was built with it and adds a 12³-cell drop (c_drop_12, 10 368 tetrahedra) run by tetpbd on 1 and 2 threads (see 'Parallel' below)." } else { "this run was built without it (see 'Parallel' below); large bodies on 2 threads are also measured by the `scaling` binary." });
    let _ = writeln!(s, "![error vs time](plot.png)\n\n![material scenes](materials.png)\n\nData: [results.csv](results.csv) (one row per run of scenes a, b, e and f), [contacts.csv](contacts.csv) (one row per run of scenes c and d), [squash_volume.csv](squash_volume.csv) (volume error per frame of every squash run), drawn for one budget in [squash_volume.png](squash_volume.png).\n");
    let _ = writeln!(s, "## Headline (Pareto fronts)\n");
    let _ = writeln!(s, "Each engine's Pareto front is the set of its runs that no other run of the same engine beats in both median ms per frame and error. At each rapier front point we take tetpbd's cheapest run with an error at most rapier's (equal error) and tetpbd's most accurate run costing at most rapier's (equal time), and quote the medians over rapier's front: **speed** = rapier ms / tetpbd ms at equal error, **accuracy** = rapier error / tetpbd error at equal time; above 1 favours tetpbd. The hard models are the like-for-like comparison (same exact answer in both engines); 'all models' mixes materials that differ between the engines, each measured against its own reference. The material scenes e and f give both engines the same elastic material (Young's modulus, Poisson's ratio, density): see 'Material scenes e) and f)'. Contact runs (scenes c and d) that did not come to rest are left out of the fronts on both sides and listed under 'Runs that did not come to rest'; scenes a and b leave out non-finite runs (a beam still swinging at the last frame counts its motion as deviation).\n");
    let mut details = String::new();
    let mut briefs: Vec<String> = Vec::new();
    for scene in scenes {
        let cases: &[(&Metric, bool)] = match (scene.kind, scene.material.is_some()) {
            (SceneKind::HangingBeam, true) => &[(&DEV, false)],
            (SceneKind::Squash, true) => &[(&DEV, false), (&LATE_VOLUME, false)],
            (SceneKind::HangingBeam, false) => &[(&DEV, true), (&STRAIN, true), (&DEV, false)],
            (SceneKind::Squash, false) => &[
                (&DEV, true),
                (&LATE_VOLUME, true),
                (&DEV, false),
                (&LATE_VOLUME, false),
            ],
        };
        for (m, hard) in cases {
            let b = headline(&mut details, rows, scene.name, m, *hard, false);
            let c = headline(&mut String::new(), rows, scene.name, m, *hard, true);
            let models = selection(*hard, scene.material.is_some());
            briefs.push(brief_row(scene.name, models, m.name, &b, &c));
        }
    }
    briefs.extend(crate::summary_contacts::headlines(
        &mut details,
        contacts.0,
        contacts.1,
    ));
    let _ = writeln!(s, "| scene | models | error | speed at equal error | accuracy at equal time | rapier front points | speed, by CPU time | accuracy, by CPU time |\n|---|---|---|---:|---:|---:|---:|---:|");
    for b in &briefs {
        let _ = writeln!(s, "{b}");
    }
    let mut spread: Vec<f64> = rows
        .iter()
        .map(|r| r.timing_spread)
        .filter(|x| x.is_finite())
        .collect();
    spread.sort_by(f64::total_cmp);
    if let (Some(m), Some(p90)) = (median(spread.clone()), spread.get(spread.len() * 9 / 10)) {
        let _ = writeln!(s, "\nTiming noise: the wall-time medians of the two runs of each configuration differ by {:.1} % (median over all configurations; 90th percentile {:.1} %). Ratios near 1 in the table are within that noise.", m * 100.0, p90 * 100.0);
    }
    let _ = writeln!(s, "\nThe last two columns repeat the comparison with each run's median thread CPU time per frame instead of its wall time (both engines run on the calling thread): on a loaded machine they show how much of the wall-time figure is contention.");
    crate::summary_contacts::unsettled(&mut s, contacts.1);
    let _ = writeln!(s, "\n### Details\n\n{details}");
    crate::summary_setup::setup(&mut s, scenes, rows, references);
    crate::summary_materials::section(&mut s, scenes, references);
    crate::summary_contacts::section(&mut s, contacts.0, contacts.1);
    s
}
