//! Frame-by-frame and substep-by-substep printing of one random scene (`--trace`).

use rapier3d::prelude::RigidBodyHandle;
use tetpbd::Particles;
use tetpbd_rapier::CoupledWorld;

/// Prints every soft body's kinetic energy and fastest particle after each substep.
pub(super) struct SubstepTrace;

impl tetpbd::SubstepHook for SubstepTrace {
    fn project(&mut self, world: &mut hecs::World, substep: tetpbd::SubstepContext) {
        let h = substep.h();
        let bodies: Vec<String> = world
            .query::<&Particles>()
            .iter()
            .map(|p| {
                let ke: f32 = p
                    .positions()
                    .iter()
                    .zip(p.prev_positions())
                    .zip(p.masses())
                    .map(|((x, x0), m)| 0.5 * m * ((x - x0) / h).norm_squared())
                    .sum();
                format!("{ke:.1}")
            })
            .collect();
        println!("  projected {}: {bodies:?}", substep.substep());
    }

    fn end_substep(&mut self, world: &mut hecs::World, substep: tetpbd::SubstepContext) {
        let bodies: Vec<String> = world
            .query::<&Particles>()
            .iter()
            .map(|p| {
                let (i, v) = p
                    .velocities()
                    .iter()
                    .enumerate()
                    .max_by(|a, b| a.1.norm().total_cmp(&b.1.norm()))
                    .map_or((0, nalgebra::Vector3::zeros()), |(i, v)| (i, *v));
                let x = p.positions().get(i).copied().unwrap_or_default();
                format!(
                    "KE {:.1} max {:.1} #{i} at {:.3} {:.3} {:.3} v {:.1} {:.1} {:.1}",
                    p.kinetic_energy(),
                    p.max_speed(),
                    x.x,
                    x.y,
                    x.z,
                    v.x,
                    v.y,
                    v.z
                )
            })
            .collect();
        println!("  substep {}: {bodies:?}", substep.substep());
    }
}

/// One frame of a traced scene: every soft body's mass, fastest particle, speed, kinetic and
/// potential energy, lowest point and centre; the rigid bodies' speeds; the contact counts.
pub(super) fn print_frame(
    f: u32,
    gain: f32,
    s: &CoupledWorld,
    boxes: &[RigidBodyHandle],
    stats: &tetpbd_rapier::CouplingStats,
) {
    let speeds: Vec<String> = s
        .soft
        .query::<&Particles>()
        .iter()
        .map(|p| {
            let c = p.center_of_mass();
            let m = p.total_mass();
            let v = p.linear_momentum() / m;
            format!(
                "{m:.1} kg max {:.2} v {:.2} KE {:.1} PE {:.1} low {:.3} @ {:.2} {:.2} {:.2}",
                p.max_speed(),
                v.norm(),
                p.kinetic_energy(),
                m * 9.81 * c.y,
                p.aabb().0.y,
                c.x,
                c.y,
                c.z
            )
        })
        .collect();
    let rigid: Vec<String> = boxes
        .iter()
        .map(|&h| {
            let b = &s.physics.bodies[h];
            format!(
                "{:.2}@{:.2} w {:.1}",
                b.linvel().length(),
                b.translation().y,
                b.angvel().length()
            )
        })
        .collect();
    let c = &stats.soft_contacts;
    println!(
            "frame {f}: E {:.1} soft {speeds:?} rigid {rigid:?} soft contacts {} deep {} clamps {} pen {:.3}, rigid contacts {} written {} pen {:.3}",
            gain,
            c.contacts,
            c.deep,
            c.clamps,
            c.max_penetration,
            stats.contacts,
            stats.bodies_written,
            stats.max_penetration
        );
}
