//! Running one scene under one configuration and measuring it.

use nalgebra::Vector3;
use tetpbd::{
    Particles, SoftBody, SoftBodyBuilder, Solver, SolverSettings, StateError, StepStats, TetMesh,
    Tetrahedra,
};

use crate::config::Config;

/// How the body starts, relative to its rest pose.
#[derive(Clone, Debug, PartialEq)]
pub enum Start {
    /// At rest.
    Rest,
    /// Mirrored through the plane x = 0: every tetrahedron inverted.
    Mirrored,
    /// Flattened onto the plane y = 0.
    Flattened,
    /// Every vertex at one point.
    Collapsed,
    /// Every vertex at a deterministic pseudo-random point inside a cube of this half size, m.
    Scrambled(f32),
    /// One vertex moved by this offset, m.
    Dragged(u32, Vector3<f32>),
}

/// One scene: a mesh, how it starts, and how it is stepped.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The mesh.
    pub mesh: TetMesh,
    /// Pinned vertices.
    pub pinned: Vec<u32>,
    /// The initial state.
    pub start: Start,
    /// Solver settings (frame dt, substeps, gravity, safety net).
    pub settings: SolverSettings,
    /// Frames to run.
    pub frames: usize,
    /// Multiplies the soft compliances (1 = the configuration's own).
    pub compliance_scale: f32,
    /// Multiplies the soft volume compliance on top of [`Scene::compliance_scale`] (1: the
    /// same scale for every family).
    pub volume_compliance_scale: f32,
    /// Relative volume epsilon of the builder.
    pub epsilon: f32,
    /// The case demands recovery: no inverted tetrahedron and volume within 1 % at the end.
    pub require_recovery: bool,
    /// The body falls freely for the whole run: the reference energy is `½M(g t)²`.
    pub free_fall: bool,
    /// Initial velocity of every particle, m/s.
    pub velocity: Vector3<f32>,
    /// An immovable ground at y = 0 ([`crate::ground::Ground`]); the body must end intact
    /// (as [`Scene::require_recovery`] asks) and never rise faster than it came.
    pub ground: bool,
}

impl Scene {
    /// A scene with default settings: 60 frames of 1/60 s, 10 substeps, gravity, no safety net.
    pub fn new(mesh: TetMesh) -> Scene {
        Scene {
            mesh,
            pinned: Vec::new(),
            start: Start::Rest,
            settings: SolverSettings::default(),
            frames: 60,
            compliance_scale: 1.0,
            volume_compliance_scale: 1.0,
            epsilon: SoftBodyBuilder::DEFAULT_EPSILON,
            require_recovery: false,
            free_fall: false,
            velocity: Vector3::zeros(),
            ground: false,
        }
    }
}

/// What one run measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outcome {
    /// The builder's error, if the mesh was rejected (a clean outcome, not a failure).
    pub build_error: Option<String>,
    /// The solver's settings error, if rejected.
    pub settings_error: Option<String>,
    /// Every position and velocity finite at every frame.
    pub finite: bool,
    /// Non-finite resets the solver's safety net made.
    pub non_finite_resets: u64,
    /// Velocity clamps the correction-speed safety net made.
    pub velocity_clamps: u64,
    /// Peak kinetic energy over the run divided by the reference energy
    /// `max(KE₀, M·9.81 m/s²·L, ½M(g t)² for free fall)`, with L the rest bounding-box diagonal.
    pub peak_ke_ratio: f32,
    /// First frame with no inverted tetrahedron and total volume within 1 % of rest.
    pub recovered_at: Option<usize>,
    /// Inverted tetrahedra at the end.
    pub final_inverted: usize,
    /// |total volume / rest − 1| at the end; for a body thrown at the ground, |total volume /
    /// the volume of the same body set down at rest ([`Outcome::resting_volume_ratio`]) − 1|.
    pub final_volume_error: f32,
    /// Total volume / rest volume at the end; for a body on the ground, once settled
    /// ([`crate::settle`]).
    pub final_volume_ratio: f32,
    /// For a body thrown at the ground: its [`Outcome::final_volume_ratio`] when set down on
    /// the ground at rest instead (the same scene without the throw).
    pub resting_volume_ratio: Option<f32>,
    /// For a body thrown at the ground: the peak internal kinetic energy of the same body set
    /// down on the ground at rest instead, divided by this run's reference energy (its own
    /// settling oscillation, which [`Outcome::calm`] does not count against the impact).
    pub resting_internal_ratio: Option<f32>,
    /// The reference energy the ratios are taken against, J.
    pub reference: f32,
    /// Final max |C| per family (edge m, vertex–face m, volume m³), where present.
    pub final_max_c: [Option<f32>; 3],
    /// Largest particle speed at the end, m/s.
    pub final_max_speed: f32,
    /// Kinetic energy at the end divided by the reference energy.
    pub final_ke_ratio: f32,
    /// Peak over the run of the internal kinetic energy
    /// ([`crate::energy::internal_kinetic`]: relative to the body's best-fit rigid motion)
    /// divided by the reference energy.
    pub peak_internal_ratio: f32,
    /// Internal kinetic energy at the end divided by the reference energy.
    pub final_internal_ratio: f32,
    /// Whether the case demanded recovery.
    pub require_recovery: bool,
    /// Largest rise of the kinetic + gravitational energy ([`crate::energy::motion`]) over the
    /// whole mechanical energy at the start (with the elastic energy of the compliant
    /// constraints, [`crate::energy::mechanical`]), divided by the reference energy: what
    /// the body gained without external work (pins do none, the ground only removes
    /// energy). At most rounding.
    pub energy_gain: f32,
    /// For a body thrown at the ground: its speed of approach and the largest upward speed
    /// of its centre of mass afterwards, m/s.
    pub rebound: Option<(f32, f32)>,
    /// Substeps per frame the run used ([`substeps_for`]).
    pub substeps: u32,
}

