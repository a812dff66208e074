//! Runs the stability suite and writes `docs/stability.md`.
//!
//! ```text
//! cargo run --release -p tetpbd-stability --bin stability [-- --out docs/stability.md] [--fast]
//! ```
//!
//! `--fast` skips the long cases. Every case runs under every configuration without any
//! safety net (the defaults); the cases outside the sweep over grid splits and substep
//! counts run again with `max_correction_speed` = 10 m/s.
//!
//! `--coupled <text>` runs only the coupled cases whose name contains `<text>` and prints
//! their cells instead of writing the report:
//!
//! ```text
//! cargo run --release -p tetpbd-stability --bin stability -- --coupled "1000 kg on soft"
//! ```
//!
//! `--no-energy-limit` turns `SafetySettings::limit_correction_energy` off in every
//! uncoupled scene and `--net-everywhere` runs the sweeps under the safety net too (to compare
//! the options; pass `--out` so the comparison does not overwrite `docs/stability.md`).
//!
//! `--case TEXT` keeps only the cases whose name contains `TEXT` (repeatable; coupled cases
//! included), `--no-coupled` skips the coupled table. `--config TEXT` keeps only the
//! columns whose label contains `TEXT` (repeatable; e.g. `--config material`). Pass `--out`
//! with a filter so the partial matrix does not overwrite `docs/stability.md`.

use std::fmt::Write as _;
use std::process::Command;
use std::time::Instant;

use tetpbd_viz::Progress;

use tetpbd_stability::{
    all_cases, coupled_cases, markdown, run_scene, verdict, CaseKind, Config, CoupledOutcome,
    Outcome, Verdict, SWEEP_SUBSTEPS,
};

const SAFETY_NET: f32 = 10.0;

