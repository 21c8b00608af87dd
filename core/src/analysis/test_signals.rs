//! Seeded noise for the analysis tests.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Standard normal deviates by Box–Muller from a seeded ChaCha stream.
pub struct Noise(pub ChaCha8Rng);

impl Noise {
    pub fn new(seed: u64) -> Noise {
        Noise(ChaCha8Rng::seed_from_u64(seed))
    }
    pub fn gauss(&mut self) -> f64 {
        let u1: f64 = 1.0 - self.0.gen::<f64>();
        let u2: f64 = self.0.gen();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
    pub fn uniform(&mut self) -> f64 {
        self.0.gen()
    }
}
