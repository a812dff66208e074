//! Helpers shared by the tests: a pseudo-random generator for the fuzz tests, and an
//! assertion on typed errors.
#![allow(dead_code)]

/// Asserts that the error `err` is the `variant` (a struct-like variant's path) with these
/// field patterns, other fields free (`matches!(err, variant { field: value, .. })`),
/// printing the error when it is not.
#[allow(unused_macros)]
macro_rules! assert_error {
    ($err:ident, $variant:path $(, $field:ident: $value:pat)*) => {
        assert!(matches!($err, $variant { $($field: $value,)* .. }), "{}", $err)
    };
}

/// xorshift64* pseudo-random numbers.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// A number in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}
