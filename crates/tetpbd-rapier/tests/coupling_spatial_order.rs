//! Attachments and contact reports of a body whose particles the builder renumbered for
//! locality (`SoftBodyBuilder::spatial_order`): mesh vertex indices go through
//! `Particles::particle_of`, and the right physical points are held.

mod coupling_common;

use coupling_common::{ground, particles, scene};
use nalgebra::Vector3;
use rapier3d::prelude::RigidBodyBuilder;
use tetpbd::generators::{self, CellSplit};
use tetpbd::SoftBodyBuilder;
use tetpbd_rapier::{Attachments, SoftCollider, SoftFeature};

#[test]
fn a_renumbered_beam_hangs_from_its_root_vertices() {
    let mut s = scene(10);
    let anchor = s.physics.bodies.insert(RigidBodyBuilder::fixed());
    let beam = generators::beam(0.6, 0.1, 6, 1, CellSplit::Six).expect("mesh");
    let (mesh, _) = generators::shuffled(&beam, 11);
    // Root vertices by input index, in the shuffled mesh.
    let roots: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&v| mesh.vertices[v as usize].x < 1e-4)
        .collect();
    assert_eq!(roots.len(), 4);
    let b = SoftBodyBuilder::new(mesh.clone())
        .spatial_order(true)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .build()
        .expect("body");
    assert_ne!(
        b.particles.source(),
        (0..b.particles.len() as u32).collect::<Vec<_>>().as_slice(),
        "the builder renumbered the particles"
    );
    let mut att = Attachments::new();
    for &v in &roots {
        let k = b.particles.particle_of(v).expect("vertex");
        att.attach_to_body(&b.particles, k, &s.physics.bodies, anchor, 0.0)
            .expect("attach");
    }
    let e = b.spawn(&mut s.soft);
    s.soft.insert_one(e, att).expect("entity");
    for _ in 0..60 {
        s.step().expect("step");
    }
    let p = particles(&s, e);
    for &v in &roots {
        let x = p.positions()[p.particle_of(v).expect("vertex") as usize];
        let moved = (x - mesh.vertices[v as usize]).norm();
        assert!(moved < 1e-3, "root vertex {v} moved {moved} m");
    }
    // The free end sags under gravity: the beam hangs from its root, not from other points.
    let tip = (0..mesh.vertices.len() as u32)
        .find(|&v| mesh.vertices[v as usize].x > 0.6 - 1e-4)
        .expect("tip vertex");
    let x = p.positions()[p.particle_of(tip).expect("vertex") as usize];
    assert!(
        x.y < mesh.vertices[tip as usize].y - 1e-3,
        "tip at {x:?} did not sag"
    );
}

#[test]
fn contact_reports_name_particles_that_touch() {
    let mut s = scene(10);
    ground(&mut s);
    let cube = generators::box_grid(Vector3::repeat(0.4), [3, 3, 3], CellSplit::Six).expect("mesh");
    let (mesh, _) = generators::shuffled(&cube, 5);
    let e = SoftBodyBuilder::new(mesh)
        .spatial_order(true)
        .edges(0.0)
        .volume(0.0)
        .translation(Vector3::new(0.0, 0.25, 0.0))
        .build()
        .expect("body")
        .spawn(&mut s.soft);
    s.soft
        .insert_one(e, SoftCollider::default())
        .expect("entity");
    for _ in 0..60 {
        s.step().expect("step");
    }
    let p = particles(&s, e);
    let touching: Vec<u32> = s
        .coupling
        .contacts()
        .iter()
        .filter_map(|c| match c.feature {
            SoftFeature::Particle(i) => Some(i),
            SoftFeature::Triangle(_) => None,
        })
        .collect();
    assert!(!touching.is_empty(), "the cube rests on the ground");
    for i in touching {
        let rest_y = p.rest_positions()[i as usize].y;
        assert!(
            rest_y < -0.2 + 1e-4,
            "particle {i} (rest y {rest_y} m) is not on the bottom face"
        );
        assert!(p.positions()[i as usize].y < 0.01);
    }
}
