//! Slivers' orientation gets the last word: the volume and vertex–face constraints of a body's
//! inverted sliver tetrahedra are projected again after its edges, in every iteration, until
//! none is left inverted.
//!
//! # Why edges cannot hold a sliver upright
//!
//! Mirroring one vertex of a tetrahedron through the plane of its opposite face keeps all
//! six of its edge lengths: edges never see a tetrahedron's orientation, only its
//! neighbours do, through the shared vertex. For an ordinary tetrahedron the mirrored vertex
//! moves by twice an altitude comparable to its edges, and the neighbours' edges resist it
//! strongly. For a *sliver* — altitude `a` much smaller than its longest edge `L` (a plate
//! or a slab one cell thick) — the vertex moves by `2a`, and the edges of its neighbours
//! change by `O(a)` at most, `O(a²/L)` along the plate: the edges hold an inverted sliver
//! almost as well as an upright one. Only the orientation constraints (signed volume,
//! signed vertex–face heights) tell them apart.
//!
//! In a Gauss–Seidel iteration the families are projected in
//! [`crate::SolverSettings::order`], edges last by default. A thin body under a load it
//! cannot carry in one sweep (a plate held by a 1 mm strip carries a thousand times its
//! weight there) is folded by the edges' corrections, and the orientation of its slivers is
//! lost after the volume constraints have spoken: tetrahedra next to the pins inverted at
//! the largest bend and stayed inverted, the hard volume constraints' total volume 50 % off.
//!
//! # The rule
//!
//! A tetrahedron is a sliver when its smallest rest altitude `3V₀/A_max` (`A_max` its
//! largest face) is below [`SLIVER_ALTITUDE`] times its longest rest edge. The builder lists
//! a body's slivers ([`crate::Tetrahedra`]). After the families, in each iteration, each
//! sliver of a body with edge constraints that the families left inverted (signed volume of
//! the other sign than its rest volume, or zero) has its volume constraint and its four
//! vertex–face constraints (those of the families the body has) projected once more, with
//! the same multipliers: one more Gauss–Seidel visit of the constraints that alone see the
//! sliver's orientation, so that theirs is the last word on it in that iteration. A body
//! without edges or without slivers is skipped; a sliver that is upright is left alone:
//! ordinary meshes pay nothing and step bit for bit as before.
//!
//! **Swept until none is inverted.** Neighbouring slivers share vertices: a sliver set upright
//! early in a sweep can be turned over again by a later neighbour's projection (on a slab
//! pinned at one end, the root sliver visited first was upright when visited and inverted when
//! the sweep ended, every substep, for seconds). The sweep is repeated while it projected
//! anything, at most [`SLIVER_SWEEPS`] times; a repeat visits only the slivers still
//! inverted.
//!
//! **Only inverted slivers.** Visiting every sliver once more helped a bending slab more,
//! but gave a compliant plate energy at one substep (vertex–face + edges, soft: a rise of
//! 3 % of `M g L` on the 10 m slab, 22 % on the 1 m plate): the correction-energy budget
//! ([`crate::stabilisation::correction_energy`]) counts each multiplier's release once.
//! Restricted to inverted slivers no run of the sweep gained energy
//! (`docs/decisions/sliver-orientation.md`).

use hecs::World;
use nalgebra::Vector3;

use crate::body::activation::Asleep;
use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::kernels::scalar::{self, ParticleAccess};
use crate::kernels::working_copy::{self, CopyMode};

/// A tetrahedron whose smallest rest altitude is below this fraction of its longest rest
/// edge is a sliver (dimensionless). A regular tetrahedron has 0.82, the six tetrahedra of
/// a cube cell 0.41; a cell of a 1 cm × 1 m × 1 m slab 0.007.
pub const SLIVER_ALTITUDE: f64 = 0.1;

/// Sweeps over a body's slivers per iteration at most: a sliver set upright early in a sweep
/// can be turned over again by a neighbour's projection later in it.
pub const SLIVER_SWEEPS: usize = 4;

