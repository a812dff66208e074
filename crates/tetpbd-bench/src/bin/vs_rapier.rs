//! tetpbd (through `tetpbd-rapier`) against rapier 0.36's built-in soft bodies on the contact
//! scenes of `tetpbd_bench`: c) a soft cube dropped 5 cm onto rigid ground and left to rest
//! (4³, 8³ and 12³ cells), d) the pile of nine cubes (soft–soft contacts). Same meshes, same
//! frame dt and substeps, in one process.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin vs_rapier [-- --frames F] [--pile] [--tetpbd-only] [--self-weight]
//! ```
//!
//! `--pile` runs only scene d); `--tetpbd-only` prints tetpbd's rows at every substep count
//! and runs no rapier (no comparisons); `--self-weight` runs tetpbd with
//! `StackingSettings::self_weight` on.
//!
//! Prints, per engine and scene: median wall ms per frame over the resting phase (cube: from
//! 2 s on, pile: from 3 s on), the settled max |v| (largest particle speed over the last 30
//! frames), the largest ground penetration and interpenetration at rest, and the largest
//! volume error at rest. rapier runs at 10 and 20 substeps (its hard pile is unstable at 10),
//! tetpbd undamped and with `DeformationDamping` 5/s (rapier's springs are critically damped)
//! at 5 to 80 (5, 10, 12, 15, 20, 40, 80); per rapier run: the ratio at the same substeps, tetpbd's cheapest run at least
//! as accurate as rapier's on every one of those observables, and the cheapest at equal or
//! better volume error alone: the speed-ups at equal or better error. Runs that did not come
//! to rest ([`ContactResult::came_to_rest`]: still moving at 0.02 m/s, below the ground, or
//! non-finite) are marked and take no part in those comparisons, on either side. Interpenetration: depth
//! of a surface particle of one body inside another's tetrahedra; settled max |v| from
//! positions (displacement over a frame / dt).

use clap::Parser;
use tetpbd_bench::{build_contact, run_contact, ContactEngine, ContactResult, ContactScene, DT};

use rapier3d::prelude::{SoftBodyCellModel, SoftBodySolver};

/// rapier's substep counts; tetpbd runs at each of them and at more.
const RAPIER_SUBSTEPS: [u32; 2] = [10, 20];
/// tetpbd's substep counts (each undamped and damped).
const TETPBD_SUBSTEPS: [u32; 7] = [5, 10, 12, 15, 20, 40, 80];
const RAPIER: ContactEngine = ContactEngine::Rapier {
    cell: SoftBodyCellModel::Volume,
    solver: SoftBodySolver::Constraints,
    hard: true,
};

type Res<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn measure(engine: ContactEngine, scene: &ContactScene, substeps: u32) -> Res<ContactResult> {
    run_contact(build_contact(engine, scene, substeps, 1)?.as_mut(), scene)
}

fn print_row(name: &str, tets: usize, x: &ContactResult) {
    println!(
        "{name:40} {tets:6}   {:9.3}   {:10.2e}   {:11.2e}   {:11}   {:10.3}{}",
        x.ms_median,
        x.settled_speed,
        x.rest_penetration,
        x.interpenetration
            .map(|d| format!("{d:.2e}"))
            .unwrap_or_else(|| "—".to_string()),
        x.rest_volume_err_pct,
        if x.came_to_rest() {
            ""
        } else {
            "   did not come to rest"
        }
    );
}

type Found = Option<(ContactEngine, u32, ContactResult)>;

/// tetpbd against rapier 0.36's soft bodies on a soft cube dropped onto rigid ground and a
/// pile of nine cubes: ms per frame and the errors at rest, and the speed-ups at equal error.
#[derive(Parser)]
#[command(name = "vs_rapier")]
struct Args {
    /// Frames per run (at least 240).
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(240..))]
    frames: u32,
    /// Only the pile.
    #[arg(long)]
    pile: bool,
    /// tetpbd's rows at every substep count, no rapier.
    #[arg(long)]
    tetpbd_only: bool,
    /// tetpbd with `StackingSettings::self_weight` on.
    #[arg(long)]
    self_weight: bool,
}

