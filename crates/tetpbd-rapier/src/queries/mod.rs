//! Scene queries against soft bodies: ray casts, point projection and containment, AABB and
//! shape overlap, and the same ray cast and projection over rapier's colliders and the soft
//! bodies in one call. [`SoftQueries`] holds the snapshot the queries answer against (its
//! docs give the refresh rule and the conventions); one file per kind of query.

mod body;
mod error;
mod filter;
mod location;
mod overlap;
mod point;
mod ray;
mod scene;

use hecs::{Entity, World};
use rapier3d::parry::partitioning::{Bvh, BvhBuildStrategy};
use tetpbd::{Particles, Surface, Tetrahedra};

use crate::soft_collider::SoftCollider;
use body::{QueryBody, Skip};

pub use error::QueryError;
pub use filter::SoftQueryFilter;
pub use location::SoftLocation;
pub use point::{SoftPointProjection, SoftVolumePoint};
pub use ray::SoftRayHit;
pub use scene::{ScenePointProjection, SceneRayHit};

/// Scene queries against the soft bodies of a hecs world: ray casts
/// ([`cast_ray`](Self::cast_ray), [`intersect_ray`](Self::intersect_ray)), point projection
/// and containment ([`project_point`](Self::project_point),
/// [`contains_point`](Self::contains_point), [`intersect_point`](Self::intersect_point)),
/// overlaps ([`intersect_aabb`](Self::intersect_aabb),
/// [`intersect_shape`](Self::intersect_shape)), and the nearest ray hit or surface point over
/// rapier's colliders and the soft bodies at once ([`cast_ray_scene`](Self::cast_ray_scene),
/// [`project_point_scene`](Self::project_point_scene)). Every query takes a
/// [`SoftQueryFilter`] (groups, an excluded entity, a predicate), like rapier's
/// `QueryFilter`.
///
/// # The snapshot, and when to refresh it
///
/// The queries answer against a *snapshot*: every soft body's particle positions, collision
/// groups and bounds as they were at the last [`SoftQueries::update`]. **Call `update` after
/// every step, and after writing particle positions, adding or removing bodies or changing a
/// body's [`SoftCollider`]**; until then the queries answer for the world as it was (nothing
/// is read from the world during a query, so the answers of one frame agree with each other).
///
/// Each body keeps a BVH over its surface triangles and one over its tetrahedra (the
/// soft–soft contacts' per-body structure), built on the body's shape the first time it is
/// seen or when its mesh changes, and refitted (boxes only) at every later `update`: cost
/// O(particles + tetrahedra) per body. A BVH over the bodies' bounds is rebuilt at every
/// `update`. Figures: `docs/performance.md`, "Scene queries".
///
/// # Conventions
///
/// Inputs and outputs are rapier's types ([`Ray`](rapier3d::geometry::Ray), glam
/// [`Vector`](rapier3d::math::Vector), [`Pose`](rapier3d::math::Pose),
/// [`Aabb`](rapier3d::geometry::Aabb)); lengths in m; a time of impact in units of the ray
/// direction's length (m for a unit direction), as in rapier. Normals are the outward unit
/// normals of the surface triangles. A NaN or infinite input is rejected with a
/// [`QueryError`] naming the value; a body whose positions are not finite is left out of the
/// snapshot and listed by [`SoftQueries::skipped`]. Bodies whose `SoftCollider` is disabled
/// are not in the snapshot.
///
/// ```
/// use nalgebra::Vector3;
/// use rapier3d::prelude::{Ray, Vector};
/// use tetpbd::{generators, SoftBodyBuilder};
/// use tetpbd_rapier::{SoftQueries, SoftQueryFilter};
///
/// let mut world = hecs::World::new();
/// let mesh = generators::box_grid(Vector3::repeat(1.0), [2, 2, 2], generators::CellSplit::Six)?;
/// let cube = SoftBodyBuilder::new(mesh).build()?.spawn(&mut world);
/// let mut queries = SoftQueries::new();
/// queries.update(&world);
/// let ray = Ray::new(Vector::new(0.0, 5.0, 0.0), Vector::new(0.0, -1.0, 0.0));
/// let hit = queries.cast_ray(&ray, f32::MAX, true, SoftQueryFilter::new())?.expect("hit");
/// assert_eq!(hit.entity, cube);
/// assert!((hit.time_of_impact - 4.5).abs() < 1e-5); // the cube's top face is at y = 0.5
/// assert!((hit.normal - Vector::Y).length() < 1e-5);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone)]
pub struct SoftQueries {
    /// The bodies of the snapshot, sorted by entity bits.
    bodies: Vec<QueryBody>,
    /// BVH over the bodies' bounds (leaf `i` is `bodies[i]`).
    top: Bvh,
    default_collider: SoftCollider,
    skipped: Vec<Entity>,
    stamp: u64,
}

