//! Building soft bodies from vertices and tetrahedra.

use hecs::{Entity, World};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::lumped_mass::{pinned_inverse_masses, rest_volumes_and_masses};
use crate::body::mesh::{Surface, Tetrahedra};
use crate::body::particles::Particles;
use crate::body::placement::Placement;
use crate::body::rest_families::{edge_constraints, vertex_face_constraints};
use crate::error::BuildError;
use crate::kernels::slots::{Slot, WorkCopy};
use crate::ordering::partition::{auto_parts, longest_axis, part_order, slab_parts};
use crate::ordering::spatial::{inverse, mean_edge_length, relabel_tets, row_order};

/// A tetrahedral mesh: vertex positions (m) and tetrahedra as vertex indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetMesh {
    /// Vertex positions, m.
    pub vertices: Vec<Vector3<f32>>,
    /// Tetrahedra, four vertex indices each, either orientation.
    pub tets: Vec<[u32; 4]>,
}

/// A built soft body: its components, ready to be spawned as one entity.
///
/// Fields are the components; `None` families are simply not added.
#[derive(Clone, Debug)]
pub struct SoftBody {
    /// Particle state.
    pub particles: Particles,
    /// Tetrahedra with rest volumes.
    pub tetrahedra: Tetrahedra,
    /// Boundary triangles.
    pub surface: Surface,
    /// Edge family, if chosen.
    pub edges: Option<EdgeConstraints>,
    /// Vertex–face family, if chosen.
    pub vertex_face: Option<VertexFaceConstraints>,
    /// Volume family, if chosen.
    pub volume: Option<VolumeConstraints>,
    /// Plastic flow, if chosen.
    pub plasticity: Option<crate::Plasticity>,
    /// Neo-Hookean material, if chosen ([`SoftBodyBuilder::material`]).
    pub material: Option<crate::NeoHookeanMaterial>,
    /// Tearing, if chosen ([`SoftBodyBuilder::tearing`]).
    pub tearing: Option<crate::Tearing>,
}

impl SoftBody {
    /// Spawns the body as one entity holding its components.
    pub fn spawn(self, world: &mut World) -> Entity {
        let mut b = hecs::EntityBuilder::new();
        b.add(self.particles).add(self.tetrahedra).add(self.surface);
        b.add(crate::Activation::default());
        b.add(crate::Untangle::default());
        if let Some(e) = self.edges {
            b.add(e);
        }
        if let Some(v) = self.vertex_face {
            b.add(v);
        }
        if let Some(v) = self.volume {
            b.add(v);
        }
        if let Some(p) = self.plasticity {
            b.add(p);
        }
        if let Some(m) = self.material {
            b.add(m);
        }
        if let Some(t) = self.tearing {
            b.add(t);
            // Present from the start, so a split puts its pieces in the body's own archetype
            // (a new archetype would grow the world's query caches in the next frame).
            b.add(crate::TearRelaxation::default());
        }
        world.spawn(b.build())
    }
}

/// Builds a [`SoftBody`] from raw vertices and tetrahedra, choosing its constraint families.
///
/// ```
/// use tetpbd::{generators, SoftBodyBuilder};
/// let mesh = generators::box_grid(nalgebra::Vector3::new(1.0, 1.0, 1.0), [2, 2, 2], generators::CellSplit::Six)?;
/// let body = SoftBodyBuilder::new(mesh).density(1000.0).edges(0.0).volume(0.0).build()?;
/// assert!(body.vertex_face.is_none());
/// # Ok::<(), tetpbd::BuildError>(())
/// ```
#[derive(Clone, Debug)]
pub struct SoftBodyBuilder {
    mesh: TetMesh,
    density: f32,
    edge: Option<f32>,
    vertex_face: Option<f32>,
    volume: Option<f32>,
    plasticity: Option<crate::PlasticitySettings>,
    material: Option<crate::Material>,
    tearing: Option<crate::TearingSettings>,
    pinned: Vec<u32>,
    placement: Placement,
    epsilon: f32,
    spatial_order: bool,
    parts: usize,
}

impl SoftBodyBuilder {
    /// Default relative volume epsilon: a tetrahedron with `|V| < 1e-6 · (longest edge)³`
    /// is rejected as degenerate.
    pub const DEFAULT_EPSILON: f32 = 1e-6;

