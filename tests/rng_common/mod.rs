//! The tests' one seeded generator (splitmix64): reproducible on every machine.
#![allow(dead_code)]

use glam::DVec3;

/// splitmix64.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [0, 1) on 24 bits, as f32.
    pub fn unit_f32(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u32 << 24) as f32
    }
    /// Uniform in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
    /// Uniform integer in [0, n).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    /// Uniform integer in [lo, hi] (inclusive; modulo bias is irrelevant to the tests).
    pub fn int_in(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next() % (hi - lo + 1) as u64) as i64
    }
    /// Standard normal (Box-Muller).
    pub fn normal(&mut self) -> f64 {
        let u = self.unit().max(1e-300);
        let v = self.unit();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
    /// A unit vector within `max_tilt` radians of +z.
    pub fn tilted(&mut self, max_tilt: f64) -> DVec3 {
        let c = 1.0 - self.unit() * (1.0 - max_tilt.cos());
        let s = (1.0 - c * c).max(0.0).sqrt();
        let p = 2.0 * std::f64::consts::PI * self.unit();
        DVec3::new(s * p.cos(), s * p.sin(), c)
    }
    /// A uniformly distributed unit vector (rejection sampling in the unit ball).
    pub fn dir(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(
                2.0 * self.unit() - 1.0,
                2.0 * self.unit() - 1.0,
                2.0 * self.unit() - 1.0,
            );
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}
