//! [`FrameExport`]: every frame of a scene as files for ParaView or Blender.

use std::path::{Path, PathBuf};

use tetpbd::{Particles, Tetrahedra};
use tetpbd_io::{triangles_obj, write_tetrahedra_vtu};

use crate::error::VizError;
use crate::snapshot::{SceneView, Snapshot};

/// Writes frames into a folder:
///
/// * `<name>_<frame>.obj` for every item of the frame's [`Snapshot`] (soft surfaces
///   `soft<entity id>`, colliders `rigid<collider index>`), world coordinates, m;
/// * `soft<entity id>_<frame>.vtu` for every soft body with [`Tetrahedra`], with per-tetrahedron
///   `volume_ratio` and `inverted` cell data ([`tetpbd_io::tetrahedra_vtu`]).
///
/// Frame numbers have four digits (`_0000`), so ParaView opens each name as a time series.
#[derive(Debug)]
pub struct FrameExport {
    dir: PathBuf,
    frame: u32,
}

impl FrameExport {
    /// Creates the folder `dir` (and its parents) if needed.
    pub fn new(dir: impl Into<PathBuf>) -> Result<Self, VizError> {
        let dir = dir.into();
        std::fs::create_dir_all(&dir).map_err(|source| VizError::Io {
            path: dir.clone(),
            source,
        })?;
        Ok(FrameExport { dir, frame: 0 })
    }

    /// The folder written to.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Frames written so far.
    pub fn frames(&self) -> u32 {
        self.frame
    }

    /// Writes the next frame of `scene`, whose triangles are `snapshot` (taken by the caller
    /// with [`Snapshot::capture`], so a renderer can share it).
    pub fn write(&mut self, scene: &dyn SceneView, snapshot: &Snapshot) -> Result<(), VizError> {
        let frame = self.frame;
        for item in &snapshot.items {
            let path = self.dir.join(format!("{}_{frame:04}.obj", item.name));
            let text =
                triangles_obj(&item.mesh.positions, &item.mesh.triangles).map_err(|source| {
                    VizError::Write {
                        path: path.clone(),
                        source,
                    }
                })?;
            std::fs::write(&path, text).map_err(|source| VizError::Io { path, source })?;
        }
        let mut soft = scene
            .soft()
            .query::<(hecs::Entity, &Particles, &Tetrahedra)>();
        for (entity, particles, tets) in soft.iter() {
            let path = self.dir.join(format!("soft{}_{frame:04}.vtu", entity.id()));
            write_tetrahedra_vtu(&path, particles, tets)
                .map_err(|source| VizError::Write { path, source })?;
        }
        self.frame += 1;
        Ok(())
    }
}
