//! Per-body acceleration structures of soft–soft contacts: parry BVHs over a soft body's
//! surface triangles and tetrahedra, refitted as the body deforms, and the small triangle
//! geometry the contacts need.
//!
//! Everything a body's cache stores is in *surface-local* indices (position in
//! [`tetpbd::Surface::vertices`]), so the contact solver can work on a flat copy of the
//! surface particles of every body in the frame.

use nalgebra::Vector3;
use rapier3d::parry::bounding_volume::Aabb;
use rapier3d::parry::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};
use rapier3d::parry::query::{PointProjection, Ray};
use tetpbd::{Surface, Tetrahedra};

use crate::convert::to_glam;

/// Cached structures of one soft body, kept across frames while its mesh is unchanged.
#[derive(Clone)]
pub(crate) struct BodyCache {
    /// The surface triangles the cache was built from (particle indices), to detect changes.
    pub source_triangles: Vec<[u32; 3]>,
    /// Number of particles and tetrahedra when built, to detect changes.
    pub particle_count: usize,
    pub tet_count: usize,
    /// Particle index of each surface-local vertex (a copy of `Surface::vertices`).
    pub vertices: Vec<u32>,
    /// Surface triangles in surface-local indices.
    pub triangles: Vec<[u32; 3]>,
    /// Tetrahedra (particle indices).
    pub tets: Vec<[u32; 4]>,
    /// BVH over `triangles` (leaf `t` is triangle `t`).
    pub tri_bvh: Bvh,
    /// BVH over `tets` (leaf `t` is tetrahedron `t`).
    pub tet_bvh: Bvh,
    pub workspace: BvhWorkspace,
    /// Self-collision exclusion: for surface-local vertex `k`, the sorted particle indices
    /// sharing a tetrahedron with it (itself included), `ring[ring_start[k]..ring_start[k+1]]`.
    /// Empty until a self-colliding body needs it.
    pub ring_start: Vec<u32>,
    pub ring: Vec<u32>,
}

impl BodyCache {
    /// Builds the cache, or `None` when the mesh refers to particles that do not exist.
    pub fn build(surface: &Surface, tets: &Tetrahedra, particle_count: usize) -> Option<Self> {
        let n = particle_count as u32;
        let vertices = surface.vertices().to_vec();
        if vertices.iter().any(|&i| i >= n) || tets.indices().iter().flatten().any(|&i| i >= n) {
            return None;
        }
        let local = |i: u32| vertices.binary_search(&i).ok().map(|k| k as u32);
        let mut triangles = Vec::with_capacity(surface.triangles().len());
        for t in surface.triangles() {
            triangles.push([local(t[0])?, local(t[1])?, local(t[2])?]);
        }
        let empty = Aabb::new(to_glam(&Vector3::zeros()), to_glam(&Vector3::zeros()));
        let tri_bvh = Bvh::from_iter(
            BvhBuildStrategy::Binned,
            (0..triangles.len()).map(|t| (t, empty)),
        );
        let tet_bvh = Bvh::from_iter(
            BvhBuildStrategy::Binned,
            (0..tets.len()).map(|t| (t, empty)),
        );
        Some(BodyCache {
            source_triangles: surface.triangles().to_vec(),
            particle_count,
            tet_count: tets.len(),
            vertices,
            triangles,
            tets: tets.indices().to_vec(),
            tri_bvh,
            tet_bvh,
            workspace: BvhWorkspace::default(),
            ring_start: Vec::new(),
            ring: Vec::new(),
        })
    }

    /// `true` while the cache still describes this mesh.
    pub fn matches(&self, surface: &Surface, tets: &Tetrahedra, particle_count: usize) -> bool {
        self.particle_count == particle_count
            && self.tet_count == tets.len()
            && self.source_triangles == surface.triangles()
    }

