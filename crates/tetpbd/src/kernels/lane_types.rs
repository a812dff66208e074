//! The lane types the kernels of [`crate::kernels::lanes`] are written over: `wide::f32x4` (four
//! constraints, one chunk) and [`X2`] (two chunks side by side, eight constraints).
//!
//! Every operation of [`X2`] is the same `f32x4` operation on each half, so a lane computes
//! exactly what it computes in a chunk of four: two chunks projected as one [`X2`] give
//! bit-identical results to the two chunks projected one after the other (they belong to
//! one colour class and share no particle). What the pair buys is independent work: the
//! vertex–face kernel is a chain of four dependent projections (square root, two
//! divisions each), and two chunks in flight fill the latency one chain leaves idle.

use std::ops::{Add, AddAssign, BitAnd, Div, Mul, Neg, Sub};

use wide::f32x4;

/// A vector of lanes, one constraint per lane; masks are lanes of all ones or zeros.
pub(crate) trait Lane:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + BitAnd<Output = Self>
{
    /// Lanes (a multiple of 4).
    const WIDTH: usize;
    /// All lanes 0.
    const ZERO: Self;
    /// All lanes 1.
    const ONE: Self;
    /// `x` on every lane.
    fn splat(x: f32) -> Self;
    /// Lane-wise square root.
    fn vsqrt(self) -> Self;
    /// Lane-wise maximum (`maxps`: `o` where either lane is NaN).
    fn vmax(self, o: Self) -> Self;
    /// Lane-wise `self > o` (mask).
    fn vgt(self, o: Self) -> Self;
    /// Lane-wise `self >= o` (mask).
    fn vge(self, o: Self) -> Self;
    /// `t` where the mask `self` is set, `f` elsewhere.
    fn vsel(self, t: Self, f: Self) -> Self;
    /// One bit per lane of the mask `self`, lane 0 lowest.
    fn vbits(self) -> u32;
    /// The chunks of four lanes (for `f32x4` the second is zero).
    fn quarters(self) -> [f32x4; 2];
    /// Lanes from chunks of four (for `f32x4` only the first is read).
    fn from_quarters(q: [f32x4; 2]) -> Self;

    /// Rows `[x, y, z, w]` of `WIDTH / 4` chunks (`rows[c][l]`: item `4c + l`; only the
    /// first `WIDTH / 4` are read) as lanes of x, y, z and w.
    #[inline(always)]
    fn transpose_in(rows: [[f32x4; 4]; 2]) -> [Self; 4] {
        let mut q = [[f32x4::ZERO; 4]; 2];
        for (quarter, r) in q.iter_mut().zip(rows).take(Self::WIDTH / 4) {
            *quarter = f32x4::transpose(r);
        }
        [0, 1, 2, 3].map(|j| Self::from_quarters([q[0][j], q[1][j]]))
    }

    /// The inverse of [`Lane::transpose_in`] for lanes of x, y, z: rows `[x, y, z, 0]`.
    #[inline(always)]
    fn transpose_out(v: [Self; 3]) -> [[f32x4; 4]; 2] {
        let [x, y, z] = v.map(Self::quarters);
        let mut rows = [[f32x4::ZERO; 4]; 2];
        for (c, r) in rows.iter_mut().enumerate().take(Self::WIDTH / 4) {
            *r = f32x4::transpose([x[c], y[c], z[c], f32x4::ZERO]);
        }
        rows
    }

    /// Every lane of the mask `self` is set.
    #[inline(always)]
    fn vall(self) -> bool {
        self.vbits() == (1 << Self::WIDTH) - 1
    }
}

impl Lane for f32x4 {
    const WIDTH: usize = 4;
    const ZERO: Self = f32x4::ZERO;
    const ONE: Self = f32x4::ONE;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        f32x4::splat(x)
    }
    #[inline(always)]
    fn vsqrt(self) -> Self {
        self.sqrt()
    }
    #[inline(always)]
    fn vmax(self, o: Self) -> Self {
        self.fast_max(o)
    }
    #[inline(always)]
    fn vgt(self, o: Self) -> Self {
        self.simd_gt(o)
    }
    #[inline(always)]
    fn vge(self, o: Self) -> Self {
        self.simd_ge(o)
    }
    #[inline(always)]
    fn vsel(self, t: Self, f: Self) -> Self {
        self.select(t, f)
    }
    #[inline(always)]
    fn vbits(self) -> u32 {
        self.to_bitmask() & 0xf
    }
    #[inline(always)]
    fn quarters(self) -> [f32x4; 2] {
        [self, f32x4::ZERO]
    }
    #[inline(always)]
    fn from_quarters(q: [f32x4; 2]) -> Self {
        q[0]
    }
}

/// Two chunks of four lanes.
#[derive(Clone, Copy)]
pub(crate) struct X2(pub [f32x4; 2]);

