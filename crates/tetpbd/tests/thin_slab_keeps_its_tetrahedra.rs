//! A one-cell-thick cantilever slab (aspect 100) pinned at one end bends under its weight at
//! default settings without gaining energy; a few tetrahedra next to the root, slivers of
//! 1 m × 1 cm, stay inverted after its largest bend (a known limit of sliver meshes, listed
//! in the stability report's findings).

mod common;

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{hecs, Particles, SoftBodyBuilder, Solver, SolverSettings, Tetrahedra};

struct Bend {
    /// Most tetrahedra inverted at once.
    most: usize,
    /// Inverted at the end.
    end: usize,
    /// Lowest tip height, m.
    lowest: f32,
    /// Largest rise of kinetic + gravitational energy over the start, J.
    gain: f64,
    /// `M g L` (L the slab's length), J.
    scale: f64,
}

/// A 10 m × 1 cm × 1 m slab of 10 × 1 × 1 cells, hard edges + volume, its end at x = −5 m
/// pinned, default settings (10 substeps, gravity), 3 s.
fn bend(split: CellSplit) -> Bend {
    let mesh = box_grid(Vector3::new(10.0, 0.01, 1.0), [10, 1, 1], split).unwrap();
    let root: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].x < -4.99)
        .collect();
    let mut world = hecs::World::new();
    let body = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .pinned(root)
        .build()
        .unwrap()
        .spawn(&mut world);
    let mut solver = Solver::new(SolverSettings::default()).unwrap();
    let (e0, scale) = {
        let p = world.get::<&Particles>(body).unwrap();
        (
            common::mechanical_energy(&p),
            f64::from(p.total_mass()) * 9.81 * 10.0,
        )
    };
    let (mut most, mut lowest, mut gain) = (0, f32::INFINITY, f64::NEG_INFINITY);
    for _ in 0..180 {
        solver.step(&mut world).unwrap();
        let (p, t) = world
            .query_one_mut::<(&Particles, &Tetrahedra)>(body)
            .unwrap();
        most = most.max(t.count_inverted(p.positions()));
        let tip = p
            .positions()
            .iter()
            .filter(|x| x.x > 4.99)
            .map(|x| x.y)
            .fold(f32::INFINITY, f32::min);
        lowest = lowest.min(tip);
        gain = gain.max(common::mechanical_energy(p) - e0);
    }
    let (p, t) = world
        .query_one_mut::<(&Particles, &Tetrahedra)>(body)
        .unwrap();
    Bend {
        most,
        end: t.count_inverted(p.positions()),
        lowest,
        gain,
        scale,
    }
}

/// Guarded so that a fix shows up here: the root's slivers end inverted (2 of 50–60 on
/// either split, 3–4 at most at once).
#[test]
fn cantilever_slab_bends_without_gaining_energy_but_may_leave_root_slivers_inverted() {
    for split in [CellSplit::Six, CellSplit::Five] {
        let b = bend(split);
        eprintln!(
            "{split:?}: most inverted {}, at the end {}, tip down to {} m, energy gain {:e} of M g L",
            b.most,
            b.end,
            b.lowest,
            b.gain / b.scale
        );
        assert!(
            b.lowest < -0.1,
            "{split:?}: the slab bends (tip at {} m)",
            b.lowest
        );
        assert!(
            b.gain < 1e-4 * b.scale,
            "{split:?}: gained {} J without external work",
            b.gain
        );
        assert!(
            b.end > 0 && b.end <= b.most && b.most <= 6,
            "{split:?}: {} inverted at the end ({} at most): update the known limit",
            b.end,
            b.most
        );
    }
}
