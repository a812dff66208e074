//! One soft body as the scene queries see it: a snapshot of its particle positions taken by
//! [`SoftQueries::update`](super::SoftQueries::update), with the body's triangle and
//! tetrahedron BVHs fitted to that snapshot.

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::geometry::InteractionGroups;
use rapier3d::parry::bounding_volume::Aabb;
use rapier3d::parry::partitioning::BvhBuildStrategy;
use tetpbd::{Surface, Tetrahedra};

use crate::convert::{finite3, to_glam};
use crate::soft_soft::bvh::BodyCache;

/// A soft body in the query snapshot.
#[derive(Clone)]
pub(crate) struct QueryBody {
    pub entity: Entity,
    /// The body's collision groups (its `SoftCollider`, or the default one).
    pub groups: InteractionGroups,
    /// Bounds of the body's particles at the snapshot, m.
    pub aabb: Aabb,
    /// Triangles, tetrahedra and their BVHs (the soft–soft contacts' per-body structure).
    pub cache: BodyCache,
    /// Every particle's position at the snapshot, m.
    pub positions: Vec<Vector3<f32>>,
    /// Surface-local positions (`positions[cache.vertices[k]]`), m.
    pub xs: Vec<Vector3<f32>>,
    /// The snapshot the body was last refreshed in (to drop bodies that left the world).
    pub seen: u64,
}

/// Why a body was left out of the snapshot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Skip {
    /// Its surface or tetrahedra name particles it does not have.
    BrokenMesh,
    /// A particle position is NaN or infinite.
    NonFinite,
}

impl QueryBody {
    /// A new snapshot of a body, with BVHs built for its current shape.
    pub fn build(
        entity: Entity,
        groups: InteractionGroups,
        (positions, surface, tets): (&[Vector3<f32>], &Surface, &Tetrahedra),
    ) -> Result<Self, Skip> {
        let cache = BodyCache::build(surface, tets, positions.len()).ok_or(Skip::BrokenMesh)?;
        let mut body = QueryBody {
            entity,
            groups,
            aabb: Aabb::new_invalid(),
            cache,
            positions: Vec::new(),
            xs: Vec::new(),
            seen: 0,
        };
        body.refit(positions)?;
        // The cache starts from empty boxes: build the trees' topology once on the real
        // shape; later snapshots only refit the boxes.
        let cache = &mut body.cache;
        cache
            .tri_bvh
            .rebuild(&mut cache.workspace, BvhBuildStrategy::Binned);
        cache
            .tet_bvh
            .rebuild(&mut cache.workspace, BvhBuildStrategy::Binned);
        Ok(body)
    }

    /// `true` while the snapshot still describes this mesh.
    pub fn matches(
        &self,
        positions: &[Vector3<f32>],
        surface: &Surface,
        tets: &Tetrahedra,
    ) -> bool {
        self.cache.matches(surface, tets, positions.len())
    }

    /// Copies the positions and refits both BVHs and the body's bounds to them (nothing to do
    /// for a body that has not moved since the last snapshot).
    pub fn refit(&mut self, positions: &[Vector3<f32>]) -> Result<(), Skip> {
        if self.positions == positions {
            return Ok(());
        }
        if !positions.iter().all(finite3) {
            return Err(Skip::NonFinite);
        }
        self.positions.clear();
        self.positions.extend_from_slice(positions);
        self.xs.clear();
        self.xs
            .extend(self.cache.vertices.iter().map(|&i| positions[i as usize]));
        let (mut lo, mut hi) = (Vector3::repeat(f32::MAX), Vector3::repeat(f32::MIN));
        for p in positions {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        self.aabb = if positions.is_empty() {
            Aabb::new_invalid()
        } else {
            Aabb::new(to_glam(&lo), to_glam(&hi))
        };
        // Triangle boxes grown by a hair of the body's size, so that a ray grazing a box
        // face (a face of an axis-aligned body) is not lost to the box test's rounding.
        let pad = vec![1e-5 * (hi - lo).norm(); self.xs.len()];
        self.cache.refit_triangles(&self.xs, &pad);
        self.cache.refit_tets(&self.positions);
        Ok(())
    }

    /// The corners of surface triangle `t` at the snapshot, m.
    pub fn triangle(&self, t: usize) -> [Vector3<f32>; 3] {
        self.cache.triangles[t].map(|k| self.xs[k as usize])
    }

    /// The particle indices of surface triangle `t`.
    pub fn triangle_particles(&self, t: usize) -> [u32; 3] {
        self.cache.triangles[t].map(|k| self.cache.vertices[k as usize])
    }

    /// The corners of tetrahedron `t` at the snapshot, m.
    pub fn tet(&self, t: usize) -> [Vector3<f32>; 4] {
        self.cache.tets[t].map(|i| self.positions[i as usize])
    }
}

impl QueryBody {
    /// The tetrahedron holding `x` at the snapshot and `x`'s barycentric weights in it
    /// (the lowest-numbered one when `x` is on a face shared by several).
    pub fn locate(&self, x: &Vector3<f32>) -> Option<super::SoftLocation> {
        let q = to_glam(x);
        let probe = Aabb::new(q, q);
        let mut best: Option<(u32, [f32; 4])> = None;
        for t in self.cache.tet_bvh.intersect_aabb(&probe) {
            if best.is_some_and(|(b, _)| b < t) {
                continue;
            }
            if let Some(w) = crate::soft_soft::bvh::tet_barycentric(x, &self.tet(t as usize)) {
                best = Some((t, w));
            }
        }
        let (tet, barycentric) = best?;
        Some(super::SoftLocation::Interior {
            tet,
            particles: self.cache.tets[tet as usize],
            barycentric,
        })
    }
}
