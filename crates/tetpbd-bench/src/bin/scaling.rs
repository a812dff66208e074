//! ms per frame for bodies of about 1k, 10k, 100k and 1M tetrahedra (10 substeps of a
//! 1/60 s frame), for edges + volume, for vertex–face and for the Neo-Hookean material (soft
//! tissue), on 1 and 2 threads.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --features parallel --bin scaling [-- --min-cells N --max-cells N --frames F --parts P --set edges+volume|vertex-face|material --sequential --shuffle --spatial-order on|off|both --breakdown --per-frame --no-energy-limit --keep-helpers-awake --move-helpers-off --given-pool]
//! ```
//!
//! `--keep-helpers-awake` and `--move-helpers-off` turn on
//! [`tetpbd::ParallelSettings::keep_helpers_awake`] and
//! [`tetpbd::ParallelSettings::move_helpers_off_step_core`] (both off by default).
//! Each body is stepped on its pool's thread (`ThreadPool::install`); with `--given-pool`
//! the pool is given to the solver ([`tetpbd::Solver::set_thread_pool`]) and the body is
//! stepped from the main thread instead.
//!
//! With `--features parallel` the 1-thread and the 2-thread runs are *interleaved*: two
//! copies of the body, one stepped on a pool of one thread and one on a pool of two, frame
//! after frame in turn, so that a change of the machine's load (other processes, clock)
//! hits both columns alike. The speed-up is the median over the frames of the ratio of each
//! 1-thread frame to the 2-thread frame after it, with the lower and upper quartiles of
//! those ratios beside it. `--sequential` runs all the 1-thread frames first, then all the
//! 2-thread ones (the older way; the speed-up is then the ratio of the medians).
//!
//! Each row ends with the CPU other processes used while it was measured, in cores (from
//! `/proc/stat` less this process's own time): on a shared 2-core machine anything above a
//! few hundredths of a core takes time from the 2-thread column.
//!
//! `--error` prints, after the measured frames, the constraint error of the 1-thread body
//! (one more frame with [`tetpbd::DiagnosticSettings::measure_error`]): how well the sweep
//! order converges, e.g. to compare `--parts 1` with a partitioned order.
//!
//! `--set` measures one family set only (default all three).
//!
//! `--no-energy-limit` turns [`tetpbd::SafetySettings::limit_correction_energy`] off (to
//! measure its cost).
//!
//! `--parts P` builds the bodies cut into `P` slabs for the sweep order
//! ([`tetpbd::SoftBodyBuilder::parts`]; default 0, the builder's choice).
//!
//! `--breakdown` also prints, per body and thread count, the median ms per frame spent in
//! prediction, the copies into and out of the working copy, each family's system and the
//! velocity update (from [`tetpbd::StepStats`]), the phases of a sweep of the edges and of
//! the tetrahedra (colour classes of the plain layout, tasks and classes of a partitioned
//! one) and, built with `--features sync-stats`, the median ms per frame the threads spent
//! waiting at phase boundaries (summed over both threads) and for a pass's last chunks.
//!
//! `--per-frame` also prints every measured frame's ms on 1 and on 2 threads: the
//! 2-thread column at 100k tetrahedra is bimodal on this machine (docs/performance.md), and
//! its median alone hides how many frames ran at which speed.
//!
//! `--shuffle` numbers each grid's vertices and tetrahedra in a random order (as mesh files
//! may); `--spatial-order` builds the bodies with the builder's particle renumbering on, off
//! or both (default: the builder's default).
//!
//! Without `--features parallel` only the single-threaded column is measured. Prints medians
//! over the measured frames (the first two frames of each body are warm-up) and ns per
//! tetrahedron per substep (1 thread).

#[cfg(feature = "parallel")]
use std::sync::Arc;
use std::time::Instant;

use clap::Parser;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, shuffled, CellSplit};
use tetpbd::{EdgeConstraints, SoftBodyBuilder, Solver, SolverSettings, StepStats, TetMesh};
use tetpbd_bench::{orders, FamilySet, SpatialOrder};

