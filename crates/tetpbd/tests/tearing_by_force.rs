//! Tearing by force: a bar hung from its top with a load growing at its bottom stays whole
//! below the load at which the most loaded face carries the threshold and tears within 10 %
//! of it, for several sizes, densities, meshes, stiffnesses and substep counts (the threshold
//! means the same newtons in each); a one-frame spike of the load tears nothing through the
//! smoothing and tears without it; bad force thresholds are typed errors.

mod common;

use common::Rng;
use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    BuildError, Material, NeoHookeanMaterial, Particles, Pieces, SoftBodyBuilder, Solver,
    SolverSettings, TearEvent, Tearing, TearingError, TearingSettings, TetMesh, Tetrahedra,
    UserForces,
};

const G: f32 = 9.81;

/// One hung bar: its size, mesh, material and solver.
#[derive(Clone, Copy, Debug)]
struct Bar {
    width: f32,
    length: f32,
    cells: [u32; 3],
    density: f32,
    /// Young's modulus, Pa (Neo-Hookean); `None`: hard edges and a hard volume family.
    young: Option<f32>,
    poisson: f32,
    /// The material's damping time, s.
    damping: f32,
    substeps: u32,
    /// Force threshold, N.
    force: f32,
    smoothing_time: f32,
}

impl Bar {
    fn mesh(&self) -> TetMesh {
        let size = Vector3::new(self.width, self.length, self.width);
        box_grid(size, self.cells, CellSplit::Six).unwrap()
    }

    fn section(&self) -> f32 {
        self.width * self.width
    }

    /// The load (N) at which the most loaded interior face carries the threshold at rest:
    /// under the uniaxial nominal stress `σ(y) = (W + ρ g S (y − y_bottom)) / S`, a face of
    /// rest area `A` and normal `n` carries `σ n_y² A` (see `crate::body::face_forces`).
    fn analytic_load(&self) -> f32 {
        let mesh = self.mesh();
        let (s, bottom) = (self.section(), -self.length / 2.0);
        interior_faces(&mesh)
            .into_iter()
            .filter(|(share, _)| *share > 1e-6 * s)
            .map(|(share, y)| self.force * s / share - self.density * G * s * (y - bottom))
            .fold(f32::INFINITY, f32::min)
    }

    fn settings(&self) -> TearingSettings {
        TearingSettings {
            strain: None,
            force: Some(self.force),
            smoothing_time: self.smoothing_time,
            pieces: Pieces::KeepOne,
        }
    }

    fn spawn(&self, world: &mut World) -> Entity {
        let mesh = self.mesh();
        let top: Vec<u32> = (0..mesh.vertices.len() as u32)
            .filter(|&i| mesh.vertices[i as usize].y > self.length / 2.0 - 1e-5)
            .collect();
        let builder = SoftBodyBuilder::new(mesh)
            .density(self.density)
            .tearing(self.settings())
            .pinned(top);
        let builder = match self.young {
            Some(e) => {
                let m = Material::new(e, self.poisson).unwrap();
                builder.material(m.with_damping(self.damping).unwrap())
            }
            None => builder.edges(0.0).volume(0.0),
        };
        let body = builder.build().unwrap();
        let forces = UserForces::new(&body.particles);
        let e = body.spawn(world);
        world.insert_one(e, forces).unwrap();
        e
    }

    /// The bar's solver: its substeps, or more when its material needs them
    /// ([`NeoHookeanMaterial::max_stable_substep`]).
    fn solver(&self, world: &World, e: Entity) -> Solver {
        let stable = world.get::<&NeoHookeanMaterial>(e).ok().map_or(0, |m| {
            let t = world.get::<&Tetrahedra>(e).unwrap();
            let p = world.get::<&Particles>(e).unwrap();
            (1.0 / 60.0 / m.max_stable_substep(&t, &p)).ceil() as u32
        });
        Solver::new(SolverSettings {
            substeps: self.substeps.max(stable),
            damping: 1.0,
            ..Default::default()
        })
        .unwrap()
    }
}