impl Default for SoftQueries {
    fn default() -> Self {
        Self::new()
    }
}

impl std::fmt::Debug for SoftQueries {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SoftQueries")
            .field("bodies", &self.bodies.len())
            .field("skipped", &self.skipped)
            .finish_non_exhaustive()
    }
}

impl SoftQueries {
    /// An empty snapshot; call [`SoftQueries::update`] before querying.
    pub fn new() -> Self {
        SoftQueries {
            bodies: Vec::new(),
            top: Bvh::new(),
            default_collider: SoftCollider::default(),
            skipped: Vec::new(),
            stamp: 0,
        }
    }

    /// The collision properties (groups, enabled) of bodies without a [`SoftCollider`]
    /// component ([`SoftCollider::default`] unless set; a coupled scene passes its
    /// [`crate::CouplingSettings::default_collider`]).
    pub fn default_collider(&self) -> &SoftCollider {
        &self.default_collider
    }

    /// Sets the collision properties of bodies without a [`SoftCollider`] component (from the
    /// next [`SoftQueries::update`] on).
    pub fn set_default_collider(&mut self, collider: SoftCollider) {
        self.default_collider = collider;
    }

    /// Takes the snapshot the queries answer against: every soft body of `world` (an entity
    /// with `Particles`, `Surface` and `Tetrahedra`) whose `SoftCollider` is enabled, at its
    /// current positions. Cost: O(particles + tetrahedra) per body whose mesh is unchanged
    /// (refit), plus a BVH build for a body seen for the first time or whose mesh changed.
    pub fn update(&mut self, world: &World) {
        self.stamp += 1;
        self.skipped.clear();
        let mut query = world.query::<(
            Entity,
            &Particles,
            &Surface,
            &Tetrahedra,
            Option<&SoftCollider>,
        )>();
        for (entity, particles, surface, tets, collider) in query.iter() {
            let collider = collider.copied().unwrap_or(self.default_collider);
            if !collider.is_enabled() {
                continue;
            }
            let mesh = (particles.positions(), surface, tets);
            if self.refresh(entity, collider, mesh).is_err() {
                self.skipped.push(entity);
            }
        }
        let stamp = self.stamp;
        self.bodies.retain(|b| b.seen == stamp);
        self.skipped.sort_unstable_by_key(|e| e.to_bits());
        self.top = Bvh::from_iter(
            BvhBuildStrategy::Binned,
            self.bodies.iter().enumerate().map(|(i, b)| (i, b.aabb)),
        );
    }

    /// Refits (or builds) the snapshot of one body.
    fn refresh(
        &mut self,
        entity: Entity,
        collider: SoftCollider,
        mesh: (&[nalgebra::Vector3<f32>], &Surface, &Tetrahedra),
    ) -> Result<(), Skip> {
        let key = entity.to_bits();
        let slot = self
            .bodies
            .binary_search_by_key(&key, |b| b.entity.to_bits());
        let body = match slot {
            Ok(i) if self.bodies[i].matches(mesh.0, mesh.1, mesh.2) => {
                let body = &mut self.bodies[i];
                body.refit(mesh.0)?;
                body
            }
            Ok(i) => {
                self.bodies[i] = QueryBody::build(entity, collider.collision_groups(), mesh)?;
                &mut self.bodies[i]
            }
            Err(i) => {
                let body = QueryBody::build(entity, collider.collision_groups(), mesh)?;
                self.bodies.insert(i, body);
                &mut self.bodies[i]
            }
        };
        body.groups = collider.collision_groups();
        body.seen = self.stamp;
        Ok(())
    }

    /// The soft bodies left out of the last snapshot: their surface or tetrahedra name
    /// particles they do not have, or a particle position is NaN or infinite. Sorted.
    pub fn skipped(&self) -> &[Entity] {
        &self.skipped
    }

    /// Number of soft bodies in the snapshot.
    pub fn len(&self) -> usize {
        self.bodies.len()
    }

    /// `true` when the snapshot holds no soft body.
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }
}
