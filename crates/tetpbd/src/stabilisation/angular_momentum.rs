//! Removing the spin Gauss–Seidel creates
//! ([`crate::SolverSettings::conserve_angular_momentum`]).
//!
//! A body's internal constraints exert no net force and no net torque. Each projection's
//! correction `Δᵢ = wᵢ∇ᵢC Δλ` is free of both *about the positions it was computed at*
//! (the gradients of a rotation-invariant `C` sum to zero, and `Σ pᵢ × ∇ᵢC = 0`), so linear
//! momentum is conserved exactly. Angular momentum is not, for two second-order reasons:
//!
//! * the velocity is `vᵢ = (xᵢ − x̄ᵢ)/h` with `x̄ᵢ` the substep start. Moving the particles
//!   by `Δᵢ` changes `L = Σ mᵢ xᵢ × vᵢ` by
//!
//!   ```text
//!   h ΔL = Σ mᵢ [(xᵢ + Δᵢ) × (xᵢ + Δᵢ − x̄ᵢ) − xᵢ × (xᵢ − x̄ᵢ)] = Σ mᵢ x̄ᵢ × Δᵢ,
//!   ```
//!
//!   which vanishes for a torque-free correction only where the body has not moved since
//!   the substep start (`xᵢ = x̄ᵢ`);
//! * Gauss–Seidel applies the corrections one after another, each computed at positions the
//!   previous ones moved, so even from rest the sum carries a commutator term `Σ mᵢ Δ₂ × Δ₁`.
//!
//! In a body whose constraints cannot all be met (a tangled, self-intersecting equilibrium,
//! crates/tetpbd-stability/src/bin/findings.md) the corrections are centimetres every
//! substep and the error is a steady torque: undamped, a tangled 1 m cube released at rest
//! reached 22 kJ of rotation in 10 s.
//!
//! The fix removes the rigid-rotation part of the families' corrections, once per
//! iteration. With `rᵢ = x̄ᵢ − c` (`c` the centre of mass at the substep start), the
//! mass-weighted least-squares rotation of the correction field,
//!
//! ```text
//! θ = argmin Σ mᵢ |Δᵢ − θ × rᵢ|²,   I θ = Σ mᵢ rᵢ × Δᵢ = h ΔL,
//! I = Σ mᵢ (|rᵢ|² 𝟙 − rᵢ rᵢᵀ)  (the inertia tensor at the substep start),
//! ```
//!
//! is subtracted, `Δᵢ ← Δᵢ − θ × rᵢ`: afterwards `Σ mᵢ rᵢ × Δᵢ = 0`, so the families leave
//! `L` unchanged, and `Σ mᵢ θ × rᵢ = θ × Σ mᵢ rᵢ = 0` leaves the linear momentum as it was.
//! It is an orthogonal projection in the mass-weighted norm, so it never lengthens the
//! correction field: `Σ mᵢ|θ × rᵢ|² ≤ Σ mᵢ|Δᵢ|²`. `I` is inverted through its eigenvalues,
//! those below `10⁻⁹` of the largest taken as zero (a body collapsed onto a line or a
//! point has no rotation about that axis to remove, and `h ΔL` has no component there).
//! A rotation is `C`-invariant to first order, so the constraint errors change by
//! `O(|θ|²)`.
//!
//! Only the families' own corrections are measured (between the working copy's load and
//! store, [`crate::kernels::working_copy`]): a [`crate::SubstepHook`]'s contacts and attachments apply real
//! torques and are left alone. A body with a pinned particle is skipped: its pins exert
//! torque. Sums in f32 over blocks of 256 particles and in f64 across blocks, in block
//! order on one thread: the result does not depend on the thread count (with the
//! `parallel` feature the blocks of a large body are summed concurrently, then folded in
//! order). Cost: the copy back from the working copy, which this pass takes over, measures
//! the corrections on the way, plus one more pass to apply `θ`.

use hecs::World;
use nalgebra::{Matrix3, Vector3};

use crate::body::particles::Particles;
use crate::kernels::working_copy::Slot;
use crate::solver::systems::add_compensated;

/// Eigenvalues of the inertia tensor below this fraction of the largest count as zero.
const INERTIA_CUTOFF: f64 = 1e-9;

