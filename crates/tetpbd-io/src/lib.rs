//! Mesh files in and frames out for [`tetpbd`] soft bodies.
//!
//! * In: TetGen `.node`/`.ele` ([`read_tetgen_str`], [`read_tetgen_files`]) and Gmsh `.msh`
//!   4.1 or 2.2 ASCII and 4.1 binary ([`read_msh_str`], [`read_msh_bytes`],
//!   [`read_msh_file`]) into a [`tetpbd::TetMesh`]. Malformed input gives a [`ReadError`]
//!   naming the file kind and line (byte offset in binary data); the readers never panic.
//! * Out: surfaces as Wavefront OBJ ([`surface_obj`], [`triangles_obj`]) and tetrahedra as
//!   VTK unstructured grids ([`tetrahedra_vtu`]) with per-tetrahedron `volume_ratio` and
//!   `inverted` cell data; and meshes back as TetGen or Gmsh text ([`write_tetgen`],
//!   [`write_msh`]).
//! * [`drop_unreferenced_vertices`] removes vertices no tetrahedron uses (Gmsh files often
//!   hold surface or geometry nodes), which [`tetpbd::SoftBodyBuilder`] would reject.
//! * Surface meshes in (feature `mesher`, on by default; it brings `parry3d` and `tobj`): a
//!   closed triangle [`SurfaceMesh`] from an OBJ file or arrays is filled with tetrahedra by parry's `volume_mesh` ([`TetrahedralizeBuilder`],
//!   cell size in m), and a fine render mesh is embedded in the tetrahedra and moved with
//!   them ([`Skin`], barycentric skinning). Errors are [`SurfaceError`] and [`SkinError`].
//!   [`shapes`] generates the sample assets under `examples/assets/`.
//! * The `tet_export` binary reads a `.msh` or `.node`/`.ele` mesh, hangs it from its highest
//!   vertices under gravity and writes each frame as OBJ and VTU:
//!   `cargo run -p tetpbd-io --features cli --bin tet_export -- mesh.node out/ --frames 60`.
//!
//! ```
//! use tetpbd::SoftBodyBuilder;
//! use tetpbd_io::{read_tetgen_str, surface_obj, tetrahedra_vtu};
//!
//! let node = "# one tetrahedron, numbered from 1\n4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
//! let ele = "1 4 0\n1 1 2 3 4\n";
//! let mesh = read_tetgen_str(node, ele)?;
//! assert_eq!(mesh.tets, vec![[0, 1, 2, 3]]);
//!
//! let body = SoftBodyBuilder::new(mesh).density(1000.0).edges(0.0).build()?;
//! let obj = surface_obj(&body.surface, body.particles.positions())?;
//! assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), 4);
//! let vtu = tetrahedra_vtu(&body.particles, &body.tetrahedra)?;
//! assert!(vtu.contains("NumberOfCells=\"1\""));
//!
//! let err = read_tetgen_str(node, "1 4 0\n1 1 2 3 9\n").unwrap_err();
//! assert_eq!(err.to_string(), ".ele line 2: vertex 9 does not exist (4 vertices)");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod compact;
mod error;
#[cfg(feature = "mesher")]
mod glam;
mod gmsh;
mod gmsh22;
mod gmsh_binary;
#[cfg(feature = "mesher")]
mod mesher_error;
mod obj;
#[cfg(feature = "mesher")]
pub mod shapes;
#[cfg(feature = "mesher")]
mod skin;
mod skin_follow;
#[cfg(feature = "mesher")]
mod surface;
mod tetgen;
#[cfg(feature = "mesher")]
mod tetrahedralize;
mod text;
mod vtu;

pub use compact::drop_unreferenced_vertices;
pub use error::{FileKind, ReadError, WriteError};
pub use gmsh::{read_msh_bytes, read_msh_file, read_msh_str, write_msh};
#[cfg(feature = "mesher")]
pub use mesher_error::{SkinError, SurfaceError};
pub use obj::{surface_obj, triangles_obj, write_surface_obj};
#[cfg(feature = "mesher")]
pub use skin::{Skin, SkinBinding};
pub use skin_follow::PieceSkin;
#[cfg(feature = "mesher")]
pub use surface::SurfaceMesh;
pub use tetgen::{read_tetgen_files, read_tetgen_str, write_tetgen};
#[cfg(feature = "mesher")]
pub use tetrahedralize::TetrahedralizeBuilder;
pub use vtu::{tetrahedra_vtu, write_tetrahedra_vtu};