/// The faces of a tetrahedron `[p0, p1, p2, p3]`, each opposite one corner.
const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// The largest face area (m²) of the tetrahedron with corners `x`.
pub(crate) fn largest_face(x: &[Vector3<f64>; 4]) -> f64 {
    FACES
        .iter()
        .map(|f| 0.5 * (x[f[1]] - x[f[0]]).cross(&(x[f[2]] - x[f[0]])).norm())
        .fold(0.0f64, f64::max)
}

/// The indices of the slivers among `tets` at the rest positions `rest` (module docs);
/// tetrahedra with an index past `rest` or no extent are left out.
pub(crate) fn slivers(tets: &[[u32; 4]], rest: &[Vector3<f32>]) -> Vec<u32> {
    let mut out = Vec::new();
    for (k, t) in tets.iter().enumerate() {
        let corners = t.map(|i| rest.get(i as usize).map(|v| v.cast::<f64>()));
        let [Some(a), Some(b), Some(c), Some(d)] = corners else {
            continue;
        };
        let x = [a, b, c, d];
        let volume = ((b - a).dot(&(c - a).cross(&(d - a))) / 6.0).abs();
        let face = largest_face(&x);
        let mut longest = 0.0f64;
        for i in 0..4 {
            for j in i + 1..4 {
                longest = longest.max((x[i] - x[j]).norm());
            }
        }
        if face > 0.0 && 3.0 * volume / face < SLIVER_ALTITUDE * longest {
            out.push(k as u32);
        }
    }
    out
}

/// Projects, on the working copy, the volume and vertex–face constraints of the slivers of
/// every awake body with edge constraints once more (module docs), substep `h` (s).
pub(crate) fn project_slivers(world: &mut World, h: f32) {
    let q = world.query_mut::<(
        &mut Particles,
        &Tetrahedra,
        &EdgeConstraints,
        Option<&mut VolumeConstraints>,
        Option<&mut VertexFaceConstraints>,
    )>();
    for (p, tets, _, mut volume, mut vertex_face) in q.without::<&Asleep>() {
        if tets.slivers.is_empty() || (volume.is_none() && vertex_face.is_none()) {
            continue;
        }
        let h2 = h * h;
        working_copy::with_access(p, CopyMode::Resident, |acc| {
            for _ in 0..SLIVER_SWEEPS {
                let mut projected = false;
                for &k in &tets.slivers {
                    let families = (volume.as_deref_mut(), vertex_face.as_deref_mut());
                    projected |= project_if_inverted(acc, tets, k as usize, families, h2);
                }
                if !projected {
                    break;
                }
            }
        });
    }
}

/// Projects the volume and vertex–face constraints (of the families given) of tetrahedron
/// `k` once more if it is inverted, substep `h2` = h² (s²). Returns whether it was.
fn project_if_inverted(
    acc: &mut impl ParticleAccess,
    tets: &Tetrahedra,
    k: usize,
    (volume, vertex_face): (
        Option<&mut VolumeConstraints>,
        Option<&mut VertexFaceConstraints>,
    ),
    h2: f32,
) -> bool {
    let (Some(&tet), Some(&rest)) = (tets.indices.get(k), tets.rest_volumes.get(k)) else {
        return false;
    };
    let x = tet.map(|i| acc.x(i as usize));
    if crate::constraints::signed_volume(&x[0], &x[1], &x[2], &x[3]) * rest > 0.0 {
        return false;
    }
    if let Some(v) = volume {
        let at = v.compliance / h2;
        if let Some(l) = v.lambdas.get_mut(k) {
            scalar::volume(acc, tet, rest, l, at);
        }
    }
    if let Some(v) = vertex_face {
        let at = v.compliance / h2;
        if let (Some(hs), Some(l)) = (v.rest_heights.get(k), v.lambdas.get_mut(k)) {
            scalar::vertex_face_held(acc, tet, hs, l, at, [true; 4]);
        }
    }
    true
}
