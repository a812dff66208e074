//! [`Raster`]: an RGB image with a depth buffer, filled by triangles and lines in camera space.

use nalgebra::Vector3;

use crate::camera::{Camera, ViewPoint};
use crate::error::VizError;

/// Largest image side, pixels.
const MAX_SIDE: u32 = 16384;

/// An RGB colour, 8 bits per channel.
pub type Rgb = [u8; 3];

/// An RGB image and its depth buffer (inverse view depth, 1/m; 0 = nothing drawn).
#[derive(Clone, Debug)]
pub struct Raster {
    width: u32,
    height: u32,
    rgb: Vec<Rgb>,
    inv_depth: Vec<f32>,
}

impl Raster {
    /// A `width × height` image filled with `background`.
    pub fn new(width: u32, height: u32, background: Rgb) -> Result<Raster, VizError> {
        if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
            return Err(VizError::ImageSize { width, height });
        }
        let n = (width * height) as usize;
        Ok(Raster {
            width,
            height,
            rgb: vec![background; n],
            inv_depth: vec![0.0; n],
        })
    }

    /// Width, pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height, pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The colour at pixel (`x`, `y`), `y` down from the top row.
    pub fn pixel(&self, x: u32, y: u32) -> Option<Rgb> {
        (x < self.width && y < self.height).then(|| self.rgb[(y * self.width + x) as usize])
    }

    /// The pixels row by row, 3 bytes each.
    pub fn bytes(&self) -> Vec<u8> {
        self.rgb.iter().flatten().copied().collect()
    }

    /// Copies `src` into this image with its left edge at column `x0` and its top at row 0;
    /// what falls outside is dropped. Depth is not copied.
    pub fn blit(&mut self, src: &Raster, x0: u32) {
        for y in 0..src.height.min(self.height) {
            for x in 0..src.width {
                if x0 + x < self.width {
                    self.rgb[(y * self.width + x0 + x) as usize] =
                        src.rgb[(y * src.width + x) as usize];
                }
            }
        }
    }

    /// Fills the world-space triangle `tri` (m) in `color`, nearer surfaces hiding farther
    /// ones. The part behind the camera's near plane is cut away.
    pub fn triangle(&mut self, camera: &Camera, tri: [Vector3<f32>; 3], color: Rgb) {
        let view = tri.map(|p| camera.view(&p));
        let polygon = clip_near(&view, camera.near);
        if polygon.len() < 3 {
            return;
        }
        let screen: Vec<(f32, f32, f32)> = polygon
            .iter()
            .map(|v| {
                let (x, y) = camera.project(v, self.width, self.height);
                (x, y, 1.0 / v.depth)
            })
            .collect();
        for k in 1..screen.len() - 1 {
            self.fill([screen[0], screen[k], screen[k + 1]], color);
        }
    }

    /// Fills a screen-space triangle of (x, y, 1/depth) corners.
    fn fill(&mut self, s: [(f32, f32, f32); 3], color: Rgb) {
        let edge = |a: (f32, f32, f32), b: (f32, f32, f32), x: f32, y: f32| {
            (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0)
        };
        let area = edge(s[0], s[1], s[2].0, s[2].1);
        if area.abs() < 1e-12 || !area.is_finite() {
            return;
        }
        let (min_x, max_x) = pixel_span([s[0].0, s[1].0, s[2].0], self.width);
        let (min_y, max_y) = pixel_span([s[0].1, s[1].1, s[2].1], self.height);
        if min_x > max_x || min_y > max_y {
            return;
        }
        for py in min_y as u32..=max_y as u32 {
            for px in min_x as u32..=max_x as u32 {
                let (x, y) = (px as f32 + 0.5, py as f32 + 0.5);
                let w0 = edge(s[1], s[2], x, y) / area;
                let w1 = edge(s[2], s[0], x, y) / area;
                let w2 = edge(s[0], s[1], x, y) / area;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let inv = w0 * s[0].2 + w1 * s[1].2 + w2 * s[2].2;
                self.plot(px, py, inv, color);
            }
        }
    }

    /// Draws the world-space segment `a`–`b` (m), one pixel wide, in front of surfaces it
    /// lies on: its depth is pulled towards the camera by the fraction `bias`.
    pub fn line(
        &mut self,
        camera: &Camera,
        a: Vector3<f32>,
        b: Vector3<f32>,
        color: Rgb,
        bias: f32,
    ) {
        let (mut va, mut vb) = (camera.view(&a), camera.view(&b));
        if va.depth < camera.near && vb.depth < camera.near {
            return;
        }
        if va.depth < camera.near {
            va = cut(&vb, &va, camera.near);
        } else if vb.depth < camera.near {
            vb = cut(&va, &vb, camera.near);
        }
        let (ax, ay) = camera.project(&va, self.width, self.height);
        let (bx, by) = camera.project(&vb, self.width, self.height);
        let steps = (bx - ax)
            .abs()
            .max((by - ay).abs())
            .ceil()
            .min(4.0 * MAX_SIDE as f32);
        let n = steps.max(1.0) as u32;
        for k in 0..=n {
            let t = k as f32 / n as f32;
            let (x, y) = (ax + t * (bx - ax), ay + t * (by - ay));
            if x < 0.0 || y < 0.0 || x >= self.width as f32 || y >= self.height as f32 {
                continue;
            }
            let inv = (1.0 - t) / va.depth + t / vb.depth;
            self.plot(x as u32, y as u32, inv * (1.0 + bias), color);
        }
    }

    /// Writes `color` at a pixel if `inv` (1/depth) is nearer than what is there.
    fn plot(&mut self, x: u32, y: u32, inv: f32, color: Rgb) {
        let i = (y * self.width + x) as usize;
        if inv > self.inv_depth[i] {
            self.inv_depth[i] = inv;
            self.rgb[i] = color;
        }
    }
}

/// First and last pixel index (as floats) a triangle with corner coordinates `c` can touch on
/// an axis of `size` pixels; first > last when it is off the image.
fn pixel_span(c: [f32; 3], size: u32) -> (f32, f32) {
    let lo = c[0].min(c[1]).min(c[2]).floor().max(0.0);
    let hi = c[0].max(c[1]).max(c[2]).ceil().min(size as f32 - 1.0);
    (lo, hi)
}

/// The point of segment `inside`–`outside` on the plane `depth = near`.
fn cut(inside: &ViewPoint, outside: &ViewPoint, near: f32) -> ViewPoint {
    let t = (inside.depth - near) / (inside.depth - outside.depth);
    ViewPoint {
        x: inside.x + t * (outside.x - inside.x),
        y: inside.y + t * (outside.y - inside.y),
        depth: near,
    }
}

/// The part of the triangle with `depth ≥ near` (Sutherland–Hodgman against one plane).
fn clip_near(tri: &[ViewPoint; 3], near: f32) -> Vec<ViewPoint> {
    let mut out = Vec::with_capacity(4);
    for k in 0..3 {
        let (a, b) = (&tri[k], &tri[(k + 1) % 3]);
        let (a_in, b_in) = (a.depth >= near, b.depth >= near);
        if a_in {
            out.push(*a);
        }
        if a_in != b_in {
            out.push(if a_in {
                cut(a, b, near)
            } else {
                cut(b, a, near)
            });
        }
    }
    out
}
