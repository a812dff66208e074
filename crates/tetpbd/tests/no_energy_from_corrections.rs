//! The families' corrections never add kinetic energy a body did not have (beyond what its
//! compliant constraints release), whatever its start: tangled, collapsed, scrambled or
//! crushed by an impact, at every substep count and on both grid splits, at default settings.

mod common;

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    hecs, ImpactReach, Particles, SoftBodyBuilder, Solver, SolverSettings, SubstepContext,
    SubstepHook, Surface, Tetrahedra,
};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Families {
    EdgesVertexFace,
    EdgesVolume,
}

#[derive(Clone, Copy, Debug)]
enum Start {
    Mirrored,
    Collapsed,
    Scrambled,
}

struct Outcome {
    peak_ke: f32,
    final_ke: f32,
    inverted: usize,
    volume_ratio: f32,
    max_speed: f32,
}

fn build(size: f32, cells: u32, split: CellSplit, families: Families) -> tetpbd::SoftBody {
    let mesh = box_grid(Vector3::repeat(size), [cells; 3], split).unwrap();
    let b = SoftBodyBuilder::new(mesh).density(1000.0);
    let b = match families {
        Families::EdgesVertexFace => b.edges(0.0).vertex_face(0.0),
        Families::EdgesVolume => b.edges(0.0).volume(0.0),
    };
    b.build().unwrap()
}

fn volume(p: &Particles, t: &Tetrahedra) -> (f32, f32) {
    let now: f32 = (0..t.len()).map(|k| t.volume_at(k, p.positions())).sum();
    let rest: f32 = (0..t.len())
        .map(|k| t.volume_at(k, p.rest_positions()))
        .sum();
    (now, rest)
}

fn outcome(world: &mut hecs::World, body: hecs::Entity, peak_ke: f32) -> Outcome {
    let (p, t) = world
        .query_one_mut::<(&Particles, &Tetrahedra)>(body)
        .unwrap();
    let (now, rest) = volume(p, t);
    Outcome {
        peak_ke,
        final_ke: p.kinetic_energy(),
        inverted: t.count_inverted(p.positions()),
        volume_ratio: now / rest,
        max_speed: p.max_speed(),
    }
}

/// A 1 m cube of 4³ cells released at rest from `start`, gravity off.
fn tangled(
    split: CellSplit,
    families: Families,
    start: Start,
    substeps: u32,
    frames: usize,
) -> Outcome {
    let mut world = hecs::World::new();
    let body = build(1.0, 4, split, families).spawn(&mut world);
    {
        let mut p = world.get::<&mut Particles>(body).unwrap();
        let c = p.center_of_mass();
        let mut rng = common::Rng::new(7);
        for i in 0..p.len() {
            let x = p.positions()[i];
            let y = match start {
                Start::Mirrored => Vector3::new(2.0 * c.x - x.x, x.y, x.z),
                Start::Collapsed => c,
                Start::Scrambled => c + rng.vec(0.5).cast::<f32>(),
            };
            p.set_position(i, y).unwrap();
        }
    }
    let mut solver = Solver::new(SolverSettings {
        substeps,
        gravity: Vector3::zeros(),
        safety: tetpbd::SafetySettings {
            limit_correction_energy: true,
            ..Default::default()
        },
        ..Default::default()
    })
    .unwrap();
    let mut peak: f32 = 0.0;
    for _ in 0..frames {
        solver.step(&mut world).unwrap();
        peak = peak.max(world.get::<&Particles>(body).unwrap().kinetic_energy());
    }
    outcome(&mut world, body, peak)
}

/// Immovable ground at y = 0 with restitution 0: particles below it are put back on it (a
/// position constraint run by the solver after the families, as a coupling's contacts are;
/// the depth beyond the body's local reach moves the whole body, `ImpactReach`), and a particle on it leaves the substep with no normal velocity (the velocity pass of an
/// XPBD contact, Müller et al. 2020, with e = 0).
struct Ground;

impl SubstepHook for Ground {
    fn project(&mut self, world: &mut hecs::World, _substep: SubstepContext) {
        for (p, surface) in world.query_mut::<(&mut Particles, &Surface)>() {
            let mut impact = ImpactReach::of(p, surface);
            for i in 0..p.len() {
                let depth = -p.positions()[i].y;
                impact.push_out(p, i, depth, &Vector3::y());
            }
        }
    }
    fn end_substep(&mut self, world: &mut hecs::World, _substep: SubstepContext) {
        for p in world.query_mut::<&mut Particles>() {
            for i in 0..p.len() {
                if p.positions()[i].y <= 0.0 {
                    p.velocities_mut()[i].y = 0.0;
                }
            }
        }
    }
}

