//! Headless pictures of [`Snapshot`]s: flat Lambert-shaded triangles over a ground grid,
//! seen by a [`Camera`] fixed for a whole run.

use nalgebra::Vector3;

use crate::camera::Camera;
use crate::error::VizError;
use crate::raster::{Raster, Rgb};
use crate::snapshot::{ItemKind, Snapshot};

/// Colours of the soft bodies, cycled in snapshot order.
const SOFT_COLORS: [Rgb; 4] = [
    [230, 120, 50],
    [200, 70, 80],
    [235, 180, 50],
    [170, 90, 190],
];
/// Colour of fixed colliders.
const FIXED_COLOR: Rgb = [150, 150, 150];
/// Colours of dynamic rigid bodies, cycled in snapshot order.
const DYNAMIC_COLORS: [Rgb; 3] = [[70, 110, 185], [95, 140, 205], [55, 90, 160]];
/// Colour of kinematic rigid bodies.
const KINEMATIC_COLOR: Rgb = [80, 160, 90];
/// Colour of the ground plane drawn when no fixed collider is the ground.
const GROUND_COLOR: Rgb = [205, 205, 198];
/// Colour of the ground grid lines.
const GRID_COLOR: Rgb = [110, 110, 110];
/// Fraction of light every surface gets whatever its orientation.
const AMBIENT: f32 = 0.35;

/// Size, background and viewing direction of rendered frames.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Background colour.
    pub background: Rgb,
    /// Direction from the scene's centre to the eye (any length).
    pub view_from: Vector3<f32>,
    /// Vertical field of view, radians.
    pub fov_y: f32,
    /// Direction towards the light (any length).
    pub light: Vector3<f32>,
}

impl Default for RenderSettings {
    /// 320 × 240 pixels, seen from the front right and above, 40° field of view.
    fn default() -> Self {
        RenderSettings {
            width: 320,
            height: 240,
            background: [236, 241, 246],
            view_from: Vector3::new(0.9, 0.7, 1.6),
            fov_y: 40f32.to_radians(),
            light: Vector3::new(0.4, 1.0, 0.6),
        }
    }
}

/// The ground under a scene: a grid at height `y`, on a plane of its own unless a fixed
/// collider already is the ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ground {
    /// Height, m.
    pub y: f32,
    /// Centre of the grid, (x, z), m.
    pub center: (f32, f32),
    /// Half the side of the grid, m.
    pub half: f32,
    /// Grid spacing, m.
    pub cell: f32,
    /// Whether to draw the plane under the grid.
    pub fill: bool,
}

/// A camera and a ground, fixed for every frame of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// The camera.
    pub camera: Camera,
    /// The ground grid.
    pub ground: Ground,
}

/// 1, 2 or 5 times a power of ten, the smallest such at least `x` (> 0).
fn nice_step(x: f32) -> f32 {
    let p = 10f32.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= x)
        .unwrap_or(10.0 * p)
}

impl View {
    /// A view of everything that moves in `snapshots` (soft bodies, dynamic and kinematic
    /// colliders; fixed colliders count only when nothing else is there), over all of them,
    /// so the camera stays put for the run. The ground is the top of a fixed collider under
    /// the scene's centre when there is one, else a plane under the lowest point.
    pub fn fit(snapshots: &[&Snapshot], settings: &RenderSettings) -> View {
        let moving = |k: ItemKind| k != ItemKind::Fixed;
        let union = |keep: &dyn Fn(ItemKind) -> bool| {
            snapshots
                .iter()
                .flat_map(|s| s.items.iter())
                .filter(|i| keep(i.kind))
                .filter_map(|i| i.mesh.aabb())
                .reduce(|(a, b), (c, d)| (a.inf(&c), b.sup(&d)))
        };
        let (lo, hi) = union(&moving)
            .or_else(|| union(&|_| true))
            .unwrap_or((Vector3::repeat(-0.5), Vector3::repeat(0.5)));
        let (cx, cz) = (0.5 * (lo.x + hi.x), 0.5 * (lo.z + hi.z));
        let size = (hi - lo).norm().max(1e-3);
        let ground_top = snapshots
            .iter()
            .flat_map(|s| s.items.iter())
            .filter(|i| i.kind == ItemKind::Fixed)
            .filter_map(|i| i.mesh.aabb())
            .filter(|(a, b)| {
                a.x <= cx && cx <= b.x && a.z <= cz && cz <= b.z && b.y <= lo.y + 0.05 * size
            })
            .map(|(_, b)| b.y)
            .reduce(f32::max);
        let half = 0.5 * (hi.x - lo.x).max(hi.z - lo.z) + 0.5 * size;
        let ground = Ground {
            y: ground_top.unwrap_or(lo.y),
            center: (cx, cz),
            half,
            cell: nice_step(half / 5.0),
            fill: ground_top.is_none(),
        };
        let lo = Vector3::new(lo.x, lo.y.min(ground.y), lo.z);
        View {
            camera: Camera::framing(lo, hi, settings.view_from, settings.fov_y),
            ground,
        }
    }

