//! [`GroundUpSweep`]: the ground-up sweep ([`ground_up`](super::ground_up) module docs) of a
//! body as one call, for a hook that knows which particles something immovable holds.

use hecs::{Entity, QueryOneError, World};

use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::solver::hook::SubstepContext;
use crate::stabilisation::ground_up::{project_stacked, BodyConstraints, StackingLayers};

/// One more Gauss–Seidel sweep over a body's own constraints, ordered from the particles
/// something immovable holds (its *roots*) outwards with the roots held, for a heavy load
/// on a light body: a support's reaction reaches the top of the body within one sweep
/// (theory, cost and limits in the `stabilisation::ground_up` module docs).
///
/// Call it from [`SubstepHook::project`](crate::SubstepHook::project) on a body resting on
/// something immovable: it projects in the solver's family order, with its kernel and the
/// substep length of the [`SubstepContext`]. It does not conserve the body's momentum (the
/// impulses it leaves out are the supports'), so it is wrong for a free body.
///
/// Keeps the levels of the last body it swept, and its allocations: levels are computed again
/// only when the roots or the body change, so keep one per body.
///
/// ```
/// use nalgebra::Vector3;
/// use tetpbd::generators::{box_grid, CellSplit};
/// use tetpbd::{GroundUpSweep, Particles, SoftBodyBuilder, SolverSettings, SubstepHook};
///
/// /// Holds a body's particles below y = 0.01 m as if they stood on the ground.
/// struct Ground(hecs::Entity, GroundUpSweep);
/// impl SubstepHook for Ground {
///     fn project(&mut self, world: &mut hecs::World, substep: tetpbd::SubstepContext) {
///         let held: Vec<u32> = world.get::<&Particles>(self.0).map_or(Vec::new(), |p| {
///             (0..p.len() as u32).filter(|&i| p.positions()[i as usize].y < 0.01).collect()
///         });
///         let levels = self.1.project(world, self.0, held, &substep).expect("a soft body");
///         assert_eq!(levels, 2);
///     }
/// }
///
/// let mut world = hecs::World::new();
/// let mesh = box_grid(Vector3::new(0.2, 0.4, 0.2), [1, 2, 1], CellSplit::Six)?;
/// let body = SoftBodyBuilder::new(mesh)
///     .edges(0.0)
///     .volume(0.0)
///     .translation(Vector3::new(0.0, 0.2, 0.0))
///     .build()?
///     .spawn(&mut world);
/// let mut solver = tetpbd::Solver::new(SolverSettings { gravity: Vector3::zeros(), ..Default::default() })?;
/// solver.step_with(&mut world, &mut Ground(body, GroundUpSweep::new()))?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, Default)]
pub struct GroundUpSweep {
    /// The body the layers were built for.
    body: Option<Entity>,
    layers: StackingLayers,
}

impl GroundUpSweep {
    /// A sweep that has not seen a body yet (it allocates on its first call).
    pub fn new() -> Self {
        Self::default()
    }

    /// One ground-up sweep of `entity`'s constraint families, with its pinned particles and
    /// `held` (particle indices; out-of-range ones are ignored) as the roots: the
    /// constraints level by level away from the roots, the roots held (inverse mass 0 for
    /// the sweep). XPBD with the families' compliances; the multipliers accumulate with the
    /// substep's other projections. Returns the number of levels swept, 0 when there is no
    /// root and nothing ran.
    ///
    /// Errors: `entity` does not exist or has no [`Particles`] or [`Tetrahedra`].
    pub fn project(
        &mut self,
        world: &mut World,
        entity: Entity,
        held: impl IntoIterator<Item = u32>,
        substep: &SubstepContext,
    ) -> Result<u32, QueryOneError> {
        let (p, tets, edges, vertex_face, volume) = world.query_one_mut::<(
            &mut Particles,
            &Tetrahedra,
            Option<&mut EdgeConstraints>,
            Option<&mut VertexFaceConstraints>,
            Option<&mut VolumeConstraints>,
        )>(entity)?;
        if self.body != Some(entity) || !self.layers.fits(p.len(), tets) {
            self.layers = StackingLayers::new(p.len(), tets);
            self.body = Some(entity);
        }
        let pinned = (0..p.len() as u32).filter(|&i| p.inv_masses()[i as usize] == 0.0);
        let top = self
            .layers
            .set_roots(tets, edges.as_deref(), held.into_iter().chain(pinned));
        if top == 0 {
            return Ok(0);
        }
        let families = BodyConstraints {
            edges,
            vertex_face,
            volume,
        };
        let frame = substep.frame();
        let (order, kernel, h) = (frame.order, frame.kernel, frame.h());
        project_stacked(p, tets, families, order, h, &mut self.layers, kernel);
        Ok(top)
    }

    /// Level of particle `i` of the body last swept, in tetrahedra from the roots (0 for a
    /// root); `None` when no root reached it or `i` is out of range.
    pub fn level(&self, i: usize) -> Option<u32> {
        self.layers.level(i)
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::body::families::Family;
    use crate::body::generators::{box_grid, CellSplit};
    use crate::kernels::count::Kernel;
    use crate::SoftBodyBuilder;

    /// Layers built for another body (other particle and tetrahedron counts) leave the
    /// body alone.
    #[test]
    fn layers_of_another_body_do_nothing() {
        let column = |cells: [u32; 3]| {
            let size = Vector3::new(cells[0] as f32, cells[1] as f32, cells[2] as f32) * 0.2;
            let mesh = box_grid(size, cells, CellSplit::Six).unwrap();
            SoftBodyBuilder::new(mesh)
                .edges(0.0)
                .volume(0.0)
                .build()
                .unwrap()
        };
        let a = column([2, 3, 2]);
        let mut b = column([2, 2, 2]);
        let x = a.particles.positions();
        let bottom = (0..x.len() as u32).filter(|&i| x[i as usize].y < -0.29);
        let mut layers = StackingLayers::new(x.len(), &a.tetrahedra);
        assert!(layers.set_roots(&a.tetrahedra, a.edges.as_ref(), bottom) > 0);
        assert!(!layers.fits(b.particles.len(), &b.tetrahedra));
        assert!(!StackingLayers::default().fits(b.particles.len(), &b.tetrahedra));
        for x in b.particles.positions_mut() {
            x.y *= 0.9;
        }
        let before = b.particles.positions().to_vec();
        let families = BodyConstraints {
            edges: b.edges.as_mut(),
            vertex_face: None,
            volume: b.volume.as_mut(),
        };
        let count = project_stacked(
            &mut b.particles,
            &b.tetrahedra,
            families,
            Family::ALL,
            1.0 / 600.0,
            &mut layers,
            Kernel::Simd,
        );
        assert_eq!(count.applied, 0);
        assert_eq!(b.particles.positions(), &before[..]);
    }
}