/// Kinetic plus gravitational energy of a body (J, gravity 9.81 m/s² along −y).
fn energy(p: &Particles) -> f32 {
    let height: f32 = p
        .positions()
        .iter()
        .zip(p.masses())
        .map(|(x, m)| m * x.y)
        .sum();
    p.kinetic_energy() + 9.81 * height
}

/// A 0.5 m cube of 4³ cells hitting the ground at `speed` (m/s), gravity on, 2 s. Returns
/// the outcome with `peak_ke` the largest energy after the first frame relative to the
/// start's, and `max_speed` the largest upward speed of the centre of mass (m/s).
fn impact(split: CellSplit, speed: f32, substeps: u32) -> Outcome {
    let mut world = hecs::World::new();
    let body = build(0.5, 4, split, Families::EdgesVolume).spawn(&mut world);
    let e0 = {
        let mut p = world.get::<&mut Particles>(body).unwrap();
        for i in 0..p.len() {
            let x = p.positions()[i];
            p.set_position(i, x + Vector3::new(0.0, 0.3, 0.0)).unwrap();
            p.set_velocity(i, Vector3::new(0.0, -speed, 0.0)).unwrap();
        }
        energy(&p)
    };
    let mut solver = Solver::new(SolverSettings {
        substeps,
        safety: tetpbd::SafetySettings {
            limit_correction_energy: true,
            ..Default::default()
        },
        ..Default::default()
    })
    .unwrap();
    let (mut peak, mut rising) = (f32::NEG_INFINITY, 0.0f32);
    for frame in 0..120 {
        solver.step_with(&mut world, &mut Ground).unwrap();
        let p = world.get::<&Particles>(body).unwrap();
        if frame > 0 {
            peak = peak.max(energy(&p) / e0);
        }
        rising = rising.max(p.linear_momentum().y / p.total_mass());
    }
    let mut o = outcome(&mut world, body, 0.0);
    o.peak_ke = peak;
    o.max_speed = rising;
    o
}

const SUBSTEPS: [u32; 6] = [1, 5, 10, 20, 40, 80];
const SPLITS: [CellSplit; 2] = [CellSplit::Five, CellSplit::Six];

/// `M g L` of the 1 m, 1000 kg cube (L its diagonal), J: the energy scale of the checks.
const REFERENCE: f32 = 1000.0 * 9.81 * 1.732;

/// Cases that stay calm but settle in a tangled state instead of recovering (listed in
/// docs/decisions/correction-energy.md): once the corrections no longer become velocity,
/// nothing carries these starts through a configuration where the projections balance.
fn known_tangled(split: CellSplit, families: Families, start: Start, substeps: u32) -> bool {
    use CellSplit::Six;
    use Families::EdgesVertexFace as Vfe;
    match (split, families, start) {
        (Six, Vfe, Start::Mirrored) => substeps == 1,
        (Six, Vfe, Start::Collapsed) => true,
        (Six, Vfe, Start::Scrambled) => substeps <= 40,
        _ => false,
    }
}

fn check_tangled(split: CellSplit, families: Families, start: Start, substeps: u32) {
    let o = tangled(split, families, start, substeps, 300);
    let case = format!("{split:?} {families:?} {start:?} {substeps} substeps");
    assert!(
        o.peak_ke < 1e-4 * REFERENCE,
        "{case}: released at rest, reached {} J",
        o.peak_ke
    );
    let recovered = o.inverted == 0 && (o.volume_ratio - 1.0).abs() < 0.01;
    if known_tangled(split, families, start, substeps) {
        assert!(!recovered, "{case} recovers now: update the known cases");
    } else {
        assert!(
            recovered,
            "{case}: {} inverted, volume ×{}",
            o.inverted, o.volume_ratio
        );
    }
}

/// A mirrored six-tetrahedra cube of hard edges + vertex–face recovers its shape without
/// moving at 5, 10, 20 and 40 substeps (more substeps must not make it worse).
#[test]
fn mirrored_six_tetrahedra_cube_recovers_without_gaining_energy_at_any_substep_count() {
    for substeps in [5, 10, 20, 40] {
        check_tangled(
            CellSplit::Six,
            Families::EdgesVertexFace,
            Start::Mirrored,
            substeps,
        );
    }
}

#[test]
fn collapsed_and_scrambled_edges_volume_cubes_recover_without_gaining_energy() {
    check_tangled(CellSplit::Six, Families::EdgesVolume, Start::Collapsed, 5);
    check_tangled(CellSplit::Six, Families::EdgesVolume, Start::Scrambled, 5);
}

