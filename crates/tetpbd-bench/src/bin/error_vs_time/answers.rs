//! The converged answers of the material scenes side by side: both engines are given the same
//! E, ν and density, so their references can be compared with each other (and the beam's
//! tip with Euler–Bernoulli), which says how far the two engines' materials agree once the
//! time-stepping error is gone.

use nalgebra::Vector3;

use crate::engines::Model;
use crate::metrics::deviation;
use crate::reference::Reference;
use crate::scenes::{Scene, SceneKind};

/// A reference's answer next to tetpbd's material reference on the same scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct Answer {
    /// Beam: mean downward displacement of the tip vertices (largest rest x) after the last
    /// frame, m.
    pub tip_drop: Option<f64>,
    /// Deviation (the scene's metric, relative to the body size) of this reference from
    /// tetpbd's material reference on the same scene.
    pub vs_material: Option<f32>,
}

/// Mean downward displacement of the vertices at the largest rest x after the last frame of
/// `trajectory`, m (None for an empty trajectory).
pub fn tip_drop(scene: &Scene, trajectory: &[Vec<Vector3<f64>>]) -> Option<f64> {
    let last = trajectory.last()?;
    let rest = &scene.mesh.vertices;
    let max = rest.iter().map(|v| v.x).fold(f32::NEG_INFINITY, f32::max);
    let tol = 1e-6 * (1.0 + max.abs());
    let tip: Vec<usize> = (0..rest.len())
        .filter(|&i| (rest[i].x - max).abs() <= tol)
        .collect();
    let sum: f64 = tip.iter().map(|&i| f64::from(rest[i].y) - last[i].y).sum();
    (!tip.is_empty()).then(|| sum / tip.len() as f64)
}

/// The Euler–Bernoulli tip deflection of the beam scene under its own weight, m: `q L⁴ /
/// (8 E I)` with `q = ρ g a²` and `I = a⁴/12`, i.e. `1.5 ρ g L⁴ / (E a²)` (linear theory:
/// small deflections, slender beam), for the scene's material. None for other scenes.
pub fn euler_bernoulli_tip(scene: &Scene) -> Option<f64> {
    let material = scene.material?;
    if scene.kind != SceneKind::HangingBeam {
        return None;
    }
    let extent = |f: fn(&Vector3<f32>) -> f32| {
        let v = scene.mesh.vertices.iter().map(f);
        let (lo, hi) = v.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
        f64::from(hi - lo)
    };
    let (l, a) = (extent(|v| v.x), extent(|v| v.y));
    let (rho, g, e) = (
        f64::from(scene.density),
        f64::from(scene.gravity.abs()),
        f64::from(material.young_modulus()),
    );
    Some(1.5 * rho * g * l.powi(4) / (e * a * a))
}

/// The answers of `refs`, one per `(scene, model)` job in the same order; only material
/// scenes get figures.
pub fn answers(jobs: &[(&Scene, Model)], refs: &[Reference]) -> Vec<Answer> {
    jobs.iter()
        .zip(refs)
        .map(|(&(scene, _), r)| {
            if scene.material.is_none() {
                return Answer::default();
            }
            let ours = jobs
                .iter()
                .zip(refs)
                .find(|((sc, m), _)| sc.name == scene.name && *m == Model::Material)
                .map(|(_, r)| r);
            Answer {
                tip_drop: (scene.kind == SceneKind::HangingBeam)
                    .then(|| tip_drop(scene, &r.trajectory))
                    .flatten(),
                vs_material: ours.map(|o| deviation(scene, &r.trajectory, &o.trajectory).max),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tip drop reads the vertices at the free end only, and the Euler–Bernoulli figure is
    /// the closed form for the 2 m × 0.2 m beam (1.5 ρ g L⁴ / (E a²)); a scene without a
    /// material has none.
    #[test]
    fn tip_drop_and_euler_bernoulli_read_the_beam() {
        let scene = Scene::material_beam(true);
        let rest: Vec<Vector3<f64>> = scene.mesh.vertices.iter().map(|v| v.cast()).collect();
        // Lower the free end by 0.3 m and the rest of the beam by less (x · 0.1 m).
        let bent: Vec<Vector3<f64>> = rest
            .iter()
            .map(|v| {
                let drop = if v.x > 1.999 { 0.3 } else { 0.1 * v.x };
                v - Vector3::y() * drop
            })
            .collect();
        assert_eq!(tip_drop(&scene, std::slice::from_ref(&rest)), Some(0.0));
        let tip = tip_drop(&scene, &[rest, bent]).expect("frames");
        assert!((tip - 0.3).abs() < 1e-6, "tip drop {tip}");
        let material = scene.material.expect("material scene");
        let eb = euler_bernoulli_tip(&scene).expect("material beam");
        let expected = 1.5 * 1000.0 * 9.81 * 16.0 / (f64::from(material.young_modulus()) * 0.04);
        assert!((eb / expected - 1.0).abs() < 1e-5, "{eb} vs {expected}");
        assert_eq!(euler_bernoulli_tip(&Scene::hanging_beam(true)), None);
        assert_eq!(euler_bernoulli_tip(&Scene::material_squash(true)), None);
    }
}