    /// Whether [`Self::spatial_order`] is on by default. Off: the generators already number
    /// their vertices in rows; turn it on for meshes read from files.
    pub const DEFAULT_SPATIAL_ORDER: bool = false;

    /// Starts from a mesh. Defaults: density 1000 kg/m³, no constraint family, nothing pinned.
    pub fn new(mesh: TetMesh) -> Self {
        SoftBodyBuilder {
            mesh,
            density: 1000.0,
            edge: None,
            vertex_face: None,
            volume: None,
            plasticity: None,
            material: None,
            tearing: None,
            pinned: Vec::new(),
            placement: Placement::default(),
            epsilon: Self::DEFAULT_EPSILON,
            spatial_order: Self::DEFAULT_SPATIAL_ORDER,
            parts: 0,
        }
    }

    /// Starts from raw arrays.
    pub fn from_arrays(vertices: Vec<Vector3<f32>>, tets: Vec<[u32; 4]>) -> Self {
        Self::new(TetMesh { vertices, tets })
    }

    /// Density, kg/m³; masses are lumped as `density · |V| / 4` per tetrahedron corner.
    pub fn density(mut self, density: f32) -> Self {
        self.density = density;
        self
    }

    /// Adds the edge family with compliance `alpha` (m/N; 0 = rigid).
    pub fn edges(mut self, alpha: f32) -> Self {
        self.edge = Some(alpha);
        self
    }

    /// Adds the vertex–face family with compliance `alpha` (m/N).
    pub fn vertex_face(mut self, alpha: f32) -> Self {
        self.vertex_face = Some(alpha);
        self
    }

    /// Adds the volume family with compliance `alpha` (m⁵/N).
    pub fn volume(mut self, alpha: f32) -> Self {
        self.volume = Some(alpha);
        self
    }

    /// Gives the body plastic flow (a [`crate::Plasticity`] component): the rest state of
    /// every family it has follows the shape it is held in past `settings.yield_strain`.
    /// Checked by [`Self::build`] ([`BuildError::Plasticity`]).
    pub fn plasticity(mut self, settings: crate::PlasticitySettings) -> Self {
        self.plasticity = Some(settings);
        self
    }

    /// Gives the body a continuum material ([`crate::NeoHookeanMaterial`]): stable
    /// Neo-Hookean with Young's modulus and Poisson's ratio in physical units, stiffness
    /// independent of the mesh resolution. Alone or with any of the families.
    pub fn material(mut self, material: crate::Material) -> Self {
        self.material = Some(material);
        self
    }

    /// Lets the body tear (a [`crate::Tearing`] component): a face shared by two
    /// tetrahedra splits once its smoothed strain passes `settings.strain` or its smoothed
    /// force `settings.force`. Checked by
    /// [`Self::build`] ([`BuildError::Tearing`]).
    pub fn tearing(mut self, settings: crate::TearingSettings) -> Self {
        self.tearing = Some(settings);
        self
    }

    /// Pins these vertices (inverse mass 0), given as indices into the input mesh's
    /// vertices (whatever [`Self::spatial_order`] does to the particle numbering).
    pub fn pinned(mut self, vertices: impl IntoIterator<Item = u32>) -> Self {
        self.pinned.extend(vertices);
        self
    }

    /// Initial velocity of every free particle, m/s.
    pub fn velocity(mut self, v: Vector3<f32>) -> Self {
        self.placement.linear_velocity = v;
        self
    }

    /// Initial angular velocity about the placed body's centre of mass, rad/s (added to
    /// [`Self::velocity`] on free particles).
    pub fn angular_velocity(mut self, w: Vector3<f32>) -> Self {
        self.placement.angular_velocity = w;
        self
    }

    /// Moves the mesh by `t` (m) after rotating it; rest data is translation-free.
    pub fn translation(mut self, t: Vector3<f32>) -> Self {
        self.placement.translation = t;
        self
    }

    /// Rotates the mesh about its origin before translating it; rest data is rotation-free.
    pub fn rotation(mut self, r: UnitQuaternion<f32>) -> Self {
        self.placement.rotation = r;
        self
    }

    /// Rotation and translation at once (rotation about the mesh's origin first).
    pub fn pose(mut self, pose: Isometry3<f32>) -> Self {
        self.placement.rotation = pose.rotation;
        self.placement.translation = pose.translation.vector;
        self
    }