/// ms per frame for hanging cubes of about 1k, 10k, 100k and 1M tetrahedra, edges + volume
/// and vertex–face, on 1 and 2 threads (2 with `--features parallel`).
#[derive(Parser)]
#[command(name = "scaling")]
struct Args {
    /// Smallest cube to measure, cells per side (of 6, 12, 26, 55).
    #[arg(long, default_value_t = 0)]
    min_cells: u32,
    /// Largest cube to measure, cells per side.
    #[arg(long, default_value_t = 55)]
    max_cells: u32,
    /// Measured frames per body (at least 1).
    #[arg(long, default_value_t = 15, value_parser = clap::value_parser!(u32).range(1..))]
    frames: u32,
    /// Slabs of the sweep order (`SoftBodyBuilder::parts`; 0: the builder's choice).
    #[arg(long, default_value_t = 0)]
    parts: usize,
    /// One family set only (default all three).
    #[arg(long, value_enum)]
    set: Option<FamilySet>,
    /// All 1-thread frames first, then all 2-thread ones (instead of interleaved).
    #[arg(long)]
    sequential: bool,
    /// Number each grid's vertices and tetrahedra in a random order.
    #[arg(long)]
    shuffle: bool,
    /// Particle orders to measure (default: the builder's).
    #[arg(long, value_enum)]
    spatial_order: Option<SpatialOrder>,
    /// Also print the median ms per frame of each phase.
    #[arg(long)]
    breakdown: bool,
    /// Also print every measured frame.
    #[arg(long)]
    per_frame: bool,
    /// Print the constraint error of the 1-thread body after the measured frames.
    #[arg(long)]
    error: bool,
    /// `SafetySettings::limit_correction_energy` off (to measure its cost).
    #[arg(long)]
    no_energy_limit: bool,
    /// `ParallelSettings::keep_helpers_awake` on.
    #[arg(long)]
    keep_helpers_awake: bool,
    /// `ParallelSettings::move_helpers_off_step_core` on.
    #[arg(long)]
    move_helpers_off: bool,
    /// Give the pool to the solver (`Solver::set_thread_pool`) instead of installing it.
    #[arg(long)]
    given_pool: bool,
}

/// The command line, parsed once.
fn args() -> &'static Args {
    static ARGS: std::sync::OnceLock<Args> = std::sync::OnceLock::new();
    ARGS.get_or_init(Args::parse)
}

/// Warm-up frames of each body, not measured.
const WARM_UP: usize = 2;

/// One body being stepped, with what its measured frames took.
struct Body {
    world: hecs::World,
    solver: Solver,
    /// ms per measured frame.
    times: Vec<f64>,
    /// ms per measured frame of prediction, copies, volume, vertex–face, edges, velocities.
    phases: [Vec<f64>; 6],
    /// Per measured frame (`sync-stats` builds; zeros otherwise): ms waiting at phase
    /// boundaries, ms closing passes, the share of chunks the helpers ran, and the helpers'
    /// moves off the stepping thread's core.
    waits: [Vec<f64>; 4],
    /// Phases of a sweep of the edges and of the tetrahedra.
    sweep_phases: (usize, usize),
}

