//! Observables of the contact scenes, computed the same way from either engine's particle
//! positions: ground penetration, interpenetration of the bodies, volume error, speed.

use std::error::Error;

use nalgebra::Vector3;
use rapier3d::parry::query::PointQuery;
use rapier3d::parry::shape::Triangle;
use tetpbd::constraint::signed_volume;

use crate::contact_scene::ContactScene;
use crate::contact_sim::ContactSim;
use crate::rapier_setup::to_rapier;
use crate::DT;

/// Largest particle speed below which a scene counts as settled, m/s.
pub const SETTLED_SPEED: f32 = 0.02;

/// Frames between two interpenetration evaluations in the resting phase (the last frame is
/// always evaluated).
const INTERPENETRATION_EVERY: usize = 10;

/// Observables of one frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct ContactObservables {
    /// Depth of the lowest particle below the ground's top face (y = 0), m; 0 when none is
    /// below.
    pub ground_penetration: f32,
    /// Largest |total volume / rest volume − 1| over the bodies, %.
    pub volume_err_pct: f32,
    /// Largest particle speed over the frame (displacement since the previous frame / dt),
    /// m/s.
    pub max_speed: f32,
    /// Inverted tetrahedra over all bodies.
    pub inverted: usize,
}

/// Evaluates the observables of `x` (positions per body) after a frame that started at
/// `prev`.
pub fn observe_contact(
    scene: &ContactScene,
    x: &[Vec<Vector3<f32>>],
    prev: &[Vec<Vector3<f32>>],
) -> ContactObservables {
    let mut o = ContactObservables::default();
    for (b, xb) in x.iter().enumerate() {
        let (mut v, mut v0) = (0.0f64, 0.0f64);
        for t in &scene.cube.tets {
            let rest = tet_volume(t, &scene.cube.vertices);
            let now = tet_volume(t, xb);
            v += f64::from(now * rest.signum());
            v0 += f64::from(rest.abs());
            if now * rest <= 0.0 {
                o.inverted += 1;
            }
        }
        o.volume_err_pct = o.volume_err_pct.max(((v / v0 - 1.0).abs() * 100.0) as f32);
        for (i, p) in xb.iter().enumerate() {
            o.ground_penetration = o.ground_penetration.max(-p.y);
            if let Some(q) = prev.get(b).and_then(|pb| pb.get(i)) {
                o.max_speed = o.max_speed.max((p - q).norm() / DT);
            }
        }
    }
    o
}

fn tet_volume(t: &[u32; 4], x: &[Vector3<f32>]) -> f32 {
    let [a, b, c, d] = t.map(|i| x[i as usize]);
    signed_volume(&a, &b, &c, &d)
}

