//! Tearing: the slab of `tetpbd-bench`'s [`SlabPull`] (1 × 0.1 × 0.4 m on the ground, its ends
//! held by two kinematic boxes moving apart, tearing past a strain of 0.3) pulled apart at
//! 1, 5 and 20 m/s, in either engine. Measured: pieces, finite state, masses, rest shapes,
//! the fastest fragment, and the lowest particle over the ground during the run and at its end.
//!
//! The fastest fragment is judged against the pull and the energy the slab can hold: a piece
//! over the ground faster than the boxes, plus the recoil of the elastic energy the slab holds
//! at the tearing strain ([`PullFigures::recoil`]), plus [`FRAGMENT_SPEED_MARGIN`], has gained
//! energy the tear did not hold (a fragment flung past the ground's edge falls, and is not
//! counted). A bar stretched to strain `ε` and let go recoils at `ε c`, `c` its wave speed
//! ([`tetpbd::impact_speed::wave_speed`]): the speed at which its stored energy `½ M ε²` per
//! unit volume, all turned into motion of the same mass, moves it. Hard constraints store no
//! energy and get no recoil.

use tetpbd::{
    impact_speed, EdgeConstraints, NeoHookeanMaterial, Particles, SoftBodyBuilder, Tetrahedra,
    VertexFaceConstraints, VolumeConstraints,
};
use tetpbd_bench::{
    Fragment, SlabPull, TearEngine, TEAR_GROUND_HALF_EXTENTS, TEAR_STRAIN, TEAR_SUBSTEPS,
};

use super::body::Engine;
use crate::config::Config;
use crate::coupled::CoupledOutcome;

/// The speeds of the sweep, m/s.
pub const PULL_SPEEDS: [f32; 3] = [1.0, 5.0, 20.0];
/// Frames stepped after the boxes stop.
const SETTLE_FRAMES: usize = 120;
/// How far below the ground's top a particle over it may be, m.
const GROUND_TOLERANCE: f32 = 0.05;
/// How much faster than the boxes a fragment over the ground may move, m/s: about what a fall
/// of 5 cm adds (`√(2 g · 0.05 m)`), the slab's height over the ground at its start.
pub const FRAGMENT_SPEED_MARGIN: f32 = 1.0;
/// A piece faster than this, m/s, has blown up: the run stops there (its cost grows with the
/// space the fragments fill) and fails.
pub const BLOWN_UP_SPEED: f32 = 1000.0;

/// What one pull measured.
#[derive(Clone, Debug, PartialEq)]
pub struct PullFigures {
    /// Speed of each box, m/s.
    pub speed: f32,
    /// The slab's recoil at the tearing strain, m/s: [`TEAR_STRAIN`] × its wave speed, 0 for
    /// hard constraints (they hold no elastic energy) and for rapier's slab.
    pub recoil: f32,
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
    /// Fastest centre of mass of a piece whose centre of mass is over the ground, over the
    /// run, m/s.
    pub fastest_over_ground: f32,
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

    /// The speed no fragment over the ground may exceed, m/s: the boxes', plus the slab's
    /// [`PullFigures::recoil`], plus [`FRAGMENT_SPEED_MARGIN`].
    pub fn speed_limit(&self) -> f32 {
        self.speed + self.recoil + FRAGMENT_SPEED_MARGIN
    }

    /// No fragment over the ground faster than [`PullFigures::speed_limit`].
    pub fn no_faster_than_the_pull(&self) -> bool {
        self.fastest_over_ground <= self.speed_limit()
    }
}

/// The slab's recoil at the tearing strain, m/s ([`PullFigures::recoil`]): the largest over
/// the soft bodies of the scene (one before it tears).
fn recoil(scene: &mut SlabPull) -> f32 {
    type Body<'a> = (
        &'a Particles,
        &'a Tetrahedra,
        Option<&'a EdgeConstraints>,
        Option<&'a VertexFaceConstraints>,
        Option<&'a VolumeConstraints>,
        Option<&'a NeoHookeanMaterial>,
    );
    let mut out = 0.0f32;
    for (p, t, e, vf, vol, m) in scene.world.soft.query_mut::<Body<'_>>() {
        let c = impact_speed::wave_speed(p, t, e, vf, vol, m);
        if c.is_finite() {
            out = out.max(TEAR_STRAIN * c);
        }
    }
    out
}

/// Whether the centre of mass of `f` is over the ground's top face.
fn over_ground(f: &Fragment) -> bool {
    let m: f32 = f.masses.iter().sum();
    if m <= 0.0 {
        return false;
    }
    let c = f
        .positions
        .iter()
        .zip(&f.masses)
        .fold(nalgebra::Vector3::zeros(), |acc, (x, &w)| acc + x * w)
        / m;
    let [gx, _, gz] = TEAR_GROUND_HALF_EXTENTS;
    c.x.abs() < gx && c.z.abs() < gz
}

/// Pulls the slab apart at `speed` m/s in `engine` (`tetpbd` with `families`, or rapier) and
/// lets it settle 2 s.
pub fn pull_apart(
    engine: TearEngine,
    speed: f32,
    families: impl FnOnce(SoftBodyBuilder) -> SoftBodyBuilder,
) -> Result<PullFigures, String> {
    pull_apart_in(engine, speed, TEAR_SUBSTEPS, families)
}

/// [`pull_apart`] with `substeps` soft substeps per frame (`tetpbd`; rapier's slab keeps the
/// scene's solver iterations).
pub fn pull_apart_in(
    engine: TearEngine,
    speed: f32,
    substeps: u32,
    families: impl FnOnce(SoftBodyBuilder) -> SoftBodyBuilder,
) -> Result<PullFigures, String> {
    let mut scene = SlabPull::new(engine, speed, families)?;
    scene.world.coupling.solver_mut().settings.substeps = substeps;
    let mut f = PullFigures {
        speed,
        recoil: recoil(&mut scene),
        events: 0,
        pieces: 0,
        finite: true,
        min_mass: 0.0,
        inverted_rest: 0,
        inverted: 0,
        fastest_fragment: 0.0,
        fastest_over_ground: 0.0,
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
        let over = pieces
            .iter()
            .filter(|p| over_ground(p))
            .map(Fragment::speed);
        f.fastest_over_ground = over.fold(f.fastest_over_ground, f32::max);
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
/// it ([`PullFigures::on_the_ground`]), and had no fragment over the ground faster than the
/// boxes plus the slab's recoil plus [`FRAGMENT_SPEED_MARGIN`]
/// ([`PullFigures::no_faster_than_the_pull`]). The
/// fastest fragment is the peak speed.
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
            && (speed > 5.0 || f.on_the_ground())
            && f.no_faster_than_the_pull();
        cols[0].push(f.pieces.to_string());
        cols[1].push(if f.blown_up {
            format!("> {BLOWN_UP_SPEED:.0} (stopped)")
        } else {
            format!(
                "{:.1} ({:.1} over the ground, limit {:.1})",
                f.fastest_fragment,
                f.fastest_over_ground,
                f.speed_limit()
            )
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