impl Outcome {
    /// Energy bound: the peak kinetic energy may not exceed this multiple of the reference.
    pub const ENERGY_BOUND: f32 = 10.0;

    /// Bound of [`Outcome::energy_gain`]: rounding of f32 positions (the free fall's
    /// potential energy alone is `M g y` with `y` hundreds of metres).
    pub const ENERGY_GAIN_BOUND: f32 = 1e-3;

    /// Kinetic energy at the end, as a fraction of the reference, below which a released
    /// body counts as at rest whatever its peak.
    pub const AT_REST: f32 = 1e-6;

    /// Whether the energy never rose above its start and a thrown body never rose faster
    /// than it came.
    pub fn energy_kept(&self) -> bool {
        self.energy_gain <= Self::ENERGY_GAIN_BOUND
            && self.rebound.is_none_or(|(came, rose)| rose < came)
    }

    /// Recovered at the end: no inverted tetrahedron and total volume within 1 % (of the
    /// volume the same body keeps set down at rest, for a body thrown at the ground:
    /// [`Outcome::final_volume_error`]).
    pub fn intact(&self) -> bool {
        self.final_inverted == 0 && self.final_volume_error < 0.01
    }

    /// Finite throughout with no non-finite reset, no inverted tetrahedron at the end and
    /// [`Self::energy_kept`]; then for a body started at rest, peak kinetic energy ≤
    /// [`Self::ENERGY_BOUND`] × the reference; for a body released from a deformed state or
    /// thrown at the ground, recovered at the end ([`Self::intact`]) and calm
    /// ([`Self::calm`]). A mesh the builder rejected with a typed error passes (a clean
    /// outcome).
    pub fn pass(&self) -> bool {
        self.pass_but_shape() && (!self.require_recovery || self.intact())
    }

    /// Finite throughout, no non-finite reset, and [`Self::energy_kept`]: what every cell
    /// holds, the vertex–face family alone thrown at the ground included.
    pub fn sound(&self) -> bool {
        self.finite && self.non_finite_resets == 0 && self.energy_kept()
    }

    /// Calm at the end. A released body: its kinetic energy decayed to ≤ 10 % of its peak
    /// or below [`Self::AT_REST`] × the reference. A body thrown at the ground may still fly
    /// or roll when the run ends (it rebounds, slower than it came): what must have decayed
    /// is its internal kinetic energy, the motion relative to its best-fit rigid motion
    /// ([`crate::energy::internal_kinetic`]), to ≤ 10 % of its peak (the impact) or below
    /// [`Self::AT_REST`] × the reference, or to no more than the same body set down on the
    /// ground at rest reaches ([`Outcome::resting_internal_ratio`]: a soft, barely damped
    /// body still sways from landing at the end, as it does set down). A body still
    /// jiggling from the impact, spinning itself apart or crushed keeps internal kinetic
    /// energy and is not calm.
    pub fn calm(&self) -> bool {
        let (peak, last) = if self.rebound.is_some() {
            (self.peak_internal_ratio, self.final_internal_ratio)
        } else {
            (self.peak_ke_ratio, self.final_ke_ratio)
        };
        let resting = self.resting_internal_ratio.unwrap_or(0.0);
        last <= 0.1 * peak || last <= Self::AT_REST || last <= resting
    }

    /// [`Self::pass`] without the shape: what a body that need not recover its shape (the
    /// vertex–face family alone) must still hold — finite, no energy gained, calm.
    pub fn pass_but_shape(&self) -> bool {
        if self.build_error.is_some() || self.settings_error.is_some() {
            return true;
        }
        let base = self.sound();
        if self.require_recovery {
            base && self.calm()
        } else {
            base && self.final_inverted == 0 && self.peak_ke_ratio <= Self::ENERGY_BOUND
        }
    }
}

