//! The components of one piece of a split body, rebuilt with the builder's own functions.
//!
//! After a split (`crate::body::split`) a body's particles and tetrahedra are renumbered;
//! what is derived from the mesh is built again the way [`crate::SoftBodyBuilder::build`]
//! builds it (solver order and colour classes, edges and their rest lengths, surface), from
//! the rest positions. What belongs to a tetrahedron travels with it: its rest volume,
//! vertex–face rest heights, the material's rest shape and its plastic stretch; what belongs to a
//! particle travels with it: position, velocity, masses, rest position, residual, forces,
//! and the multipliers of the last substep (the tear's energy bound reads them,
//! `crate::body::tear_relaxation`; the solver resets them each substep).
//!
//! A piece whose families leave its shape free is a degenerate fragment: without edges or a
//! material, vertex–face and volume constraints fix four and one of a tetrahedron's six
//! shape degrees of freedom, which a mesh's neighbours make up for but a single tetrahedron
//! or a few split off do not (`4T + T < 3n − 6` for `T` tetrahedra over `n` particles), and
//! such a piece shears, inverts and gains energy from its contacts. It gets edge constraints
//! (at the vertex–face compliance, m/N, or hard for volumes alone) and starts in its rest
//! shape, moved rigidly onto its current one (centre of mass and best rotation), moving with
//! the rigid fit of its velocities: its momentum is kept, its deformation and the kinetic
//! energy of its deformation are dropped.

use nalgebra::Vector3;

use crate::body::builder::{body_parts, SoftBody, TetMesh};
use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::forces::UserForces;
use crate::body::mesh::{Surface, Tetrahedra};
use crate::body::neo_hookean::{NeoHookeanMaterial, ReleasedScratch};
use crate::body::particles::Particles;
use crate::body::plastic_rest::RestState;
use crate::body::plasticity::Plasticity;
use crate::body::rest_families::edge_constraints;
use crate::body::tearing::{interior_faces, Tearing};
use crate::kernels::slots::{Slot, WorkCopy};
use crate::ordering::partition::part_order;

/// A split body's components, borrowed: particles with the copies appended, tetrahedra with
/// their corners renumbered (still in the old order).
pub(crate) struct SplitBody<'a> {
    pub particles: &'a Particles,
    pub tetrahedra: &'a Tetrahedra,
    pub edges: Option<&'a EdgeConstraints>,
    pub vertex_face: Option<&'a VertexFaceConstraints>,
    pub volume: Option<&'a VolumeConstraints>,
    pub plasticity: Option<&'a Plasticity>,
    pub material: Option<&'a NeoHookeanMaterial>,
    pub tearing: Option<&'a Tearing>,
    pub forces: Option<&'a UserForces>,
    /// The particle each particle of the split body was before the split: itself, or for a
    /// copy the particle it copies.
    pub origin: &'a [u32],
    /// The edges of the body before the split as sorted particle pairs, with their index.
    pub old_edges: &'a [([u32; 2], u32)],
}

/// The rebuilt components of one piece.
pub(crate) struct PieceParts {
    pub body: SoftBody,
    pub forces: Option<UserForces>,
    /// The split body's index of each of the piece's particles (ascending).
    pub particles: Vec<u32>,
    /// The split body's index of each of the piece's tetrahedra, in the piece's order.
    pub from: Vec<u32>,
}

