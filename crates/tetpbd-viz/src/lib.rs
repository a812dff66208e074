//! Frames out of the tetpbd examples: files, pictures and progress.
//!
//! * [`FrameExport`]: every frame's soft surfaces and rigid colliders as OBJ and the
//!   tetrahedra as VTU with per-tetrahedron volume ratio and inverted flag (the writers of
//!   [`tetpbd_io`]); collider shapes become triangles through parry's tessellations
//!   ([`shape_mesh()`]).
//! * Headless pictures without a GPU: [`Raster`] (z-buffered triangles and lines over an RGB
//!   buffer), [`Camera`] (look-at, perspective), [`View`] (a camera and a ground grid fitted to
//!   a run, flat Lambert shading), written as PNG, frame strips or animated PNG ([`write_png`],
//!   [`strip`]).
//! * [`Viz`]: the outputs an example's `--export DIR`, `--render DIR`, `--strip FILE`,
//!   `--animate FILE` options (or `TETPBD_EXPORT`, … variables) ask for, fed one frame at a
//!   time; [`VizOptions`] is those options as a [`clap::Args`] group that each example
//!   flattens into its own command line.
//! * [`Progress`]: a progress bar on a terminal, plain periodic lines otherwise (CI).
//!
//! ```
//! use tetpbd::generators::{box_grid, CellSplit};
//! use tetpbd::nalgebra::Vector3;
//! use tetpbd::SoftBodyBuilder;
//! use tetpbd_viz::{RenderSettings, Snapshot, View};
//!
//! let mut world = tetpbd::hecs::World::new();
//! let mesh = box_grid(Vector3::repeat(1.0), [2, 2, 2], CellSplit::Six)?;
//! SoftBodyBuilder::new(mesh).edges(0.0).build()?.spawn(&mut world);
//! let snapshot = Snapshot::capture(&world);
//! let settings = RenderSettings { width: 64, height: 48, ..Default::default() };
//! let picture = View::fit(&[&snapshot], &settings).render(&snapshot, &settings)?;
//! // The cube is in the middle of the picture, the sky in the top corner.
//! assert_ne!(picture.pixel(32, 24), Some(settings.background));
//! assert_eq!(picture.pixel(0, 0), Some(settings.background));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod camera;
mod error;
mod export;
mod mesh;
mod options;
mod png_out;
mod progress;
mod raster;
mod render;
mod session;
mod shape_mesh;
mod snapshot;

pub use camera::{Camera, ViewPoint};
pub use error::VizError;
pub use export::FrameExport;
pub use mesh::TriangleMesh;
pub use options::VizOptions;
pub use png_out::{strip, write_png};
pub use progress::Progress;
pub use raster::{Raster, Rgb};
pub use render::{Ground, RenderSettings, View};
pub use session::Viz;
pub use shape_mesh::shape_mesh;
pub use snapshot::{Item, ItemKind, SceneView, Snapshot};