/// A hanging cube (top face pinned) of `mesh` with the family set `set`.
fn body(
    mesh: &TetMesh,
    set: FamilySet,
    spatial: bool,
    parts: usize,
) -> Result<Body, Box<dyn std::error::Error>> {
    let top: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y > 0.4999)
        .collect();
    let b = SoftBodyBuilder::new(mesh.clone())
        .density(1000.0)
        .spatial_order(spatial)
        .parts(parts)
        .pinned(top);
    let b = match set {
        FamilySet::EdgesVolume => b.edges(1e-7).volume(1e-10),
        FamilySet::VertexFace => b.vertex_face(1e-7),
        FamilySet::Material => set.add_to(b),
    };
    let built = b.build()?;
    let sweep_phases = (
        built
            .edges
            .as_ref()
            .map_or(0, |e: &EdgeConstraints| e.classes().phase_count()),
        built.tetrahedra.classes().phase_count(),
    );
    let mut world = hecs::World::new();
    let e = built.spawn(&mut world);
    // Benchmarks time the solver on awake bodies: sleeping would end the work being measured.
    world
        .insert_one(e, tetpbd::Activation::never_sleeps())
        .expect("entity");
    let solver = Solver::new(SolverSettings {
        substeps: 10,
        parallel: tetpbd::ParallelSettings {
            keep_helpers_awake: args().keep_helpers_awake,
            move_helpers_off_step_core: args().move_helpers_off,
            ..Default::default()
        },
        safety: tetpbd::SafetySettings {
            limit_correction_energy: !args().no_energy_limit,
            ..Default::default()
        },
        ..Default::default()
    })?;
    Ok(Body {
        world,
        solver,
        times: Vec::new(),
        phases: Default::default(),
        waits: Default::default(),
        sweep_phases,
    })
}

impl Body {
    /// Steps one frame; records it unless `warm_up`.
    fn frame(&mut self, warm_up: bool) -> Result<(), Box<dyn std::error::Error>> {
        sync_take();
        let t = Instant::now();
        let s = self.solver.step(&mut self.world)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let waits = sync_take();
        if !warm_up {
            self.times.push(ms);
            for (v, p) in self.phases.iter_mut().zip(phase_ms(&s)) {
                v.push(p);
            }
            for (v, w) in self.waits.iter_mut().zip(waits) {
                v.push(w);
            }
        }
        Ok(())
    }
}

/// ms of phase waits and close waits since the last call, the share of the sweeps' chunks
/// that other threads than the stepping one ran, and how often a helper moved off the
/// stepping thread's core (zeros without `sync-stats`).
fn sync_take() -> [f64; 4] {
    #[cfg(feature = "sync-stats")]
    {
        let s = tetpbd::sync_stats::take();
        let [p, c] = [s.phase_wait, s.close_wait].map(|d| d.as_secs_f64() * 1e3);
        let share = s.chunks_elsewhere as f64 / s.chunks.max(1) as f64;
        [p, c, share, s.moves as f64]
    }
    #[cfg(not(feature = "sync-stats"))]
    [0.0; 4]
}

fn phase_ms(s: &StepStats) -> [f64; 6] {
    [
        s.predict_time,
        s.copy_time,
        s.volume.time,
        s.vertex_face.time,
        s.edge.time,
        s.velocity_time,
    ]
    .map(|d| d.as_secs_f64() * 1e3)
}

/// The `q`-quantile (0 ≤ q ≤ 1, nearest rank) of `v`.
fn quantile(v: &[f64], q: f64) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

fn median(v: &[f64]) -> f64 {
    quantile(v, 0.5)
}

/// CPU time, s, used so far by every process of the machine (`/proc/stat`, user + nice +
/// system + irq + softirq + steal; 0 where unreadable) and by this one (`getrusage`).
fn cpu_seconds() -> (f64, f64) {
    let all = std::fs::read_to_string("/proc/stat")
        .ok()
        .and_then(|s| {
            let line = s.lines().next()?.to_string();
            let v: Vec<f64> = line
                .split_whitespace()
                .skip(1)
                .filter_map(|x| x.parse().ok())
                .collect();
            // user nice system idle iowait irq softirq steal
            let busy = [0, 1, 2, 5, 6, 7]
                .iter()
                .filter_map(|&i| v.get(i))
                .sum::<f64>();
            Some(busy / 100.0)
        })
        .unwrap_or(0.0);
    // SAFETY: `getrusage` fills the zeroed struct it is given; RUSAGE_SELF is valid.
    let own = unsafe {
        let mut u: libc::rusage = std::mem::zeroed();
        libc::getrusage(libc::RUSAGE_SELF, &mut u);
        let t = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
        t(u.ru_utime) + t(u.ru_stime)
    };
    (all, own)
}

