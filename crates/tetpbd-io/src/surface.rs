//! Closed triangle surfaces: from arrays or OBJ files, welded and checked before they are
//! filled with tetrahedra.

use std::path::Path;

use nalgebra::Vector3;

use crate::mesher_error::SurfaceError;

/// A triangle surface: vertex positions (m) and triangles as vertex indices.
///
/// [`SurfaceMesh::new`] only checks that the arrays are usable (non-empty, finite, indices in
/// range, no triangle repeating a vertex); [`SurfaceMesh::closed`] also welds equal positions
/// and checks that the surface bounds a solid, which tetrahedralization needs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceMesh {
    /// Vertex positions, m.
    pub vertices: Vec<Vector3<f32>>,
    /// Triangles, three vertex indices each.
    pub triangles: Vec<[u32; 3]>,
}

impl SurfaceMesh {
    /// Checks and wraps vertex and index arrays.
    ///
    /// Errors: [`SurfaceError::Empty`], [`SurfaceError::NonFinite`] (names the vertex),
    /// [`SurfaceError::IndexOutOfRange`] (names the triangle and index),
    /// [`SurfaceError::DegenerateTriangle`].
    pub fn new(
        vertices: Vec<Vector3<f32>>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<SurfaceMesh, SurfaceError> {
        if vertices.is_empty() || triangles.is_empty() {
            return Err(SurfaceError::Empty {
                vertices: vertices.len(),
                triangles: triangles.len(),
            });
        }
        for (vertex, v) in vertices.iter().enumerate() {
            if let Some(&value) = v.iter().find(|c| !c.is_finite()) {
                return Err(SurfaceError::NonFinite { vertex, value });
            }
        }
        for (triangle, tri) in triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertices.len()) {
                return Err(SurfaceError::IndexOutOfRange {
                    triangle,
                    index,
                    vertex_count: vertices.len(),
                });
            }
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                return Err(SurfaceError::DegenerateTriangle { triangle });
            }
        }
        Ok(SurfaceMesh {
            vertices,
            triangles,
        })
    }

    /// Reads the triangles of every object in OBJ text (polygons are fanned into triangles;
    /// points, lines, normals, texture coordinates, colours and materials are ignored).
    ///
    /// Only the `v` (first three coordinates), `f` (vertex indices, 1-based or negative
    /// relative) and `o`/`g` lines reach `tobj`: its texture-coordinate and normal paths can
    /// panic on crafted indices (found by the fuzz test), and a surface needs neither.
    pub fn from_obj_str(text: &str) -> Result<SurfaceMesh, SurfaceError> {
        let text = positions_and_faces(text);
        let options = tobj::LoadOptions {
            triangulate: true,
            ignore_points: true,
            ignore_lines: true,
            ..tobj::LoadOptions::default()
        };
        let mut reader = std::io::BufReader::new(text.as_bytes());
        let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(SurfaceError::Obj)?;
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for model in &models {
            let mesh = &model.mesh;
            let base = vertices.len() as u32;
            vertices.extend(
                mesh.positions
                    .chunks_exact(3)
                    .map(|p| Vector3::new(p[0], p[1], p[2])),
            );
            triangles.extend(
                mesh.indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]].map(|i| base.saturating_add(i))),
            );
        }
        SurfaceMesh::new(vertices, triangles)
    }

    /// Reads an OBJ file (see [`SurfaceMesh::from_obj_str`]).
    pub fn read_obj(path: impl AsRef<Path>) -> Result<SurfaceMesh, SurfaceError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| SurfaceError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        SurfaceMesh::from_obj_str(&String::from_utf8_lossy(&bytes))
    }

    /// Volume enclosed by the triangles (divergence theorem), m³: positive when they are
    /// wound outward (counter-clockwise seen from outside), negative when inward. Only
    /// meaningful for a closed surface. Triangles naming a missing vertex are skipped (the
    /// fields are public; [`SurfaceMesh::new`] rejects them).
    pub fn enclosed_volume(&self) -> f32 {
        let corner = |i: u32| self.vertices.get(i as usize).map(|v| v.cast::<f64>());
        let sum: f64 = self
            .triangles
            .iter()
            .filter_map(|t| Some((corner(t[0])?, corner(t[1])?, corner(t[2])?)))
            .map(|(a, b, c)| a.dot(&b.cross(&c)))
            .sum();
        (sum / 6.0) as f32
    }

    /// The surface with equal positions welded into one vertex (first occurrence kept,
    /// order preserved), checked to be closed, manifold and consistently wound, and
    /// wound outward (all triangles flipped if it was wound inward).
    ///
    /// Errors: those of [`SurfaceMesh::new`], then [`SurfaceError::OpenEdge`],
    /// [`SurfaceError::NonManifoldEdge`], [`SurfaceError::InconsistentOrientation`] (edges
    /// named by welded vertex indices), [`SurfaceError::ZeroVolume`].
    pub fn closed(&self) -> Result<SurfaceMesh, SurfaceError> {
        let checked = SurfaceMesh::new(self.vertices.clone(), self.triangles.clone())?;
        let (vertices, remap) = weld(&checked.vertices);
        let triangles: Vec<[u32; 3]> = checked
            .triangles
            .iter()
            .map(|t| t.map(|i| remap[i as usize]))
            .collect();
        let mut welded = SurfaceMesh::new(vertices, triangles)?;
        check_closed(&welded.triangles)?;
        let volume = welded.enclosed_volume();
        if volume == 0.0 || !volume.is_finite() {
            return Err(SurfaceError::ZeroVolume);
        }
        if volume < 0.0 {
            for t in &mut welded.triangles {
                t.swap(1, 2);
            }
        }
        Ok(welded)
    }
}

