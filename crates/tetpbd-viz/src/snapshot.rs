//! [`Snapshot`]: the triangles of one frame of a scene (soft surfaces and rigid colliders), and
//! [`SceneView`], what a scene lends to take one.

use hecs::World;
use nalgebra::Isometry3;
use rapier3d::prelude::{ColliderSet, RigidBodySet};
use tetpbd::{Particles, Surface};
use tetpbd_rapier::CoupledWorld;

use crate::mesh::TriangleMesh;
use crate::shape_mesh::shape_mesh;

/// What a scene shows: soft bodies in a hecs world, and optionally rapier bodies and
/// colliders. Implemented for a bare [`World`], a [`CoupledWorld`] and a
/// `(&World, &RigidBodySet, &ColliderSet)` triple (an integrator's own rapier state).
pub trait SceneView {
    /// The soft bodies (entities with [`Particles`] and [`Surface`]).
    fn soft(&self) -> &World;
    /// The rigid bodies and their colliders, if the scene has any.
    fn rigid(&self) -> Option<(&RigidBodySet, &ColliderSet)>;
}

impl SceneView for World {
    fn soft(&self) -> &World {
        self
    }
    fn rigid(&self) -> Option<(&RigidBodySet, &ColliderSet)> {
        None
    }
}

impl SceneView for CoupledWorld {
    fn soft(&self) -> &World {
        &self.soft
    }
    fn rigid(&self) -> Option<(&RigidBodySet, &ColliderSet)> {
        Some((&self.physics.bodies, &self.physics.colliders))
    }
}

impl SceneView for (&World, &RigidBodySet, &ColliderSet) {
    fn soft(&self) -> &World {
        self.0
    }
    fn rigid(&self) -> Option<(&RigidBodySet, &ColliderSet)> {
        Some((self.1, self.2))
    }
}

/// What an item of a [`Snapshot`] is, which picks its colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ItemKind {
    /// A soft body's surface.
    Soft,
    /// A collider without a parent or on a fixed rigid body.
    Fixed,
    /// A collider on a dynamic rigid body.
    Dynamic,
    /// A collider on a kinematic rigid body.
    Kinematic,
}

/// One surface of a [`Snapshot`].
#[derive(Clone, Debug, PartialEq)]
pub struct Item {
    /// Soft or rigid, and which kind of rigid body.
    pub kind: ItemKind,
    /// File stem: `soft<entity id>` or `rigid<collider index>`, stable over a run.
    pub name: String,
    /// The triangles, world coordinates (m).
    pub mesh: TriangleMesh,
}

/// The surfaces of one frame: soft bodies first (in the world's query order), then colliders
/// (in the collider set's order). Colliders without area (segments, polylines) are left out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Snapshot {
    /// Soft surfaces and rigid colliders.
    pub items: Vec<Item>,
}

impl Snapshot {
    /// Takes the triangles of `scene` as they are now.
    pub fn capture(scene: &dyn SceneView) -> Snapshot {
        let mut items = Vec::new();
        let mut soft = scene.soft().query::<(hecs::Entity, &Particles, &Surface)>();
        for (entity, particles, surface) in soft.iter() {
            items.push(Item {
                kind: ItemKind::Soft,
                name: format!("soft{}", entity.id()),
                mesh: TriangleMesh {
                    positions: particles.positions().to_vec(),
                    triangles: surface.triangles().to_vec(),
                },
            });
        }
        if let Some((bodies, colliders)) = scene.rigid() {
            for (handle, collider) in colliders.iter() {
                let Some(mesh) = shape_mesh(collider.shape()) else {
                    continue;
                };
                let body = collider.parent().and_then(|h| bodies.get(h));
                let kind = match body {
                    Some(b) if b.is_dynamic() => ItemKind::Dynamic,
                    Some(b) if b.is_kinematic() => ItemKind::Kinematic,
                    _ => ItemKind::Fixed,
                };
                items.push(Item {
                    kind,
                    name: format!("rigid{}", handle.into_raw_parts().0),
                    mesh: mesh.transformed(&Isometry3::from(*collider.position())),
                });
            }
        }
        Snapshot { items }
    }
}