fn shell(cmd: &str, args: &[&str]) -> String {
    Command::new(cmd)
        .args(args)
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

fn cpu() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

/// One coupled cell as the report writes it.
fn cell(o: &CoupledOutcome) -> String {
    let verdict = if o.pass() { "**pass**" } else { "**FAIL**" };
    match &o.error {
        Some(e) => format!("rejected: {e}"),
        None => format!(
            "{verdict} {}, peak {:.1} m/s, pen {:.1e} m{}",
            o.criterion.1,
            o.peak_speed,
            o.penetration,
            if o.inverted > 0 {
                format!(", inv {}", o.inverted)
            } else {
                String::new()
            }
        ),
    }
}

/// Runs the coupled cases whose name contains `filter` and prints their cells.
fn coupled_only(filter: &str, configs: &[Config]) {
    for case in coupled_cases().iter().filter(|c| c.name.contains(filter)) {
        for c in configs {
            if case.kind == CaseKind::Long && c.soft {
                continue;
            }
            let t = Instant::now();
            let o = (case.run)(c);
            println!(
                "{} | {}: {} ({:.1} s)",
                case.name,
                c.label(),
                cell(&o),
                t.elapsed().as_secs_f64()
            );
        }
    }
}

/// The numerical stability matrix: every case of the suite under every configuration, written
/// as a Markdown report.
#[derive(clap::Parser)]
#[command(name = "stability")]
struct Args {
    /// Where the report is written.
    #[arg(long, default_value = "docs/stability.md")]
    out: String,
    /// Skip the long cases.
    #[arg(long)]
    fast: bool,
    /// `SafetySettings::limit_correction_energy` off in every uncoupled scene.
    #[arg(long)]
    no_energy_limit: bool,
    /// Run the sweeps over grid splits and substep counts under the safety net too.
    #[arg(long)]
    net_everywhere: bool,
    /// Skip the coupled cases.
    #[arg(long)]
    no_coupled: bool,
    /// Only the cases whose name contains this text (repeatable).
    #[arg(long = "case", value_name = "TEXT")]
    cases: Vec<String>,
    /// Only the configurations (columns) whose label contains this text (repeatable).
    #[arg(long = "config", value_name = "TEXT")]
    configs: Vec<String>,
    /// Run only the coupled cases whose name contains TEXT ("" for all) and print them,
    /// without writing the report.
    #[arg(long, value_name = "TEXT", num_args = 0..=1, default_missing_value = "")]
    coupled: Option<String>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = <Args as clap::Parser>::parse();
    let Args {
        out,
        fast,
        no_energy_limit: no_limit,
        net_everywhere,
        no_coupled,
        cases: filters,
        configs: column_filters,
        coupled,
    } = args;
    let wanted =
        |name: &str| filters.is_empty() || filters.iter().any(|f| name.contains(f.as_str()));
    let configs: Vec<Config> = Config::all()
        .into_iter()
        .filter(|c| {
            column_filters.is_empty()
                || column_filters
                    .iter()
                    .any(|f| c.label().contains(f.as_str()))
        })
        .collect();
    if let Some(filter) = coupled {
        coupled_only(&filter, &Config::families());
        return Ok(());
    }
    let started = Instant::now();

    let mut doc = String::new();
    writeln!(doc, "# Numerical stability matrix\n")?;
    writeln!(
        doc,
        "Generated by `cargo run --release -p tetpbd-stability --bin stability` on {} ({} cores), {} UTC, commit {}.\n",
        cpu(),
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        shell("date", &["-u", "+%Y-%m-%d %H:%M"]),
        shell("git", &["rev-parse", "--short", "HEAD"]),
    )?;
    writeln!(
        doc,
        "Rows are cases, columns the constraint configurations (α = 0: the seed's hard constraints; \
         soft: edge and vertex–face α = {:.0e} m/N, volume α = {:.0e} m⁵/N). Frames of 1/60 s and 10 substeps \
         unless the case says otherwise. A cell reads:\n\n\
         - **pass**/**FAIL**: finite at every frame, no non-finite reset, no inverted tetrahedron at the end, \
         no energy gained (`ΔE` ≤ {:.0e}) and a body thrown at the ground never rising faster than it came; \
         for a body started at rest, peak kinetic energy ≤ {} × the reference; for a body released from a deformed \
         state or thrown at the ground, recovered at the end (no inverted tetrahedron, total volume within 1 %; for a thrown body, within 1 % of \
         the volume the same body keeps when set down on the ground at rest — soft tissue under its own weight, \
         a hard body's sag at one substep — shown as `at rest vol`) \
         and calm: a released body's kinetic energy decayed to ≤ 10 % of the peak (or below {:.0e} × the \
         reference), a thrown body's *internal* kinetic energy likewise (its motion relative to its best-fit \
         rigid motion, centre-of-mass translation plus rotation, its peak sampled every substep: a body may \
         still fly, spin or roll off the ground at the end of the run, slower than it came, but not jiggle);\n\
         - *shape (vf alone)*: the vertex–face family alone kept every criterion but the shape (finite, \
         no energy gained, calm) and did not recover: expected, four heights fix four of a tetrahedron's \
         six shape degrees of freedom (see the findings below); thrown at the ground it need only stay finite and \
         gain no energy (a shape it cannot hold may keep moving inside itself);\n\
         - `KE p→f`: peak (and, for released bodies, final) kinetic energy / reference energy \
         `max(KE₀, M · 9.81 m/s² · L, ½M(gt)² for free fall)`, L the rest bounding-box diagonal;\n\
         - `ΔE`: the largest rise of the body's mechanical energy (kinetic + elastic energy `Σ C²/2α` of its \
         compliant constraints + gravitational) over its start, / the reference: the energy it gained beyond \
         the external work (pins do none, the ground only takes energy out); hard constraints hold no energy, \
         so for them it is kinetic + gravitational;\n\
         - `rises v of u m/s`: a body thrown at the ground at u m/s, the largest upward speed of its centre of mass;\n\
         - `int. p→f`: a thrown body's peak and final internal kinetic energy / reference;\n\
         - `rec. N`: first frame recovered (with the state at the end if it did not stay so); `not rec.`: inverted tetrahedra and volume error at the end;\n\
         - `e`, `vf`, `vol`: final max |C| of the edge (m), vertex–face (m) and volume (m³) families;\n\
         - `clamps`: how often the correction-speed safety net acted;\n\
         - `rejected`: the builder refused the mesh with a typed error (a clean outcome);\n\
         - *material, rubber* / *material, soft tissue*: the Neo-Hookean material alone (`Material::RUBBER`, \
         E = 1.2 MPa, ν = 0.49; `Material::SOFT_TISSUE`, E = 10 kPa, ν = 0.45), at default settings with \
         max(the case's substeps, ⌈dt / `max_stable_substep`⌉) substeps as the README says (`N substeps` in the \
         cell); its elastic energy counts in `ΔE`; the stiffest-α rows run the preset as it is (the material's \
         stiffness is its E, not a compliance).\n",
        Config::SOFT_LENGTH,
        Config::SOFT_VOLUME,
        Outcome::ENERGY_GAIN_BOUND,
        Outcome::ENERGY_BOUND,
        Outcome::AT_REST,
    )?;
    writeln!(
        doc,
        "The *recovery* rows repeat the initial-state rows on both grid splits (5 and 6 tetrahedra per \
         cell) at {SWEEP_SUBSTEPS:?} substeps; the *impact* rows throw a cube at immovable ground at 100 and \
         300 m/s on both splits at the same substep counts. Both sweeps run at default settings only, \
         the correction-energy limit included.\n"
    )?;

    let tables: Vec<(&str, Vec<_>)> = [
        ("Without safety net", None),
        (
            "With the correction-speed safety net (10 m/s)",
            Some(SAFETY_NET),
        ),
    ]
    .into_iter()
    .map(|(title, net)| {
        let cases = all_cases(net)
            .into_iter()
            .filter(|c| (!fast || c.kind == CaseKind::Fast) && wanted(&c.name))
            .filter(|c| net.is_none() || !c.sweep || net_everywhere)
            .map(|mut c| {
                c.scene.settings.safety.limit_correction_energy &= !no_limit;
                c
            })
            .collect();
        (title, cases)
    })
    .collect();
    let coupled: Vec<_> = coupled_cases()
        .into_iter()
        .filter(|c| (!fast || c.kind != CaseKind::Long) && !no_coupled && wanted(c.name))
        .collect();
    let mut progress = Progress::new(
        "stability cases",
        (tables.iter().map(|t| t.1.len()).sum::<usize>() + coupled.len()) as u64,
    );
    let mut totals = Vec::new();
    for (title, cases) in &tables {
        let mut results = Vec::new();
        let (mut passed, mut expected) = (0, Vec::new());
        for case in cases {
            let t = Instant::now();
            let row: Vec<Outcome> = configs.iter().map(|c| run_scene(&case.scene, c)).collect();
            passed += row.iter().filter(|o| o.pass()).count();
            for (c, o) in configs.iter().zip(&row) {
                if verdict(c, o) == Verdict::Expected {
                    expected.push(format!("{} / {} ({})", case.group, case.name, c.label()));
                }
            }
            progress.suspend(|| {
                println!(
                    "[{:6.1} s] {title}: {} / {}: {} of {} pass ({:.1} s)",
                    started.elapsed().as_secs_f64(),
                    case.group,
                    case.name,
                    row.iter().filter(|o| o.pass()).count(),
                    row.len(),
                    t.elapsed().as_secs_f64()
                )
            });
            progress.inc(1);
            results.push(row);
        }
        let total = cases.len() * configs.len();
        totals.push((title, passed, expected.len(), total));
        writeln!(doc, "## {title}\n")?;
        writeln!(
            doc,
            "{passed} of {total} cells pass; {} are vertex–face-alone shape cells (expected), {} fail.\n",
            expected.len(),
            total - passed - expected.len()
        )?;
        doc.push_str(&markdown(cases, &configs, &results));
        writeln!(doc)?;
        writeln!(doc, "Cases:\n")?;
        for c in cases.iter().filter(|c| !c.sweep) {
            writeln!(doc, "- *{} / {}*: {}.", c.group, c.name, c.description)?;
        }
        let mut sweeps: Vec<_> = cases
            .iter()
            .filter(|c| c.sweep)
            .map(|c| (c.group, c.description))
            .collect();
        sweeps.dedup();
        for (group, description) in sweeps {
            writeln!(doc, "- *{group} / …*: {description}.")?;
        }
        writeln!(doc)?;
        if !expected.is_empty() {
            writeln!(doc, "Vertex–face-alone shape cells (expected):\n")?;
            for e in &expected {
                writeln!(doc, "- {e}")?;
            }
            writeln!(doc)?;
        }
    }
    writeln!(doc, "## Coupled with rapier rigid bodies\n")?;
    writeln!(
        doc,
        "Through `tetpbd-rapier` (10 substeps, default coupling settings). A cell reads pass/FAIL (finite, no \
         inverted tetrahedron at the end, and the case's own criterion), the criterion's figures, the peak \
         particle speed and the largest penetration over the last second. The long case runs under the hard \
         configurations only; the material's columns are not run coupled yet.\n"
    )?;
    let families = Config::families();
    write!(doc, "| case |")?;
    for c in &families {
        write!(doc, " {} |", c.label())?;
    }
    writeln!(doc)?;
    write!(doc, "|---|")?;
    for _ in &families {
        write!(doc, "---|")?;
    }
    writeln!(doc)?;
    let mut coupled_pass = (0, 0);
    for case in &coupled {
        let t = Instant::now();
        write!(doc, "| {} |", case.name)?;
        for c in &families {
            if case.kind == CaseKind::Long && c.soft {
                write!(doc, " — |")?;
                continue;
            }
            let o: CoupledOutcome = (case.run)(c);
            coupled_pass.1 += 1;
            if o.pass() {
                coupled_pass.0 += 1;
            }
            write!(doc, " {} |", cell(&o))?;
        }
        writeln!(doc)?;
        progress.suspend(|| {
            println!(
                "[{:6.1} s] coupled: {} ({:.1} s)",
                started.elapsed().as_secs_f64(),
                case.name,
                t.elapsed().as_secs_f64()
            )
        });
        progress.inc(1);
    }
    progress.finish();
    writeln!(
        doc,
        "\n{} of {} coupled cells pass.\n",
        coupled_pass.0, coupled_pass.1
    )?;
    for case in coupled_cases() {
        writeln!(doc, "- *{}*: {}.", case.name, case.description)?;
    }
    writeln!(doc)?;
    doc.push_str(&tetpbd_stability::rapier_comparison(&coupled, |n| {
        println!("rapier: {n}")
    }));
    doc.push_str(include_str!("findings.md"));
    std::fs::write(&out, &doc)?;
    for (title, passed, expected, total) in totals {
        println!(
            "{title}: {passed} passed, {expected} expected (vertex–face alone), {} failed",
            total - passed - expected
        );
    }
    println!(
        "coupled: {} passed, {} failed",
        coupled_pass.0,
        coupled_pass.1 - coupled_pass.0
    );
    println!("wrote {out} in {:.1} s", started.elapsed().as_secs_f64());
    Ok(())
}
