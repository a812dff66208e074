//! Seeded random coupled scenes at default settings, a search for failures outside the
//! suite's cases (`cargo run --release -p tetpbd-stability --bin random_scenes`; the
//! `random_scenes` test holds the first 200 to their known flags).
//!
//! Soft bodies of random size, aspect, density, mesh split, families (the seed's
//! combinations, hard and compliant), speed, pose and spin dropped on a wide fixed ground, on
//! dynamic boxes of random mass, on each other, and rigid cubes of random mass and speed
//! thrown at them. Each scene runs 4 s and is flagged ([`Outcome::flags`]) when a step errs
//! or the energy goes non-finite, the total mechanical energy (kinetic + gravitational, soft
//! and rigid) rises more than 1 % of its scale, a soft particle ends more than 3 cm below the
//! ground, anything still moves faster than 5 cm/s in the last second, or anything moves
//! faster than 1.2 × what the start's speed and height allow (+5 m/s).

mod trace;

use nalgebra::{UnitQuaternion, Vector3};
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyHandle};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings};

use crate::Draws;

/// What may be overridden in a scene's draw, and what is printed while it runs.
#[derive(Clone, Debug)]
pub struct Options {
    /// The substep count instead of the drawn one.
    pub substeps: Option<u32>,
    /// The family combination instead of the drawn one: 0 hard edges + volume, 1 compliant
    /// edges + volume, 2 hard edges + vertex–face, 3 compliant vertex–face + hard volume.
    pub family: Option<u64>,
    /// Print the scene frame by frame.
    pub trace: bool,
    /// With `trace`: also print every body's kinetic energy after each substep of the
    /// frames from this one on, to `substeps_until`.
    pub substeps_from: Option<u32>,
    /// Last frame whose substeps `substeps_from` prints.
    pub substeps_until: u32,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            substeps: None,
            family: None,
            trace: false,
            substeps_from: None,
            substeps_until: u32::MAX,
        }
    }
}

/// The names of [`Outcome::flags`], in order.
pub const FLAGS: [&str; 5] = [
    "error",
    "energy gain",
    "below ground",
    "moving at 4 s",
    "launched",
];

/// What a scene measured.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    /// Largest rise of the total mechanical energy (kinetic + gravitational) over its
    /// start, J.
    pub gain: f32,
    /// The start's total mechanical energy scale (kinetic + m g size), J.
    pub scale: f32,
    /// Lowest soft particle at the end, m (the ground's top is at 0).
    pub lowest_end: f32,
    /// Fastest soft particle or rigid body over the last second, m/s.
    pub end_speed: f32,
    /// Fastest anything moved after the first frames, m/s.
    pub fastest: f32,
    /// Fastest anything could move from the scene's start: its largest speed and a fall
    /// from its highest point, m/s.
    pub start_speed: f32,
    /// First error a step returned.
    pub error: Option<String>,
}

/// Kinetic + gravitational energy of everything (J) and the fastest speed (m/s).
fn energy(s: &CoupledWorld) -> (f32, f32) {
    let (mut e, mut fastest) = (0.0f64, 0.0f32);
    for p in s.soft.query::<&Particles>().iter() {
        e += f64::from(p.kinetic_energy());
        for (x, m) in p.positions().iter().zip(p.masses()) {
            e += f64::from(m * 9.81 * x.y);
        }
        fastest = fastest.max(p.max_speed());
    }
    for (_, b) in s.physics.bodies.iter() {
        if b.is_dynamic() {
            let v = b.linvel().length();
            e += f64::from(0.5 * b.mass() * v * v + b.mass() * 9.81 * b.translation().y);
            let w = b.angvel();
            let i = b.mass_properties().effective_angular_inertia();
            let iw = i * w;
            e += f64::from(0.5 * w.dot(iw));
            fastest = fastest.max(v);
        }
    }
    (e as f32, fastest)
}

