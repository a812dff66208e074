//! A small XPBD stepper in `f64` for converged references: the same model as tetpbd's
//! [`tetpbd::Solver`] (same particles, masses, pins, constraint families in the same solver
//! order, compliances, gravity, damping and substep scheme), run in double precision so that
//! doubling its substeps can be carried on until the answer stops changing at 1e-6 of the
//! body size, below where `f32` rounding stops it.
//!
//! It reuses the core's constraint math ([`tetpbd::constraint`], generic over the scalar)
//! and mirrors [`tetpbd::systems`]: prediction with `v ← (v + h g)·max(0, 1 − damping·h)`,
//! multipliers reset every substep, `iterations` Gauss–Seidel sweeps over the families in
//! [`SolverSettings::order`], each in the body's stored (colour) order, followed by the spin
//! removal on a free body ([`tetpbd::SafetySettings::conserve_angular_momentum`]), then
//! `v = (x − x_prev)/h` (with the correction-speed safety net's clamp and momentum
//! restoration when it is set).
//! Degenerate configurations get the core's fallbacks (edge: rest direction; vertex–face: rest
//! normal; volume: skipped). Not mirrored: `f32` compensated summation (not needed in `f64`),
//! SIMD lanes (the same sweep to rounding), external accelerations and hooks (no scene of the
//! report has them).

use nalgebra::{Matrix3, Vector3};
use tetpbd::constraint::{self, Evaluated, VERTEX_FACE_ORDER};
use tetpbd::{Family, SoftBody, SolverSettings};

/// The solver's face-thinness threshold, in f64.
const KAPPA: f64 = constraint::VERTEX_FACE_KAPPA as f64;

/// Why a body or settings cannot be run by [`Xpbd64`].
#[derive(Clone, Debug, PartialEq)]
pub enum Xpbd64Error {
    /// The settings failed [`SolverSettings::validate`].
    Settings(tetpbd::SettingsError),
}

impl std::fmt::Display for Xpbd64Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Xpbd64Error::Settings(e) => write!(f, "invalid solver settings: {e}"),
        }
    }
}

impl std::error::Error for Xpbd64Error {}

type V3 = Vector3<f64>;

fn wide(v: &Vector3<f32>) -> V3 {
    v.cast::<f64>()
}

/// One soft body stepped in `f64`.
#[derive(Clone, Debug)]
pub struct Xpbd64 {
    x: Vec<V3>,
    prev: Vec<V3>,
    v: Vec<V3>,
    w: Vec<f64>,
    rest: Vec<V3>,
    /// Input vertex of each particle.
    source: Vec<u32>,
    tets: Vec<[u32; 4]>,
    edges: Option<(Vec<[u32; 2]>, Vec<f64>, f64)>,
    vertex_face: Option<(Vec<[f64; 4]>, f64)>,
    volume: Option<(Vec<f64>, f64)>,
    dt: f64,
    substeps: u32,
    iterations: u32,
    gravity: V3,
    damping: f64,
    order: [Family; 3],
    max_correction_speed: Option<f64>,
    conserve_angular_momentum: bool,
    /// Positions before an iteration's families (scratch of the spin removal).
    before: Vec<V3>,
    degenerate: u64,
}

impl Xpbd64 {
    /// Takes `body` (as built by [`tetpbd::SoftBodyBuilder`], with its current positions and
    /// velocities as the start state) and the solver settings it would run with. Rest lengths,
    /// volumes and heights are recomputed in `f64` from the body's rest positions.
    pub fn new(body: &SoftBody, settings: &SolverSettings) -> Result<Xpbd64, Xpbd64Error> {
        settings.validate().map_err(Xpbd64Error::Settings)?;
        let p = &body.particles;
        let rest: Vec<V3> = p.rest_positions().iter().map(wide).collect();
        let tets = body.tetrahedra.indices().to_vec();
        let at = |i: u32| rest[i as usize];
        let edges = body.edges.as_ref().map(|e| {
            let list = e.edges().to_vec();
            let lengths = list.iter().map(|[a, b]| (at(*a) - at(*b)).norm()).collect();
            (list, lengths, f64::from(e.compliance()))
        });
        let vertex_face = body.vertex_face.as_ref().map(|vf| {
            let heights = tets
                .iter()
                .map(|t| {
                    VERTEX_FACE_ORDER.map(|o| {
                        let [a, b, c, d] = o.map(|k| at(t[k]));
                        // As the builder: the rest value of the degeneracy-aware form (the
                        // builder rejected degenerate tetrahedra, so every face has a plane).
                        constraint::bounded_height(&a, &b, &c, &d, KAPPA, 0.0).unwrap_or(0.0)
                    })
                })
                .collect();
            (heights, f64::from(vf.compliance()))
        });
        let volume = body.volume.as_ref().map(|v| {
            let vols = tets
                .iter()
                .map(|t| {
                    let [a, b, c, d] = t.map(at);
                    constraint::signed_volume(&a, &b, &c, &d)
                })
                .collect();
            (vols, f64::from(v.compliance()))
        });
        let x: Vec<V3> = p.positions().iter().map(wide).collect();
        Ok(Xpbd64 {
            prev: x.clone(),
            x,
            v: p.velocities().iter().map(wide).collect(),
            w: p.inv_masses().iter().map(|w| f64::from(*w)).collect(),
            rest,
            source: p.source().to_vec(),
            tets,
            edges,
            vertex_face,
            volume,
            dt: f64::from(settings.dt),
            substeps: settings.substeps,
            iterations: settings.iterations,
            gravity: wide(&settings.gravity),
            damping: f64::from(settings.damping),
            order: settings.order,
            max_correction_speed: settings.safety.max_correction_speed.map(f64::from),
            conserve_angular_momentum: settings.safety.conserve_angular_momentum,
            before: Vec::new(),
            degenerate: 0,
        })
    }