    /// Refits the triangle BVH to the boxes of the triangles at `x` (surface-local
    /// positions), each vertex's box grown by its `motion` (m).
    pub fn refit_triangles(&mut self, x: &[Vector3<f32>], motion: &[f32]) {
        for (t, tri) in self.triangles.iter().enumerate() {
            let (mut lo, mut hi) = (Vector3::repeat(f32::MAX), Vector3::repeat(f32::MIN));
            for &k in tri {
                let r = Vector3::repeat(motion[k as usize]);
                lo = lo.inf(&(x[k as usize] - r));
                hi = hi.sup(&(x[k as usize] + r));
            }
            let aabb = Aabb::new(to_glam(&lo), to_glam(&hi));
            self.tri_bvh.insert_or_update_partially(aabb, t as u32, 0.0);
        }
        self.tri_bvh.refit_without_opt();
    }

    /// Refits the tetrahedron BVH to the particle positions `p` (all particles).
    pub fn refit_tets(&mut self, p: &[Vector3<f32>]) {
        for (t, tet) in self.tets.iter().enumerate() {
            let (mut lo, mut hi) = (Vector3::repeat(f32::MAX), Vector3::repeat(f32::MIN));
            for &i in tet {
                lo = lo.inf(&p[i as usize]);
                hi = hi.sup(&p[i as usize]);
            }
            let aabb = Aabb::new(to_glam(&lo), to_glam(&hi));
            self.tet_bvh.insert_or_update_partially(aabb, t as u32, 0.0);
        }
        self.tet_bvh.refit_without_opt();
    }

