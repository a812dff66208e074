//! Impulses and placement beside the cases of the main sweeps: bodies renumbered for
//! locality and bodies with some pinned particles.

use nalgebra::{UnitQuaternion, Vector3};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::SoftBodyBuilder;

#[test]
fn impulse_at_a_point_of_a_renumbered_partly_pinned_body_changes_momentum_by_the_impulse() {
    for (cells, scale) in [([3, 2, 4], 0.05), ([5, 1, 2], 30.0)] {
        let mesh = box_grid(Vector3::new(1.0, 0.5, 0.7), cells, CellSplit::Six).unwrap();
        let mut b = SoftBodyBuilder::new(mesh)
            .edges(0.0)
            .volume(0.0)
            .spatial_order(true)
            .pinned([0, 1, 2])
            .scale(scale)
            .rotation(UnitQuaternion::from_euler_angles(0.4, 1.0, -0.2))
            .build()
            .unwrap();
        let free_momentum = |b: &tetpbd::SoftBody| -> Vector3<f64> {
            let p = &b.particles;
            p.velocities()
                .iter()
                .zip(p.masses())
                .zip(p.inv_masses())
                .filter(|(_, w)| **w > 0.0)
                .map(|((v, m), _)| v.cast::<f64>() * f64::from(*m))
                .sum()
        };
        let j = Vector3::new(3.0, -1.0, 2.0) * scale * scale * scale;
        let target = b.particles.center_of_mass();
        let before = free_momentum(&b);
        let hit = b
            .particles
            .apply_impulse_at_point(&b.tetrahedra, j, target)
            .unwrap();
        let dp = free_momentum(&b) - before;
        assert!(
            (dp - j.cast::<f64>()).norm() <= 1e-5 * f64::from(j.norm()),
            "{cells:?}: {dp:?}"
        );
        assert!(hit.inside, "{cells:?}: the centre of a box lies inside it");
        for (k, w) in hit.weights.iter().enumerate() {
            let i = b.tetrahedra.indices()[hit.tetrahedron][k] as usize;
            if b.particles.is_pinned(i) {
                assert_eq!(*w, 0.0, "a pinned corner takes no share");
            }
        }
    }
}

#[test]
fn spin_given_to_a_partly_pinned_body_leaves_its_pins_at_rest() {
    let mesh = box_grid(Vector3::repeat(0.4), [2, 2, 2], CellSplit::Five).unwrap();
    let b = SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .pinned([0, 4])
        .scale(2.5)
        .angular_velocity(Vector3::new(0.0, 4.0, 1.0))
        .velocity(Vector3::new(1.0, 0.0, 0.0))
        .build()
        .unwrap();
    let p = &b.particles;
    for i in 0..p.len() {
        if p.is_pinned(i) {
            assert_eq!(p.velocities()[i], Vector3::zeros(), "pinned particle {i}");
        } else {
            assert!(p.velocities()[i].norm() > 0.0, "free particle {i}");
        }
    }
}
