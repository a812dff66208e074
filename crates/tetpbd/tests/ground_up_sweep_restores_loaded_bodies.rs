//! The ground-up (stacking) sweep: levels from the roots, roots held, one ordered sweep.

use hecs::World;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::systems::Kernel;
use tetpbd::{
    EdgeConstraints, FrameContext, GroundUpSweep, Particles, SoftBodyBuilder, SolverSettings,
    SubstepContext, Tetrahedra,
};

/// A column of three cells standing on y = 0; returns the entity and its bottom particles.
fn column(world: &mut World, families: &str) -> (hecs::Entity, Vec<u32>) {
    column_of(world, families, [1, 3, 1])
}

/// A column of `cells` cells of 0.2 m standing on y = 0; returns the entity and its bottom
/// particles.
fn column_of(world: &mut World, families: &str, cells: [u32; 3]) -> (hecs::Entity, Vec<u32>) {
    let size = Vector3::new(cells[0] as f32, cells[1] as f32, cells[2] as f32) * 0.2;
    let mesh = box_grid(size, cells, CellSplit::Six).unwrap();
    let b = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .translation(Vector3::new(0.0, size.y / 2.0, 0.0));
    let b = match families {
        "edges+volume" => b.edges(0.0).volume(0.0),
        "vertex-face" => b.vertex_face(0.0),
        _ => b.vertex_face(0.0).edges(0.0),
    };
    let e = b.build().unwrap().spawn(world);
    let p = world.get::<&Particles>(e).unwrap();
    let bottom = (0..p.len() as u32)
        .filter(|&i| p.positions()[i as usize].y < 1e-4)
        .collect();
    (e, bottom)
}

/// The context of a substep of 1/600 s (the default 1/60 s frame in 10 substeps) with
/// `kernel`.
fn substep(kernel: Kernel) -> SubstepContext {
    let settings = SolverSettings {
        kernel,
        ..SolverSettings::default()
    };
    FrameContext::new(&settings, settings.dt, settings.gravity).substep(0, 0)
}

#[test]
fn levels_count_cells_from_the_roots() {
    let mut world = World::new();
    let (e, bottom) = column(&mut world, "edges+volume");
    assert_eq!(bottom.len(), 4);
    let positions = world.get::<&Particles>(e).unwrap().positions().to_vec();
    let ctx = substep(Kernel::Simd);
    let mut sweep = GroundUpSweep::new();
    let top = sweep.project(&mut world, e, bottom.iter().copied(), &ctx);
    assert_eq!(top, Ok(3));
    for (i, x) in positions.iter().enumerate() {
        let expected = (x.y / 0.2).round() as u32;
        assert_eq!(sweep.level(i), Some(expected), "particle {i} at {x:?}");
    }
    // The same roots again (in another order): the same levels.
    let again = sweep.project(&mut world, e, bottom.iter().rev().copied(), &ctx);
    assert_eq!(again, Ok(3));
    // One root: the column is reached from one corner.
    let one = sweep.project(&mut world, e, [bottom[0]], &ctx).unwrap();
    assert!(one >= 3, "{one}");
    assert_eq!(sweep.level(bottom[0] as usize), Some(0));
    // No roots: nothing reached.
    assert_eq!(sweep.project(&mut world, e, [], &ctx), Ok(0));
    assert_eq!(sweep.level(0), None);
    // Pinned particles are roots too.
    world
        .get::<&mut Particles>(e)
        .unwrap()
        .set_pinned(bottom[1] as usize, true)
        .unwrap();
    assert!(sweep.project(&mut world, e, [], &ctx).unwrap() >= 3);
    assert_eq!(sweep.level(bottom[1] as usize), Some(0));
    // An entity that is not a soft body.
    let empty = world.spawn(());
    assert!(sweep.project(&mut world, empty, [], &ctx).is_err());
}

/// Largest edge error `| |x_i − x_j| − d |` of a body, m.
fn max_edge_error(p: &Particles, edges: &EdgeConstraints) -> f32 {
    let x = p.positions();
    edges
        .edges()
        .iter()
        .zip(edges.rest_lengths())
        .map(|(&[a, b], &d)| ((x[a as usize] - x[b as usize]).norm() - d).abs())
        .fold(0.0, f32::max)
}