/// Copies every swept body's working copy back ([`crate::kernels::working_copy::store`]) and removes the
/// rigid-rotation part of the corrections the families made on it since it was loaded (the
/// copy in the slots, `Particles` still holding the positions before the families).
pub(crate) fn store_bodies_without_spin(world: &mut World) {
    crate::kernels::working_copy::for_each_swept(world, store_without_spin);
}

/// [`store_bodies_without_spin`] for one body. A free body is stored and measured in one
/// pass, then corrected in a second; a body with a pinned particle is only stored.
fn store_without_spin(p: &mut Particles) {
    let n = p.positions.len();
    if n == 0 || p.work.0.len() != n || p.inv_masses.contains(&0.0) {
        crate::kernels::working_copy::store(p);
        return;
    }
    // Raw moments about the first particle's start `o` (small numbers, little
    // cancellation), summed in f32 over blocks of `BLOCK` particles and in f64 across blocks,
    // in block order (the same sums for any thread count).
    let o = p.prev_positions[0];
    let mut sums = Moments::<f64>::default();
    let Particles {
        positions,
        prev_positions,
        residuals,
        masses,
        work,
        ..
    } = p;
    let run = StoreRun {
        slots: &work.0,
        positions,
        residuals,
        prev_positions,
        masses,
    };
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::particles_worth_it(n) {
        BLOCKS.with_borrow_mut(|blocks| {
            blocks.clear();
            blocks.resize(n.div_ceil(BLOCK), Moments::default());
            crate::parallel::sweeps::store_measuring(run, o, blocks);
            for block in blocks.iter() {
                sums.fold(block);
            }
        });
        return finish(sums, positions, residuals, prev_positions, o);
    }
    let StoreRun {
        slots,
        positions,
        residuals,
        prev_positions,
        masses,
    } = run;
    for start in (0..n).step_by(BLOCK) {
        let r = start..(start + BLOCK).min(n);
        let block = StoreRun {
            slots: &slots[r.clone()],
            positions: &mut positions[r.clone()],
            residuals: &mut residuals[r.clone()],
            prev_positions: &prev_positions[r.clone()],
            masses: &masses[r],
        }
        .store_measuring(o);
        sums.fold(&block);
    }
    finish(sums, positions, residuals, prev_positions, o);
}

/// Solves for `θ` from the sums and applies `Δᵢ −= θ × rᵢ` to the stored positions.
fn finish(
    sums: Moments<f64>,
    positions: &mut [Vector3<f32>],
    residuals: &mut [Vector3<f32>],
    prev_positions: &[Vector3<f32>],
    o: Vector3<f32>,
) {
    let [xx, yy, zz, xy, xz, yz] = sums.second;
    let second = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    let Some((c, theta)) = rigid_fit(sums.mass, sums.first, second, sums.torque, sums.push) else {
        return;
    };
    if theta == Vector3::zeros() {
        return;
    }
    // Δᵢ −= θ × rᵢ = rᵢ × θ, with rᵢ = x̄ᵢ − o − c.
    let (theta, c) = (theta.cast::<f32>(), c.cast::<f32>());
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::particles_worth_it(positions.len()) {
        crate::parallel::sweeps::rotate_back(positions, residuals, prev_positions, [o, c], theta);
        return;
    }
    rotate_back(positions, residuals, prev_positions, [o, c], theta);
}

/// `xᵢ += (x̄ᵢ − o − c) × θ` (compensated) for a run of particles, `[o, c]` the sums'
/// origin and the centre of mass relative to it.
pub(crate) fn rotate_back(
    positions: &mut [Vector3<f32>],
    residuals: &mut [Vector3<f32>],
    prev_positions: &[Vector3<f32>],
    [o, c]: [Vector3<f32>; 2],
    theta: Vector3<f32>,
) {
    for ((x, r), xb) in positions.iter_mut().zip(residuals).zip(prev_positions) {
        add_compensated(x, r, (xb - o - c).cross(&theta));
    }
}

/// The arrays of a run of particles the measuring copy back reads and writes.
pub(crate) struct StoreRun<'a> {
    /// The working copy (after the families).
    pub slots: &'a [Slot],
    /// Positions: before the families on entry, the slots' on return, m.
    pub positions: &'a mut [Vector3<f32>],
    /// Rounding residuals, likewise, m.
    pub residuals: &'a mut [Vector3<f32>],
    /// Substep starts, m.
    pub prev_positions: &'a [Vector3<f32>],
    /// Lumped masses, kg.
    pub masses: &'a [f32],
}