/// The `v`, `f` and `o`/`g` lines of OBJ text, with `v` cut to its three coordinates and
/// each face corner cut to its vertex index.
fn positions_and_faces(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                out.push('v');
                for t in tokens.take(3) {
                    out.push(' ');
                    out.push_str(t);
                }
            }
            Some("f") => {
                out.push('f');
                for t in tokens {
                    out.push(' ');
                    out.push_str(t.split('/').next().unwrap_or(t));
                }
            }
            Some(k @ ("o" | "g")) => {
                out.push_str(k);
                for t in tokens {
                    out.push(' ');
                    out.push_str(t);
                }
            }
            _ => continue,
        }
        out.push('\n');
    }
    out
}

/// Welds exactly equal positions (`-0.0` equals `0.0`): the kept vertices in order of first
/// occurrence, and for each input vertex its new index. Deterministic (sorting, no hashing).
fn weld(vertices: &[Vector3<f32>]) -> (Vec<Vector3<f32>>, Vec<u32>) {
    let key = |v: &Vector3<f32>| v.map(|c| (c + 0.0).to_bits());
    let mut order: Vec<u32> = (0..vertices.len() as u32).collect();
    order.sort_by_key(|&i| {
        let k = key(&vertices[i as usize]);
        (k.x, k.y, k.z, i)
    });
    // Each vertex points at the first (lowest-index) vertex of its equal run.
    let mut first = vec![0u32; vertices.len()];
    let mut start = 0;
    for k in 0..order.len() {
        if key(&vertices[order[k] as usize]) != key(&vertices[order[start] as usize]) {
            start = k;
        }
        first[order[k] as usize] = order[start];
    }
    let mut new_index = vec![u32::MAX; vertices.len()];
    let mut kept = Vec::new();
    let mut remap = Vec::with_capacity(vertices.len());
    for (i, &f) in first.iter().enumerate() {
        if f as usize == i {
            new_index[i] = kept.len() as u32;
            kept.push(vertices[i]);
        }
        remap.push(new_index[f as usize]);
    }
    (kept, remap)
}

/// Every undirected edge must be used by exactly two triangles, once in each direction.
fn check_closed(triangles: &[[u32; 3]]) -> Result<(), SurfaceError> {
    // (sorted edge, direction flag): flag 0 when the triangle runs low → high.
    let mut edges: Vec<([u32; 2], u8)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .map(|(a, b)| if a < b { ([a, b], 0) } else { ([b, a], 1) })
        .collect();
    edges.sort_unstable();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        let [a, b] = edges[i].0;
        match j - i {
            1 => return Err(SurfaceError::OpenEdge { a, b }),
            2 if edges[i].1 == edges[i + 1].1 => {
                return Err(SurfaceError::InconsistentOrientation { a, b })
            }
            2 => {}
            n => return Err(SurfaceError::NonManifoldEdge { a, b, triangles: n }),
        }
        i = j;
    }
    Ok(())
}