    /// Builds the one-ring exclusion lists (once) for self collision.
    pub fn ensure_rings(&mut self) {
        if !self.ring_start.is_empty() || self.vertices.is_empty() {
            return;
        }
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for tet in &self.tets {
            for &a in tet {
                if let Ok(k) = self.vertices.binary_search(&a) {
                    for &b in tet {
                        pairs.push((k as u32, b));
                    }
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        self.ring_start = vec![0; self.vertices.len() + 1];
        self.ring = Vec::with_capacity(pairs.len());
        for (k, b) in pairs {
            self.ring_start[k as usize + 1] += 1;
            self.ring.push(b);
        }
        for k in 0..self.vertices.len() {
            self.ring_start[k + 1] += self.ring_start[k];
        }
    }

    /// `true` when surface triangle `t` touches surface-local vertex `k` or one of its
    /// tetrahedron neighbours (never a self-collision pair).
    pub fn excluded(&self, k: usize, t: usize) -> bool {
        let own = self.vertices[k];
        let ring = match (self.ring_start.get(k), self.ring_start.get(k + 1)) {
            (Some(&a), Some(&b)) => &self.ring[a as usize..b as usize],
            _ => &[][..],
        };
        self.triangles[t].iter().any(|&v| {
            let i = self.vertices[v as usize];
            i == own || ring.binary_search(&i).is_ok()
        })
    }

    /// `true` when `x` lies strictly inside one of the body's tetrahedra at positions `p`.
    pub fn contains(&self, x: &Vector3<f32>, p: &[Vector3<f32>]) -> bool {
        let q = to_glam(x);
        let aabb = Aabb::new(q, q);
        let inside = self
            .tet_bvh
            .intersect_aabb(&aabb)
            .any(|t| in_tet(x, &self.tets[t as usize].map(|i| p[i as usize])));
        inside
    }

    /// The surface triangle closest to `x` (surface-local positions `xs`).
    pub fn closest_triangle(&self, x: &Vector3<f32>, xs: &[Vector3<f32>]) -> Option<usize> {
        let tris = &self.triangles;
        let best = self.tri_bvh.project_point(to_glam(x), f32::MAX, |t, _| {
            let [a, b, c] = tris.get(t as usize)?.map(|k| xs[k as usize]);
            let w = closest_barycentric(x, &a, &b, &c);
            let q = a * w[0] + b * w[1] + c * w[2];
            q.iter()
                .all(|v| v.is_finite())
                .then(|| PointProjection::new(false, to_glam(&q)))
        })?;
        Some(best.0 as usize)
    }
}

impl BodyCache {
    /// Distance (m) from `x` along the unit direction `dir` to the first surface triangle
    /// the ray leaves the body through (outward normal · `dir` > 0), triangles at the
    /// surface-local positions `xs`; `None` when the ray leaves through none.
    pub fn exit_distance(
        &self,
        x: &Vector3<f32>,
        dir: &Vector3<f32>,
        xs: &[Vector3<f32>],
    ) -> Option<f32> {
        let ray = Ray::new(to_glam(x), to_glam(dir));
        let tris = &self.triangles;
        let hit = self.tri_bvh.cast_ray(&ray, f32::MAX, |t, _| {
            let [a, b, c] = tris.get(t as usize)?.map(|k| xs[k as usize]);
            let n = triangle_normal(&a, &b, &c)?;
            if n.dot(dir) <= 0.0 {
                return None;
            }
            ray_triangle(x, dir, &a, &b, &c)
        })?;
        Some(hit.1)
    }
}

/// Möller–Trumbore: distance along `dir` from `o` to triangle `(a, b, c)`, if hit ahead.
fn ray_triangle(
    o: &Vector3<f32>,
    dir: &Vector3<f32>,
    a: &Vector3<f32>,
    b: &Vector3<f32>,
    c: &Vector3<f32>,
) -> Option<f32> {
    ray_triangle_barycentric(o, dir, [a, b, c], 0.0).map(|(t, _)| t)
}

/// Möller–Trumbore: the ray parameter `t ≥ 0` (in units of `|dir|`) at which the ray
/// `o + t dir` meets triangle `(a, b, c)`, and the barycentric coordinates of the hit point
/// (weights of `a`, `b`, `c`; in `[0, 1]`, summing to 1); `None` when it misses, runs
/// parallel to the triangle's plane or the triangle is degenerate. A hit up to `slack`
/// (dimensionless, in barycentric units) outside the triangle counts, its weights clamped
/// back onto the triangle: with a slack of a few ulps a ray through a vertex or edge shared
/// by several triangles meets at least one of them despite rounding.
pub(crate) fn ray_triangle_barycentric(
    o: &Vector3<f32>,
    dir: &Vector3<f32>,
    [a, b, c]: [&Vector3<f32>; 3],
    slack: f32,
) -> Option<(f32, [f32; 3])> {
    let e1 = b - a;
    let e2 = c - a;
    let pv = dir.cross(&e2);
    let det = e1.dot(&pv);
    if det.abs() <= 1e-12 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - a;
    let u = tv.dot(&pv) * inv;
    if !(-slack..=1.0 + slack).contains(&u) {
        return None;
    }
    let qv = tv.cross(&e1);
    let v = dir.dot(&qv) * inv;
    if v < -slack || u + v > 1.0 + slack {
        return None;
    }
    let t = e2.dot(&qv) * inv;
    if !(t >= 0.0 && t.is_finite()) {
        return None;
    }
    if slack == 0.0 {
        return Some((t, [1.0 - u - v, u, v]));
    }
    let w = [1.0 - u - v, u, v].map(|w| w.max(0.0));
    let sum = w[0] + w[1] + w[2];
    Some((t, w.map(|w| w / sum)))
}

/// `true` when `x` lies strictly inside the tetrahedron `t` (either orientation).
pub(crate) fn in_tet(x: &Vector3<f32>, t: &[Vector3<f32>; 4]) -> bool {
    let vol = |a: &Vector3<f32>, b: &Vector3<f32>, c: &Vector3<f32>, d: &Vector3<f32>| {
        (b - a).dot(&(c - a).cross(&(d - a)))
    };
    let total = vol(&t[0], &t[1], &t[2], &t[3]);
    if total == 0.0 || !total.is_finite() {
        return false;
    }
    let s = total.signum();
    vol(x, &t[1], &t[2], &t[3]) * s > 0.0
        && vol(&t[0], x, &t[2], &t[3]) * s > 0.0
        && vol(&t[0], &t[1], x, &t[3]) * s > 0.0
        && vol(&t[0], &t[1], &t[2], x) * s > 0.0
}

/// Barycentric coordinates of `x` in tetrahedron `t` (weights of its four corners, summing
/// to 1), when `x` lies inside it or on its boundary (all weights ≥ 0, either orientation);
/// `None` outside or for a flat tetrahedron.
pub(crate) fn tet_barycentric(x: &Vector3<f32>, t: &[Vector3<f32>; 4]) -> Option<[f32; 4]> {
    let vol = |a: &Vector3<f32>, b: &Vector3<f32>, c: &Vector3<f32>, d: &Vector3<f32>| {
        (b - a).dot(&(c - a).cross(&(d - a)))
    };
    let total = vol(&t[0], &t[1], &t[2], &t[3]);
    if total == 0.0 || !total.is_finite() {
        return None;
    }
    let w = [
        vol(x, &t[1], &t[2], &t[3]) / total,
        vol(&t[0], x, &t[2], &t[3]) / total,
        vol(&t[0], &t[1], x, &t[3]) / total,
        vol(&t[0], &t[1], &t[2], x) / total,
    ];
    w.iter().all(|w| *w >= 0.0 && w.is_finite()).then_some(w)
}

/// Unit normal `(b − a) × (c − a) / |…|` of a triangle, or `None` when it is degenerate.
#[inline]
pub(crate) fn triangle_normal(
    a: &Vector3<f32>,
    b: &Vector3<f32>,
    c: &Vector3<f32>,
) -> Option<Vector3<f32>> {
    let m = (b - a).cross(&(c - a));
    let len = m.norm();
    let scale = (b - a).norm_squared() + (c - a).norm_squared();
    (len.is_finite() && len > 1e-7 * scale && len > 0.0).then(|| m / len)
}

/// Barycentric coordinates of the projection of `x` onto the plane of `(a, b, c)` with unit
/// normal `n` (unclamped: negative outside the triangle).
#[inline]
pub(crate) fn plane_barycentric(
    x: &Vector3<f32>,
    a: &Vector3<f32>,
    b: &Vector3<f32>,
    c: &Vector3<f32>,
    n: &Vector3<f32>,
) -> [f32; 3] {
    let area = (b - a).cross(&(c - a)).dot(n);
    if area.abs() <= f32::MIN_POSITIVE {
        return [1.0 / 3.0; 3];
    }
    let wa = (b - x).cross(&(c - x)).dot(n) / area;
    let wb = (c - x).cross(&(a - x)).dot(n) / area;
    [wa, wb, 1.0 - wa - wb]
}

/// Barycentric coordinates of the point of triangle `(a, b, c)` closest to `x`
/// (Ericson, "Real-Time Collision Detection", 5.1.5).
pub(crate) fn closest_barycentric(
    x: &Vector3<f32>,
    a: &Vector3<f32>,
    b: &Vector3<f32>,
    c: &Vector3<f32>,
) -> [f32; 3] {
    let ab = b - a;
    let ac = c - a;
    let ap = x - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = x - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = safe_div(d1, d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = x - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = safe_div(d2, d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = safe_div(d4 - d3, (d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = va + vb + vc;
    let v = safe_div(vb, denom);
    let w = safe_div(vc, denom);
    [1.0 - v - w, v, w]
}

#[inline]
fn safe_div(a: f32, b: f32) -> f32 {
    let r = a / b;
    if r.is_finite() {
        r.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_regions() {
        let a = Vector3::new(0.0, 0.0, 0.0);
        let b = Vector3::new(1.0, 0.0, 0.0);
        let c = Vector3::new(0.0, 1.0, 0.0);
        let w = closest_barycentric(&Vector3::new(0.25, 0.25, 3.0), &a, &b, &c);
        assert!((w[0] - 0.5).abs() < 1e-6 && (w[1] - 0.25).abs() < 1e-6);
        assert_eq!(
            closest_barycentric(&Vector3::new(-1.0, -1.0, 0.0), &a, &b, &c),
            [1.0, 0.0, 0.0]
        );
        let w = closest_barycentric(&Vector3::new(1.0, 1.0, 0.0), &a, &b, &c);
        assert!((w[1] - 0.5).abs() < 1e-6 && (w[2] - 0.5).abs() < 1e-6);
        let n = triangle_normal(&a, &b, &c).expect("normal");
        let p = plane_barycentric(&Vector3::new(2.0, 0.0, 1.0), &a, &b, &c, &n);
        assert!((p[1] - 2.0).abs() < 1e-6 && (p[0] + 1.0).abs() < 1e-6);
        assert!(triangle_normal(&a, &b, &(b * 2.0)).is_none());
    }

    #[test]
    fn ray_hits_triangle() {
        let a = Vector3::new(0.0, 0.0, 1.0);
        let b = Vector3::new(1.0, 0.0, 1.0);
        let c = Vector3::new(0.0, 1.0, 1.0);
        let z = Vector3::z();
        let t = ray_triangle(&Vector3::new(0.2, 0.2, 0.0), &z, &a, &b, &c);
        assert!((t.expect("hit") - 1.0).abs() < 1e-6);
        assert!(ray_triangle(&Vector3::new(0.8, 0.8, 0.0), &z, &a, &b, &c).is_none());
        assert!(ray_triangle(&Vector3::new(0.2, 0.2, 2.0), &z, &a, &b, &c).is_none());
    }

    #[test]
    fn inside_tetrahedron() {
        let t = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
        ];
        assert!(in_tet(&Vector3::new(0.1, 0.1, 0.1), &t));
        assert!(!in_tet(&Vector3::new(0.5, 0.5, 0.5), &t));
        let flipped = [t[0], t[2], t[1], t[3]];
        assert!(in_tet(&Vector3::new(0.1, 0.1, 0.1), &flipped));
    }
}

#[cfg(test)]
mod bvh_tests {
    use super::*;
    use tetpbd::generators::{self, CellSplit};
    use tetpbd::SoftBodyBuilder;

    /// The refitted triangle BVH finds exactly the triangles a brute-force box test finds,
    /// also after the body moved and deformed.
    #[test]
    fn refit_matches_brute_force() {
        let mesh = generators::box_grid(Vector3::new(2.0, 0.06, 2.0), [8, 1, 8], CellSplit::Six)
            .expect("mesh");
        let body = SoftBodyBuilder::new(mesh).build().expect("body");
        let n = body.particles.len();
        let mut cache = BodyCache::build(&body.surface, &body.tetrahedra, n).expect("cache");
        let mut xs: Vec<Vector3<f32>> = cache
            .vertices
            .iter()
            .map(|&i| body.particles.positions()[i as usize])
            .collect();
        let motion = vec![0.001; xs.len()];
        for round in 0..3 {
            cache.refit_triangles(&xs, &motion);
            for k in 0..40 {
                let q = Vector3::new(-1.0 + 0.05 * k as f32, 0.03 + 0.001 * round as f32, 0.013);
                let r = 0.02;
                let (lo, hi) = (q - Vector3::repeat(r), q + Vector3::repeat(r));
                let aabb = Aabb::new(to_glam(&lo), to_glam(&hi));
                let mut found: Vec<u32> = cache.tri_bvh.intersect_aabb(&aabb).collect();
                found.sort_unstable();
                let brute: Vec<u32> = (0..cache.triangles.len() as u32)
                    .filter(|&t| {
                        let (mut a, mut b) = (Vector3::repeat(f32::MAX), Vector3::repeat(f32::MIN));
                        for &v in &cache.triangles[t as usize] {
                            a = a.inf(&(xs[v as usize] - Vector3::repeat(0.001)));
                            b = b.sup(&(xs[v as usize] + Vector3::repeat(0.001)));
                        }
                        (0..3).all(|i| a[i] <= hi[i] && lo[i] <= b[i])
                    })
                    .collect();
                assert_eq!(found, brute, "round {round}, query {k}");
            }
            for k in 0..40 {
                let q = Vector3::new(-0.9 + 0.045 * k as f32, 0.01 * round as f32, 0.013);
                let t = cache.closest_triangle(&q, &xs);
                assert!(t.is_some(), "round {round}, closest query {k}: none");
            }
            for (j, x) in xs.iter_mut().enumerate() {
                x.y += 0.001 * (j % 7) as f32;
                x.x += 0.01;
            }
        }
    }
}
