//! Plates one cell thick (slivers of aspect 100–1000) held along one edge and swinging under
//! their weight at default settings: the orientation constraints of their inverted slivers
//! get the last word after the edges (`stabilisation::sliver_orientation`, swept until none
//! is left inverted), so the hard plates end with every tetrahedron upright at 1–80
//! substeps, and the pass adds no energy.

mod common;

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{hecs, Particles, SoftBodyBuilder, Solver, SolverSettings, Tetrahedra};

/// What one swing measured.
struct Swing {
    /// Inverted tetrahedra at the end.
    end: usize,
    /// Largest rise of kinetic + gravitational energy over the start, as a fraction of
    /// `M g L` (L the plate's width).
    gain: f64,
}

/// A 1 m × `thickness` × 1 m plate of `cells` × 1 × `cells` cells (`split`), its edge at
/// x = −0.5 m pinned, hard edges with volume (`volume`) or vertex–faces, default settings
/// but `substeps`, 2 s.
fn swing(thickness: f32, cells: u32, split: CellSplit, volume: bool, substeps: u32) -> Swing {
    let size = Vector3::new(1.0, thickness, 1.0);
    let mesh = box_grid(size, [cells, 1, cells], split).unwrap();
    let pinned: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].x < -0.49)
        .collect();
    let b = SoftBodyBuilder::new(mesh).density(1000.0).edges(0.0);
    let b = if volume {
        b.volume(0.0)
    } else {
        b.vertex_face(0.0)
    };
    let mut world = hecs::World::new();
    let body = b.pinned(pinned).build().unwrap().spawn(&mut world);
    let settings = SolverSettings {
        substeps,
        ..SolverSettings::default()
    };
    let mut solver = Solver::new(settings).unwrap();
    let (e0, scale) = {
        let p = world.get::<&Particles>(body).unwrap();
        (
            common::mechanical_energy(&p),
            f64::from(p.total_mass()) * 9.81,
        )
    };
    let mut gain = f64::NEG_INFINITY;
    for _ in 0..120 {
        solver.step(&mut world).unwrap();
        let p = world.get::<&Particles>(body).unwrap();
        gain = gain.max(common::mechanical_energy(&p) - e0);
    }
    let (p, t) = world
        .query_one_mut::<(&Particles, &Tetrahedra)>(body)
        .unwrap();
    Swing {
        end: t.count_inverted(p.positions()),
        gain: gain / scale,
    }
}

/// A deterministic pseudo-random number in [0, 1) from `seed`.
fn unit(seed: u64) -> f32 {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    s ^= s >> 29;
    s = s.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    s ^= s >> 32;
    (s >> 40) as f32 / (1u64 << 24) as f32
}

#[test]
fn hard_thin_plates_end_upright_and_never_gain_energy() {
    let mut report = Vec::new();
    for seed in 0..4u64 {
        // Thickness 1–5 mm (aspect 200–1000), 3 or 4 cells a side, both grid splits.
        let thickness = 1e-3 * (1.0 + 4.0 * unit(seed));
        let cells = 3 + (seed % 2) as u32;
        let split = if seed < 2 {
            CellSplit::Six
        } else {
            CellSplit::Five
        };
        for volume in [true, false] {
            for substeps in [1, 5, 10, 20, 40, 80] {
                let s = swing(thickness, cells, split, volume, substeps);
                let set = if volume {
                    "edges+volume"
                } else {
                    "vertex-face+edges"
                };
                eprintln!(
                    "{thickness:.4} m, {cells} cells, {split:?}, {set}, {substeps} substeps: \
                     {} inverted, gain {:e} M g L",
                    s.end, s.gain
                );
                report.push((thickness, cells, split, set, substeps, s));
            }
        }
    }
    let mut upright = 0;
    for (thickness, cells, split, set, substeps, s) in &report {
        let case = format!("{thickness} m, {cells} cells, {split:?}, {set}, {substeps} substeps");
        // Without the sliver pass 26 of these 48 runs ended with 4–28 tetrahedra inverted;
        // with a single sweep of it, 2–3 runs with one.
        assert!(s.end == 0, "{case}: {} tetrahedra end inverted", s.end);
        upright += usize::from(s.end == 0);
        // Hard vertex–face + edges gains up to 4e-3 M g L on the five-tetrahedra plates with
        // or without the sliver pass (a known limit of that family); edges + volume never.
        let bound = if *set == "edges+volume" { 1e-5 } else { 1e-2 };
        assert!(s.gain < bound, "{case}: gained {:e} M g L", s.gain);
    }
    assert!(
        upright == report.len(),
        "{upright} of {} runs end with every tetrahedron upright",
        report.len()
    );
}