/// `(n_y² A, centroid height)` of every face shared by two tetrahedra at rest (m², m).
fn interior_faces(mesh: &TetMesh) -> Vec<(f32, f32)> {
    let mut keys: Vec<[u32; 3]> = Vec::new();
    for t in &mesh.tets {
        for skip in 0..4 {
            let mut k: Vec<u32> = (0..4).filter(|&c| c != skip).map(|c| t[c]).collect();
            k.sort_unstable();
            keys.push([k[0], k[1], k[2]]);
        }
    }
    keys.sort_unstable();
    keys.windows(2)
        .filter(|w| w[0] == w[1])
        .map(|w| {
            let [a, b, c] = w[0].map(|i| mesh.vertices[i as usize]);
            let m = (b - a).cross(&(c - a));
            let area = 0.5 * m.norm();
            let ny = m.y / m.norm();
            (ny * ny * area, (a.y + b.y + c.y) / 3.0)
        })
        .collect()
}

/// Sets the bar's load to `load` (N, downwards) on its bottom particles, each taking the
/// share of the bottom face's area nearest it (the consistent load of a uniform traction).
fn set_load(world: &mut World, e: Entity, bar: &Bar, load: f32) {
    let (p, t, f) = world
        .query_one_mut::<(&Particles, &Tetrahedra, &mut UserForces)>(e)
        .unwrap();
    f.reset_forces();
    let half = bar.width / 2.0;
    let cell = [
        bar.width / bar.cells[0] as f32,
        bar.width / bar.cells[2] as f32,
    ];
    let weight = |x: f32, h: f32| {
        if (x.abs() - half).abs() < 1e-5 {
            0.5 * h
        } else {
            h
        }
    };
    for i in 0..p.len() {
        let r = p.rest_positions()[i];
        if r.y > -bar.length / 2.0 + 1e-5 {
            continue;
        }
        let share = weight(r.x, cell[0]) * weight(r.z, cell[1]) / bar.section();
        let at = p.positions()[i];
        f.add_force_at_point(p, t, Vector3::new(0.0, -load * share, 0.0), at)
            .unwrap();
    }
}

/// Runs `bar` under the loads `load(frame)` (N) for `frames` frames; returns the first
/// frame that tore, with the load then, and the largest smoothed face force seen (N).
fn run(bar: &Bar, frames: usize, load: impl Fn(usize) -> f32) -> (Option<(usize, f32)>, f32) {
    let mut world = World::new();
    let e = bar.spawn(&mut world);
    let mut solver = bar.solver(&world, e);
    let mut peak = 0.0f32;
    for frame in 0..frames {
        set_load(&mut world, e, bar, load(frame));
        solver.step(&mut world).unwrap();
        if !solver.tear_events().is_empty() {
            return (Some((frame, load(frame))), peak);
        }
        peak = peak.max(world.get::<&Tearing>(e).unwrap().max_smoothed_force());
    }
    (None, peak)
}

/// A random bar of the sweep: 0.06–0.15 m wide, 0.3–0.8 m long, 300–3000 kg/m³, 2 or 3
/// cells across, 8–30 substeps (more when the material needs them), a Neo-Hookean material
/// with ν = 0 (a uniaxial stress up to the pinned top) stiff enough that the bar stretches
/// about 1 % at the tearing load, the threshold 3–6 times the force of the bar's weight on its
/// most loaded face.
fn random_bar(rng: &mut Rng, case: usize) -> Bar {
    let width = rng.range(0.06, 0.15) as f32;
    let length = rng.range(0.3, 0.8) as f32;
    let density = rng.range(300.0, 3000.0) as f32;
    let across = 2 + (case % 2) as u32;
    let along = (length / (width / across as f32)).round().clamp(4.0, 12.0) as u32;
    let mut bar = Bar {
        width,
        length,
        cells: [across, along, across],
        density,
        young: None,
        poisson: 0.0,
        damping: 1e-3,
        substeps: [8, 15, 30][case % 3],
        force: 1.0,
        smoothing_time: 0.05,
    };
    let share = interior_faces(&bar.mesh())
        .iter()
        .fold(0.0f32, |m, f| m.max(f.0));
    bar.force = density * G * length * share * rng.range(3.0, 6.0) as f32;
    let stress = bar.analytic_load() / bar.section();
    bar.young = Some(100.0 * stress);
    bar
}