/// One ground-up sweep of a body's own families with `bottom` as the roots.
fn sweep(world: &mut World, e: hecs::Entity, bottom: &[u32]) {
    sweep_with(world, e, bottom, Kernel::Simd);
}

/// [`sweep`] with the given kernel.
fn sweep_with(world: &mut World, e: hecs::Entity, bottom: &[u32], kernel: Kernel) {
    sweep_kept(world, e, bottom, kernel, &mut None);
}

/// [`sweep_with`] with the sweep in `kept` (created there on the first call), as a
/// caller that keeps it across sweeps does.
fn sweep_kept(
    world: &mut World,
    e: hecs::Entity,
    bottom: &[u32],
    kernel: Kernel,
    kept: &mut Option<GroundUpSweep>,
) {
    let sweep = kept.get_or_insert_with(GroundUpSweep::new);
    let levels = sweep.project(world, e, bottom.iter().copied(), &substep(kernel));
    assert!(levels.unwrap() > 0);
}

/// The top of the column pushed down by 5 cm: ground-up sweeps with hard constraints
/// restore the column (the roots do not move): the first one takes a good part of the
/// squash out, repeated ones converge to the rest shape.
#[test]
fn a_squashed_column_is_restored_from_the_ground_up() {
    for families in ["edges+volume", "vertex-face", "vertex-face+edges"] {
        let mut world = World::new();
        let (e, bottom) = column(&mut world, families);
        let before: Vec<Vector3<f32>> = {
            let mut p = world.get::<&mut Particles>(e).unwrap();
            for x in p.positions_mut() {
                if x.y > 0.5 {
                    x.y -= 0.05;
                }
            }
            p.positions().to_vec()
        };
        let height = |w: &World| {
            let p = w.get::<&Particles>(e).unwrap();
            p.positions().iter().map(|x| x.y).fold(f32::MIN, f32::max)
        };
        sweep(&mut world, e, &bottom);
        let first = height(&world);
        for _ in 0..49 {
            sweep(&mut world, e, &bottom);
        }
        let last = height(&world);
        println!("{families}: top at {first:.4} m after one sweep, {last:.4} after 50 (rest 0.6, squashed 0.55)");
        let p = world.get::<&Particles>(e).unwrap();
        for &i in &bottom {
            assert_eq!(p.positions()[i as usize], before[i as usize], "{families}");
        }
        assert!(
            first > 0.56,
            "{families}: top at {first} after one stacked sweep"
        );
        assert!(
            (last - 0.6).abs() < 0.005,
            "{families}: top at {last} after 50 sweeps"
        );
        let tets = world.get::<&Tetrahedra>(e).unwrap();
        assert_eq!(tets.count_inverted(p.positions()), 0, "{families}");
    }
}

/// A column 16 cells tall with every particle above the roots moved sideways by up to
/// 1 mm: ground-up sweeps only shrink the error. (A sweep that froze every level below the
/// current one would explode deep bodies, but only with the substeps' velocities: that is
/// guarded through the coupling, by the deep-body stacking test at the workspace root.)
#[test]
fn a_tall_column_shaken_sideways_settles() {
    let mut world = World::new();
    let (e, bottom) = column_of(&mut world, "edges+volume", [2, 16, 2]);
    let mut seed = 12345u32;
    let mut rand = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
    };
    {
        let mut p = world.get::<&mut Particles>(e).unwrap();
        for x in p.positions_mut() {
            if x.y > 1e-4 {
                x.x += 1e-3 * rand();
                x.z += 1e-3 * rand();
            }
        }
    }
    let error = |w: &World| {
        let p = w.get::<&Particles>(e).unwrap();
        max_edge_error(&p, &w.get::<&EdgeConstraints>(e).unwrap())
    };
    let start = error(&world);
    let mut worst = start;
    for _ in 0..20 {
        sweep(&mut world, e, &bottom);
        worst = worst.max(error(&world));
    }
    let end = error(&world);
    println!(
        "edge error: {start:.3e} m at the start, at most {worst:.3e}, {end:.3e} after 20 sweeps"
    );
    assert!(worst <= start, "the error grew to {worst} (start {start})");
    assert!(
        end < 0.5 * start,
        "the error only went from {start} to {end}"
    );
}