fn aabb(x: &[Vector3<f32>]) -> (Vector3<f32>, Vector3<f32>) {
    x.iter().fold(
        (
            Vector3::repeat(f32::INFINITY),
            Vector3::repeat(f32::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    )
}

/// Largest depth of a surface particle of one body inside another body, m: for every surface
/// vertex of body A inside a tetrahedron of body B, its distance to B's boundary surface.
pub fn interpenetration(scene: &ContactScene, x: &[Vec<Vector3<f32>>]) -> f32 {
    let boxes: Vec<_> = x.iter().map(|b| aabb(b)).collect();
    let tri = scene.surface.triangles();
    let mut worst = 0.0f32;
    for (a, xa) in x.iter().enumerate() {
        for (b, xb) in x.iter().enumerate() {
            let ((la, ha), (lb, hb)) = (boxes[a], boxes[b]);
            if a == b || !(0..3).all(|k| la[k] <= hb[k] && lb[k] <= ha[k]) {
                continue;
            }
            for &v in scene.surface.vertices() {
                let p = xa[v as usize];
                if !(0..3).all(|k| lb[k] <= p[k] && p[k] <= hb[k]) || !inside(scene, xb, &p) {
                    continue;
                }
                let depth = tri
                    .iter()
                    .map(|t| {
                        let [u, v, w] = t.map(|i| to_rapier(&xb[i as usize]));
                        Triangle::new(u, v, w).distance_to_local_point(to_rapier(&p), true)
                    })
                    .fold(f32::INFINITY, f32::min);
                worst = worst.max(depth);
            }
        }
    }
    worst
}

/// `p` lies inside one of the tetrahedra of the body at `x` or on its boundary (a point on a
/// face shared by two tetrahedra belongs to both).
fn inside(scene: &ContactScene, x: &[Vector3<f32>], p: &Vector3<f32>) -> bool {
    scene.cube.tets.iter().any(|t| {
        let [a, b, c, d] = t.map(|i| x[i as usize]);
        let v = signed_volume(&a, &b, &c, &d);
        let parts = [
            signed_volume(p, &b, &c, &d),
            signed_volume(&a, p, &c, &d),
            signed_volume(&a, &b, p, &d),
            signed_volume(&a, &b, &c, p),
        ];
        v != 0.0 && parts.iter().all(|s| s * v.signum() >= 0.0)
    })
}

/// What one run of a contact scene gave.
#[derive(Clone, Debug, Default)]
pub struct ContactResult {
    /// Median wall ms per frame over the resting phase.
    pub ms_median: f64,
    /// Median thread CPU ms per frame over the same frames.
    pub cpu_ms_median: f64,
    /// Wall ms of every frame of the resting phase, sorted.
    pub frame_ms: Vec<f64>,
    /// Thread CPU ms of every frame of the resting phase, sorted.
    pub frame_cpu_ms: Vec<f64>,
    /// Median wall ms per frame over the whole run (falling and landing included).
    pub ms_median_all: f64,
    /// Largest particle speed over the last 30 frames, m/s.
    pub settled_speed: f32,
    /// First time after which the largest particle speed stays below [`SETTLED_SPEED`], s.
    pub settle_s: Option<f32>,
    /// Largest ground penetration over the resting phase, m.
    pub rest_penetration: f32,
    /// Largest ground penetration over the whole run, m.
    pub peak_penetration: f32,
    /// Height of the lowest particle after the last frame, m (the gap a contact skin keeps
    /// above the ground when positive).
    pub rest_min_y: f32,
    /// Largest interpenetration of two bodies over the resting phase (every
    /// `INTERPENETRATION_EVERY` frames and the last), m; None for one body.
    pub interpenetration: Option<f32>,
    /// Largest volume error of a body over the resting phase, %.
    pub rest_volume_err_pct: f32,
    /// Most inverted tetrahedra in any frame.
    pub max_inverted: usize,
    /// `false` when a position became non-finite.
    pub finite: bool,
    /// The body holding the fastest particle over the last frame: its index in placement
    /// order, that particle's speed (m/s) and the body's centre (mean particle position, m).
    /// Says which body keeps a run from coming to rest and where it is (on the ground, on
    /// another body, beyond the ground's edge). None for a non-finite run.
    pub fastest_body: Option<(usize, f32, Vector3<f32>)>,
}

impl ContactResult {
    /// `true` when the run came to rest: every position finite, settled max |v| below
    /// [`SETTLED_SPEED`], and no particle below the ground in the resting phase. A run that
    /// did not is unstable for the comparisons: its errors are those of a run still moving or
    /// blown up, so it is neither a point to beat nor a candidate in them and is listed apart.
    pub fn came_to_rest(&self) -> bool {
        self.finite && self.settled_speed < SETTLED_SPEED && self.rest_penetration <= 0.0
    }

    /// `true` when this run is at least as good as `other` on every error observable
    /// (settled speed, ground penetration, interpenetration, volume error).
    pub fn at_least_as_accurate_as(&self, other: &ContactResult) -> bool {
        self.finite
            && self.settled_speed <= other.settled_speed
            && self.rest_penetration <= other.rest_penetration
            && self.interpenetration.unwrap_or(0.0) <= other.interpenetration.unwrap_or(0.0)
            && self.rest_volume_err_pct <= other.rest_volume_err_pct
    }

    /// Pools another run's resting-phase frame times into this one's medians.
    pub fn pool_timing(&mut self, other: &ContactResult) {
        self.frame_ms.extend_from_slice(&other.frame_ms);
        self.frame_ms.sort_by(f64::total_cmp);
        self.ms_median = median_sorted(&self.frame_ms);
        self.frame_cpu_ms.extend_from_slice(&other.frame_cpu_ms);
        self.frame_cpu_ms.sort_by(f64::total_cmp);
        self.cpu_ms_median = median_sorted(&self.frame_cpu_ms);
    }
}

fn median_sorted(v: &[f64]) -> f64 {
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Runs `sim` through `scene.frames` frames and measures it. A non-finite position stops the
/// run (`finite == false`, errors infinite).
pub fn run_contact(
    sim: &mut dyn ContactSim,
    scene: &ContactScene,
) -> Result<ContactResult, Box<dyn Error>> {
    let mut r = ContactResult {
        finite: true,
        ..Default::default()
    };
    let mut all = Vec::with_capacity(scene.frames);
    let mut speeds = Vec::with_capacity(scene.frames);
    let mut prev = sim.bodies();
    let mut older = prev.clone();
    let many = prev.len() > 1;
    let mut worst_inter = 0.0f32;
    for f in 0..scene.frames {
        let (ms, cpu) = sim.step()?;
        all.push(ms);
        let x = sim.bodies();
        if !x.iter().flatten().all(|p| p.iter().all(|c| c.is_finite())) {
            r.finite = false;
            break;
        }
        let o = observe_contact(scene, &x, &prev);
        speeds.push(o.max_speed);
        r.peak_penetration = r.peak_penetration.max(o.ground_penetration);
        r.max_inverted = r.max_inverted.max(o.inverted);
        if f >= scene.rest_from {
            r.frame_ms.push(ms);
            r.frame_cpu_ms.push(cpu);
            r.rest_penetration = r.rest_penetration.max(o.ground_penetration);
            r.rest_volume_err_pct = r.rest_volume_err_pct.max(o.volume_err_pct);
            let k = f - scene.rest_from;
            if many && (k.is_multiple_of(INTERPENETRATION_EVERY) || f + 1 == scene.frames) {
                worst_inter = worst_inter.max(interpenetration(scene, &x));
            }
        }
        r.rest_min_y = x
            .iter()
            .flatten()
            .map(|p| p.y)
            .fold(f32::INFINITY, f32::min);
        older = std::mem::replace(&mut prev, x);
    }
    r.frame_ms.sort_by(f64::total_cmp);
    r.frame_cpu_ms.sort_by(f64::total_cmp);
    all.sort_by(f64::total_cmp);
    r.ms_median = median_sorted(&r.frame_ms);
    r.cpu_ms_median = median_sorted(&r.frame_cpu_ms);
    r.ms_median_all = median_sorted(&all);
    r.interpenetration = many.then_some(worst_inter);
    if r.finite {
        r.fastest_body = fastest_body(&prev, &older);
        r.settled_speed = speeds.iter().rev().take(30).copied().fold(0.0, f32::max);
        r.settle_s = speeds
            .iter()
            .rposition(|&v| v >= SETTLED_SPEED)
            .map_or(Some(0.0), |f| {
                (f + 1 < speeds.len()).then_some((f + 1) as f32 * DT)
            });
    } else {
        r.settled_speed = f32::INFINITY;
        r.rest_penetration = f32::INFINITY;
        r.rest_volume_err_pct = f32::INFINITY;
        r.interpenetration = many.then_some(f32::INFINITY);
    }
    Ok(r)
}

/// The body with the fastest particle between frames `before` and `now`: index, speed (m/s),
/// centre (m).
fn fastest_body(
    now: &[Vec<Vector3<f32>>],
    before: &[Vec<Vector3<f32>>],
) -> Option<(usize, f32, Vector3<f32>)> {
    now.iter()
        .zip(before)
        .enumerate()
        .map(|(b, (x, p))| {
            let v = x
                .iter()
                .zip(p)
                .map(|(a, c)| (a - c).norm() / DT)
                .fold(0.0, f32::max);
            let centre = x.iter().sum::<Vector3<f32>>() / x.len().max(1) as f32;
            (b, v, centre)
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separated_cubes_do_not_interpenetrate_and_overlapping_ones_do() {
        let scene = ContactScene::pile(10).expect("pile");
        let x: Vec<_> = (0..2).map(|b| scene.start(b)).collect();
        // Cubes 0 and 1 touch face to face at x = -0.5 (and 1.05 apart in height): no depth.
        assert_eq!(interpenetration(&scene, &x), 0.0);
        let mut moved = x.clone();
        for p in &mut moved[1] {
            p.x -= 0.1;
            p.y -= 1.05;
        }
        let d = interpenetration(&scene, &moved);
        assert!((d - 0.1).abs() < 1e-4, "{d}");
        let o = observe_contact(&scene, &x, &x);
        assert!(o.volume_err_pct < 1e-4 && o.max_speed == 0.0 && o.inverted == 0);
        assert_eq!(o.ground_penetration, 0.0);
    }
}