/// The piece made of the split body's particles `particles` (ascending) and tetrahedra
/// `tets` (ascending), rebuilt as described in the module docs.
pub(crate) fn assemble(b: &SplitBody, particles: &[u32], tets: &[u32]) -> PieceParts {
    let p = b.particles;
    let mut local = vec![u32::MAX; p.len()];
    for (k, &i) in particles.iter().enumerate() {
        local[i as usize] = k as u32;
    }
    let mut new_particles = piece_particles(p, particles);
    if shape_edges(b, tets.len(), particles.len()).is_some() {
        settle_rigidly(&mut new_particles);
    }
    let rest = &new_particles.rest_positions;
    let local_tets: Vec<[u32; 4]> = tets
        .iter()
        .map(|&t| b.tetrahedra.indices[t as usize].map(|i| local[i as usize]))
        .collect();
    // Solver order and colour classes, as the builder makes them.
    let (parts, part_of) = body_parts(rest, &local_tets, 0);
    let (order, classes) = part_order(&local_tets, &part_of, parts, rest.len());
    let from: Vec<u32> = order.iter().map(|&k| tets[k]).collect();
    let pick = |t: &u32| *t as usize;
    let indices: Vec<[u32; 4]> = order.iter().map(|&k| local_tets[k]).collect();
    let slivers = crate::stabilisation::sliver_orientation::slivers(&indices, rest);
    let tetrahedra = Tetrahedra {
        indices,
        slivers,
        rest_volumes: from
            .iter()
            .map(|t| b.tetrahedra.rest_volumes[pick(t)])
            .collect(),
        source: from.iter().map(|t| b.tetrahedra.source[pick(t)]).collect(),
        classes,
    };
    let count = tetrahedra.len();
    let mesh = TetMesh {
        vertices: rest.clone(),
        tets: tetrahedra.indices.clone(),
    };
    let edge_compliance = b
        .edges
        .map(|e| e.compliance)
        .or_else(|| shape_edges(b, count, rest.len()));
    let mut edges = edge_compliance.map(|alpha| edge_constraints(&mesh, &part_of, parts, alpha));
    if let (Some(e), Some(old)) = (edges.as_mut(), b.edges) {
        carry_edge_multipliers(e, old, b, particles);
    }
    let mut vertex_face = b.vertex_face.map(|v| VertexFaceConstraints {
        rest_heights: from.iter().map(|t| v.rest_heights[pick(t)]).collect(),
        lambdas: from.iter().map(|t| v.lambdas[pick(t)]).collect(),
        compliance: v.compliance,
    });
    let volume = b.volume.map(|v| VolumeConstraints {
        lambdas: from.iter().map(|t| v.lambdas[pick(t)]).collect(),
        compliance: v.compliance,
    });
    let mut material = b.material.map(|m| NeoHookeanMaterial {
        material: m.material,
        rest_inverse: from.iter().map(|t| m.rest_inverse[pick(t)]).collect(),
        lambdas: from.iter().map(|t| m.lambdas[pick(t)]).collect(),
        released: 0.0,
        tet_released: ReleasedScratch(vec![0.0; count]),
    });
    let plasticity = b
        .plasticity
        .map(|pl| pl.for_piece(&from, &tetrahedra.indices, edges.as_ref()));
    let mut tetrahedra = tetrahedra;
    if let Some(pl) = &plasticity {
        // Edge rest lengths from the plastic rest shapes, as the flow pass sets them.
        let mut state = RestState {
            tetrahedra: &mut tetrahedra,
            vertex_face: vertex_face.as_mut(),
            edges: edges.as_mut(),
            material: material.as_mut(),
        };
        state.refresh_edges(pl, rest);
    }
    let tearing = b.tearing.map(|old| {
        let mut t = piece_tearing(old, &from, &tetrahedra, rest);
        t.prepare_forces(&tetrahedra, edges.as_ref());
        t
    });
    // A copy made by the split has no force of its own (the force stays on the particle it
    // copies, so the body's total force is kept).
    let forces = b.forces.map(|f| UserForces {
        forces: particles
            .iter()
            .map(|&i| f.forces.get(i as usize).copied().unwrap_or_default())
            .collect(),
    });
    let surface = Surface::from_tetrahedra(&tetrahedra.indices, rest);
    PieceParts {
        body: SoftBody {
            particles: new_particles,
            tetrahedra,
            surface,
            edges,
            vertex_face,
            volume,
            plasticity,
            material,
            tearing,
        },
        forces,
        particles: particles.to_vec(),
        from,
    }
}

/// The compliance of the edges a piece of `count` tetrahedra over `n` particles gets when its
/// families leave its shape free (module docs): `Some` for a body without edges or a material
/// whose vertex–face and volume constraints (four and one per tetrahedron) are fewer than the
/// piece's `3n − 6` shape degrees of freedom; the vertex–face family's compliance (m/N, the
/// same units as an edge's), or 0 for volumes alone.
fn shape_edges(b: &SplitBody, count: usize, n: usize) -> Option<f32> {
    if b.edges.is_some() || b.material.is_some() {
        return None;
    }
    let per_tet = 4 * usize::from(b.vertex_face.is_some()) + usize::from(b.volume.is_some());
    if per_tet * count >= (3 * n).saturating_sub(6) {
        return None;
    }
    Some(b.vertex_face.map_or(0.0, |v| v.compliance))
}

/// Gives each edge of a piece (its particles `particles` of the split body) the multiplier
/// of the edge of the body before the split it comes from (the energy bound reads them,
/// `crate::body::tear_relaxation`; the solver resets them each substep).
fn carry_edge_multipliers(
    e: &mut EdgeConstraints,
    old: &EdgeConstraints,
    b: &SplitBody,
    particles: &[u32],
) {
    for (k, &[i, j]) in e.edges.iter().enumerate() {
        let o = |l: u32| b.origin[particles[l as usize] as usize];
        let (a, c) = (o(i), o(j));
        let key = [a.min(c), a.max(c)];
        if let Ok(at) = b.old_edges.binary_search_by_key(&key, |x| x.0) {
            e.lambdas[k] = old.lambdas[b.old_edges[at].1 as usize];
        }
    }
}

