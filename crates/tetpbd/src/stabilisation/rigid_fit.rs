//! The rigid fit of a field on a body's particles (centre of mass, inertia tensor,
//! pseudo-inverse), the one implementation of the idea: the angular-momentum conservation
//! (whose sums the correction-energy limit shares) and the safety net's momentum
//! restoration fit it to corrections and clamped velocities (serial and parallel, from the
//! moments and runs of particles here), and
//! [`Particles::rigid_fit`] fits it to a body's velocities for the deformation damping and
//! for couplings (rolling resistance, restitution, soft–soft contacts).

use nalgebra::{Matrix3, Vector3};

use crate::body::particles::Particles;
use crate::kernels::compensated::add_compensated;
use crate::kernels::slots::Slot;
use wide::f32x4;

/// Eigenvalues of the inertia tensor below this fraction of the largest count as zero.
const INERTIA_CUTOFF: f64 = 1e-9;

/// Particles per f32 block of the angular-momentum conservation's sums.
pub(crate) const BLOCK: usize = 256;

/// Mass-weighted moments of the substep starts `x̄` and corrections `Δ` of some particles.
#[derive(Clone, Copy, Default)]
pub(crate) struct Moments<T: nalgebra::Scalar + Copy> {
    /// Σ m.
    pub(crate) mass: T,
    /// Σ m x̄.
    pub(crate) first: Vector3<T>,
    /// Σ m x̄ x̄ᵀ as `[xx, yy, zz, xy, xz, yz]`.
    pub(crate) second: [T; 6],
    /// Σ m x̄ × Δ.
    pub(crate) torque: Vector3<T>,
    /// Σ m Δ.
    pub(crate) push: Vector3<T>,
    /// Σ m v·Δ (`v` the predicted velocity relative to the first particle's).
    pub(crate) work: T,
    /// Σ m |Δ|².
    pub(crate) square: T,
    /// Σ m x̄ × v.
    pub(crate) momentum_moment: Vector3<T>,
    /// Σ m v.
    pub(crate) momentum: Vector3<T>,
    /// The largest inverse mass, 1/kg.
    pub(crate) inv_mass: T,
    /// Σ m over the free particles (inverse mass > 0), kg: those the prediction accelerates.
    pub(crate) free_mass: T,
    /// Σ m v over the free particles (`v` relative to the first particle's), kg m/s.
    pub(crate) free_momentum: Vector3<T>,
}

impl Moments<f32> {
    #[inline(always)]
    fn add<const SPIN: bool>(&mut self, m: f32, x: Vector3<f32>, d: Vector3<f32>, v: Vector3<f32>) {
        let mv = v * m;
        self.work += mv.dot(&d);
        self.square += m * d.norm_squared();
        self.push += d * m;
        // Mass and spread are kept without the spin too: the energy limit's rounding floor
        // needs the body's size.
        let mx = x * m;
        self.mass += m;
        self.second[0] += mx.x * x.x;
        self.second[1] += mx.y * x.y;
        self.second[2] += mx.z * x.z;
        if !SPIN {
            return;
        }
        self.momentum_moment += x.cross(&mv);
        self.momentum += mv;
        self.first += mx;
        self.second[3] += mx.x * x.y;
        self.second[4] += mx.x * x.z;
        self.second[5] += mx.y * x.z;
        self.torque += mx.cross(&d);
    }
}

impl Moments<f64> {
    /// Adds one block's f32 sums.
    pub(crate) fn fold(&mut self, b: &Moments<f32>) {
        self.mass += f64::from(b.mass);
        self.first += b.first.cast::<f64>();
        for k in 0..6 {
            self.second[k] += f64::from(b.second[k]);
        }
        self.torque += b.torque.cast::<f64>();
        self.push += b.push.cast::<f64>();
        self.work += f64::from(b.work);
        self.square += f64::from(b.square);
        self.momentum_moment += b.momentum_moment.cast::<f64>();
        self.momentum += b.momentum.cast::<f64>();
        self.inv_mass = self.inv_mass.max(f64::from(b.inv_mass));
        self.free_mass += f64::from(b.free_mass);
        self.free_momentum += b.free_momentum.cast::<f64>();
    }

    /// [`rigid_fit`] of the corrections these sums measured: the centre of mass and `θ`.
    pub(crate) fn fit(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let [xx, yy, zz, xy, xz, yz] = self.second;
        let second = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
        rigid_fit(self.mass, self.first, second, self.torque, self.push)
    }
}

