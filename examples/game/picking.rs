//! Picking by ray cast and dragging with a grab, with a scripted mouse.
//!
//! `pick` is the one place that asks the scene which soft body a ray hits (a ray cast
//! against the soft bodies' surfaces); everything else works from its answer (entity and
//! point).

use nalgebra::Vector3;
use tetpbd_rapier::prelude::{Grab, Particles, SoftQueries, SoftQueryFilter, Tetrahedra};
use tetpbd_rapier::rapier3d::geometry::Ray;
use tetpbd_rapier::rapier3d::math::Vector;

/// Grab stretch under the body's own weight, m: the compliance is this over `M g`.
const STRETCH_UNDER_WEIGHT: f32 = 0.01;
/// Largest grab force in body weights: lifts with at most twice gravity's acceleration.
const MAX_FORCE_IN_WEIGHTS: f32 = 3.0;

/// The first soft surface a ray from `origin` along `dir` hits: the entity and the point.
///
/// A scene query ([`SoftQueries`]) against the soft bodies as they are now: the snapshot is
/// taken here, at the press. A game that queries every frame keeps one `SoftQueries` and
/// updates it after each physics step.
fn pick(
    soft: &hecs::World,
    origin: Vector3<f32>,
    dir: Vector3<f32>,
) -> Option<(hecs::Entity, Vector3<f32>)> {
    let mut queries = SoftQueries::new();
    queries.update(soft);
    let ray = Ray::new(
        Vector::new(origin.x, origin.y, origin.z),
        Vector::new(dir.x, dir.y, dir.z),
    );
    let hit = queries
        .cast_ray(&ray, f32::MAX, true, SoftQueryFilter::new())
        .ok()??;
    Some((
        hit.entity,
        Vector3::new(hit.point.x, hit.point.y, hit.point.z),
    ))
}

/// A mouse that presses on the scene at a third of the run, drags 0.4 m up and 0.5 m to the
/// side, and lets go at two thirds.
pub struct ScriptedMouse {
    camera: Vector3<f32>,
    press: usize,
    release: usize,
    held: Option<(hecs::Entity, Vector3<f32>)>,
    log: Vec<String>,
}

impl ScriptedMouse {
    pub fn new(frames: usize, camera: Vector3<f32>) -> ScriptedMouse {
        ScriptedMouse {
            camera,
            press: frames / 3,
            release: 2 * frames / 3,
            held: None,
            log: Vec::new(),
        }
    }

    /// The mouse at displayed frame `frame`: press (pick and grab), drag, release.
    pub fn update(
        &mut self,
        frame: usize,
        soft: &mut hecs::World,
    ) -> Result<(), Box<dyn std::error::Error>> {
        if frame == self.press {
            // The cursor over the middle of the floor, where the jelly rests.
            let dir = (Vector3::new(0.0, 0.2, 0.0) - self.camera).normalize();
            match pick(soft, self.camera, dir) {
                Some((entity, point)) => {
                    let grab = {
                        let p = soft.get::<&Particles>(entity)?;
                        let t = soft.get::<&Tetrahedra>(entity)?;
                        let weight = p.total_mass() * 9.81;
                        let compliance = STRETCH_UNDER_WEIGHT / weight;
                        Grab::at(&p, &t, point, compliance, MAX_FORCE_IN_WEIGHTS * weight)?
                    };
                    soft.insert_one(entity, grab)?;
                    self.held = Some((entity, point));
                    self.log
                        .push(format!("picked {entity:?} at {:?}", point.as_slice()));
                }
                None => self.log.push("the pick missed".into()),
            }
        } else if frame == self.release {
            if let Some((entity, _)) = self.held.take() {
                soft.remove_one::<Grab>(entity)?;
                self.log.push(format!("released at frame {frame}"));
            }
        } else if let Some((entity, start)) = self.held {
            let s = (frame - self.press) as f32 / (self.release - self.press).max(1) as f32;
            let ease = 0.5 - 0.5 * (std::f32::consts::PI * s).cos();
            let target = start + Vector3::new(0.5, 0.4, 0.0) * ease;
            soft.get::<&mut Grab>(entity)?.set_target(target)?;
        }
        Ok(())
    }

    /// What the mouse did.
    pub fn summary(&self) -> String {
        self.log.join("; ")
    }
}
