//! The immovable ground of the impact cases: the plane y = 0, restitution 0.
//!
//! A [`SubstepHook`] that runs after the families every substep: a body touching the plane
//! that approaches it faster than its constraints carry a push has the excess approach taken
//! as a whole ([`ImpactReach::limit_approach`], [`impact_speed`]); a particle below the plane
//! is put back on it (a position constraint, as a coupling's contacts are), the depth beyond
//! the body's local reach taken by the whole body ([`ImpactReach`], as the rapier coupling's
//! contacts do), and a particle on it leaves the substep with no normal velocity (the
//! velocity pass of an XPBD contact, Müller et al. 2020, with restitution 0). It only ever
//! removes energy. The coupled table
//! runs rapier colliders through `tetpbd-rapier`; this plane keeps the impact rows
//! independent of the coupling so every constraint configuration is measured the same way.
//!
//! It also records the largest internal kinetic energy of a body at the end of any substep
//! ([`crate::energy::internal_kinetic`]): an impact's vibration lasts a few substeps, well
//! inside the frame it happens in, where a frame-by-frame sample would miss it.

use tetpbd::nalgebra::Vector3;
use tetpbd::{
    hecs, impact_speed, EdgeConstraints, ImpactReach, NeoHookeanMaterial, Particles, SubstepHook,
    Surface, Tetrahedra, VertexFaceConstraints, VolumeConstraints,
};

/// The plane y = 0 (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct Ground {
    peak_internal: f64,
}

impl Ground {
    /// The largest internal kinetic energy of a body at the end of a substep so far, J.
    pub fn peak_internal(&self) -> f64 {
        self.peak_internal
    }
}

impl SubstepHook for Ground {
    fn project(&mut self, world: &mut hecs::World, substep: tetpbd::SubstepContext) {
        type Body<'a> = (
            &'a mut Particles,
            Option<&'a Surface>,
            Option<&'a Tetrahedra>,
            Option<&'a EdgeConstraints>,
            Option<&'a VertexFaceConstraints>,
            Option<&'a VolumeConstraints>,
            Option<&'a NeoHookeanMaterial>,
        );
        for (p, surface, tets, edges, vf, volume, material) in world.query_mut::<Body<'_>>() {
            let mut impact =
                surface.map_or(ImpactReach::new(f32::INFINITY), |s| ImpactReach::of(p, s));
            let touching =
                (0..p.len()).any(|i| p.positions()[i].y < 0.0 && p.inv_masses()[i] > 0.0);
            if let (true, Some(t)) = (touching, tets) {
                let c = impact_speed::wave_speed(p, t, edges, vf, volume, material);
                let limit = impact_speed::approach_limit(impact.reach(), c, substep.h());
                impact.limit_approach(p, &Vector3::y(), limit);
            }
            for i in 0..p.len() {
                let depth = -p.positions()[i].y;
                impact.push_out(p, i, depth, &Vector3::y());
            }
        }
    }

    fn end_substep(&mut self, world: &mut hecs::World, _substep: tetpbd::SubstepContext) {
        for p in world.query_mut::<&mut Particles>() {
            for i in 0..p.len() {
                if p.positions()[i].y <= 0.0 && p.velocities()[i].y < 0.0 {
                    p.velocities_mut()[i].y = 0.0;
                }
            }
            let internal = crate::energy::internal_kinetic(p);
            self.peak_internal = self.peak_internal.max(internal);
        }
    }
}