/// Puts a fragment in its rest shape, moved rigidly to fit its particles (centre of mass and
/// best rotation of the rest shape onto the current one), moving with the rigid fit of its
/// velocities (its linear and angular momentum): its deformation and the kinetic energy of
/// its deformation are dropped. Pinned particles, or a fit that is not defined, leave it as
/// it is.
fn settle_rigidly(p: &mut Particles) {
    if p.inv_masses.contains(&0.0) {
        return;
    }
    let Some(fit) = p.rigid_fit() else {
        return;
    };
    let total: f64 = p.masses.iter().map(|&m| f64::from(m)).sum();
    if total.is_nan() || total <= 0.0 {
        return;
    }
    let rest_centre: Vector3<f64> = p
        .rest_positions
        .iter()
        .zip(&p.masses)
        .map(|(r, &m)| r.cast::<f64>() * f64::from(m))
        .sum::<Vector3<f64>>()
        / total;
    let c = fit.centre.cast::<f64>();
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    for ((x, r), &m) in p.positions.iter().zip(&p.rest_positions).zip(&p.masses) {
        a += (x.cast::<f64>() - c) * (r.cast::<f64>() - rest_centre).transpose() * f64::from(m);
    }
    let svd = a.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return;
    };
    let mut d = nalgebra::Matrix3::<f64>::identity();
    d[(2, 2)] = (u * v_t).determinant().signum();
    let rot = u * d * v_t;
    if !rot.iter().all(|x| x.is_finite()) {
        return;
    }
    let (vc, omega) = (
        fit.velocity.cast::<f64>(),
        fit.angular_velocity.cast::<f64>(),
    );
    for i in 0..p.positions.len() {
        let x = c + rot * (p.rest_positions[i].cast::<f64>() - rest_centre);
        let v = vc + omega.cross(&(x - c));
        p.positions[i] = x.cast::<f32>();
        p.prev_positions[i] = p.positions[i];
        p.velocities[i] = v.cast::<f32>();
    }
}

/// The particles `list` of `p`, in that order; the piece's vertex map names, for each
/// input vertex, the first particle built from it (`u32::MAX` when none is in the piece).
fn piece_particles(p: &Particles, list: &[u32]) -> Particles {
    fn gather<T: Copy>(v: &[T], list: &[u32]) -> Vec<T> {
        list.iter().map(|&i| v[i as usize]).collect()
    }
    let source = gather(&p.source, list);
    let mut vertex_to_particle = vec![u32::MAX; p.vertex_to_particle.len()];
    for (k, &s) in source.iter().enumerate() {
        if let Some(slot) = vertex_to_particle.get_mut(s as usize) {
            if *slot == u32::MAX {
                *slot = k as u32;
            }
        }
    }
    Particles {
        positions: gather(&p.positions, list),
        prev_positions: gather(&p.prev_positions, list),
        velocities: gather(&p.velocities, list),
        inv_masses: gather(&p.inv_masses, list),
        masses: gather(&p.masses, list),
        rest_positions: gather(&p.rest_positions, list),
        residuals: gather(&p.residuals, list),
        source,
        vertex_to_particle,
        work: WorkCopy(vec![Slot::default(); list.len()]),
        written: true,
        hook: Default::default(),
    }
}

/// The tearing state of a piece whose tetrahedron `k` was the split body's `from[k]`: its
/// interior faces, each keeping the smoothed strain and force and torn flag it had.
fn piece_tearing(
    old: &Tearing,
    from: &[u32],
    tetrahedra: &Tetrahedra,
    rest: &[Vector3<f32>],
) -> Tearing {
    let mut faces = interior_faces(&tetrahedra.indices, rest);
    // The piece's index of each of the split body's tetrahedra in it, sorted by the latter.
    let mut new_of: Vec<(u32, u32)> = from
        .iter()
        .enumerate()
        .map(|(k, &t)| (t, k as u32))
        .collect();
    new_of.sort_unstable();
    let map = |t: u32| {
        new_of
            .binary_search_by_key(&t, |e| e.0)
            .ok()
            .map(|j| new_of[j].1)
    };
    for f in &old.faces {
        let (Some(a), Some(b)) = (map(f.tets[0]), map(f.tets[1])) else {
            continue;
        };
        let key = [a.min(b), a.max(b)];
        if let Ok(j) = faces.binary_search_by_key(&key, |g| g.tets) {
            faces[j].smoothed = f.smoothed;
            faces[j].smoothed_force = f.smoothed_force;
            faces[j].torn = f.torn;
        }
    }
    Tearing {
        settings: old.settings,
        faces,
        forces: Default::default(),
        largest_index: None,
    }
}