fn hash_unit(mut s: u64) -> f32 {
    s ^= s >> 33;
    s = s.wrapping_mul(0xff51_afd7_ed55_8ccd);
    s ^= s >> 33;
    s = s.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    s ^= s >> 33;
    (s >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
}

/// What [`run_scene_observed`] shows its observer after each frame.
pub struct FrameView<'a> {
    /// The frame just stepped, from 1.
    pub frame: usize,
    /// The solver's statistics of that frame (errors measured).
    pub stats: &'a StepStats,
    /// The body's particles after it.
    pub particles: &'a Particles,
    /// The reference energy the outcome's kinetic energy ratios are taken against, J.
    pub reference: f32,
    /// Total volume / rest volume after it.
    pub volume_ratio: f32,
}

impl Start {
    /// Moves the particles of `p` to this start, `centre` the centre of the rest bounding
    /// box (mirroring plane, flattening plane, collapse point, scrambling box).
    pub fn apply(&self, p: &mut Particles, centre: Vector3<f32>) -> Result<(), StateError> {
        for i in 0..p.len() {
            let x = p.positions()[i];
            let y = match self {
                Start::Rest => x,
                Start::Mirrored => Vector3::new(2.0 * centre.x - x.x, x.y, x.z),
                Start::Flattened => Vector3::new(x.x, centre.y, x.z),
                Start::Collapsed => centre,
                Start::Scrambled(half) => {
                    let s = i as u64 * 3;
                    centre + Vector3::new(hash_unit(s), hash_unit(s + 1), hash_unit(s + 2)) * *half
                }
                Start::Dragged(v, offset) if *v as usize == i => x + offset,
                Start::Dragged(..) => x,
            };
            p.set_position(i, y)?;
        }
        Ok(())
    }
}

/// The substeps per frame a body runs with: the scene's, or for a body with the Neo-Hookean
/// material at least `dt / max_stable_substep` (as the README tells integrators to choose
/// them: the material is explicit in shear).
pub fn stable_substeps(body: &SoftBody, settings: &SolverSettings) -> u32 {
    let Some(m) = &body.material else {
        return settings.substeps;
    };
    let h = m.max_stable_substep(&body.tetrahedra, &body.particles);
    let needed = (settings.dt / h).ceil();
    if needed.is_finite() && needed >= 1.0 {
        settings.substeps.max(needed.min(u32::MAX as f32) as u32)
    } else {
        settings.substeps
    }
}

/// The substeps per frame `scene` runs with under `config` ([`stable_substeps`]; the
/// scene's own if the body cannot be built).
pub fn substeps_for(scene: &Scene, config: &Config) -> u32 {
    builder(scene, config)
        .build()
        .map_or(scene.settings.substeps, |b| {
            stable_substeps(&b, &scene.settings)
        })
}

fn builder(scene: &Scene, config: &Config) -> SoftBodyBuilder {
    let builder = SoftBodyBuilder::new(scene.mesh.clone())
        .density(1000.0)
        .pinned(scene.pinned.iter().copied())
        .volume_epsilon(scene.epsilon);
    let scale = scene.compliance_scale;
    config.apply_scaled(builder, scale, scale * scene.volume_compliance_scale)
}

/// Runs `scene` under `config`.
pub fn run_scene(scene: &Scene, config: &Config) -> Outcome {
    run_scene_observed(scene, config, |_| {})
}

