//! What the unit tests share: a deterministic random-number generator without a dependency.

/// xorshift64* (Vigna, ACM Trans. Math. Softw. 42, 30 (2016)): the state, seeded non-zero.
pub struct Rng(pub u64);

impl Rng {
    /// A number in [0, 1) (53 random bits).
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A number in [-1, 1).
    pub fn signed(&mut self) -> f64 {
        self.next() * 2.0 - 1.0
    }

    /// An integer in `0..=max`.
    pub fn natural(&mut self, max: u32) -> u32 {
        (self.next() * (max + 1) as f64) as u32 % (max + 1)
    }
}
