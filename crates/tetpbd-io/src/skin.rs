//! Barycentric skinning: points of a fine render mesh embedded in the tetrahedra of a
//! coarse simulation mesh, moved with it every frame.

use crate::glam::to_glam;
use nalgebra::{Matrix3, Vector3};
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use parry3d::query::PointQuery;
use parry3d::shape::Tetrahedron;

use crate::mesher_error::SkinError;
use crate::tetrahedralize::builder_volume;

/// Where one embedded point lives: four tetrahedron vertices and their weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkinBinding {
    /// Index of the tetrahedron (in the slice given to [`Skin::embed`]).
    pub tet: u32,
    /// Its four vertex indices.
    pub vertices: [u32; 4],
    /// Barycentric coordinates of the point in the tetrahedron at embedding time; they sum
    /// to 1 and are not clamped (negative for a point outside the tetrahedron).
    pub weights: [f32; 4],
    /// Distance from the point to the tetrahedron at embedding time, m (0 inside).
    pub distance: f32,
}

/// Points embedded in tetrahedra: each point is bound to one tetrahedron with its
/// barycentric coordinates there, and [`Skin::deform`] places it at the same barycentric
/// coordinates in the moved tetrahedron.
///
/// * A point inside the tetrahedral mesh is bound to a tetrahedron containing it (the first
///   found when it lies on a shared face or edge, which gives the same position).
/// * A point outside is bound to the nearest tetrahedron with its *unclamped* barycentric
///   coordinates: it follows that tetrahedron's affine motion (extrapolation), so it is
///   reproduced exactly at rest and moved exactly by any affine motion, but the further out
///   it is, the more it amplifies that tetrahedron's deformation. [`Skin::outside_count`]
///   and [`Skin::max_outside_distance`] say how far out the points are; a mesh from
///   [`crate::TetrahedralizeBuilder`] contains its own surface, so its vertices are inside.
///
/// Embedding searches a parry BVH over the tetrahedra's boxes (best-first nearest
/// tetrahedron), not all pairs. Deforming allocates nothing.
///
/// ```
/// use nalgebra::Vector3;
/// use tetpbd_io::Skin;
/// let tet_vertices = [Vector3::zeros(), Vector3::x(), Vector3::y(), Vector3::z()];
/// let points = [Vector3::new(0.2, 0.2, 0.2), Vector3::new(-1.0, 0.0, 0.0)];
/// let skin = Skin::embed(&tet_vertices, &[[0, 1, 2, 3]], &points)?;
/// assert_eq!(skin.outside_count(), 1);
/// let moved: Vec<_> = tet_vertices.iter().map(|p| p * 2.0).collect();
/// let mut out = [Vector3::zeros(); 2];
/// skin.deform(&moved, &mut out)?;
/// assert!((out[0] - Vector3::new(0.4, 0.4, 0.4)).norm() < 1e-6);
/// assert!((out[1] - Vector3::new(-2.0, 0.0, 0.0)).norm() < 1e-6);
/// # Ok::<(), tetpbd_io::SkinError>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Skin {
    pub(crate) bindings: Vec<SkinBinding>,
    pub(crate) vertex_count: usize,
}