#[test]
fn a_hung_bar_tears_by_force_near_the_analytic_load() {
    let mut rng = Rng::new(0x7ea7_f0ce);
    let mut worst = 0.0f32;
    for case in 0..8 {
        let bar = random_bar(&mut rng, case);
        let expected = bar.analytic_load();
        assert!(expected > 0.0, "{bar:?}: {expected} N");
        // 0 → 0.8 W* over 2 s, held 1 s: whole; then up to 1.6 W* over 2 s: torn.
        let load = |frame: usize| {
            let t = frame as f32 / 60.0;
            expected
                * if t < 2.0 {
                    0.4 * t
                } else if t < 3.0 {
                    0.8
                } else {
                    0.8 + 0.4 * (t - 3.0)
                }
        };
        let (tear, peak) = run(&bar, 300, load);
        let Some((frame, at)) = tear else {
            panic!("{bar:?}: never tore, expected at {expected} N (peak face force {peak} N)");
        };
        let error = at / expected - 1.0;
        eprintln!(
            "case {case}: {:?} cells, {} kg/m³, E {:?}, {} substeps: threshold {:.2} N, \
             tore at {at:.1} N (frame {frame}), analytic {expected:.1} N ({:+.1} %); \
             largest smoothed face force before {peak:.2} N",
            bar.cells,
            bar.density,
            bar.young,
            bar.substeps,
            bar.force,
            100.0 * error
        );
        assert!(
            frame >= 180,
            "{bar:?}: tore at {at} N, below 0.8 × {expected} N"
        );
        worst = worst.max(error.abs());
    }
    assert!(worst < 0.1, "worst error {:.1} %", 100.0 * worst);
}

#[test]
fn smoothing_keeps_a_one_frame_force_spike_from_tearing() {
    let mut rng = Rng::new(0x5b1c_e000);
    for case in 0..2 {
        for (smoothing_time, tears) in [(0.1, false), (0.0, true)] {
            let mut bar = random_bar(&mut rng, case);
            bar.smoothing_time = smoothing_time;
            let expected = bar.analytic_load();
            // Up to half the tearing load over 1 s, one frame at 1.5 times it (the bar rings
            // after it), then half again.
            let load = |frame: usize| match frame {
                0..60 => 0.5 * expected * frame as f32 / 60.0,
                90 => 1.5 * expected,
                _ => 0.5 * expected,
            };
            let (tear, peak) = run(&bar, 150, load);
            eprintln!(
                "τ {smoothing_time} s: {tear:?}, peak smoothed force {peak:.2} of {:.2} N",
                bar.force
            );
            assert_eq!(tear.is_some(), tears, "{bar:?}: {tear:?}");
        }
    }
}

#[test]
fn bad_force_thresholds_are_typed_errors() {
    let mesh = || box_grid(Vector3::new(1.0, 1.0, 1.0), [1, 1, 1], CellSplit::Six).unwrap();
    for value in [0.0, -5.0, f32::NAN, f32::INFINITY] {
        let s = TearingSettings {
            force: Some(value),
            ..Default::default()
        };
        let err = SoftBodyBuilder::new(mesh()).tearing(s).build().unwrap_err();
        match err {
            BuildError::Tearing(TearingError::BadForce { value: v }) => {
                assert!(
                    v == value || (v.is_nan() && value.is_nan()),
                    "{v} for {value}"
                )
            }
            other => panic!("{value}: {other:?}"),
        }
        let body = SoftBodyBuilder::new(mesh()).edges(0.0).build().unwrap();
        let mut t = Tearing::new(Default::default(), &body.particles, &body.tetrahedra).unwrap();
        assert!(matches!(
            t.set_settings(s),
            Err(TearingError::BadForce { .. })
        ));
        assert_eq!(t.settings().force, None, "the old settings stay");
    }
}

/// A body given a force threshold after it was built makes its scratch once and tears like
/// one built with it.
#[test]
fn a_force_threshold_set_later_tears_like_one_built_in() {
    let mut rng = Rng::new(0x1a7e);
    let bar = random_bar(&mut rng, 0);
    let expected = bar.analytic_load();
    let load = |frame: usize| expected * 0.6 * frame as f32 / 60.0;
    let (built, _) = run(&bar, 180, load);
    let mut world = World::new();
    let e = bar.spawn(&mut world);
    {
        let mut t = world.get::<&mut Tearing>(e).unwrap();
        t.set_settings(TearingSettings {
            force: None,
            ..bar.settings()
        })
        .unwrap();
        t.set_settings(bar.settings()).unwrap();
    }
    let mut solver = bar.solver(&world, e);
    let mut later: Option<Vec<TearEvent>> = None;
    for frame in 0..180 {
        set_load(&mut world, e, &bar, load(frame));
        solver.step(&mut world).unwrap();
        if !solver.tear_events().is_empty() {
            later = Some(solver.tear_events().to_vec());
            assert_eq!(Some(frame), built.map(|b| b.0));
            break;
        }
    }
    assert!(later.is_some() && built.is_some(), "{built:?}");
}