fn check_impact(split: CellSplit, speed: f32, substeps: u32) {
    let o = impact(split, speed, substeps);
    let case = format!("{split:?} {speed} m/s {substeps} substeps");
    assert!(
        o.peak_ke <= 1.0,
        "{case}: energy ×{} of the start's",
        o.peak_ke
    );
    assert!(o.max_speed < speed, "{case}: leaves at {} m/s", o.max_speed);
    // Against the volume the same body keeps set down on the ground (a hard body sags under
    // its weight at one substep: one projection a frame does not hold it).
    let resting = impact(split, 0.0, substeps).volume_ratio;
    let intact = o.inverted == 0 && (o.volume_ratio / resting - 1.0).abs() < 0.01;
    assert!(
        intact,
        "{case}: {} inverted, volume ×{} (×{resting} at rest)",
        o.inverted, o.volume_ratio
    );
}

/// A 0.5 m cube hitting immovable ground at 100 or 300 m/s ends intact (no inverted
/// tetrahedron, volume within 1 % of the body set down at rest) and never leaves faster than
/// it came.
#[test]
fn fast_cube_hitting_immovable_ground_ends_intact() {
    for speed in [100.0, 300.0] {
        check_impact(CellSplit::Six, speed, 10);
    }
}

/// 100 and 300 m/s on both splits at 1–80 substeps (release build: `.ci/run`).
#[test]
#[ignore = "long: the full sweep"]
fn impacts_end_intact_at_any_substep_count() {
    for split in SPLITS {
        for speed in [100.0, 300.0] {
            for substeps in SUBSTEPS {
                check_impact(split, speed, substeps);
            }
        }
    }
}

/// A mirrored cube thrown spinning (2 m/s, 3 rad/s) keeps its linear and angular momentum
/// while the limit holds back its snap-back: one scale per body keeps the linear momentum,
/// and the rigid part of what it holds back, fitted about the positions the substep ends
/// at, is given back. Typical over these 30 frames of untangling: linear 1–2e-5, angular
/// 4e-6 relative (8 % of the angular momentum lost without the give-back). Where giving it
/// all back would add kinetic energy (corrections pulling a turning body's particles
/// inwards spin it up) the energy bound wins (`stabilisation::give_back`): the
/// six-tetrahedra cube keeps its angular momentum to 2e-3.
#[test]
fn limited_tangled_body_keeps_its_momentum() {
    for split in SPLITS {
        let mut world = hecs::World::new();
        let body = build(1.0, 4, split, Families::EdgesVertexFace).spawn(&mut world);
        let (p0, l0, scale) = {
            let mut p = world.get::<&mut Particles>(body).unwrap();
            let c = p.center_of_mass();
            let omega = Vector3::new(0.0, 3.0, 1.0);
            for i in 0..p.len() {
                let x = p.positions()[i];
                p.set_position(i, Vector3::new(2.0 * c.x - x.x, x.y, x.z))
                    .unwrap();
                let v = Vector3::new(2.0, 0.0, 0.0) + omega.cross(&(x - c));
                p.set_velocity(i, v).unwrap();
            }
            let scale: f32 = p
                .velocities()
                .iter()
                .zip(p.masses())
                .map(|(v, m)| m * v.norm())
                .sum();
            (p.linear_momentum(), p.angular_momentum(), scale)
        };
        let ke0 = world.get::<&Particles>(body).unwrap().kinetic_energy();
        let mut solver = Solver::new(SolverSettings {
            gravity: Vector3::zeros(),
            safety: tetpbd::SafetySettings {
                limit_correction_energy: true,
                ..Default::default()
            },
            ..Default::default()
        })
        .unwrap();
        let (mut limited, mut peak) = (0, 0.0f32);
        for _ in 0..30 {
            limited += solver.step(&mut world).unwrap().energy_limited;
            peak = peak.max(world.get::<&Particles>(body).unwrap().kinetic_energy());
        }
        assert!(limited > 0, "{split:?}: the limit acts");
        // Hard constraints store no energy: what is given back never adds any.
        assert!(
            peak <= ke0 * (1.0 + 1e-4),
            "{split:?}: kinetic energy {peak} J from {ke0} J"
        );
        let p = world.get::<&Particles>(body).unwrap();
        let dp = (p.linear_momentum() - p0).norm() / scale;
        // About the origin: the centre moves, Σ m x × v includes that.
        let dl = (p.angular_momentum() - l0).norm() / (scale * 2.0);
        eprintln!("{split:?}: linear {dp:e} angular {dl:e} limited {limited}");
        assert!(
            dp < 1e-4,
            "{split:?}: linear momentum drift {dp:e} (relative)"
        );
        // Five tetrahedra per cell: the whole give-back fits the energy bound; six: the
        // bound trims it.
        let angular_bound = match split {
            CellSplit::Five => 1e-4,
            CellSplit::Six => 1e-2,
        };
        assert!(
            dl < angular_bound,
            "{split:?}: angular momentum drift {dl:e} (relative)"
        );
    }
}