/// The rigid rotation that best fits a field `wᵢ` on particles of masses `mᵢ` at `xᵢ`,
/// from sums about any origin: `mass = Σ mᵢ`, `first = Σ mᵢ xᵢ`, `second = Σ mᵢ xᵢ xᵢᵀ`,
/// `moment = Σ mᵢ xᵢ × wᵢ`, `total = Σ mᵢ wᵢ`. Returns the centre of mass `c` and
/// `θ = I⁺ Σ mᵢ rᵢ × wᵢ` with `rᵢ = xᵢ − c` and `I = Σ mᵢ(|rᵢ|²𝟙 − rᵢrᵢᵀ)` (eigenvalues
/// below [`INERTIA_CUTOFF`] of the largest taken as zero): the least-squares `θ` of
/// `Σ mᵢ |wᵢ − θ × rᵢ|²` for the part of `w` without its mean. `None` without mass or when
/// not finite. Used by the spin removal (`w` the corrections), the safety net's momentum
/// restoration (`crate::stabilisation::momentum_restoration`, `w` the velocity the clamp
/// removed) and [`Particles::rigid_fit`] (`w` the velocities).
pub(crate) fn rigid_fit(
    mass: f64,
    first: Vector3<f64>,
    second: Matrix3<f64>,
    moment: Vector3<f64>,
    total: Vector3<f64>,
) -> Option<(Vector3<f64>, Vector3<f64>)> {
    fit_sums(mass, first, second, moment, total).map(|f| (f.centre, f.theta))
}

/// [`rigid_fit`] with the inertia tensor and its pseudo-inverse.
struct SumsFit {
    centre: Vector3<f64>,
    theta: Vector3<f64>,
    inertia: Matrix3<f64>,
    pseudo_inverse: Matrix3<f64>,
}

fn fit_sums(
    mass: f64,
    first: Vector3<f64>,
    second: Matrix3<f64>,
    moment: Vector3<f64>,
    total: Vector3<f64>,
) -> Option<SumsFit> {
    if !(mass.is_finite() && mass > 0.0) {
        return None;
    }
    let c = first / mass;
    let spread = second - c * c.transpose() * mass;
    let inertia = Matrix3::identity() * spread.trace() - spread;
    let b = moment - c.cross(&total);
    if !inertia.iter().chain(b.iter()).all(|x| x.is_finite()) {
        return None;
    }
    let eig = inertia.symmetric_eigen();
    let largest = eig.eigenvalues.max();
    if !(largest.is_finite() && largest > 0.0) {
        return None;
    }
    let mut theta = Vector3::zeros();
    let mut pseudo_inverse = Matrix3::zeros();
    for k in 0..3 {
        let l = eig.eigenvalues[k];
        if l > largest * INERTIA_CUTOFF {
            let u = eig.eigenvectors.column(k);
            theta += u * (u.dot(&b) / l);
            pseudo_inverse += u * u.transpose() / l;
        }
    }
    theta.iter().all(|v| v.is_finite()).then_some(SumsFit {
        centre: c,
        theta,
        inertia,
        pseudo_inverse,
    })
}

/// The rigid motion that best fits the velocities of a body's free particles (those with
/// inverse mass > 0; pinned ones are left out): see [`Particles::rigid_fit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidFit {
    /// `M = Σ mᵢ`, kg.
    pub mass: f32,
    /// Centre of mass `c = Σ mᵢxᵢ / M`, m.
    pub centre: Vector3<f32>,
    /// Velocity of the centre of mass `v_c = Σ mᵢvᵢ / M`, m/s.
    pub velocity: Vector3<f32>,
    /// Inertia tensor about `c`, `I = Σ mᵢ(|rᵢ|²𝟙 − rᵢrᵢᵀ)` with `rᵢ = xᵢ − c`, kg·m².
    pub inertia: Matrix3<f32>,
    /// Pseudo-inverse `I⁺` of [`RigidFit::inertia`] (eigenvalues below 10⁻⁹ of the largest
    /// taken as zero: a body collapsed onto a line or a point has no rotation about that
    /// axis), 1/(kg·m²).
    pub inverse_inertia: Matrix3<f32>,
    /// Angular velocity `ω = I⁺ Σ mᵢ rᵢ × vᵢ`, rad/s.
    pub angular_velocity: Vector3<f32>,
}

impl RigidFit {
    /// Velocity of the fitted rigid motion at `x`: `v_c + ω × (x − c)`, m/s.
    pub fn velocity_at(&self, x: &Vector3<f32>) -> Vector3<f32> {
        self.velocity + self.angular_velocity.cross(&(x - self.centre))
    }
}