    /// Positions in input mesh vertex order, m.
    pub fn positions(&self) -> Vec<V3> {
        let mut out = vec![V3::zeros(); self.x.len()];
        for (k, &i) in self.source.iter().enumerate() {
            out[i as usize] = self.x[k];
        }
        out
    }

    /// Degenerate configurations met so far (projected along a fallback or skipped).
    pub fn degenerate(&self) -> u64 {
        self.degenerate
    }

    /// Advances one frame of `dt`.
    pub fn step(&mut self) {
        let h = self.dt / f64::from(self.substeps);
        let keep = (1.0 - self.damping * h).max(0.0);
        for _ in 0..self.substeps {
            for i in 0..self.x.len() {
                self.prev[i] = self.x[i];
                if self.w[i] > 0.0 {
                    self.v[i] = (self.v[i] + self.gravity * h) * keep;
                }
                self.x[i] += self.v[i] * h;
            }
            let mut lambdas = Lambdas::new(self);
            // The spin removal's centre and inertia (substep start, fixed over the
            // iterations) and the positions before the families (a reused buffer).
            let spin = (self.conserve_angular_momentum && self.w.iter().all(|&w| w > 0.0))
                .then(|| centre_and_inertia(&self.prev, self.w.iter().map(|w| 1.0 / w)));
            let mut before = std::mem::take(&mut self.before);
            for _ in 0..self.iterations {
                before.clone_from(&self.x);
                for family in self.order {
                    match family {
                        Family::Edge => self.project_edges(h, &mut lambdas.edge),
                        Family::VertexFace => self.project_vertex_face(h, &mut lambdas.vf),
                        Family::Volume => self.project_volume(h, &mut lambdas.volume),
                    }
                }
                if let Some(fit) = spin {
                    self.remove_spin(&before, fit);
                }
            }
            self.before = before;
            let mut clamped = false;
            for i in 0..self.x.len() {
                let mut v = (self.x[i] - self.prev[i]) / h;
                if let Some(limit) = self.max_correction_speed {
                    let dv = v - self.v[i];
                    let n = dv.norm();
                    if n > limit {
                        v = self.v[i] + dv * (limit / n);
                        clamped = true;
                    }
                }
                self.v[i] = v;
            }
            if clamped && self.w.iter().all(|&w| w > 0.0) {
                self.restore_momentum(h);
            }
        }
    }

    /// The solver's spin removal (as tetpbd's `spin` module): the rigid-rotation part of the
    /// families' corrections `x − before`, about the centre of mass at the substep start.
    fn remove_spin(&mut self, before: &[V3], (c, inertia): (V3, Matrix3<f64>)) {
        let m = self.w.iter().map(|w| 1.0 / w);
        let mut torque = V3::zeros();
        for ((x, b), (p, mi)) in self.x.iter().zip(before).zip(self.prev.iter().zip(m)) {
            torque += (p - c).cross(&(x - b)) * mi;
        }
        let theta = pseudo_solve(&inertia, &torque);
        for (x, p) in self.x.iter_mut().zip(&self.prev) {
            *x -= theta.cross(&(p - c));
        }
    }

    /// The safety net's momentum restoration (as tetpbd's): the linear and angular momentum
    /// the clamp removed from the free body, given back as a rigid velocity change.
    fn restore_momentum(&mut self, h: f64) {
        let m = self.w.iter().map(|w| 1.0 / w);
        let (c, inertia) = centre_and_inertia(&self.x, m.clone());
        let (mut total, mut dp, mut dl) = (0.0, V3::zeros(), V3::zeros());
        for ((x, p), (v, mi)) in self.x.iter().zip(&self.prev).zip(self.v.iter().zip(m)) {
            total += mi;
            let dv = (v - (x - p) / h) * mi;
            dp += dv;
            dl += (x - c).cross(&dv);
        }
        let u = -dp / total;
        let omega = pseudo_solve(&inertia, &-dl);
        for (v, x) in self.v.iter_mut().zip(&self.x) {
            *v += u + omega.cross(&(x - c));
        }
    }

