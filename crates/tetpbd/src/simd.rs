//! The lane types the kernels of [`crate::lanes`] are written over: `wide::f32x4` (four
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
