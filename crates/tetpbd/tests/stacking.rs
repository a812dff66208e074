//! The ground-up (stacking) sweep: levels from the roots, lower particles frozen.

use hecs::World;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{
    project_stacked, BodyConstraints, EdgeConstraints, Family, Particles, SoftBodyBuilder,
    StackingLayers, Tetrahedra, VertexFaceConstraints, VolumeConstraints,
};

/// A column of three cells standing on y = 0; returns the entity and its bottom particles.
fn column(world: &mut World, families: &str) -> (hecs::Entity, Vec<u32>) {
    let mesh = box_grid(Vector3::new(0.2, 0.6, 0.2), [1, 3, 1], CellSplit::Six).unwrap();
    let b = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .translation(Vector3::new(0.0, 0.3, 0.0));
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

#[test]
fn levels_count_cells_from_the_roots() {
    let mut world = World::new();
    let (e, bottom) = column(&mut world, "edges+volume");
    assert_eq!(bottom.len(), 4);
    let (p, tets, edges) = world
        .query_one_mut::<(&Particles, &Tetrahedra, &EdgeConstraints)>(e)
        .unwrap();
    let mut layers = StackingLayers::new(p.len(), tets);
    assert!(layers.fits(p.len(), tets));
    let top = layers.set_roots(tets, Some(edges), bottom.iter().copied());
    assert_eq!(top, 3);
    for (i, x) in p.positions().iter().enumerate() {
        let expected = (x.y / 0.2).round() as u32;
        assert_eq!(layers.level(i), Some(expected), "particle {i} at {x:?}");
    }
    // The same roots again (in another order): the same levels.
    let again = layers.set_roots(tets, Some(edges), bottom.iter().rev().copied());
    assert_eq!(again, 3);
    // One root: the column is reached from one corner.
    let one = layers.set_roots(tets, Some(edges), [bottom[0]]);
    assert!(one >= 3, "{one}");
    assert_eq!(layers.level(bottom[0] as usize), Some(0));
    // No roots: nothing reached.
    assert_eq!(layers.set_roots(tets, Some(edges), []), 0);
    assert_eq!(layers.level(0), None);
    // Built for another body.
    assert!(!StackingLayers::new(p.len() + 1, tets).fits(p.len(), tets));
    assert!(!StackingLayers::default().fits(p.len(), tets));
}

/// The top of the column pushed down by 5 cm: one ground-up sweep with hard constraints
/// restores the column by moving the upper particles only (the roots do not move), and
/// brings it much closer to its rest shape than the squashed start.
#[test]
fn a_squashed_column_is_restored_from_the_ground_up() {
    for families in ["edges+volume", "vertex-face", "vertex-face+edges"] {
        let mut world = World::new();
        let (e, bottom) = column(&mut world, families);
        let (p, tets, edges, vf, vol) = world
            .query_one_mut::<(
                &mut Particles,
                &Tetrahedra,
                Option<&mut EdgeConstraints>,
                Option<&mut VertexFaceConstraints>,
                Option<&mut VolumeConstraints>,
            )>(e)
            .unwrap();
        for i in 0..p.len() {
            let x = p.positions()[i];
            if x.y > 0.5 {
                p.positions_mut()[i].y -= 0.05;
            }
        }
        let before: Vec<Vector3<f32>> = p.positions().to_vec();
        let height = |p: &Particles| p.positions().iter().map(|x| x.y).fold(f32::MIN, f32::max);
        let mut layers = StackingLayers::new(p.len(), tets);
        layers.set_roots(tets, edges.as_deref(), bottom.iter().copied());
        let count = project_stacked(
            p,
            tets,
            BodyConstraints {
                edges,
                vertex_face: vf,
                volume: vol,
            },
            Family::ALL,
            1.0 / 600.0,
            &layers,
        );
        assert!(count.applied > 0, "{families}");
        for &i in &bottom {
            assert_eq!(p.positions()[i as usize], before[i as usize], "{families}");
        }
        let top = height(p);
        println!("{families}: top at {top:.4} m after one sweep (rest 0.6, squashed 0.55)");
        assert!(
            (top - 0.6).abs() < 0.01,
            "{families}: top at {top} after one stacked sweep"
        );
        assert_eq!(tets.count_inverted(p.positions()), 0, "{families}");
    }
}
