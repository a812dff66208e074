//! Rigid corners of triangle meshes and heightfields poking into a coarse soft surface are
//! caught by the soft surface triangles, as those of polyhedra are: a spike of a fixed
//! terrain does not pass between the particles of a coarse soft slab.

mod coupling_common;

use coupling_common::{ground, inverted, particles, scene, soft_box};
use nalgebra::Vector3;
use rapier3d::geometry::Array2;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, TriMeshFlags};
use tetpbd_rapier::{SoftCollider, SoftFeature};

/// Height of the spike's tip above the ground, m.
const TIP: f32 = 0.5;

/// Drops a coarse soft slab (3 × 0.2 × 3 m, 3 × 1 × 3 cells: the centre of the slab is the
/// centre of a cell, 0.5 m from every particle) onto a fixed spike with its tip at the
/// slab's centre, 1 s. Returns the slab's lowest particle at the end and the number of
/// triangle contacts reported in the last frame.
fn drop_on(spike: ColliderBuilder) -> (f32, usize) {
    let mut s = scene(10);
    ground(&mut s);
    let (_, spike_h) = s.physics.insert(RigidBodyBuilder::fixed(), spike);
    let slab = soft_box(
        &mut s,
        Vector3::new(3.0, 0.2, 3.0),
        [3, 1, 3],
        Vector3::new(0.0, TIP + 0.2, 0.0),
        SoftCollider::default(),
    );
    for _ in 0..60 {
        s.step().expect("step");
    }
    let triangles = s
        .coupling
        .contacts()
        .iter()
        .filter(|c| c.collider == spike_h && matches!(c.feature, SoftFeature::Triangle(_)))
        .count();
    let low = particles(&s, slab).aabb().0.y;
    println!("lowest particle {low:.4} m, triangle contacts with the spike {triangles}");
    assert_eq!(inverted(&s, slab), 0, "slab inverted");
    (low, triangles)
}

fn check(spike: ColliderBuilder) {
    let (low, triangles) = drop_on(spike);
    assert!(triangles > 0, "no triangle contact with the spike");
    // The slab rests on the tip instead of falling around it (its lowest particle, 0.5 m
    // from the tip horizontally, would then lie on the spike's flanks, far below the tip).
    assert!(
        low > TIP - 0.1,
        "slab fell around the spike: lowest particle {low} m"
    );
}

#[test]
fn trimesh_spike_is_caught_by_soft_triangles() {
    // A four-sided pyramid, 1 m wide at the ground, tip at the origin's vertical.
    let v = vec![
        Vector::new(-0.5, 0.0, -0.5),
        Vector::new(0.5, 0.0, -0.5),
        Vector::new(0.5, 0.0, 0.5),
        Vector::new(-0.5, 0.0, 0.5),
        Vector::new(0.0, TIP, 0.0),
    ];
    let idx = vec![
        [0, 4, 1],
        [1, 4, 2],
        [2, 4, 3],
        [3, 4, 0],
        [0, 1, 2],
        [0, 2, 3],
    ];
    let mesh = ColliderBuilder::trimesh_with_flags(v, idx, TriMeshFlags::ORIENTED).expect("mesh");
    check(mesh);
}

/// A fixed polyhedron's corners are paired only with the soft triangles that can reach them
/// (`contacts::corner` module docs): the tip is still caught by the triangle over it.
#[test]
fn fixed_convex_spike_is_caught_by_soft_triangles() {
    let v = [
        Vector::new(-0.5, 0.0, -0.5),
        Vector::new(0.5, 0.0, -0.5),
        Vector::new(0.5, 0.0, 0.5),
        Vector::new(-0.5, 0.0, 0.5),
        Vector::new(0.0, TIP, 0.0),
    ];
    check(ColliderBuilder::convex_hull(&v).expect("convex hull"));
}

#[test]
fn heightfield_peak_is_caught_by_soft_triangles() {
    // 3 × 3 heights over 1 m × 1 m: one peak in the middle.
    let mut heights = Array2::repeat(3, 3, 0.0);
    heights[(1, 1)] = TIP;
    check(ColliderBuilder::heightfield(
        heights,
        Vector::new(1.0, 1.0, 1.0),
    ));
}