fn compare(scene: &ContactScene, args: &Args) -> Res<()> {
    let self_weight = args.self_weight;
    let undamped = ContactEngine::Tetpbd {
        damping: 0.0,
        self_weight,
    };
    let damped = ContactEngine::Tetpbd {
        damping: 5.0,
        self_weight,
    };
    let mut ours = Vec::new();
    for substeps in TETPBD_SUBSTEPS {
        for e in [undamped, damped] {
            let x = measure(e, scene, substeps)?;
            if args.tetpbd_only {
                print_row(
                    &format!("{}, {substeps} substeps", e.label()),
                    scene.tets(),
                    &x,
                );
            }
            ours.push((e, substeps, x));
        }
    }
    if args.tetpbd_only {
        return Ok(());
    }
    for substeps in RAPIER_SUBSTEPS {
        let r = measure(RAPIER, scene, substeps)?;
        println!("  {substeps} substeps");
        for (e, _, x) in ours.iter().filter(|(_, n, _)| *n == substeps) {
            print_row(&e.label(), scene.tets(), x);
        }
        print_row(&RAPIER.label(), scene.tets(), &r);
        for (e, _, x) in ours.iter().filter(|(_, n, _)| *n == substeps) {
            println!(
                "    same substeps, rapier ms / tetpbd ms ({}): {:.2}×",
                e.label(),
                r.ms_median / x.ms_median
            );
        }
        if !r.came_to_rest() {
            // A run still moving or blown up is no point to beat: a ratio against it only
            // measures how far it went.
            println!("    rapier did not come to rest: no equal-or-better comparison");
            continue;
        }
        // The cheapest tetpbd run that came to rest and is at least as accurate as rapier's on
        // every observable, and on the volume error alone.
        let (mut all, mut volume): (Found, Found) = (None, None);
        for (e, n, x) in ours.iter().filter(|(_, _, x)| x.came_to_rest()) {
            let cheaper = |b: &Found| b.as_ref().is_none_or(|(_, _, b)| x.ms_median < b.ms_median);
            if x.at_least_as_accurate_as(&r) && cheaper(&all) {
                all = Some((*e, *n, x.clone()));
            }
            if x.rest_volume_err_pct <= r.rest_volume_err_pct && cheaper(&volume) {
                volume = Some((*e, *n, x.clone()));
            }
        }
        for (what, best) in [
            (
                "settled max|v|, ground penetration, interpenetration and volume error",
                all,
            ),
            ("volume error alone", volume),
        ] {
            match best {
                Some((e, n, x)) => {
                    print_row(&format!("{}, {n} substeps", e.label()), scene.tets(), &x);
                    println!(
                        "    at equal or better {what}: {:.2}× rapier's speed",
                        r.ms_median / x.ms_median
                    );
                }
                None => {
                    println!("    at equal or better {what}: no tetpbd run with 5–80 substeps")
                }
            }
        }
    }
    Ok(())
}

/// `/proc/loadavg` (1, 5, 15 min), or "unknown".
fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".to_string())
}

fn main() -> Res<()> {
    let args = Args::parse();
    let frames = args.frames as usize;
    println!(
        "hard edges + volume in both engines, rapier at {RAPIER_SUBSTEPS:?} substeps, dt {DT:.4} s, {frames} frames, load average {}",
        load()
    );
    println!("engine                                     tets   ms/frame    max|v| m/s   ground pen. m   interpen. m   volume err %");
    for cells in [4u32, 8, 12].into_iter().filter(|_| !args.pile) {
        let scene = ContactScene::drop(cells, frames)?;
        println!("c) 1 m cube, {cells}³ cells, dropped 5 cm onto rigid ground");
        compare(&scene, &args)?;
    }
    println!("d) pile of nine 1 m cubes (4³ cells) on rigid ground");
    compare(&ContactScene::pile(frames)?, &args)?;
    println!("load average at the end: {}", load());
    Ok(())
}