impl Particles {
    /// The rigid motion that best fits the velocities of the free particles: the `v_c`, `ω`
    /// minimising `Σ mᵢ |vᵢ − v_c − ω × rᵢ|²` over the free particles (`rᵢ = xᵢ − c`), i.e.
    ///
    /// ```text
    /// M = Σ mᵢ,  c = Σ mᵢxᵢ / M,  v_c = Σ mᵢvᵢ / M,
    /// I = Σ mᵢ(|rᵢ|²𝟙 − rᵢrᵢᵀ),  ω = I⁺ Σ mᵢ rᵢ × vᵢ   (I⁺: pseudo-inverse, see RigidFit)
    /// ```
    ///
    /// so `M v_c` and `I ω` are the free particles' linear and angular momentum about `c`.
    /// Sums in f64 about the first free particle, in particle order (one pass); the same
    /// inertia solve as the solver's angular-momentum conservation. `None` without free mass
    /// or when a result is not finite.
    pub fn rigid_fit(&self) -> Option<RigidFit> {
        let o = self.origin()?;
        let (mut mass, mut first, mut total) = (0.0f64, Vector3::zeros(), Vector3::zeros());
        let (mut second, mut moment) = (Matrix3::<f64>::zeros(), Vector3::zeros());
        for i in self.free() {
            let m = f64::from(self.masses[i]);
            let x = self.positions[i].cast::<f64>() - o;
            let mv = self.velocities[i].cast::<f64>() * m;
            mass += m;
            first += x * m;
            second += x * x.transpose() * m;
            total += mv;
            moment += x.cross(&mv);
        }
        let fit = fit_sums(mass, first, second, moment, total)?;
        let velocity = total / mass;
        let out = RigidFit {
            mass: mass as f32,
            centre: (fit.centre + o).cast::<f32>(),
            velocity: velocity.cast::<f32>(),
            inertia: fit.inertia.cast::<f32>(),
            inverse_inertia: fit.pseudo_inverse.cast::<f32>(),
            angular_velocity: fit.theta.cast::<f32>(),
        };
        let finite = out
            .centre
            .iter()
            .chain(out.velocity.iter())
            .all(|x| x.is_finite())
            && out.inverse_inertia.iter().all(|x| x.is_finite());
        finite.then_some(out)
    }

    /// The translational part of [`Particles::rigid_fit`] alone (one cheaper pass): the
    /// velocity of the free particles' centre of mass `Σ mᵢvᵢ / Σ mᵢ` (m/s) and their mass
    /// `Σ mᵢ` (kg), sums in f64. `None` without free mass or when not finite.
    pub fn free_velocity(&self) -> Option<(Vector3<f32>, f32)> {
        let (mut mass, mut total) = (0.0f64, Vector3::<f64>::zeros());
        for i in self.free() {
            let m = f64::from(self.masses[i]);
            mass += m;
            total += self.velocities[i].cast::<f64>() * m;
        }
        if !(mass.is_finite() && mass > 0.0) {
            return None;
        }
        let v = (total / mass).cast::<f32>();
        v.iter().all(|x| x.is_finite()).then_some((v, mass as f32))
    }

    /// Inverse mass of the body moved as one rigid whole, 1/kg: `1 / Σ mᵢ` (summed in f32,
    /// in particle order); 0 when a particle is pinned (the body is held in place) or the
    /// mass is not above 0.
    pub fn rigid_inv_mass(&self) -> f32 {
        if self.inv_masses.iter().any(|&w| w <= 0.0) {
            return 0.0;
        }
        let mass = self.total_mass();
        if mass > 0.0 {
            1.0 / mass
        } else {
            0.0
        }
    }

    /// Adds the velocity `dv` (m/s) to every free particle: a rigid velocity change of the
    /// whole body that adds no deformation. Nothing when `dv` is zero or not finite.
    pub fn add_free_velocity(&mut self, dv: &Vector3<f32>) {
        if *dv == Vector3::zeros() || !dv.iter().all(|c| c.is_finite()) {
            return;
        }
        for (v, &w) in self.velocities.iter_mut().zip(&self.inv_masses) {
            if w > 0.0 {
                *v += dv;
            }
        }
    }

    /// Indices of the free particles (inverse mass > 0).
    fn free(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.len()).filter(|&i| self.inv_masses[i] > 0.0)
    }

    /// The first free particle's position in f64 (the fit's summation origin).
    fn origin(&self) -> Option<Vector3<f64>> {
        self.free().next().map(|i| self.positions[i].cast::<f64>())
    }
}

