//! Running one configuration and measuring it: observables both engines share (volume kept,
//! edge stretch, inverted tetrahedra, shape), tetpbd's own per-family |C|, and the deviation
//! from a reference run (the references themselves: [`crate::reference`]).

use nalgebra::{Matrix3, Vector3};

use crate::engines::Sim;
use crate::scenes::{tet_volume, Scene, SceneKind, DT};

/// Observables computed the same way from either engine's positions.
#[derive(Clone, Copy, Debug, Default)]
pub struct Observables {
    /// Total signed volume over rest volume, minus one, in %.
    pub volume_err_pct: f32,
    /// RMS over the mesh edges of the strain `|l / l₀ − 1|`.
    pub edge_strain_rms: f32,
    /// Largest edge strain.
    pub edge_strain_max: f32,
    /// Tetrahedra whose signed volume changed sign.
    pub inverted: usize,
}

/// Evaluates the shared observables at positions `x`.
pub fn observe(scene: &Scene, x: &[Vector3<f32>]) -> Observables {
    let (mut now, mut rest, mut inverted) = (0.0f64, 0.0f64, 0);
    for (t, v0) in scene.mesh.tets.iter().zip(&scene.rest_volumes) {
        let v = tet_volume(t, x);
        now += f64::from(v * v0.signum());
        rest += f64::from(v0.abs());
        if v * v0 <= 0.0 {
            inverted += 1;
        }
    }
    let (mut sum_sq, mut max) = (0.0f64, 0.0f32);
    for ([a, b], l0) in scene.edges.iter().zip(&scene.rest_lengths) {
        let s = ((x[*a as usize] - x[*b as usize]).norm() / l0 - 1.0).abs();
        sum_sq += f64::from(s * s);
        max = max.max(s);
    }
    Observables {
        volume_err_pct: ((now / rest - 1.0) * 100.0) as f32,
        edge_strain_rms: (sum_sq / scene.edges.len().max(1) as f64).sqrt() as f32,
        edge_strain_max: max,
        inverted,
    }
}

/// Max and RMS of tetpbd's `|C|` of one family after the last frame (m or m³).
#[derive(Clone, Copy, Debug, Default)]
pub struct FamilyError {
    /// RMS of C.
    pub rms: f32,
    /// Max |C|.
    pub max: f32,
}

/// What one run of one configuration gave.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Median wall ms per frame over the frames after the warm-up.
    pub ms_median: f64,
    /// Wall ns per constraint projection over the measured frames (tetpbd only).
    pub ns_per_projection: Option<f64>,
    /// Wall ms of every measured frame (after the warm-up), sorted.
    pub frame_ms: Vec<f64>,
    /// Median thread CPU ms per frame over the same frames.
    pub cpu_ms_median: f64,
    /// The wall-time median of each run pooled into this one (this run's first).
    pub repeat_medians: Vec<f64>,
    /// Thread CPU ms of every measured frame, sorted.
    pub frame_cpu_ms: Vec<f64>,
    /// Projections and their wall ms over the measured frames.
    pub projections: (u64, f64),
    /// Observables after the last frame.
    pub last: Observables,
    /// Largest number of inverted tetrahedra over all frames.
    pub max_inverted: usize,
    /// tetpbd's per-family |C| after the last frame, in [`tetpbd::Family::ALL`] order (None: rapier,
    /// or the family is not in the set).
    pub families: [Option<FamilyError>; 3],
    /// Squash: first time after which volume and edge lengths stay within 1 % of rest, s.
    pub recover_s: Option<f32>,
    /// Largest particle speed over the last frame, m/s (from the last two frames' positions).
    pub final_speed: f32,
    /// `false` when a position became non-finite.
    pub finite: bool,
    /// Positions after every frame.
    pub trajectory: Vec<Vec<Vector3<f32>>>,
    /// Volume error after every frame, %.
    pub volume_series: Vec<f32>,
}