impl Outcome {
    /// Which of [`FLAGS`] the scene raised.
    pub fn flags(&self) -> [bool; 5] {
        [
            self.error.is_some(),
            self.gain > 1e-2 * self.scale + 1e-3,
            self.lowest_end < -0.03,
            self.end_speed > 0.05,
            self.fastest > 1.2 * self.start_speed + 5.0,
        ]
    }
}

/// A scene as built, before it runs.
struct Built {
    s: CoupledWorld,
    what: String,
    boxes: Vec<RigidBodyHandle>,
    top: f32,
    scale_size: f32,
    start_speed: f32,
}

/// A soft body of random size, density, mesh and families.
fn random_body(
    rng: &mut Draws,
    at: Vector3<f32>,
    v: Vector3<f32>,
    family: Option<u64>,
) -> (SoftBodyBuilder, f32, String) {
    let size = rng.log(0.1, 1.2);
    let cells = rng.pick(&[2u32, 3, 4]);
    let split = rng.pick(&[CellSplit::Five, CellSplit::Six]);
    let aspect = Vector3::new(
        rng.range(0.5, 1.5),
        rng.range(0.5, 1.5),
        rng.range(0.5, 1.5),
    );
    let dims = aspect * size;
    let mesh = generators::box_grid(dims, [cells; 3], split).expect("mesh");
    let density = rng.log(20.0, 3000.0);
    let mut b = SoftBodyBuilder::new(mesh)
        .density(density)
        .translation(at + Vector3::y() * (0.5 * dims.max()))
        .rotation(UnitQuaternion::from_euler_angles(
            rng.range(-3.1, 3.1),
            rng.range(-3.1, 3.1),
            rng.range(-3.1, 3.1),
        ))
        .velocity(v)
        .angular_velocity(Vector3::new(
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
            0.0,
        ));
    let fam = rng.bits() % 4;
    let fam = family.unwrap_or(fam);
    let desc = format!("[{cells}³ {split:?} fam {fam} ρ {density:.0}]");
    b = match fam {
        0 => b.edges(0.0).volume(0.0),
        1 => b.edges(rng.log(1e-7, 1e-4)).volume(rng.log(1e-10, 1e-7)),
        2 => b.edges(0.0).vertex_face(0.0),
        _ => b.vertex_face(rng.log(1e-7, 1e-5)).volume(0.0),
    };
    (b, dims.max(), desc)
}

