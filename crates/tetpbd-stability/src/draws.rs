//! [`Draws`]: the one deterministic stream of pseudo-random draws of the suite's seeded
//! families (SplitMix64), the same on every machine and thread count.

/// A deterministic stream of draws (SplitMix64).
#[derive(Clone, Debug)]
pub struct Draws(u64);

impl Draws {
    /// The stream starting at state `seed`.
    pub fn from_seed(seed: u64) -> Draws {
        Draws(seed)
    }

    /// The stream of draw `index` of family `seed` (streams of neighbouring indices are
    /// unrelated).
    pub fn stream(seed: u64, index: u64) -> Draws {
        let mut d = Draws(seed);
        d.0 ^= d.bits().wrapping_add(index);
        d
    }

    /// The next 64 random bits.
    pub fn bits(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        (self.bits() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.unit()
    }

    /// Log-uniform in `[a, b)` (both > 0).
    pub fn log(&mut self, a: f32, b: f32) -> f32 {
        self.range(a.ln(), b.ln()).exp()
    }

    /// Uniform in `0..n` from the high bits (`n` > 0).
    pub fn below(&mut self, n: u64) -> u64 {
        (self.bits() >> 33) % n
    }

    /// One of `xs` (not empty), from the low bits.
    pub fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[(self.bits() % xs.len() as u64) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_stay_in_their_ranges_and_repeat_per_seed() {
        let (mut a, mut b) = (Draws::stream(7, 3), Draws::stream(7, 3));
        for _ in 0..1000 {
            let u = a.unit();
            assert!((0.0..1.0).contains(&u));
            assert_eq!(u, b.unit());
            let r = a.range(-2.0, 5.0);
            assert!((-2.0..5.0).contains(&r));
            let l = a.log(0.1, 10.0);
            assert!((0.1..10.0001).contains(&l));
            assert!(a.below(6) < 6);
            b.range(-2.0, 5.0);
            b.log(0.1, 10.0);
            b.below(6);
        }
        assert_ne!(Draws::stream(7, 3).bits(), Draws::stream(7, 4).bits());
    }
}