    /// Scales the mesh uniformly by `s` (> 0) about its origin: the rest shape, and with it
    /// masses and rest lengths, is the scaled mesh.
    pub fn scale(mut self, s: f32) -> Self {
        self.placement.scale = s;
        self
    }

    /// Pose, scale and initial motion at once (see [`Placement`]).
    pub fn placement(mut self, placement: Placement) -> Self {
        self.placement = placement;
        self
    }

    /// Relative volume epsilon (see [`Self::DEFAULT_EPSILON`]).
    pub fn volume_epsilon(mut self, eps: f32) -> Self {
        self.epsilon = eps;
        self
    }

    /// Renumbers the particles in rows of about one edge length so that particles close in space are close in memory, which speeds up the projections of
    /// meshes whose vertex numbering is unrelated to space (mesh files). When on, particle `k`
    /// of the built body is input vertex [`Particles::source`]`()[k]`, and
    /// [`Particles::particle_of`] maps a vertex index to its particle. Default
    /// [`Self::DEFAULT_SPATIAL_ORDER`].
    pub fn spatial_order(mut self, on: bool) -> Self {
        self.spatial_order = on;
        self
    }

    /// Cuts the body into `parts` slabs along its longest axis for the solver's sweep order
    /// (fewer phases per parallel sweep); 0 (the default) chooses by size (1, the plain
    /// colour classes, below 50,000 tetrahedra). The order changes which
    /// constraint is projected after which (so the rounding and, slightly, the convergence),
    /// never what a step does on a given number of threads versus another.
    pub fn parts(mut self, parts: usize) -> Self {
        self.parts = parts;
        self
    }

    /// Validates the input and builds the components.
    pub fn build(self) -> Result<SoftBody, BuildError> {
        self.check_parameters()?;
        let SoftBodyBuilder {
            mesh,
            density,
            edge,
            vertex_face,
            volume,
            plasticity,
            material,
            tearing,
            pinned,
            placement,
            epsilon,
            spatial_order,
            parts,
        } = self;
        let mut mesh = mesh;
        let n = mesh.vertices.len();
        for (i, v) in mesh.vertices.iter_mut().enumerate() {
            let input_finite = v.iter().all(|c| c.is_finite());
            *v *= placement.scale;
            if !(input_finite && placement.place(v).iter().all(|c| c.is_finite())) {
                return Err(BuildError::NonFiniteVertex { vertex: i });
            }
        }
        let positions: Vec<Vector3<f32>> =
            mesh.vertices.iter().map(|v| placement.place(v)).collect();
        let (rest_volumes, masses) = rest_volumes_and_masses(&mesh, density, epsilon)?;
        let inv_masses = pinned_inverse_masses(&masses, &pinned)?;
        let velocities = placement.velocities(&positions, &masses, &inv_masses);
        // Particle order (see `ordering::spatial`): particle `k` is input vertex
        // `particle_source[k]`.
        let (particle_source, local_tets, local_source) =
            particle_order(&mesh.vertices, mesh.tets, spatial_order);
        let permute = |v: Vec<Vector3<f32>>| -> Vec<Vector3<f32>> {
            particle_source.iter().map(|&i| v[i as usize]).collect()
        };
        let positions = permute(positions);
        let velocities = permute(velocities);
        let vertices = permute(mesh.vertices);
        let pick =
            |v: &[f32]| -> Vec<f32> { particle_source.iter().map(|&i| v[i as usize]).collect() };
        let (masses, inv_masses) = (pick(&masses), pick(&inv_masses));
        let surface = Surface::from_tetrahedra(&local_tets, &vertices);
        // Solver order for tetrahedra and edges (see `ordering::colouring` and
        // `ordering::partition`); `source` maps back.
        let (parts, part_of) = body_parts(&vertices, &local_tets, parts);
        let (order, tet_classes) = part_order(&local_tets, &part_of, parts, n);
        let tets: Vec<[u32; 4]> = order.iter().map(|&t| local_tets[t]).collect();
        let rest_volumes: Vec<f32> = order
            .iter()
            .map(|&t| rest_volumes[local_source[t] as usize])
            .collect();
        let source: Vec<u32> = order.iter().map(|&t| local_source[t]).collect();
        let mesh = TetMesh { vertices, tets };
        let edges = edge.map(|alpha| edge_constraints(&mesh, &part_of, parts, alpha));
        let vertex_face = vertex_face.map(|alpha| vertex_face_constraints(&mesh, alpha));
        let volume = volume.map(|alpha| VolumeConstraints {
            lambdas: vec![0.0; mesh.tets.len()],
            compliance: alpha,
        });
        let slivers = crate::stabilisation::sliver_orientation::slivers(&mesh.tets, &mesh.vertices);
        let tetrahedra = Tetrahedra {
            indices: mesh.tets,
            rest_volumes,
            source,
            classes: tet_classes,
            slivers,
        };
        let material =
            material.map(|m| crate::NeoHookeanMaterial::new(m, &tetrahedra, &mesh.vertices));
        let mut body = SoftBody {
            particles: Particles {
                prev_positions: positions.clone(),
                positions,
                velocities,
                inv_masses,
                masses,
                rest_positions: mesh.vertices,
                residuals: vec![Vector3::zeros(); n],
                vertex_to_particle: inverse(&particle_source),
                source: particle_source,
                work: WorkCopy(vec![Slot::default(); n]),
                written: false,
                hook: Default::default(),
            },
            tetrahedra,
            surface,
            edges,
            vertex_face,
            volume,
            plasticity: None,
            material,
            tearing: None,
        };
        if let Some(settings) = plasticity {
            let (p, t, e) = (&body.particles, &body.tetrahedra, body.edges.as_ref());
            body.plasticity = Some(crate::Plasticity::new(settings, p, t, e)?);
        }
        if let Some(settings) = tearing {
            let (p, t) = (&body.particles, &body.tetrahedra);
            let mut tearing = crate::Tearing::new(settings, p, t)?;
            tearing.prepare_forces(t, body.edges.as_ref());
            body.tearing = Some(tearing);
        }
        Ok(body)
    }