/// Runs `sim` through `scene.frames` frames.
pub fn run(sim: &mut dyn Sim, scene: &Scene) -> RunResult {
    let mut times = Vec::with_capacity(scene.frames);
    let mut cpu = Vec::with_capacity(scene.frames);
    let (mut proj, mut proj_ms) = (0u64, 0.0f64);
    let mut trajectory = Vec::with_capacity(scene.frames);
    let mut obs = Vec::with_capacity(scene.frames);
    let mut families = [None; 3];
    let mut finite = true;
    for f in 0..scene.frames {
        let cost = sim.step();
        if f >= scene.warmup {
            times.push(cost.ms);
            cpu.push(cost.cpu_ms);
            proj += cost.projections;
            proj_ms += cost.ms;
        }
        let x = sim.positions();
        if !x.iter().all(|p| p.iter().all(|c| c.is_finite())) {
            finite = false;
        }
        obs.push(observe(scene, &x));
        trajectory.push(x);
        if let Some(errors) = sim.family_errors() {
            families = errors.map(|e| {
                e.map(|e| FamilyError {
                    rms: e.rms,
                    max: e.max,
                })
            });
        }
    }
    times.sort_by(f64::total_cmp);
    cpu.sort_by(f64::total_cmp);
    let final_speed = match trajectory.len() {
        n if n >= 2 => trajectory[n - 1]
            .iter()
            .zip(&trajectory[n - 2])
            .map(|(a, b)| (a - b).norm() / DT)
            .fold(0.0, f32::max),
        _ => 0.0,
    };
    let recover_s = match scene.kind {
        SceneKind::Squash => recovery_time(&obs),
        SceneKind::HangingBeam => None,
    };
    RunResult {
        ms_median: times.get(times.len() / 2).copied().unwrap_or(f64::NAN),
        ns_per_projection: (proj > 0).then(|| proj_ms * 1e6 / proj as f64),
        repeat_medians: vec![times.get(times.len() / 2).copied().unwrap_or(f64::NAN)],
        frame_ms: times,
        cpu_ms_median: cpu.get(cpu.len() / 2).copied().unwrap_or(f64::NAN),
        frame_cpu_ms: cpu,
        projections: (proj, proj_ms),
        last: obs.last().copied().unwrap_or_default(),
        max_inverted: obs.iter().map(|o| o.inverted).max().unwrap_or(0),
        families,
        recover_s,
        final_speed,
        finite,
        volume_series: obs.iter().map(|o| o.volume_err_pct).collect(),
        trajectory,
    }
}

impl RunResult {
    /// Relative spread of the pooled runs' wall-time medians, `max / min − 1` (NaN for a
    /// single run).
    pub fn timing_spread(&self) -> f64 {
        if self.repeat_medians.len() < 2 {
            return f64::NAN;
        }
        let lo = self
            .repeat_medians
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let hi = self.repeat_medians.iter().copied().fold(0.0, f64::max);
        if lo > 0.0 && lo.is_finite() {
            hi / lo - 1.0
        } else {
            f64::NAN
        }
    }

    /// Pools the frame times of another run of the same configuration into this one's timing
    /// (the median is then over both runs' measured frames).
    pub fn pool_timing(&mut self, other: &RunResult) {
        self.repeat_medians.push(other.ms_median);
        self.frame_ms.extend_from_slice(&other.frame_ms);
        self.frame_ms.sort_by(f64::total_cmp);
        self.ms_median = self
            .frame_ms
            .get(self.frame_ms.len() / 2)
            .copied()
            .unwrap_or(f64::NAN);
        self.frame_cpu_ms.extend_from_slice(&other.frame_cpu_ms);
        self.frame_cpu_ms.sort_by(f64::total_cmp);
        self.cpu_ms_median = self
            .frame_cpu_ms
            .get(self.frame_cpu_ms.len() / 2)
            .copied()
            .unwrap_or(f64::NAN);
        self.projections.0 += other.projections.0;
        self.projections.1 += other.projections.1;
        let (n, ms) = self.projections;
        self.ns_per_projection = (n > 0).then(|| ms * 1e6 / n as f64);
    }
}

/// First time after which the total volume stays within 1 % of rest and the RMS edge strain
/// below 1 % (the shape is back; rotation-invariant, since the free block may turn).
fn recovery_time(obs: &[Observables]) -> Option<f32> {
    let ok = |o: &Observables| o.volume_err_pct.abs() <= 1.0 && o.edge_strain_rms <= 0.01;
    let mut first = None;
    for (f, o) in obs.iter().enumerate() {
        match (ok(o), first) {
            (true, None) => first = Some(f),
            (false, _) => first = None,
            _ => {}
        }
    }
    first.map(|f| (f + 1) as f32 * DT)
}

/// Deviation of a run from a reference, relative to the body size.
#[derive(Clone, Copy, Debug, Default)]
pub struct Deviation {
    /// Largest particle displacement over the compared frames.
    pub max: f32,
    /// RMS particle displacement over the compared frames.
    pub rms: f32,
}