impl Skin {
    /// Embeds `points` (m) in the tetrahedra `tets` over `positions` (m).
    ///
    /// For a soft body pass the built body's own arrays, `body.particles.positions()` and
    /// `body.tetrahedra.indices()`, with the points placed as the body is (e.g. moved by
    /// the same translation), so the bindings use the body's particle indices.
    ///
    /// Errors: [`SkinError::NoTetrahedra`], [`SkinError::IndexOutOfRange`],
    /// [`SkinError::NonFinite`] (a used vertex or a point), [`SkinError::DegenerateTet`]
    /// (volume below the soft-body builder's epsilon).
    pub fn embed(
        positions: &[Vector3<f32>],
        tets: &[[u32; 4]],
        points: &[Vector3<f32>],
    ) -> Result<Skin, SkinError> {
        if tets.is_empty() {
            return Err(SkinError::NoTetrahedra);
        }
        let mut inverses = Vec::with_capacity(tets.len());
        let mut boxes = Vec::with_capacity(tets.len());
        for t in 0..tets.len() {
            let corners = corners(positions, tets, t)?;
            inverses.push(inverse(&corners, t)?);
            boxes.push(Aabb::from_points(corners.iter().map(to_glam)));
        }
        if let Some(index) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(SkinError::NonFinite {
                what: "point",
                index,
            });
        }
        let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes);
        let mut bindings = Vec::with_capacity(points.len());
        for p in points {
            let q = to_glam(p);
            let barycentric = |t: u32| {
                let (a, m_inv) = &inverses[t as usize];
                m_inv * (p.cast::<f64>() - a)
            };
            // Inside (by the barycentric coordinates, cheap) is distance 0; otherwise parry
            // measures the distance to the tetrahedron.
            let tet_distance = |t: u32| {
                let l = barycentric(t);
                if l.min() >= 0.0 && l.sum() <= 1.0 {
                    return 0.0;
                }
                let [a, b, c, d] = tets[t as usize].map(|i| to_glam(&positions[i as usize]));
                Tetrahedron::new(a, b, c, d).distance_to_local_point(q, true)
            };
            let (t, distance) = bvh
                .find_best(
                    f32::MAX,
                    |node, _| node.aabb().distance_to_local_point(q, true),
                    |leaf, _| Some(tet_distance(leaf)),
                )
                .unwrap_or_else(|| (0, tet_distance(0)));
            let l = barycentric(t).map(|w| w as f32);
            bindings.push(SkinBinding {
                tet: t,
                vertices: tets[t as usize],
                weights: [1.0 - l.x - l.y - l.z, l.x, l.y, l.z],
                distance,
            });
        }
        Ok(Skin {
            bindings,
            vertex_count: positions.len(),
        })
    }

    /// Writes each embedded point's position in the tetrahedra at `positions` (m) into `out`;
    /// no allocation. `positions` must have the length the skin was embedded with and `out`
    /// one entry per point ([`SkinError::LengthMismatch`] otherwise).
    pub fn deform(
        &self,
        positions: &[Vector3<f32>],
        out: &mut [Vector3<f32>],
    ) -> Result<(), SkinError> {
        if positions.len() != self.vertex_count {
            return Err(SkinError::LengthMismatch {
                what: "positions",
                expected: self.vertex_count,
                found: positions.len(),
            });
        }
        if out.len() != self.bindings.len() {
            return Err(SkinError::LengthMismatch {
                what: "output",
                expected: self.bindings.len(),
                found: out.len(),
            });
        }
        for (o, b) in out.iter_mut().zip(&self.bindings) {
            let [a, c, d, e] = b.vertices.map(|i| positions[i as usize]);
            let [wa, wc, wd, we] = b.weights;
            *o = a * wa + c * wc + d * wd + e * we;
        }
        Ok(())
    }

    /// One binding per embedded point, in the order given.
    pub fn bindings(&self) -> &[SkinBinding] {
        &self.bindings
    }

    /// Number of embedded points.
    pub fn len(&self) -> usize {
        self.bindings.len()
    }

    /// `true` when no point is embedded.
    pub fn is_empty(&self) -> bool {
        self.bindings.is_empty()
    }

    /// Number of points that were outside every tetrahedron (bound by extrapolation).
    pub fn outside_count(&self) -> usize {
        self.bindings.iter().filter(|b| b.distance > 0.0).count()
    }

    /// Largest distance from a point to its tetrahedron at embedding time, m (0 when all
    /// points are inside).
    pub fn max_outside_distance(&self) -> f32 {
        self.bindings.iter().map(|b| b.distance).fold(0.0, f32::max)
    }
}

/// The four corners of tetrahedron `t`, checked for range and finiteness.
fn corners(
    positions: &[Vector3<f32>],
    tets: &[[u32; 4]],
    t: usize,
) -> Result<[Vector3<f32>; 4], SkinError> {
    let mut out = [Vector3::zeros(); 4];
    for (o, &i) in out.iter_mut().zip(&tets[t]) {
        let p = positions
            .get(i as usize)
            .ok_or(SkinError::IndexOutOfRange {
                tet: t,
                index: i,
                vertex_count: positions.len(),
            })?;
        if !p.iter().all(|c| c.is_finite()) {
            return Err(SkinError::NonFinite {
                what: "vertex",
                index: i as usize,
            });
        }
        *o = *p;
    }
    Ok(out)
}

/// First corner and inverse edge matrix `[b − a, c − a, d − a]⁻¹` (f64), or
/// [`SkinError::DegenerateTet`] when the volume is below the builder's epsilon.
fn inverse(
    corners: &[Vector3<f32>; 4],
    t: usize,
) -> Result<(Vector3<f64>, Matrix3<f64>), SkinError> {
    let (volume, ok) = builder_volume(corners);
    let degenerate = SkinError::DegenerateTet { tet: t, volume };
    if !ok {
        return Err(degenerate);
    }
    let [a, b, c, d] = corners.map(|p| p.cast::<f64>());
    let m = Matrix3::from_columns(&[b - a, c - a, d - a]);
    m.try_inverse().map(|inv| (a, inv)).ok_or(degenerate)
}