    fn project_edges(&mut self, h: f64, lambdas: &mut [f64]) {
        let Some((edges, lengths, alpha)) = &self.edges else {
            return;
        };
        let alpha_tilde = alpha / (h * h);
        for (k, &[a, b]) in edges.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let fallback = (self.rest[a] - self.rest[b]) / lengths[k];
            let d = self.x[a] - self.x[b];
            if d.norm() <= 1e-6 * lengths[k] {
                self.degenerate += 1;
            }
            if let Some(e) = constraint::edge(&self.x[a], &self.x[b], lengths[k], Some(&fallback)) {
                let w = [self.w[a], self.w[b]];
                constraint::apply(&mut self.x, [a, b], w, &e, &mut lambdas[k], alpha_tilde);
            }
        }
    }

    fn project_vertex_face(&mut self, h: f64, lambdas: &mut [[f64; 4]]) {
        let Some((heights, alpha)) = &self.vertex_face else {
            return;
        };
        let alpha_tilde = alpha / (h * h);
        for (t, tet) in self.tets.iter().enumerate() {
            for (k, order) in VERTEX_FACE_ORDER.iter().enumerate() {
                let idx = order.map(|o| tet[o] as usize);
                let p = idx.map(|i| self.x[i]);
                let w = idx.map(|i| self.w[i]);
                let bounded = constraint::vertex_face_bounded(
                    &p[0],
                    &p[1],
                    &p[2],
                    &p[3],
                    heights[t][k],
                    KAPPA,
                );
                let e = match bounded {
                    Some(e) => e,
                    None => {
                        self.degenerate += 1;
                        let r = idx.map(|i| self.rest[i]);
                        let n = (r[2] - r[0]).cross(&(r[3] - r[0])).normalize();
                        Evaluated {
                            c: (p[1] - p[0]).dot(&n) - heights[t][k],
                            grad: [-n, n, V3::zeros(), V3::zeros()],
                        }
                    }
                };
                constraint::apply(&mut self.x, idx, w, &e, &mut lambdas[t][k], alpha_tilde);
            }
        }
    }

    fn project_volume(&mut self, h: f64, lambdas: &mut [f64]) {
        let Some((volumes, alpha)) = &self.volume else {
            return;
        };
        let alpha_tilde = alpha / (h * h);
        for (t, tet) in self.tets.iter().enumerate() {
            let idx = tet.map(|i| i as usize);
            let p = idx.map(|i| self.x[i]);
            let w = idx.map(|i| self.w[i]);
            let e = constraint::volume(&p[0], &p[1], &p[2], &p[3], volumes[t]);
            if !constraint::apply(&mut self.x, idx, w, &e, &mut lambdas[t], alpha_tilde)
                && w.iter().any(|w| *w > 0.0)
            {
                self.degenerate += 1;
            }
        }
    }
}

/// The multipliers of one substep, zero at its start.
struct Lambdas {
    edge: Vec<f64>,
    vf: Vec<[f64; 4]>,
    volume: Vec<f64>,
}

impl Lambdas {
    fn new(s: &Xpbd64) -> Lambdas {
        Lambdas {
            edge: vec![0.0; s.edges.as_ref().map_or(0, |e| e.0.len())],
            vf: vec![[0.0; 4]; s.vertex_face.as_ref().map_or(0, |_| s.tets.len())],
            volume: vec![0.0; s.volume.as_ref().map_or(0, |_| s.tets.len())],
        }
    }
}

/// Centre of mass and inertia tensor about it of points `x` with masses `m`.
fn centre_and_inertia(x: &[V3], m: impl Iterator<Item = f64> + Clone) -> (V3, Matrix3<f64>) {
    let total: f64 = m.clone().sum();
    let c = x.iter().zip(m.clone()).map(|(x, mi)| x * mi).sum::<V3>() / total;
    let mut inertia = Matrix3::zeros();
    for (x, mi) in x.iter().zip(m) {
        let r = x - c;
        inertia += (Matrix3::identity() * r.norm_squared() - r * r.transpose()) * mi;
    }
    (c, inertia)
}

/// `I⁺ b`, eigenvalues of `I` below 1e-9 of the largest taken as zero (as tetpbd's).
fn pseudo_solve(inertia: &Matrix3<f64>, b: &V3) -> V3 {
    let eig = inertia.symmetric_eigen();
    let largest = eig.eigenvalues.max();
    let mut x = V3::zeros();
    for k in 0..3 {
        let l = eig.eigenvalues[k];
        if largest > 0.0 && l > largest * 1e-9 {
            let u = eig.eigenvectors.column(k);
            x += u * (u.dot(b) / l);
        }
    }
    x
}
