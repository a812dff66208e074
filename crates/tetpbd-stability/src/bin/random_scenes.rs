//! `cargo run --release -p tetpbd-stability --bin random_scenes [-- --scenes N]`
//!
//! Seeded random coupled scenes at default settings, a search for failures outside the
//! suite's cases: soft bodies of random size, aspect, density, mesh split, families (the
//! seed's combinations, hard and compliant), speed, pose and spin dropped on a wide fixed
//! ground, on dynamic boxes of random mass, on each other, and rigid cubes of random mass
//! and speed thrown at them. Each scene runs 4 s and is flagged when a step errs or the
//! energy goes non-finite, the total mechanical energy (kinetic + gravitational, soft and
//! rigid) rises more than 1 % of its scale, a soft particle ends more than 3 cm below the
//! ground, anything moves faster than 1.2 × what the start's speed and height allow (+5 m/s),
//! or anything still moves faster than 5 cm/s in the last second (the scenes are
//! `tetpbd_stability::random_scenes`; the `random_scenes` test holds the first 200 to their
//! known flags). It prints one line per scene and the count of each flag. `--scene K` runs one scene,
//! `--trace` prints it frame by frame, `--substeps` and `--family` override the draw.

use tetpbd_stability::random_scenes;

/// Options of the command line.
#[derive(clap::Parser, Debug)]
#[command(about = "Seeded random coupled scenes at default settings, flagged when they misbehave")]
struct Options {
    /// Number of scenes (seeds 0..N).
    #[arg(long, default_value_t = 40)]
    scenes: u64,
    /// Run only this scene.
    #[arg(long)]
    scene: Option<u64>,
    /// Override the drawn substep count.
    #[arg(long)]
    substeps: Option<u32>,
    /// Override the drawn family combination: 0 hard edges + volume, 1 compliant edges +
    /// volume, 2 hard edges + vertex–face, 3 compliant vertex–face + hard volume.
    #[arg(long)]
    family: Option<u64>,
    /// Print the chosen scene frame by frame.
    #[arg(long)]
    trace: bool,
    /// With `--trace`: also print every body's kinetic energy after each substep of the
    /// frames from this one on (to `--substeps-until`).
    #[arg(long)]
    substeps_from: Option<u32>,
    /// Last frame whose substeps `--substeps-from` prints.
    #[arg(long, default_value_t = u32::MAX)]
    substeps_until: u32,
}

fn main() {
    let opts = <Options as clap::Parser>::parse();
    let names = random_scenes::FLAGS;
    let scene_options = random_scenes::Options {
        substeps: opts.substeps,
        family: opts.family,
        trace: opts.trace,
        substeps_from: opts.substeps_from,
        substeps_until: opts.substeps_until,
    };
    let mut counts = [0usize; 5];
    let mut flagged = 0usize;
    let mut run = 0usize;
    for k in (0..opts.scenes).filter(|k| opts.scene.is_none_or(|o| o == *k)) {
        let (what, o) = random_scenes::run(k, &scene_options);
        let flags = o.flags();
        let found: Vec<&str> = names
            .iter()
            .zip(flags)
            .filter(|(_, f)| *f)
            .map(|(n, _)| *n)
            .collect();
        for (c, f) in counts.iter_mut().zip(flags) {
            *c += usize::from(f);
        }
        run += 1;
        flagged += usize::from(!found.is_empty());
        println!(
            "{} {what}gain {:.2e} of {:.2e} J, lowest {:.3} m, end speed {:.3} m/s, fastest {:.1} of {:.1} m/s{}{}",
            if found.is_empty() { "ok  " } else { "FLAG" },
            o.gain,
            o.scale,
            o.lowest_end,
            o.end_speed,
            o.fastest,
            o.start_speed,
            if found.is_empty() { String::new() } else { format!(" {found:?}") },
            o.error.map_or(String::new(), |e| format!(" ({e})")),
        );
    }
    println!("{flagged} of {run} scenes flagged");
    for (n, c) in names.iter().zip(counts) {
        println!("  {n}: {c}");
    }
}
