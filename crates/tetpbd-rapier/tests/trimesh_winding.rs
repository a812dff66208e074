//! Soft bodies rest on triangle meshes of either winding, open or closed, with or without
//! pseudo-normals (`TriMeshFlags::ORIENTED`, `FIX_INTERNAL_EDGES`), where a rigid body rests.

mod robust_common;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, TriMeshFlags};
use robust_common::{particles, scene, soft_box};
use tetpbd_rapier::CoupledWorld;

/// Flags of the meshes tried.
const FLAGS: [(&str, TriMeshFlags); 3] = [
    ("no flags", TriMeshFlags::empty()),
    ("ORIENTED", TriMeshFlags::ORIENTED),
    ("FIX_INTERNAL_EDGES", TriMeshFlags::FIX_INTERNAL_EDGES),
];

/// A 10 m square of two triangles at y = 0, wound counter-clockwise seen from above
/// (normal up) or clockwise (normal down).
fn square(clockwise: bool) -> (Vec<Vector>, Vec<[u32; 3]>) {
    let v = vec![
        Vector::new(-5.0, 0.0, -5.0),
        Vector::new(5.0, 0.0, -5.0),
        Vector::new(5.0, 0.0, 5.0),
        Vector::new(-5.0, 0.0, 5.0),
    ];
    let up = vec![[0, 2, 1], [0, 3, 2]];
    let down = vec![[0, 1, 2], [0, 2, 3]];
    (v, if clockwise { down } else { up })
}

/// A closed 10 m × 1 m × 10 m slab whose top is at y = 0, its triangles wound outwards or
/// inwards.
fn closed_slab(inwards: bool) -> (Vec<Vector>, Vec<[u32; 3]>) {
    let (x, z) = (5.0, 5.0);
    let v: Vec<Vector> = (0..8)
        .map(|k| {
            let sx = if k & 1 == 0 { -x } else { x };
            let sy = if k & 2 == 0 { -1.0 } else { 0.0 };
            let sz = if k & 4 == 0 { -z } else { z };
            Vector::new(sx, sy, sz)
        })
        .collect();
    // Outward faces of the box with corners indexed by bits (x, y, z).
    let quads = [
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
    ];
    let mut idx = Vec::new();
    for [a, b, c, d] in quads {
        idx.push([a, b, c]);
        idx.push([a, c, d]);
    }
    if inwards {
        for t in &mut idx {
            t.swap(1, 2);
        }
    }
    (v, idx)
}

/// Drops a soft cube of `size` m at `speed` m/s onto the mesh; returns its lowest particle
/// and its fastest particle after 2 s.
fn drop_soft(
    mesh: (Vec<Vector>, Vec<[u32; 3]>),
    flags: TriMeshFlags,
    size: f32,
    speed: f32,
) -> (f32, f32) {
    let mut s = scene();
    add_mesh(&mut s, mesh, flags);
    let at = Vector3::new(0.1, size / 2.0 + 0.05, -0.2);
    let cells = (size / 0.15).ceil() as u32;
    let e = soft_box(
        &mut s,
        Vector3::repeat(size),
        [cells; 3],
        at,
        Vector3::new(0.0, -speed, 0.0),
        1000.0,
    );
    for _ in 0..120 {
        let stats = s.step().expect("step");
        assert_eq!(stats.soft.non_finite_resets, 0);
    }
    let p = particles(&s, e);
    (p.aabb().0.y, p.max_speed())
}

fn add_mesh(s: &mut CoupledWorld, (v, idx): (Vec<Vector>, Vec<[u32; 3]>), flags: TriMeshFlags) {
    let collider = ColliderBuilder::trimesh_with_flags(v, idx, flags).expect("mesh");
    s.physics.insert(RigidBodyBuilder::fixed(), collider);
}

/// Lowest point of a rigid 0.5 m cube dropped at 2 m/s onto the mesh, after 2 s.
fn drop_rigid(mesh: (Vec<Vector>, Vec<[u32; 3]>), flags: TriMeshFlags) -> f32 {
    let mut s = scene();
    add_mesh(&mut s, mesh, flags);
    let (h, _) = s.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.1, 0.3, -0.2))
            .linvel(Vector::new(0.0, -2.0, 0.0)),
        ColliderBuilder::cuboid(0.25, 0.25, 0.25),
    );
    for _ in 0..120 {
        s.step().expect("step");
    }
    s.physics.bodies[h].translation().y - 0.25
}

fn check_rests(what: &str, (lowest, speed): (f32, f32)) {
    assert!(
        (-0.01..0.02).contains(&lowest),
        "{what}: lowest particle at {lowest} m, not resting on the mesh at 0"
    );
    assert!(speed < 0.2, "{what}: still moving at {speed} m/s");
}

#[test]
fn soft_cube_rests_on_an_open_square_of_either_winding() {
    for clockwise in [false, true] {
        for (name, flags) in FLAGS {
            let rigid = drop_rigid(square(clockwise), flags);
            let what = format!("clockwise {clockwise}, {name}");
            // The rigid reference: rapier rests a rigid cube on every variant but the
            // clockwise one with internal-edge fixing, whose pseudo-normals point down (the
            // cube falls through). The soft cube must rest on all of them.
            let rapier_falls = clockwise && flags == TriMeshFlags::FIX_INTERNAL_EDGES;
            assert_eq!(
                rigid.abs() > 0.02,
                rapier_falls,
                "{what}: rigid cube at {rigid}"
            );
            for (size, speed) in [(0.3f32, 0.5f32), (0.5, 2.0), (1.0, 5.0)] {
                let r = drop_soft(square(clockwise), flags, size, speed);
                check_rests(&format!("{what}, {size} m at {speed} m/s"), r);
            }
        }
    }
}

#[test]
fn soft_cube_rests_on_a_closed_mesh_wound_outwards_or_inwards() {
    for inwards in [false, true] {
        for (name, flags) in FLAGS {
            let what = format!("inwards {inwards}, {name}");
            for (size, speed) in [(0.3f32, 0.5f32), (0.5, 2.0), (1.0, 5.0)] {
                let r = drop_soft(closed_slab(inwards), flags, size, speed);
                check_rests(&format!("{what}, {size} m at {speed} m/s"), r);
            }
        }
    }
}

#[test]
fn soft_cube_thrown_up_stays_below_an_open_ceiling_of_either_winding() {
    for clockwise in [false, true] {
        for (name, flags) in FLAGS {
            for speed in [2.0f32, 6.0] {
                let mut s = scene();
                let (v, idx) = square(clockwise);
                let v = v
                    .into_iter()
                    .map(|p| p + Vector::new(0.0, 1.0, 0.0))
                    .collect();
                add_mesh(&mut s, (v, idx), flags);
                let at = Vector3::new(0.0, 0.6, 0.0);
                let up = Vector3::new(0.0, speed, 0.0);
                let e = soft_box(&mut s, Vector3::repeat(0.4), [3; 3], at, up, 1000.0);
                let mut highest = f32::MIN;
                for _ in 0..40 {
                    s.step().expect("step");
                    highest = highest.max(particles(&s, e).aabb().1.y);
                }
                assert!(
                    highest < 1.01,
                    "clockwise {clockwise}, {name}, {speed} m/s: top reached {highest} m"
                );
            }
        }
    }
}
