//! In the pile of nine cubes (`ContactScene::pile`, rapier's `fem_bench` jelly pile) at 80
//! substeps with `DeformationDamping` 5/s and the self-weight sweep, a cube struck by another
//! is not pressed into the ground, and nothing is launched by a push-out. A slow particle of
//! a body being struck is sped up within the frame, so ground contact candidates must take
//! the body's fastest particle into account, not only each particle's own path over the
//! frame (`tetpbd-rapier`, `gather::candidates`). The test replays the scene's first 60
//! frames (about 1 s) and checks every substep's end.

use tetpbd::hecs::{Entity, World};
use tetpbd::{Particles, SubstepHook};
use tetpbd_bench::{tetpbd_contact_world, ContactScene};
use tetpbd_rapier::{SoftContactSettings, SoftContacts};

/// The lowest particle of any body at the end of every substep, m.
struct Lowest {
    bodies: Vec<Entity>,
    lowest: f32,
}

impl SubstepHook for Lowest {
    fn end_substep(&mut self, world: &mut World, _h: f32) {
        for &e in &self.bodies {
            let p = world.get::<&Particles>(e).unwrap();
            for x in p.positions() {
                self.lowest = self.lowest.min(x.y);
            }
        }
    }
}

#[test]
fn struck_cube_stays_out_of_the_ground() {
    let scene = ContactScene::pile(60).unwrap();
    let (mut world, bodies) = tetpbd_contact_world(&scene, 5.0, true, 80, 1).unwrap();
    let contacts = SoftContacts::new(SoftContactSettings::default()).unwrap();
    let lowest = Lowest {
        bodies: bodies.clone(),
        lowest: f32::INFINITY,
    };
    let mut hook = (contacts, lowest);
    for frame in 0..60 {
        world.step_with(&mut hook).unwrap();
        assert!(
            hook.1.lowest > -0.01,
            "frame {frame}: a particle {} m inside the ground",
            -hook.1.lowest
        );
    }
    for &e in &bodies {
        let p = world.soft.get::<&Particles>(e).unwrap();
        assert!(p.max_speed() < 30.0, "launched: {} m/s", p.max_speed());
    }
}