/// The arrays of a run of particles the second pass of [`crate::stabilisation::angular_momentum::store_measured`] corrects.
pub(crate) struct FixUp<'a> {
    /// Positions (stored), m.
    pub positions: &'a mut [Vector3<f32>],
    /// Rounding residuals (stored), m.
    pub residuals: &'a mut [Vector3<f32>],
    /// Substep starts, m.
    pub prev_positions: &'a [Vector3<f32>],
    /// The slots, holding the positions and residuals before the families; with `s < 1`
    /// they return the displacement `(1 − s) Δᵢ` whose velocity was taken out (position
    /// lanes) and the part `s Δᵢ` that stays velocity (residual lanes).
    pub before: &'a mut [Slot],
}

impl FixUp<'_> {
    /// `xᵢ += (x̄ᵢ − o − c) × θ` (compensated), `[o, c]` the sums' origin and the centre of
    /// mass relative to it; then, where the limit's check follows, the residual loses `(1 − s)` of the
    /// correction `xᵢ + rᵢ − (xᵢ + rᵢ)_before`, so the velocity update sees `s` of it (the
    /// part taken out and the part kept are left in the slots for
    /// [`crate::stabilisation::give_back::give_back_within_budget`]).
    pub(crate) fn apply(
        self,
        [o, c]: [Vector3<f32>; 2],
        theta: Vector3<f32>,
        limit: crate::stabilisation::correction_energy::Limit,
    ) {
        let scale = limit.scale;
        let FixUp {
            positions,
            residuals,
            prev_positions,
            before,
        } = self;
        let rotate = theta != Vector3::zeros();
        for (((x, r), xb), b) in positions
            .iter_mut()
            .zip(residuals)
            .zip(prev_positions)
            .zip(before)
        {
            if rotate {
                add_compensated(x, r, (xb - o - c).cross(&theta));
            }
            if limit.check.is_some() {
                let [a, b0, c0, _] = b.xw.to_array();
                let [ra, rb, rc, _] = b.r.to_array();
                let d = (*x - Vector3::new(a, b0, c0)) + (*r - Vector3::new(ra, rb, rc));
                let w = d * (1.0 - scale);
                *r -= w;
                let kept = d - w;
                b.xw = f32x4::new([w.x, w.y, w.z, 0.0]);
                b.r = f32x4::new([kept.x, kept.y, kept.z, 0.0]);
            }
        }
    }
}

/// The arrays of a run of particles the measuring copy back reads and writes.
pub(crate) struct StoreRun<'a> {
    /// The working copy: after the families on entry, the state before them on return.
    pub slots: &'a mut [Slot],
    /// Positions: before the families on entry, the slots' on return, m.
    pub positions: &'a mut [Vector3<f32>],
    /// Rounding residuals, likewise, m.
    pub residuals: &'a mut [Vector3<f32>],
    /// Substep starts, m.
    pub prev_positions: &'a [Vector3<f32>],
    /// Velocities predicted for the substep, m/s.
    pub velocities: &'a [Vector3<f32>],
    /// Lumped masses, kg.
    pub masses: &'a [f32],
}

impl StoreRun<'_> {
    /// Copies the slots back, leaves the state before the families in them (for the second
    /// pass of [`crate::stabilisation::angular_momentum::store_measured`]) and returns the moments of the corrections (one block:
    /// f32, in particle order), `x̄` taken about `o` and `v` relative to `v0`.
    /// Without `SPIN` only the energy sums (`work`, `square`, `push`, `inv_mass`, the free
    /// particles' mass and momentum) are taken.
    pub(crate) fn store_measuring<const SPIN: bool>(
        self,
        [o, v0]: [Vector3<f32>; 2],
    ) -> Moments<f32> {
        let mut m = Moments::<f32>::default();
        for (i, slot) in self.slots.iter_mut().enumerate() {
            let [a, b, c, w] = slot.xw.to_array();
            let [ra, rb, rc, _] = slot.r.to_array();
            let (x, r) = (Vector3::new(a, b, c), Vector3::new(ra, rb, rc));
            let (x0, r0) = (self.positions[i], self.residuals[i]);
            // The correction as the velocity update will see it: position plus rounding
            // residual (see `systems::add_compensated`); at rest most of it is residual.
            let d = (x - x0) + (r - r0);
            m.add::<SPIN>(
                self.masses[i],
                self.prev_positions[i] - o,
                d,
                self.velocities[i] - v0,
            );
            m.inv_mass = m.inv_mass.max(w);
            if w > 0.0 {
                m.free_mass += self.masses[i];
                m.free_momentum += (self.velocities[i] - v0) * self.masses[i];
            }
            self.positions[i] = x;
            self.residuals[i] = r;
            slot.xw = f32x4::new([x0.x, x0.y, x0.z, w]);
            slot.r = f32x4::new([r0.x, r0.y, r0.z, 0.0]);
        }
        m
    }
}
