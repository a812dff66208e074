//! [`Camera`]: a look-at perspective camera.

use nalgebra::Vector3;

/// A perspective camera looking from `eye` at `target`, y up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Position, m.
    pub eye: Vector3<f32>,
    /// The point at the image centre, m.
    pub target: Vector3<f32>,
    /// Vertical field of view, radians.
    pub fov_y: f32,
    /// Distance of the near clipping plane, m: geometry closer than this is cut away.
    pub near: f32,
}

/// A point in the camera's frame: `x` right, `y` up, `depth` along the view direction (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewPoint {
    /// Right, m.
    pub x: f32,
    /// Up, m.
    pub y: f32,
    /// Distance in front of the eye along the view direction, m.
    pub depth: f32,
}

impl Camera {
    /// A camera looking at the box `lo`–`hi` (m) from the direction `from` (eye minus target,
    /// any length), far enough back that the box's bounding sphere fits the view.
    pub fn framing(lo: Vector3<f32>, hi: Vector3<f32>, from: Vector3<f32>, fov_y: f32) -> Camera {
        let target = 0.5 * (lo + hi);
        let radius = (0.5 * (hi - lo).norm()).max(1e-3);
        let distance = radius / (0.5 * fov_y).sin();
        let dir = from.try_normalize(1e-12).unwrap_or_else(Vector3::z);
        Camera {
            eye: target + dir * distance,
            target,
            fov_y,
            near: 0.01 * distance,
        }
    }

    /// Right, up and backward unit vectors of the camera frame.
    fn basis(&self) -> (Vector3<f32>, Vector3<f32>, Vector3<f32>) {
        let back = (self.eye - self.target)
            .try_normalize(1e-12)
            .unwrap_or_else(Vector3::z);
        let up_hint = if back.y.abs() > 0.999 {
            Vector3::z()
        } else {
            Vector3::y()
        };
        let right = up_hint.cross(&back).normalize();
        (right, back.cross(&right), back)
    }

    /// `p` (world, m) in the camera frame.
    pub fn view(&self, p: &Vector3<f32>) -> ViewPoint {
        let (right, up, back) = self.basis();
        let d = p - self.eye;
        ViewPoint {
            x: d.dot(&right),
            y: d.dot(&up),
            depth: -d.dot(&back),
        }
    }

    /// Pixel coordinates (x right, y down, pixel centres at +0.5) of a view point in front of
    /// the near plane on a `width × height` image.
    pub fn project(&self, v: &ViewPoint, width: u32, height: u32) -> (f32, f32) {
        let f = 0.5 * height as f32 / (0.5 * self.fov_y).tan();
        (
            0.5 * width as f32 + f * v.x / v.depth,
            0.5 * height as f32 - f * v.y / v.depth,
        )
    }
}