impl StoreRun<'_> {
    /// Copies the slots back and returns the moments of the corrections (one block: f32,
    /// in particle order), `x̄` taken about `o`.
    pub(crate) fn store_measuring(self, o: Vector3<f32>) -> Moments<f32> {
        let mut m = Moments::<f32>::default();
        for (i, slot) in self.slots.iter().enumerate() {
            let [a, b, c, _] = slot.xw.to_array();
            let [ra, rb, rc, _] = slot.r.to_array();
            let (x, r) = (Vector3::new(a, b, c), Vector3::new(ra, rb, rc));
            // The correction as the velocity update will see it: position plus rounding
            // residual (see `systems::add_compensated`); at rest most of it is residual.
            let d = (x - self.positions[i]) + (r - self.residuals[i]);
            m.add(self.masses[i], self.prev_positions[i] - o, d);
            self.positions[i] = x;
            self.residuals[i] = r;
        }
        m
    }
}

#[cfg(feature = "parallel")]
thread_local! {
    /// Per-block sums of the parallel path (grown once per body size, then reused).
    static BLOCKS: std::cell::RefCell<Vec<Moments<f32>>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Particles per f32 block of [`store_without_spin`]'s sums.
pub(crate) const BLOCK: usize = 256;

/// Mass-weighted moments of the substep starts `x̄` and corrections `Δ` of some particles.
#[derive(Clone, Copy, Default)]
pub(crate) struct Moments<T: nalgebra::Scalar + Copy> {
    /// Σ m.
    mass: T,
    /// Σ m x̄.
    first: Vector3<T>,
    /// Σ m x̄ x̄ᵀ as `[xx, yy, zz, xy, xz, yz]`.
    second: [T; 6],
    /// Σ m x̄ × Δ.
    torque: Vector3<T>,
    /// Σ m Δ.
    push: Vector3<T>,
}

impl Moments<f32> {
    #[inline(always)]
    fn add(&mut self, m: f32, x: Vector3<f32>, d: Vector3<f32>) {
        let mx = x * m;
        self.mass += m;
        self.first += mx;
        self.second[0] += mx.x * x.x;
        self.second[1] += mx.y * x.y;
        self.second[2] += mx.z * x.z;
        self.second[3] += mx.x * x.y;
        self.second[4] += mx.x * x.z;
        self.second[5] += mx.y * x.z;
        self.torque += mx.cross(&d);
        self.push += d * m;
    }
}

impl Moments<f64> {
    fn fold(&mut self, b: &Moments<f32>) {
        self.mass += f64::from(b.mass);
        self.first += b.first.cast::<f64>();
        for k in 0..6 {
            self.second[k] += f64::from(b.second[k]);
        }
        self.torque += b.torque.cast::<f64>();
        self.push += b.push.cast::<f64>();
    }
}

/// The rigid rotation that best fits a field `wᵢ` on particles of masses `mᵢ` at `xᵢ`,
/// from sums about any origin: `mass = Σ mᵢ`, `first = Σ mᵢ xᵢ`, `second = Σ mᵢ xᵢ xᵢᵀ`,
/// `moment = Σ mᵢ xᵢ × wᵢ`, `total = Σ mᵢ wᵢ`. Returns the centre of mass `c` and
/// `θ = I⁺ Σ mᵢ rᵢ × wᵢ` with `rᵢ = xᵢ − c` and `I = Σ mᵢ(|rᵢ|²𝟙 − rᵢrᵢᵀ)` (eigenvalues
/// below [`INERTIA_CUTOFF`] of the largest taken as zero): the least-squares `θ` of
/// `Σ mᵢ |wᵢ − θ × rᵢ|²` for the part of `w` without its mean. `None` without mass or when
/// not finite. Used by the spin removal (`w` the corrections) and the safety net's momentum
/// restoration (`crate::stabilisation::momentum_restoration`, `w` the velocity the clamp removed).
pub(crate) fn rigid_fit(
    mass: f64,
    first: Vector3<f64>,
    second: Matrix3<f64>,
    moment: Vector3<f64>,
    total: Vector3<f64>,
) -> Option<(Vector3<f64>, Vector3<f64>)> {
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
    for k in 0..3 {
        let l = eig.eigenvalues[k];
        if l > largest * INERTIA_CUTOFF {
            let u = eig.eigenvectors.column(k);
            theta += u * (u.dot(&b) / l);
        }
    }
    theta.iter().all(|v| v.is_finite()).then_some((c, theta))
}