macro_rules! x2_op {
    ($tr:ident, $f:ident) => {
        impl $tr for X2 {
            type Output = X2;
            #[inline(always)]
            fn $f(self, o: X2) -> X2 {
                X2([self.0[0].$f(o.0[0]), self.0[1].$f(o.0[1])])
            }
        }
    };
}
x2_op!(Add, add);
x2_op!(Sub, sub);
x2_op!(Mul, mul);
x2_op!(Div, div);
x2_op!(BitAnd, bitand);

impl Neg for X2 {
    type Output = X2;
    #[inline(always)]
    fn neg(self) -> X2 {
        X2([-self.0[0], -self.0[1]])
    }
}

impl AddAssign for X2 {
    #[inline(always)]
    fn add_assign(&mut self, o: X2) {
        *self = *self + o;
    }
}

impl X2 {
    #[inline(always)]
    fn map(self, f: impl Fn(f32x4) -> f32x4) -> X2 {
        X2([f(self.0[0]), f(self.0[1])])
    }
    #[inline(always)]
    fn zip(self, o: X2, f: impl Fn(f32x4, f32x4) -> f32x4) -> X2 {
        X2([f(self.0[0], o.0[0]), f(self.0[1], o.0[1])])
    }
}

impl Lane for X2 {
    const WIDTH: usize = 8;
    const ZERO: Self = X2([f32x4::ZERO; 2]);
    const ONE: Self = X2([f32x4::ONE; 2]);
    #[inline(always)]
    fn splat(x: f32) -> Self {
        X2([f32x4::splat(x); 2])
    }
    #[inline(always)]
    fn vsqrt(self) -> Self {
        self.map(f32x4::sqrt)
    }
    #[inline(always)]
    fn vmax(self, o: Self) -> Self {
        self.zip(o, |a, b| a.fast_max(b))
    }
    #[inline(always)]
    fn vgt(self, o: Self) -> Self {
        self.zip(o, |a, b| a.simd_gt(b))
    }
    #[inline(always)]
    fn vge(self, o: Self) -> Self {
        self.zip(o, |a, b| a.simd_ge(b))
    }
    #[inline(always)]
    fn vsel(self, t: Self, f: Self) -> Self {
        X2([
            self.0[0].select(t.0[0], f.0[0]),
            self.0[1].select(t.0[1], f.0[1]),
        ])
    }
    #[inline(always)]
    fn vbits(self) -> u32 {
        (self.0[0].to_bitmask() & 0xf) | ((self.0[1].to_bitmask() & 0xf) << 4)
    }
    #[inline(always)]
    fn quarters(self) -> [f32x4; 2] {
        self.0
    }
    #[inline(always)]
    fn from_quarters(q: [f32x4; 2]) -> Self {
        X2(q)
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::Y8;

/// Eight lanes in one AVX register, for the AVX2 + FMA build of the runs.
#[cfg(target_arch = "x86_64")]
mod avx {
    use std::arch::x86_64::*;
    use std::ops::{Add, AddAssign, BitAnd, Div, Mul, Neg, Sub};

    use wide::f32x4;

    use super::Lane;

    /// Two chunks of four lanes in one 256-bit register: the same IEEE operations as
    /// [`super::X2`] on each lane (add, subtract, multiply, divide and square root are
    /// correctly rounded in either width; negation flips the sign bit as `wide` does; the
    /// comparisons are ordered, false on NaN, as `wide`'s; masks are all ones or all zeros,
    /// so `blendv` selects what `wide`'s bit blend selects), in half the instructions.
    ///
    /// Only the AVX2 + FMA build of the runs (`runs::*_avx2`, entered after
    /// `is_x86_feature_detected!`) uses this type: every `unsafe` below runs an AVX
    /// instruction, sound because the CPU has AVX there.
    #[derive(Clone, Copy)]
    pub(crate) struct Y8(__m256);

    macro_rules! y8_op {
        ($tr:ident, $f:ident, $intr:ident) => {
            impl $tr for Y8 {
                type Output = Y8;
                #[inline(always)]
                fn $f(self, o: Y8) -> Y8 {
                    // SAFETY: AVX is available wherever a `Y8` is used (type docs).
                    Y8(unsafe { $intr(self.0, o.0) })
                }
            }
        };
    }
    y8_op!(Add, add, _mm256_add_ps);
    y8_op!(Sub, sub, _mm256_sub_ps);
    y8_op!(Mul, mul, _mm256_mul_ps);
    y8_op!(Div, div, _mm256_div_ps);
    y8_op!(BitAnd, bitand, _mm256_and_ps);

    impl Neg for Y8 {
        type Output = Y8;
        #[inline(always)]
        fn neg(self) -> Y8 {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            Y8(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
        }
    }

    impl AddAssign for Y8 {
        #[inline(always)]
        fn add_assign(&mut self, o: Y8) {
            *self = *self + o;
        }
    }

    impl Lane for Y8 {
        const WIDTH: usize = 8;
        // SAFETY (both): `__m256` accepts every bit pattern; eight f32 0.0 / 1.0.
        const ZERO: Self = Y8(unsafe { std::mem::transmute::<[f32; 8], __m256>([0.0; 8]) });
        const ONE: Self = Y8(unsafe { std::mem::transmute::<[f32; 8], __m256>([1.0; 8]) });
        #[inline(always)]
        fn splat(x: f32) -> Self {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            Y8(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        fn vsqrt(self) -> Self {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            Y8(unsafe { _mm256_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn vmax(self, o: Self) -> Self {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            Y8(unsafe { _mm256_max_ps(self.0, o.0) })
        }
        #[inline(always)]
        fn vgt(self, o: Self) -> Self {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            Y8(unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn vge(self, o: Self) -> Self {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            Y8(unsafe { _mm256_cmp_ps::<_CMP_GE_OQ>(self.0, o.0) })
        }
        #[inline(always)]
        fn vsel(self, t: Self, f: Self) -> Self {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            Y8(unsafe { _mm256_blendv_ps(f.0, t.0, self.0) })
        }
        #[inline(always)]
        fn vbits(self) -> u32 {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            (unsafe { _mm256_movemask_ps(self.0) }) as u32
        }
        #[inline(always)]
        fn quarters(self) -> [f32x4; 2] {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            let (lo, hi) = unsafe {
                (
                    _mm256_castps256_ps128(self.0),
                    _mm256_extractf128_ps::<1>(self.0),
                )
            };
            [f32x4::from(lo), f32x4::from(hi)]
        }
        #[inline(always)]
        fn from_quarters(q: [f32x4; 2]) -> Self {
            let (lo, hi) = (__m128::from(q[0]), __m128::from(q[1]));
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            Y8(unsafe { _mm256_set_m128(hi, lo) })
        }
        /// Row `l` of both chunks in one register, then both 4 × 4 transposes at once (the
        /// shuffles work within each 128-bit half): 8 shuffles instead of 16.
        #[inline(always)]
        fn transpose_in(rows: [[f32x4; 4]; 2]) -> [Self; 4] {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            unsafe {
                let r =
                    |l: usize| _mm256_set_m128(__m128::from(rows[1][l]), __m128::from(rows[0][l]));
                let (t0, t1) = (
                    _mm256_unpacklo_ps(r(0), r(1)),
                    _mm256_unpackhi_ps(r(0), r(1)),
                );
                let (t2, t3) = (
                    _mm256_unpacklo_ps(r(2), r(3)),
                    _mm256_unpackhi_ps(r(2), r(3)),
                );
                let (t0, t1, t2, t3) = (
                    _mm256_castps_pd(t0),
                    _mm256_castps_pd(t1),
                    _mm256_castps_pd(t2),
                    _mm256_castps_pd(t3),
                );
                [
                    _mm256_unpacklo_pd(t0, t2),
                    _mm256_unpackhi_pd(t0, t2),
                    _mm256_unpacklo_pd(t1, t3),
                    _mm256_unpackhi_pd(t1, t3),
                ]
                .map(|v| Y8(_mm256_castpd_ps(v)))
            }
        }
        /// Both inverse transposes at once, then each row's halves to its chunk.
        #[inline(always)]
        fn transpose_out(v: [Self; 3]) -> [[f32x4; 4]; 2] {
            // SAFETY: AVX is available wherever a `Y8` is used (type docs).
            unsafe {
                let [x, y, z] = v.map(|v| v.0);
                let zero = _mm256_setzero_ps();
                let (t0, t1) = (_mm256_unpacklo_ps(x, y), _mm256_unpackhi_ps(x, y));
                let (t2, t3) = (_mm256_unpacklo_ps(z, zero), _mm256_unpackhi_ps(z, zero));
                let (t0, t1, t2, t3) = (
                    _mm256_castps_pd(t0),
                    _mm256_castps_pd(t1),
                    _mm256_castps_pd(t2),
                    _mm256_castps_pd(t3),
                );
                let rows = [
                    _mm256_castpd_ps(_mm256_unpacklo_pd(t0, t2)),
                    _mm256_castpd_ps(_mm256_unpackhi_pd(t0, t2)),
                    _mm256_castpd_ps(_mm256_unpacklo_pd(t1, t3)),
                    _mm256_castpd_ps(_mm256_unpackhi_pd(t1, t3)),
                ];
                [
                    rows.map(|r| f32x4::from(_mm256_castps256_ps128(r))),
                    rows.map(|r| f32x4::from(_mm256_extractf128_ps::<1>(r))),
                ]
            }
        }
    }
}
