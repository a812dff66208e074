//! Bars pulled apart for the tearing tests: a bar along x with its end cross-sections pinned,
//! and the pull that moves them apart.

use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, TearingSettings};

/// A bar of `size` (m, along x) and `cells`, centred on the origin, its end cross-sections
/// pinned, tearing by `settings`, with the families `families` adds.
pub fn pinned_bar(
    world: &mut World,
    size: Vector3<f32>,
    cells: [u32; 3],
    settings: TearingSettings,
    families: impl FnOnce(SoftBodyBuilder) -> SoftBodyBuilder,
) -> Entity {
    let mesh = box_grid(size, cells, CellSplit::Six).unwrap();
    let ends: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| (mesh.vertices[i as usize].x.abs() - 0.5 * size.x).abs() < 1e-4)
        .collect();
    families(SoftBodyBuilder::new(mesh).tearing(settings).pinned(ends))
        .build()
        .unwrap()
        .spawn(world)
}

/// Moves every pinned particle of every body along x, away from the middle, by `dx` (m).
pub fn pull_ends(world: &mut World, dx: f32) {
    for p in world.query_mut::<&mut Particles>() {
        for i in 0..p.len() {
            if p.is_pinned(i) {
                let step = dx.copysign(p.rest_positions()[i].x);
                let x = p.positions()[i] + Vector3::new(step, 0.0, 0.0);
                p.set_position(i, x).unwrap();
            }
        }
    }
}