/// Scene `k` built from its seed: the world, its description, the rigid bodies added, the
/// top of the stack (m), the largest body size (m) and the fastest start speed (m/s).
fn build(k: u64, o: &Options) -> Built {
    let mut rng = Draws::from_seed(0x5EED_0000 + k);
    let substeps = rng.pick(&[2u32, 5, 10, 20, 40]);
    let substeps = o.substeps.unwrap_or(substeps);
    let solver = SolverSettings {
        substeps,
        ..SolverSettings::default()
    };
    let mut s = CoupledWorld::new(solver, CouplingSettings::default()).expect("settings");
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(500.0, 0.5, 500.0),
    );
    let kind = rng.bits() % 4;
    let mut what = format!("scene {k}: {substeps} substeps, ");
    let mut top = 0.0f32;
    let mut start_speed = 0.0f32;
    let mut boxes: Vec<RigidBodyHandle> = Vec::new();
    if kind == 1 {
        // A dynamic box on the ground under the soft body.
        let half = rng.log(0.1, 0.6);
        let mass = rng.log(0.1, 1000.0);
        let (h, _) = s.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(0.0, half, 0.0)),
            ColliderBuilder::cuboid(half, half, half).mass(mass),
        );
        boxes.push(h);
        top = 2.0 * half;
        what += &format!("box {mass:.2} kg half {half:.2} m, ");
    }
    let bodies = if kind == 2 { 2 + rng.bits() % 3 } else { 1 };
    let mut scale_size = 0.0f32;
    for i in 0..bodies {
        let speed = if kind == 2 {
            rng.range(0.0, 5.0)
        } else {
            rng.log(0.1, 80.0)
        };
        start_speed = start_speed.max(speed);
        let dir = Vector3::new(rng.range(-0.5, 0.5), -1.0, rng.range(-0.5, 0.5)).normalize();
        let at = Vector3::new(
            rng.range(-0.1, 0.1),
            top + 0.05 + rng.range(0.0, 0.5),
            rng.range(-0.1, 0.1),
        );
        let (b, size, desc) = random_body(&mut rng, at, dir * speed, o.family);
        b.build().expect("body").spawn(&mut s.soft);
        what += &format!("body {i} {size:.2} m {desc} at {speed:.1} m/s, ");
        top = at.y + 1.8 * size;
        scale_size = scale_size.max(size);
    }
    if kind == 3 {
        // A rigid projectile (a cube) of random mass and speed.
        let r = rng.log(0.03, 0.3);
        let mass = rng.log(0.1, 300.0);
        let speed = rng.log(1.0, 150.0);
        start_speed = start_speed.max(speed);
        let (h, _) = s.physics.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(rng.range(-0.1, 0.1), top + r + 0.3, 0.0))
                .linvel(Vector::new(0.0, -speed, 0.0)),
            ColliderBuilder::cuboid(r, r, r).mass(mass),
        );
        boxes.push(h);
        what += &format!("cube {mass:.1} kg half {r:.2} m at {speed:.0} m/s, ");
        top += 2.0 * r + 0.3;
    }
    Built {
        s,
        what,
        boxes,
        top,
        scale_size,
        start_speed,
    }
}

/// One random scene `k`: builds it, runs 4 s and measures. Returns its description and
/// outcome.
pub fn run(k: u64, o: &Options) -> (String, Outcome) {
    let Built {
        mut s,
        what,
        boxes,
        top,
        scale_size,
        start_speed,
    } = build(k, o);
    let (e0, _) = energy(&s);
    let mass: f32 = s
        .soft
        .query::<&Particles>()
        .iter()
        .map(|p| p.total_mass())
        .sum::<f32>()
        + boxes
            .iter()
            .map(|&h| s.physics.bodies[h].mass())
            .sum::<f32>();
    let ke0: f32 = {
        let (e, _) = energy(&s);
        e
    };
    let trace = o.trace;
    let o_substeps = (o.substeps_from, o.substeps_until);
    let mut o = Outcome {
        scale: ke0.abs() + mass * 9.81 * (scale_size + top),
        start_speed: (start_speed * start_speed + 2.0 * 9.81 * (top + scale_size)).sqrt(),
        lowest_end: f32::INFINITY,
        ..Outcome::default()
    };
    let frames = 240;
    for f in 0..frames {
        let substep_trace = trace && o_substeps.0.is_some_and(|a| f >= a) && f <= o_substeps.1;
        let stepped = if substep_trace {
            s.step_with(&mut trace::SubstepTrace)
        } else {
            s.step()
        };
        let stats = match stepped {
            Ok(stats) => stats,
            Err(err) => {
                o.error = Some(format!("frame {f}: {err}"));
                return (what, o);
            }
        };
        let (e, fastest) = energy(&s);
        if !e.is_finite() {
            o.error = Some(format!("frame {f}: energy {e}"));
            return (what, o);
        }
        o.gain = o.gain.max(e - e0);
        if trace {
            trace::print_frame(f, e - e0, &s, &boxes, &stats);
        }
        if f > 2 {
            o.fastest = o.fastest.max(fastest);
        }
        if f >= frames - 60 {
            o.end_speed = o.end_speed.max(fastest);
        }
    }
    for p in s.soft.query::<&Particles>().iter() {
        o.lowest_end = o.lowest_end.min(p.aabb().0.y);
    }
    (what, o)
}
