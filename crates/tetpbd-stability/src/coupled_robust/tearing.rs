//! Tearing: the slab of `tetpbd-bench`'s [`SlabPull`] (1 × 0.1 × 0.4 m on the ground, its ends
//! held by two kinematic boxes moving apart, tearing past a strain of 0.3) pulled apart at
//! 1, 5 and 20 m/s, in either engine. Measured: pieces, finite state, masses, rest shapes,
//! the fastest fragment, and the lowest particle over the ground during the run and at its end.
//!
//! Known limit, reported rather than judged: the elastic energy a stiff slab stores before a
//! face tears is released into the fragments, which can leave at 20–40 m/s when the boxes
//! pull at 20 m/s.

use tetpbd::SoftBodyBuilder;
use tetpbd_bench::{Fragment, SlabPull, TearEngine};

use super::body::Engine;
use crate::config::Config;
use crate::coupled::CoupledOutcome;

/// The speeds of the sweep, m/s.
pub const PULL_SPEEDS: [f32; 3] = [1.0, 5.0, 20.0];
/// Frames stepped after the boxes stop.
const SETTLE_FRAMES: usize = 120;
/// How far below the ground's top a particle over it may be, m.
const GROUND_TOLERANCE: f32 = 0.05;
/// A piece faster than this, m/s, has blown up: the run stops there (its cost grows with the
/// space the fragments fill) and fails.
pub const BLOWN_UP_SPEED: f32 = 1000.0;

/// What one pull measured.
#[derive(Clone, Debug, PartialEq)]
pub struct PullFigures {
    /// Speed of each box, m/s.
    pub speed: f32,
    /// Tear events over the run.
    pub events: usize,
    /// Pieces at the end.
    pub pieces: usize,
    /// Every particle finite at every frame, and every step succeeded.
    pub finite: bool,
    /// Lightest particle at the end, kg.
    pub min_mass: f32,
    /// Tetrahedra with an inverted rest shape at the end.
    pub inverted_rest: usize,
    /// Tetrahedra inverted (against their rest shape) at the end.
    pub inverted: usize,
    /// Fastest centre of mass of a piece over the run, m/s.
    pub fastest_fragment: f32,
    /// Fastest centre of mass of a piece at the end, m/s.
    pub final_fastest: f32,
    /// Lowest particle over the ground's top face over the run, m (the ground is at 0).
    pub lowest: f32,
    /// Lowest particle over the ground's top face at the end, m.
    pub final_lowest: f32,
    /// A piece passed [`BLOWN_UP_SPEED`], and the run was stopped there.
    pub blown_up: bool,
}

impl PullFigures {
    /// At the end, no particle over the ground more than 5 cm below it: no
    /// piece sank into it. (While the slab tears, a compliant slab's particles may dip
    /// deeper for a few frames: [`PullFigures::lowest`].)
    pub fn on_the_ground(&self) -> bool {
        self.final_lowest > -GROUND_TOLERANCE
    }
}

/// Pulls the slab apart at `speed` m/s in `engine` (`tetpbd` with `families`, or rapier) and
/// lets it settle 2 s.
pub fn pull_apart(
    engine: TearEngine,
    speed: f32,
    families: impl FnOnce(SoftBodyBuilder) -> SoftBodyBuilder,
) -> Result<PullFigures, String> {
    let mut scene = SlabPull::new(engine, speed, families)?;
    let mut f = PullFigures {
        speed,
        events: 0,
        pieces: 0,
        finite: true,
        min_mass: 0.0,
        inverted_rest: 0,
        inverted: 0,
        fastest_fragment: 0.0,
        final_fastest: 0.0,
        lowest: f32::INFINITY,
        final_lowest: f32::INFINITY,
        blown_up: false,
    };
    for _ in 0..scene.pull_frames() + SETTLE_FRAMES {
        match scene.step() {
            Ok(tears) => f.events += tears.len(),
            Err(_) => {
                f.finite = false;
                break;
            }
        }
        let pieces = scene.fragments();
        f.finite &= pieces.iter().all(Fragment::finite);
        f.final_fastest = pieces.iter().map(Fragment::speed).fold(0.0, f32::max);
        f.fastest_fragment = f.fastest_fragment.max(f.final_fastest);
        f.final_lowest = pieces
            .iter()
            .map(Fragment::lowest_over_ground)
            .fold(f32::INFINITY, f32::min);
        f.lowest = f.lowest.min(f.final_lowest);
        if f.final_fastest > BLOWN_UP_SPEED {
            f.blown_up = true;
            break;
        }
    }
    let pieces = scene.fragments();
    f.pieces = pieces.len();
    f.min_mass = pieces
        .iter()
        .flat_map(|p| p.masses.iter().copied())
        .fold(f32::INFINITY, f32::min);
    f.inverted_rest = pieces.iter().map(|p| p.inverted_rest).sum();
    f.inverted = pieces.iter().map(|p| p.inverted).sum();
    Ok(f)
}

/// The sweep over [`PULL_SPEEDS`] as a case's outcome: passes when every run stayed finite,
/// came apart (more than one piece), kept every mass positive and every rest shape and
/// tetrahedron uninverted, and, up to 5 m/s, ended with every particle over the ground on
/// it ([`PullFigures::on_the_ground`]). The fastest fragment is the peak speed.
pub(crate) fn pulled_apart(engine: Engine) -> Result<CoupledOutcome, String> {
    let mut out = CoupledOutcome {
        finite: true,
        ..CoupledOutcome::default()
    };
    let mut ok = true;
    let mut cols: [Vec<String>; 3] = Default::default();
    for speed in PULL_SPEEDS {
        let f = match engine {
            Engine::Tetpbd(c) => {
                let c: Config = *c;
                pull_apart(TearEngine::Tetpbd, speed, move |b| c.apply(b, 1.0))?
            }
            Engine::Rapier => pull_apart(TearEngine::Rapier, speed, SlabPull::stiff)?,
        };
        out.finite &= f.finite;
        out.peak_speed = out.peak_speed.max(f.fastest_fragment);
        out.final_speed = out.final_speed.max(f.final_fastest);
        out.inverted += f.inverted;
        ok &= !f.blown_up
            && f.pieces > 1
            && f.min_mass > 0.0
            && f.inverted_rest == 0
            && (speed > 5.0 || f.on_the_ground());
        cols[0].push(f.pieces.to_string());
        cols[1].push(if f.blown_up {
            format!("> {BLOWN_UP_SPEED:.0} (stopped)")
        } else {
            format!("{:.1}", f.fastest_fragment)
        });
        cols[2].push(format!("{:.2}→{:.2}", f.lowest, f.final_lowest));
    }
    out.criterion = (
        ok,
        format!(
            "pieces {}, fastest fragment {} m/s, lowest particle (over the run→at the end) {} m",
            cols[0].join("/"),
            cols[1].join("/"),
            cols[2].join("/")
        ),
    );
    Ok(out)
}
