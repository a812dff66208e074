//! Cutting a body with a blade, on a user call ([`cut`]).
//!
//! A face shared by two tetrahedra is cut when the segment joining their centroids (at the
//! current positions) crosses the blade: for a [`Blade::Plane`], when the centroids lie on
//! opposite sides of the plane; for a [`Blade::Triangle`], when the segment passes through
//! the triangle. The cut faces split as torn faces do ([`crate::Tearing`]): their particles
//! are duplicated where the cut separates the tetrahedra around them, never a tetrahedron
//! removed, and the body's pieces follow its [`Pieces`] setting.

use hecs::{Entity, World};
use nalgebra::Vector3;

use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::body::pieces::{centroid, split_body, TearEvent};
use crate::body::tearing::{face_key, interior_faces, Pieces, Tearing};
use crate::error::CutError;

/// A blade, in world coordinates (m).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Blade {
    /// The whole plane through `point` with normal `normal` (any non-zero length).
    Plane {
        /// A point of the plane, m.
        point: Vector3<f32>,
        /// Its normal (need not be unit).
        normal: Vector3<f32>,
    },
    /// The triangle with these corners: a bounded blade (a plane segment is two triangles).
    Triangle([Vector3<f32>; 3]),
}

impl Blade {
    /// Checks that the blade is finite and not degenerate.
    pub fn validate(&self) -> Result<(), CutError> {
        let finite = |v: &Vector3<f32>| v.iter().all(|c| c.is_finite());
        match self {
            Blade::Plane { point, normal } => {
                if !(finite(point) && finite(normal)) {
                    return Err(CutError::BadBlade { what: "not finite" });
                }
                if normal.norm_squared() <= 0.0 {
                    return Err(CutError::BadBlade {
                        what: "zero normal",
                    });
                }
            }
            Blade::Triangle(c) => {
                if !c.iter().all(finite) {
                    return Err(CutError::BadBlade { what: "not finite" });
                }
                if (c[1] - c[0]).cross(&(c[2] - c[0])).norm_squared() <= 0.0 {
                    return Err(CutError::BadBlade {
                        what: "flat triangle",
                    });
                }
            }
        }
        Ok(())
    }

    /// Whether the segment `a → b` crosses the blade (strictly: an end on it does not count).
    pub fn crosses(&self, a: &Vector3<f32>, b: &Vector3<f32>) -> bool {
        match self {
            Blade::Plane { point, normal } => {
                let (da, db) = ((a - point).dot(normal), (b - point).dot(normal));
                (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)
            }
            Blade::Triangle([p, q, r]) => {
                let n = (q - p).cross(&(r - p));
                let (da, db) = ((a - p).dot(&n), (b - p).dot(&n));
                if !((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
                    return false;
                }
                // Where the segment meets the plane, inside the triangle (edge functions).
                let x = a + (b - a) * (da / (da - db));
                let inside = |u: &Vector3<f32>, v: &Vector3<f32>| (v - u).cross(&(x - u)).dot(&n);
                let (e0, e1, e2) = (inside(p, q), inside(q, r), inside(r, p));
                (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0)
            }
        }
    }
}

/// Cuts body `entity` with `blade` (module docs); its pieces follow the [`Pieces`] setting of
/// its [`Tearing`] if it has one, else [`Pieces::Split`]. Returns the event, or `None` when the
/// blade crosses no face.
///
/// Errors: [`CutError::BadBlade`], [`CutError::NoSuchBody`].
pub fn cut(
    world: &mut World,
    entity: Entity,
    blade: &Blade,
) -> Result<Option<TearEvent>, CutError> {
    blade.validate()?;
    let (keys, mode) = {
        let mut q = world.query_one::<(&Particles, &Tetrahedra, Option<&Tearing>)>(entity);
        let (p, t, tearing) = q.get().map_err(|_| CutError::NoSuchBody { entity })?;
        let n = p.len() as u32;
        if t.indices.iter().flatten().any(|&i| i >= n) {
            return Err(CutError::NoSuchBody { entity });
        }
        let mode = tearing.map_or(Pieces::Split, |t| t.settings.pieces);
        let mut keys: Vec<[u32; 3]> = Vec::new();
        for f in interior_faces(&t.indices, &p.rest_positions) {
            let (t1, t2) = (
                &t.indices[f.tets[0] as usize],
                &t.indices[f.tets[1] as usize],
            );
            let (c1, c2) = (centroid(t1, &p.positions), centroid(t2, &p.positions));
            if blade.crosses(&c1, &c2) {
                if let Some(o) = t1.iter().position(|&i| i == f.apex[0]) {
                    keys.push(face_key(t1, o));
                }
            }
        }
        keys.sort_unstable();
        keys.dedup();
        (keys, mode)
    };
    if keys.is_empty() {
        return Ok(None);
    }
    split_body(world, entity, &keys, mode)
        .map(Some)
        .ok_or(CutError::NoSuchBody { entity })
}