    /// Checks the parameters that do not depend on the mesh's geometry.
    fn check_parameters(&self) -> Result<(), BuildError> {
        if self.mesh.vertices.is_empty() {
            return Err(BuildError::NoVertices);
        }
        let (density, epsilon) = (self.density, self.epsilon);
        if !(density.is_finite() && density > 0.0) {
            return Err(BuildError::BadDensity { value: density });
        }
        if !(epsilon.is_finite() && epsilon >= 0.0) {
            return Err(BuildError::BadEpsilon { value: epsilon });
        }
        for (family, a) in [
            ("edge", self.edge),
            ("vertex-face", self.vertex_face),
            ("volume", self.volume),
        ] {
            if let Some(a) = a {
                if !(a.is_finite() && a >= 0.0) {
                    return Err(BuildError::BadCompliance { family, value: a });
                }
            }
        }
        if let Some(s) = &self.plasticity {
            s.validate()?;
        }
        if let Some(s) = &self.tearing {
            s.validate()?;
        }
        self.placement.check()
    }
}

/// The particle order (`source[k]`: the input vertex of particle `k`), the tetrahedra
/// relabelled for it and, for each, its input index: rows in space with `spatial_order`, the
/// input order without.
fn particle_order(
    vertices: &[Vector3<f32>],
    tets: Vec<[u32; 4]>,
    spatial_order: bool,
) -> (Vec<u32>, Vec<[u32; 4]>, Vec<u32>) {
    if spatial_order {
        // Rows half an edge thick: each layer of a box grid gets its own row, so a grid
        // generator's numbering is kept.
        let cell = 0.5 * mean_edge_length(vertices, &tets);
        let order = row_order(vertices, cell);
        let (tets, tet_source) = relabel_tets(&tets, &inverse(&order));
        (order, tets, tet_source)
    } else {
        let identity = |len: usize| (0..len as u32).collect::<Vec<u32>>();
        let tet_count = tets.len();
        (identity(vertices.len()), tets, identity(tet_count))
    }
}

/// The part count (`parts`, or chosen by size when 0) and the slab of each particle.
pub(crate) fn body_parts(
    vertices: &[Vector3<f32>],
    tets: &[[u32; 4]],
    parts: usize,
) -> (usize, Vec<u32>) {
    let (axis, extent) = longest_axis(vertices);
    let parts = match parts {
        0 => auto_parts(tets.len(), extent / mean_edge_length(vertices, tets)),
        p => p,
    };
    (parts, slab_parts(vertices, tets, axis, parts))
}