/// Peak kinetic energy (J) of a compliant 1 m cube squashed to 80 % of its height and
/// released, gravity off, over 1 s.
fn squashed_peak(substeps: u32, limit: bool) -> (f32, u64) {
    let mut world = hecs::World::new();
    let mesh = box_grid(Vector3::repeat(1.0), [3; 3], CellSplit::Six).unwrap();
    let body = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(1e-6)
        .volume(1e-9)
        .build()
        .unwrap()
        .spawn(&mut world);
    {
        let mut p = world.get::<&mut Particles>(body).unwrap();
        for i in 0..p.len() {
            let x = p.positions()[i];
            p.set_position(i, Vector3::new(x.x, 0.8 * x.y, x.z))
                .unwrap();
        }
    }
    let mut solver = Solver::new(SolverSettings {
        substeps,
        gravity: Vector3::zeros(),
        safety: tetpbd::SafetySettings {
            limit_correction_energy: limit,
            ..Default::default()
        },
        ..Default::default()
    })
    .unwrap();
    let (mut peak, mut limited) = (0.0f32, 0);
    for _ in 0..60 {
        limited += solver.step(&mut world).unwrap().energy_limited;
        peak = peak.max(world.get::<&Particles>(body).unwrap().kinetic_energy());
    }
    (peak, limited)
}

/// A compliant cube squashed and released still springs back: the limit lets out the
/// elastic energy its compliant constraints release.
#[test]
fn squashed_compliant_cube_still_bounces() {
    for substeps in [1, 10, 40] {
        let (with, limited) = squashed_peak(substeps, true);
        let (without, _) = squashed_peak(substeps, false);
        assert!(
            without > 1.0,
            "{substeps} substeps: the squash holds energy ({without} J)"
        );
        assert!(
            with > 0.9 * without,
            "{substeps} substeps: bounce {with} J with the limit ({limited} limited), {without} J without"
        );
    }
}

#[test]
#[ignore = "diagnostic: prints the tangled and impact outcomes"]
fn print_outcomes() {
    for split in SPLITS {
        for speed in [100.0, 300.0] {
            for substeps in SUBSTEPS {
                let o = impact(split, speed, substeps);
                println!(
                    "{split:?} impact {speed} {substeps:>2}: energy ×{:.3} of the start's, rising at {:.2} m/s, inv {} vol {:.4}",
                    o.peak_ke, o.max_speed, o.inverted, o.volume_ratio
                );
            }
        }
        for (families, start) in [
            (Families::EdgesVertexFace, Start::Mirrored),
            (Families::EdgesVertexFace, Start::Collapsed),
            (Families::EdgesVertexFace, Start::Scrambled),
            (Families::EdgesVolume, Start::Mirrored),
            (Families::EdgesVolume, Start::Collapsed),
            (Families::EdgesVolume, Start::Scrambled),
        ] {
            for substeps in SUBSTEPS {
                let o = tangled(split, families, start, substeps, 300);
                println!(
                    "{split:?} {families:?} {start:?} {substeps:>2}: peak KE {:.3e} final {:.3e} inv {} vol {:.4} vmax {:.2e}",
                    o.peak_ke, o.final_ke, o.inverted, o.volume_ratio, o.max_speed
                );
            }
        }
    }
}

/// A hard cube hanging from its top face is held by its pins at one substep and at ten:
/// the limit measures the work of the corrections with absolute velocities, so a body whose
/// corrections carry momentum (from its pins) is not mistaken for one gaining energy.
#[test]
fn hanging_hard_cube_is_held_by_its_pins() {
    for families in [Families::EdgesVolume, Families::EdgesVertexFace] {
        for substeps in [1, 10] {
            let mesh = box_grid(Vector3::repeat(1.0), [3; 3], CellSplit::Six).unwrap();
            let top: Vec<u32> = (0..mesh.vertices.len() as u32)
                .filter(|&i| mesh.vertices[i as usize].y > 0.49)
                .collect();
            let b = SoftBodyBuilder::new(mesh).density(1000.0).pinned(top);
            let b = match families {
                Families::EdgesVolume => b.edges(0.0).volume(0.0),
                _ => b.edges(0.0).vertex_face(0.0),
            };
            let mut world = hecs::World::new();
            let body = b.build().unwrap().spawn(&mut world);
            let mut solver = Solver::new(SolverSettings {
                substeps,
                safety: tetpbd::SafetySettings {
                    limit_correction_energy: true,
                    ..Default::default()
                },
                ..Default::default()
            })
            .unwrap();
            let mut peak = 0.0f32;
            for _ in 0..120 {
                solver.step(&mut world).unwrap();
                peak = peak.max(world.get::<&Particles>(body).unwrap().kinetic_energy());
            }
            let o = outcome(&mut world, body, peak);
            assert!(
                o.peak_ke < 1e-3 * REFERENCE && o.inverted == 0,
                "{families:?}, {substeps} substeps: peak {} J, {} inverted",
                o.peak_ke,
                o.inverted
            );
        }
    }
}