/// [`run_scene`], calling `observe` after every frame it steps: how a diagnostic traces a
/// run frame by frame. The outcome is the same as [`run_scene`]'s.
pub fn run_scene_observed(
    scene: &Scene,
    config: &Config,
    mut observe: impl FnMut(&FrameView<'_>),
) -> Outcome {
    let mut out = Outcome {
        finite: true,
        require_recovery: scene.require_recovery || scene.ground,
        ..Outcome::default()
    };
    // A thrown body is compared with the same body set down at rest: the volume it keeps
    // there (soft tissue under its own weight, a hard body's sag at one substep) is not
    // the impact's doing.
    if scene.ground && scene.velocity != Vector3::zeros() {
        let resting = Scene {
            velocity: Vector3::zeros(),
            ..scene.clone()
        };
        let r = run_scene(&resting, config);
        out.resting_volume_ratio = Some(r.final_volume_ratio);
        out.resting_internal_ratio = Some(r.peak_internal_ratio * r.reference);
    }
    let resting = out.resting_volume_ratio.unwrap_or(1.0);
    let body = match builder(scene, config).build() {
        Ok(b) => b,
        Err(e) => {
            out.build_error = Some(e.to_string());
            return out;
        }
    };
    let mut settings = scene.settings.clone();
    settings.substeps = stable_substeps(&body, &settings);
    out.substeps = settings.substeps;
    let mut solver = match Solver::new(settings) {
        Ok(s) => s,
        Err(e) => {
            out.settings_error = Some(e.to_string());
            return out;
        }
    };
    solver.settings.diagnostics.measure_error = true;
    let (lo, hi) = body.particles.aabb();
    let size = (hi - lo).norm().max(1e-9);
    let mass = body.particles.total_mass();
    let mut world = hecs::World::new();
    let e = body.spawn(&mut world);
    {
        let Ok(mut p) = world.get::<&mut Particles>(e) else {
            return out;
        };
        if scene.start.apply(&mut p, (lo + hi) / 2.0).is_err() {
            out.finite = false;
            return out;
        }
        for i in 0..p.len() {
            if p.set_velocity(i, scene.velocity).is_err() {
                out.finite = false;
                return out;
            }
        }
    }
    let e0 = crate::energy::mechanical(&world, e, scene.settings.gravity);
    let mut gain = 0.0f64;
    let came = (-scene.velocity.y).max(0.0);
    let mut rose = f32::NEG_INFINITY;
    let ke0 = world
        .get::<&Particles>(e)
        .map_or(0.0, |p| p.kinetic_energy());
    let g = scene.settings.gravity.norm();
    let t_end = scene.frames as f32 * scene.settings.dt;
    let mut reference = ke0.max(mass * 9.81 * size);
    if scene.free_fall {
        reference = reference.max(0.5 * mass * (g * t_end).powi(2));
    }
    let mut peak = 0.0f32;
    let mut peak_internal = 0.0f64;
    let mut ground = crate::ground::Ground::default();
    for frame in 1..=scene.frames {
        let stepped = if scene.ground {
            solver.step_with(&mut world, &mut ground)
        } else {
            solver.step(&mut world)
        };
        gain = gain.max(crate::energy::motion(&world, e, scene.settings.gravity) - e0);
        let stats = match stepped {
            Ok(s) => s,
            Err(err) => {
                out.settings_error = Some(err.to_string());
                return out;
            }
        };
        out.non_finite_resets += stats.non_finite_resets;
        out.velocity_clamps += stats.velocity_clamps;
        let (Ok(p), Ok(t)) = (world.get::<&Particles>(e), world.get::<&Tetrahedra>(e)) else {
            return out;
        };
        let finite = p
            .positions()
            .iter()
            .chain(p.velocities())
            .all(|x| x.iter().all(|c| c.is_finite()));
        out.finite &= finite;
        peak = peak.max(p.kinetic_energy());
        peak_internal = peak_internal
            .max(crate::energy::internal_kinetic(&p))
            .max(ground.peak_internal());
        rose = rose.max(p.linear_momentum().y / mass.max(f32::MIN_POSITIVE));
        out.final_inverted = stats.inverted.unwrap_or(0);
        out.final_volume_ratio = t.volume_ratio(p.positions());
        out.final_volume_error = (t.volume_ratio(p.positions()) / resting - 1.0).abs();
        if out.recovered_at.is_none() && out.final_inverted == 0 && out.final_volume_error < 0.01 {
            out.recovered_at = Some(frame);
        }
        let max = |s: &tetpbd::FamilyStats| (s.count > 0).then(|| s.after.map_or(0.0, |e| e.max));
        out.final_max_c = [
            max(&stats.edge),
            max(&stats.vertex_face),
            max(&stats.volume),
        ];
        out.final_max_speed = p.max_speed();
        observe(&FrameView {
            frame,
            stats: &stats,
            particles: &p,
            reference,
            volume_ratio: out.final_volume_ratio,
        });
    }
    out.peak_ke_ratio = peak / reference;
    out.energy_gain = (gain / f64::from(reference)) as f32;
    if scene.ground {
        out.rebound = Some((came, rose));
    }
    let (last, last_internal) = world
        .get::<&Particles>(e)
        .map_or((f32::INFINITY, f64::INFINITY), |p| {
            (p.kinetic_energy(), crate::energy::internal_kinetic(&p))
        });
    out.final_ke_ratio = last / reference;
    out.peak_internal_ratio = (peak_internal / f64::from(reference)) as f32;
    out.final_internal_ratio = (last_internal / f64::from(reference)) as f32;
    out.reference = reference;
    if let Some(r) = out.resting_internal_ratio.as_mut() {
        *r /= reference;
    }
    if scene.ground {
        crate::settle::settle(&mut solver, &mut world, e, &mut ground, &mut out, resting);
    }
    out
}