/// The SIMD sweep (colour classes of a level in lanes) against the scalar reference (the
/// same order one projection at a time): the same positions to rounding, on a squashed and
/// sheared column of every family set.
#[test]
fn simd_sweep_agrees_with_the_scalar_reference() {
    for families in ["edges+volume", "vertex-face", "vertex-face+edges"] {
        let mut runs = Vec::new();
        for kernel in [Kernel::Scalar, Kernel::Simd] {
            let mut world = World::new();
            let (e, bottom) = column_of(&mut world, families, [3, 5, 3]);
            {
                let mut p = world.get::<&mut Particles>(e).unwrap();
                for x in p.positions_mut() {
                    x.x += 0.05 * x.y * x.y;
                    x.y *= 0.9;
                }
            }
            for _ in 0..5 {
                sweep_with(&mut world, e, &bottom, kernel);
            }
            let p = world.get::<&Particles>(e).unwrap();
            runs.push(p.positions().to_vec());
        }
        let moved = runs[0]
            .iter()
            .zip(&runs[1])
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f32::max);
        println!("{families}: largest difference SIMD − scalar {moved:.2e} m");
        assert!(
            moved < 1e-5,
            "{families}: SIMD and scalar differ by {moved} m"
        );
    }
}

/// A sweep kept across sweeps and changes of the roots (as the coupling keeps it) sweeps
/// exactly as one built afresh for each set of roots.
#[test]
fn kept_layers_sweep_as_fresh_ones() {
    for families in ["edges+volume", "vertex-face+edges"] {
        let squashed = |world: &mut World| {
            let (e, bottom) = column_of(world, families, [2, 4, 2]);
            let mut p = world.get::<&mut Particles>(e).unwrap();
            for x in p.positions_mut() {
                x.y *= 0.95;
                x.x += 0.01 * x.y;
            }
            drop(p);
            (e, bottom)
        };
        let mut kept_world = World::new();
        let (a, bottom) = squashed(&mut kept_world);
        let mut fresh_world = World::new();
        let (b, _) = squashed(&mut fresh_world);
        let root_sets = [bottom.clone(), bottom[..3].to_vec(), bottom.clone()];
        let mut kept: Option<GroundUpSweep> = None;
        for roots in &root_sets {
            sweep_kept(&mut kept_world, a, roots, Kernel::Simd, &mut kept);
            sweep(&mut fresh_world, b, roots);
        }
        let x = kept_world
            .get::<&Particles>(a)
            .unwrap()
            .positions()
            .to_vec();
        let y = fresh_world
            .get::<&Particles>(b)
            .unwrap()
            .positions()
            .to_vec();
        assert_eq!(x, y, "{families}");
    }
}

/// One sweep kept for two bodies of different sizes, called on each in turn, sweeps each as
/// a sweep of its own.
#[test]
fn a_sweep_shared_by_two_bodies_sweeps_each_as_its_own() {
    let squash = |world: &mut World, e: hecs::Entity| {
        for x in world.get::<&mut Particles>(e).unwrap().positions_mut() {
            x.y *= 0.9;
        }
    };
    let mut shared_world = World::new();
    let (a, bottom_a) = column_of(&mut shared_world, "edges+volume", [2, 3, 2]);
    let (b, bottom_b) = column_of(&mut shared_world, "edges+volume", [2, 2, 2]);
    let mut own_world = World::new();
    let (c, _) = column_of(&mut own_world, "edges+volume", [2, 3, 2]);
    let (d, _) = column_of(&mut own_world, "edges+volume", [2, 2, 2]);
    squash(&mut shared_world, a);
    squash(&mut shared_world, b);
    squash(&mut own_world, c);
    squash(&mut own_world, d);
    let (mut shared, mut own_c, mut own_d) = (None, None, None);
    for _ in 0..3 {
        sweep_kept(&mut shared_world, a, &bottom_a, Kernel::Simd, &mut shared);
        sweep_kept(&mut shared_world, b, &bottom_b, Kernel::Simd, &mut shared);
        sweep_kept(&mut own_world, c, &bottom_a, Kernel::Simd, &mut own_c);
        sweep_kept(&mut own_world, d, &bottom_b, Kernel::Simd, &mut own_d);
    }
    let x = |w: &World, e| w.get::<&Particles>(e).unwrap().positions().to_vec();
    assert_eq!(x(&shared_world, a), x(&own_world, c));
    assert_eq!(x(&shared_world, b), x(&own_world, d));
}
