//! A body's mechanical energy, for the matrix's energy column: kinetic + elastic (what its
//! compliant constraints store) + gravitational potential.
//!
//! The elastic energy of a family with compliance `α > 0` is `Σ C²/(2α)` (J; `C` in m for
//! the edges and vertex–faces, α in m/N; `C` in m³ for the volumes, α in m⁵/N). Hard
//! families (`α = 0`) hold no defined energy and count as 0: a hard body's energy is its
//! kinetic and potential energy. The Neo-Hookean material's is
//! [`tetpbd::NeoHookeanMaterial::elastic_energy`]. The potential is `−Σ mᵢ g·xᵢ` (J). Without external work
//! (pins do none: they do not move; a ground contact with restitution 0 only removes
//! energy) this sum may only fall. The matrix compares kinetic + gravitational energy
//! ([`motion`]) at every frame with the whole sum at the start: a rise above it is energy
//! gained. (Not the whole sum at every frame: with one iteration of few substeps XPBD does
//! not converge, the body is softer than its compliance, and `C²/2α` of its sag is not
//! energy it holds.)

use hecs::{Entity, World};
use nalgebra::Vector3;
use tetpbd::{
    EdgeConstraints, ElasticFamilies, NeoHookeanMaterial, Particles, Tetrahedra,
    VertexFaceConstraints, VolumeConstraints,
};

/// Elastic energy of the compliant families and the material of body `e`, J
/// ([`tetpbd::ElasticFamilies`]).
pub fn elastic(world: &World, e: Entity) -> f64 {
    let (Ok(p), Ok(t)) = (world.get::<&Particles>(e), world.get::<&Tetrahedra>(e)) else {
        return 0.0;
    };
    let (edges, volume, vertex_face, material) = (
        world.get::<&EdgeConstraints>(e).ok(),
        world.get::<&VolumeConstraints>(e).ok(),
        world.get::<&VertexFaceConstraints>(e).ok(),
        world.get::<&NeoHookeanMaterial>(e).ok(),
    );
    ElasticFamilies {
        edges: edges.as_deref(),
        volume: volume.as_deref(),
        vertex_face: vertex_face.as_deref(),
        material: material.as_deref(),
    }
    .energy(&t, p.positions())
}

/// Kinetic + elastic + gravitational energy of body `e` under gravity `g` (m/s²), J.
pub fn mechanical(world: &World, e: Entity, g: Vector3<f32>) -> f64 {
    motion(world, e, g) + elastic(world, e)
}

/// Kinetic + gravitational energy of body `e` under gravity `g` (m/s²), J: a lower bound of
/// [`mechanical`] (the elastic energy is never negative).
pub fn motion(world: &World, e: Entity, g: Vector3<f32>) -> f64 {
    let Ok(p) = world.get::<&Particles>(e) else {
        return 0.0;
    };
    let g = g.cast::<f64>();
    let potential: f64 = p
        .positions()
        .iter()
        .zip(p.masses())
        .map(|(x, &m)| -f64::from(m) * g.dot(&x.cast::<f64>()))
        .sum();
    let kinetic: f64 = p
        .velocities()
        .iter()
        .zip(p.masses())
        .map(|(v, &m)| 0.5 * f64::from(m) * v.cast::<f64>().norm_squared())
        .sum();
    kinetic + potential
}

/// Kinetic energy of body `e`'s motion relative to its best-fit rigid motion
/// ([`Particles::rigid_fit`]: centre-of-mass translation plus rotation), J: its internal,
/// vibrational kinetic energy `Σ ½ mᵢ |vᵢ − v_c − ω × (xᵢ − c)|²` over the free particles.
/// A body flying or rolling as a whole has none; one that jiggles, spins itself apart or is
/// crushed keeps it. The whole kinetic energy if the fit is not defined.
pub fn internal_kinetic(p: &Particles) -> f64 {
    let Some(fit) = p.rigid_fit() else {
        return f64::from(p.kinetic_energy());
    };
    let (c, vc, omega) = (
        fit.centre.cast::<f64>(),
        fit.velocity.cast::<f64>(),
        fit.angular_velocity.cast::<f64>(),
    );
    p.positions()
        .iter()
        .zip(p.velocities())
        .zip(p.masses().iter().zip(p.inv_masses()))
        .filter(|(_, (_, &inv_mass))| inv_mass > 0.0)
        .map(|((x, v), (&m, _))| {
            let rigid = vc + omega.cross(&(x.cast::<f64>() - c));
            0.5 * f64::from(m) * (v.cast::<f64>() - rigid).norm_squared()
        })
        .sum()
}
