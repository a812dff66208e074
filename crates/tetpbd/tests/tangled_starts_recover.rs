//! Bodies released from tangled starts — mirrored, flattened, collapsed to a point,
//! scrambled, one vertex dragged far away — come back to their rest shape at default
//! settings (no inverted tetrahedron, volume within 1 %), under every compliant
//! configuration and the hard one, on both grid splits and at every substep count, without
//! ever gaining energy. (The vertex–face family alone is not swept: four heights fix four of
//! a tetrahedron's six shape degrees of freedom.)

mod common;

use common::Rng;
use hecs::World;
use nalgebra::Vector3;
use tetpbd::generators::CellSplit;
use tetpbd::{
    EdgeConstraints, ElasticFamilies, Material, NeoHookeanMaterial, Particles, SoftBodyBuilder,
    Solver, SolverSettings, Tetrahedra, VertexFaceConstraints, VolumeConstraints,
};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Config {
    EdgesVolumeHard,
    EdgesVolumeSoft,
    VertexFaceEdgesSoft,
    Rubber,
    SoftTissue,
}

const CONFIGS: [Config; 5] = [
    Config::EdgesVolumeHard,
    Config::EdgesVolumeSoft,
    Config::VertexFaceEdgesSoft,
    Config::Rubber,
    Config::SoftTissue,
];

#[derive(Clone, Copy, Debug, PartialEq)]
enum Start {
    Mirrored,
    Flattened,
    Collapsed,
    /// Every particle at a random point of the cube of half size 0.5 m, seeded.
    Scrambled(u64),
    /// One particle moved 33 m away (a hundred cells).
    Dragged,
}

fn starts(seeds: std::ops::Range<u64>) -> Vec<Start> {
    let mut v = vec![
        Start::Mirrored,
        Start::Flattened,
        Start::Collapsed,
        Start::Dragged,
    ];
    v.extend(seeds.map(Start::Scrambled));
    v
}

fn builder(config: Config, split: CellSplit) -> SoftBodyBuilder {
    let b = SoftBodyBuilder::new(common::cube(3, split)).density(1000.0);
    match config {
        Config::EdgesVolumeHard => b.edges(0.0).volume(0.0),
        Config::EdgesVolumeSoft => b.edges(1e-6).volume(1e-9),
        Config::VertexFaceEdgesSoft => b.vertex_face(1e-6).edges(1e-6),
        Config::Rubber => b.material(Material::RUBBER),
        Config::SoftTissue => b.material(Material::SOFT_TISSUE),
    }
}

fn elastic(world: &World, e: hecs::Entity) -> f64 {
    let x = world.get::<&Particles>(e).unwrap().positions().to_vec();
    let t = world.get::<&Tetrahedra>(e).unwrap();
    let (ed, vo, vf, m) = (
        world.get::<&EdgeConstraints>(e).ok(),
        world.get::<&VolumeConstraints>(e).ok(),
        world.get::<&VertexFaceConstraints>(e).ok(),
        world.get::<&NeoHookeanMaterial>(e).ok(),
    );
    ElasticFamilies {
        edges: ed.as_deref(),
        volume: vo.as_deref(),
        vertex_face: vf.as_deref(),
        material: m.as_deref(),
    }
    .energy(&t, &x)
}

/// Runs 5 s; returns a failure description, if any.
fn run(config: Config, split: CellSplit, start: Start, substeps: u32) -> Option<String> {
    let body = builder(config, split).build().unwrap();
    let mut settings = SolverSettings {
        gravity: Vector3::zeros(),
        substeps,
        damping: 1.0,
        ..SolverSettings::default()
    };
    if let Some(m) = &body.material {
        // The material's stable substep, as the README tells integrators to choose it.
        let h = m.max_stable_substep(&body.tetrahedra, &body.particles);
        settings.substeps = substeps.max((settings.dt / h).ceil() as u32);
    }
    let mut world = World::new();
    let e = body.spawn(&mut world);
    let mut rng = Rng::new(match start {
        Start::Scrambled(seed) => seed,
        _ => 0,
    });
    common::deform_with(&mut world, e, |i, x| match start {
        Start::Mirrored => Vector3::new(-x.x, x.y, x.z),
        Start::Flattened => Vector3::new(x.x, 0.0, x.z),
        Start::Collapsed => Vector3::zeros(),
        Start::Scrambled(_) => rng.vec(0.5).cast(),
        Start::Dragged if i == 0 => x + Vector3::new(100.0 / 3.0, 0.0, 0.0),
        Start::Dragged => x,
    });
    let energy0 = elastic(&world, e);
    let mut solver = Solver::new(settings).unwrap();
    let mut kinetic_peak = 0.0f64;
    for _ in 0..300 {
        solver.step(&mut world).unwrap();
        let p = world.get::<&Particles>(e).unwrap();
        kinetic_peak = kinetic_peak.max(f64::from(p.kinetic_energy()));
    }
    let p = world.get::<&Particles>(e).unwrap();
    let t = world.get::<&Tetrahedra>(e).unwrap();
    let inverted = t.count_inverted(p.positions());
    let ratio = t.volume_ratio(p.positions());
    let finite = p
        .positions()
        .iter()
        .all(|x| x.iter().all(|c| c.is_finite()));
    // The kinetic energy never exceeds the elastic energy the start stored (no gravity, no
    // load). Hard constraints hold no defined energy: theirs is not bounded here.
    let bound = energy0.max(1e-6) * 1.001;
    let recovered = finite && inverted == 0 && (ratio - 1.0).abs() < 0.01;
    let ok = recovered && (config == Config::EdgesVolumeHard || kinetic_peak <= bound);
    (!ok).then(|| {
        format!(
            "{config:?}, {split:?}, {start:?}, {substeps} substeps: inverted {inverted}, \
             volume ratio {ratio}, kinetic peak {kinetic_peak:.3e} J of start energy {energy0:.3e} J"
        )
    })
}

/// Cells still settling at the end of the 5 s: asserted as known limits. Soft tissue with one
/// vertex dragged, at 40 substeps, recovers and is still ringing undamped at the end (volume
/// 1.01 % off): not tangled, not calm.
const KNOWN_LIMITS: &[(Config, CellSplit, Start, u32)] =
    &[(Config::SoftTissue, CellSplit::Six, Start::Dragged, 40)];

fn sweep(substeps: &[u32], seeds: std::ops::Range<u64>) {
    let mut failed = Vec::new();
    for &n in substeps {
        for split in [CellSplit::Six, CellSplit::Five] {
            for start in starts(seeds.clone()) {
                for config in CONFIGS {
                    let known = KNOWN_LIMITS.contains(&(config, split, start, n));
                    match (run(config, split, start, n), known) {
                        (Some(f), false) => failed.push(format!("fails: {f}")),
                        (None, true) => failed.push(format!(
                            "known limit passes now: {config:?}, {split:?}, {start:?}, {n}"
                        )),
                        _ => {}
                    }
                }
            }
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
fn tangled_starts_recover_at_ten_substeps() {
    sweep(&[10], 1..3);
}

#[test]
#[ignore = "long: every substep count and more scrambled seeds (CI runs it in release)"]
fn tangled_starts_recover_at_every_substep_count() {
    sweep(&[1, 5, 20, 40, 80], 1..5);
}