/// Positions after every frame, in `f64` (references, and runs widened to compare with them).
pub type Trajectory64 = Vec<Vec<Vector3<f64>>>;

/// `trajectory` widened to `f64`.
pub fn widen(trajectory: &[Vec<Vector3<f32>>]) -> Trajectory64 {
    trajectory
        .iter()
        .map(|x| x.iter().map(|p| p.cast::<f64>()).collect())
        .collect()
}

/// Compares `run` with `reference`: the last frame for the hanging beam (static
/// equilibrium; pinned, so no rigid motion to remove), every frame for the squash, each frame
/// after the best rigid alignment of the run onto the reference (the shape is compared, not
/// where the free block drifted or turned). In `f64`, so that the change between two `f64`
/// references is measured below `f32` rounding.
pub fn deviation(
    scene: &Scene,
    run: &[Vec<Vector3<f64>>],
    reference: &[Vec<Vector3<f64>>],
) -> Deviation {
    let frames: Vec<usize> = match scene.kind {
        SceneKind::HangingBeam => vec![run.len().min(reference.len()).saturating_sub(1)],
        SceneKind::Squash => (0..run.len().min(reference.len())).collect(),
    };
    let (mut max, mut sum_sq, mut n) = (0.0f64, 0.0f64, 0usize);
    for f in frames {
        let aligned = match scene.kind {
            SceneKind::HangingBeam => run[f].clone(),
            SceneKind::Squash => align(&run[f], &reference[f]),
        };
        for (a, b) in aligned.iter().zip(&reference[f]) {
            let d = (a - b).norm();
            let d = if d.is_finite() { d } else { f64::INFINITY };
            max = max.max(d);
            sum_sq += d * d;
            n += 1;
        }
    }
    let size = f64::from(scene.size);
    Deviation {
        max: (max / size) as f32,
        rms: ((sum_sq / n.max(1) as f64).sqrt() / size) as f32,
    }
}

/// `x` moved by the rotation and translation that best map it onto `target` (least squares,
/// equal weights; Kabsch). Non-finite input is returned unchanged.
pub fn align(x: &[Vector3<f64>], target: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    if x.is_empty() || !x.iter().all(|p| p.iter().all(|c| c.is_finite())) {
        return x.to_vec();
    }
    let n = x.len() as f64;
    let cx = x.iter().sum::<Vector3<f64>>() / n;
    let ct = target.iter().sum::<Vector3<f64>>() / n;
    let mut h = Matrix3::<f64>::zeros();
    for (a, b) in x.iter().zip(target) {
        h += (a - cx) * (b - ct).transpose();
    }
    let svd = h.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return x.to_vec();
    };
    let mut r = v_t.transpose() * u.transpose();
    if r.determinant() < 0.0 {
        let mut v = v_t.transpose();
        v.column_mut(2).neg_mut();
        r = v * u.transpose();
    }
    x.iter().map(|p| r * (p - cx) + ct).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    #[test]
    fn rest_shape_has_no_error_and_alignment_removes_rigid_motion() {
        let scene = Scene::squash(true);
        let rest = &scene.mesh.vertices;
        let o = observe(&scene, rest);
        assert!(o.volume_err_pct.abs() < 1e-4 && o.edge_strain_max < 1e-6 && o.inverted == 0);
        let r = Rotation3::from_euler_angles(0.3, -0.7, 1.1);
        let rest64: Vec<Vector3<f64>> = rest.iter().map(|p| p.cast()).collect();
        let moved: Vec<Vector3<f64>> = rest64
            .iter()
            .map(|p| r * p + Vector3::new(0.5, -2.0, 3.0))
            .collect();
        let aligned = align(&moved, &rest64);
        let worst = aligned
            .iter()
            .zip(&rest64)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(worst < 1e-12, "{worst}");
        let squashed = observe(&scene, &scene.start);
        assert!((squashed.volume_err_pct + 50.0).abs() < 1e-3);
    }

    #[test]
    fn recovery_is_the_start_of_the_last_good_stretch() {
        let good = Observables::default();
        let bad = Observables {
            volume_err_pct: 5.0,
            ..good
        };
        assert_eq!(recovery_time(&[bad, good, bad, good, good]), Some(4.0 * DT));
        assert_eq!(recovery_time(&[good, bad]), None);
    }
}