    /// `snapshot` drawn from this view.
    pub fn render(
        &self,
        snapshot: &Snapshot,
        settings: &RenderSettings,
    ) -> Result<Raster, VizError> {
        let mut raster = Raster::new(settings.width, settings.height, settings.background)?;
        let light = settings
            .light
            .try_normalize(1e-12)
            .unwrap_or_else(Vector3::y);
        let g = self.ground;
        let (x0, x1) = (g.center.0 - g.half, g.center.0 + g.half);
        let (z0, z1) = (g.center.1 - g.half, g.center.1 + g.half);
        if g.fill {
            let c = |x, z| Vector3::new(x, g.y, z);
            let color = shade(GROUND_COLOR, &Vector3::y(), &light);
            raster.triangle(&self.camera, [c(x0, z0), c(x1, z1), c(x1, z0)], color);
            raster.triangle(&self.camera, [c(x0, z0), c(x0, z1), c(x1, z1)], color);
        }
        let (mut soft, mut dynamic) = (0, 0);
        for item in &snapshot.items {
            let base = match item.kind {
                ItemKind::Soft => {
                    soft += 1;
                    SOFT_COLORS[(soft - 1) % SOFT_COLORS.len()]
                }
                ItemKind::Fixed => FIXED_COLOR,
                ItemKind::Dynamic => {
                    dynamic += 1;
                    DYNAMIC_COLORS[(dynamic - 1) % DYNAMIC_COLORS.len()]
                }
                ItemKind::Kinematic => KINEMATIC_COLOR,
            };
            let p = &item.mesh.positions;
            for t in &item.mesh.triangles {
                let Some(tri) = t
                    .iter()
                    .map(|&i| p.get(i as usize).copied())
                    .collect::<Option<Vec<_>>>()
                else {
                    continue;
                };
                let tri = [tri[0], tri[1], tri[2]];
                let normal = (tri[1] - tri[0]).cross(&(tri[2] - tri[0]));
                raster.triangle(&self.camera, tri, shade(base, &normal, &light));
            }
        }
        let lines = (2.0 * g.half / g.cell).round() as i32;
        for k in 0..=lines {
            let s = -g.half + k as f32 * g.cell;
            let (x, z) = (g.center.0 + s, g.center.1 + s);
            let bias = 2e-3;
            raster.line(
                &self.camera,
                Vector3::new(x, g.y, z0),
                Vector3::new(x, g.y, z1),
                GRID_COLOR,
                bias,
            );
            raster.line(
                &self.camera,
                Vector3::new(x0, g.y, z),
                Vector3::new(x1, g.y, z),
                GRID_COLOR,
                bias,
            );
        }
        Ok(raster)
    }
}

/// `base` lit by a directional light from `light` (unit) on a face with `normal` (any
/// length), both sides lit alike.
fn shade(base: Rgb, normal: &Vector3<f32>, light: &Vector3<f32>) -> Rgb {
    let lambert = normal
        .try_normalize(1e-20)
        .map_or(0.0, |n| n.dot(light).abs());
    let k = AMBIENT + (1.0 - AMBIENT) * lambert;
    base.map(|c| (c as f32 * k).round().clamp(0.0, 255.0) as u8)
}