/// Runs `f` on `pool` (on this thread without one).
#[cfg(feature = "parallel")]
fn on<T: Send>(pool: &Option<Arc<rayon::ThreadPool>>, f: impl FnOnce() -> T + Send) -> T {
    match pool {
        Some(pool) => pool.install(f),
        None => f(),
    }
}

/// Measures `one` (and `two`, on a pool of two threads): interleaved frame by frame, or
/// one body after the other when `sequential`.
fn measure(
    one: &mut Body,
    two: Option<&mut Body>,
    frames: usize,
    sequential: bool,
) -> Result<(), String> {
    #[cfg(feature = "parallel")]
    {
        let pool = |n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .ok()
                .map(Arc::new)
        };
        let (p1, p2) = (pool(1), pool(2));
        let given = args().given_pool;
        let frame = |b: &mut Body, p: &Option<Arc<rayon::ThreadPool>>, warm: bool| {
            if given {
                b.solver.set_thread_pool(p.clone());
                b.frame(warm).map_err(|e| e.to_string())
            } else {
                on(p, || b.frame(warm).map_err(|e| e.to_string()))
            }
        };
        match two {
            Some(two) if !sequential => {
                for f in 0..frames + WARM_UP {
                    frame(one, &p1, f < WARM_UP)?;
                    frame(two, &p2, f < WARM_UP)?;
                }
            }
            two => {
                for f in 0..frames + WARM_UP {
                    frame(one, &p1, f < WARM_UP)?;
                }
                if let Some(two) = two {
                    for f in 0..frames + WARM_UP {
                        frame(two, &p2, f < WARM_UP)?;
                    }
                }
            }
        }
    }
    #[cfg(not(feature = "parallel"))]
    {
        let _ = (two, sequential);
        for f in 0..frames + WARM_UP {
            one.frame(f < WARM_UP).map_err(|e| e.to_string())?;
        }
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a = args();
    let (min_cells, max_cells, frames) = (a.min_cells, a.max_cells, a.frames as usize);
    let (parts, sequential, only) = (a.parts, a.sequential, a.set);
    let (shuffle, breakdown) = (a.shuffle, a.breakdown);
    let parallel = cfg!(feature = "parallel");
    let numbering = if shuffle { "shuffled" } else { "grid" };
    let mode = if !parallel {
        "1 thread only"
    } else if sequential {
        "1-thread frames, then 2-thread frames"
    } else {
        "1- and 2-thread frames interleaved"
    };
    println!("hanging cube ({numbering} numbering), top face pinned, 10 substeps × 1 iteration per 1/60 s frame; median of {frames} frames after {WARM_UP} warm-up ({mode}); parts {parts} (0 = builder's choice)");
    if parallel {
        println!(
            "keep helpers awake: {}, move helpers off the step's core: {}, pool {}",
            a.keep_helpers_awake,
            a.move_helpers_off,
            if a.given_pool {
                "given to the solver, stepped from the main thread"
            } else {
                "installed (stepped on a pool thread)"
            }
        );
    }
    println!("set           spatial order      tets  particles   1 thread ms/frame  ns/tet/substep   2 threads ms/frame  speed-up (quartiles)");
    for cells in [6u32, 12, 26, 55]
        .into_iter()
        .filter(|c| (min_cells..=max_cells).contains(c))
    {
        let mut mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Six)?;
        if shuffle {
            mesh = shuffled(&mesh, 1).0;
        }
        for (set, spatial) in [
            FamilySet::EdgesVolume,
            FamilySet::VertexFace,
            FamilySet::Material,
        ]
        .into_iter()
        .filter(|s| only.is_none_or(|o| o == *s))
        .flat_map(|s| orders(a.spatial_order).into_iter().map(move |o| (s, o)))
        {
            let mut one = body(&mesh, set, spatial, parts)?;
            let mut two = if parallel {
                Some(body(&mesh, set, spatial, parts)?)
            } else {
                None
            };
            let (all0, own0, wall0) = {
                let (a, o) = cpu_seconds();
                (a, o, Instant::now())
            };
            measure(&mut one, two.as_mut(), frames, sequential)?;
            let (all1, own1) = cpu_seconds();
            let wall = wall0.elapsed().as_secs_f64();
            // Cores' worth of CPU other processes used meanwhile (/proc/stat counts in
            // 10 ms ticks: about ±0.01 s over the run).
            let others = ((all1 - all0) - (own1 - own0)).max(0.0) / wall;
            let one_ms = median(&one.times);
            let per_tet = one_ms * 1e6 / (mesh.tets.len() as f64 * 10.0);
            let (two_s, speed) = match &two {
                Some(t) => {
                    let ratios: Vec<f64> = if sequential {
                        vec![one_ms / median(&t.times)]
                    } else {
                        one.times.iter().zip(&t.times).map(|(a, b)| a / b).collect()
                    };
                    (
                        format!("{:.2}", median(&t.times)),
                        format!(
                            "{:.2}× ({:.2}–{:.2})",
                            median(&ratios),
                            quantile(&ratios, 0.25),
                            quantile(&ratios, 0.75)
                        ),
                    )
                }
                None => ("-".to_string(), "-".to_string()),
            };
            println!(
                "{:13} {:13} {:9} {:10}   {one_ms:17.2}  {per_tet:14.1}   {two_s:>18}  {speed}  others {others:.2} cores over {wall:.1} s",
                set.name(),
                if spatial { "on" } else { "off" },
                mesh.tets.len(),
                mesh.vertices.len()
            );
            if a.per_frame {
                let two_times = two.as_ref().map_or(&[][..], |t| &t.times[..]);
                let shares = two.as_ref().map_or(&[][..], |t| &t.waits[2][..]);
                let moves = two.as_ref().map_or(&[][..], |t| &t.waits[3][..]);
                for (i, a) in one.times.iter().enumerate() {
                    let b = two_times
                        .get(i)
                        .map_or("-".to_string(), |b| format!("{b:.2}"));
                    let share = match (shares.get(i), moves.get(i)) {
                        (Some(s), Some(m)) if cfg!(feature = "sync-stats") => {
                            format!(
                                ", helpers ran {:.0} % of the chunks, moved {m} times",
                                s * 100.0
                            )
                        }
                        _ => String::new(),
                    };
                    println!("    frame {i:3}: 1 thread {a:.2} ms, 2 threads {b} ms{share}");
                }
            }
            if a.error {
                one.solver.settings.diagnostics.measure_error = true;
                let s = one.solver.step(&mut one.world)?;
                let f = |e: Option<tetpbd::ErrorStats>| {
                    e.map_or("-".to_string(), |e| {
                        format!("rms {:.3e} max {:.3e}", e.rms, e.max)
                    })
                };
                println!(
                    "    error after {} frames: edges {}  volume {}  vertex-face {}",
                    frames + WARM_UP + 1,
                    f(s.edge.after),
                    f(s.volume.after),
                    f(s.vertex_face.after)
                );
            }
            if breakdown {
                let (e, t) = one.sweep_phases;
                println!("    phases per sweep: {e} of edges, {t} of tetrahedra");
                for (threads, b) in [(1, Some(&one)), (2, two.as_ref())] {
                    let Some(b) = b else { continue };
                    let [pr, co, vo, vf, ed, ve] = b.phases.each_ref().map(|v| median(v));
                    let [pw, cw, share, _] = b.waits.each_ref().map(|v| median(v));
                    let waits = if cfg!(feature = "sync-stats") {
                        format!(
                            "  waits: phases {pw:.2} close {cw:.2}  helpers' chunks {:.0} %",
                            share * 100.0
                        )
                    } else {
                        String::new()
                    };
                    println!("    {threads} thread(s), ms/frame: predict {pr:.2}  copies {co:.2}  volume {vo:.2}  vertex-face {vf:.2}  edges {ed:.2}  velocities {ve:.2}{waits}");
                }
            }
        }
    }
    Ok(())
}
