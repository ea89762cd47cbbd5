//! The library's one seeded generator: splitmix64 (Steele, Lea & Flood 2014), deterministic on
//! every machine. Used by the Ashikhmin-Shirley sampler, the procedural scenes and the RTL test
//! vectors.

/// splitmix64: 64 bits of state, one add and a 64-bit finalizer per draw.
#[derive(Clone, Copy, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    #[must_use]
    pub const fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[lo, hi]` (`lo <= hi`; modulo reduction).
    pub fn range(&mut self, lo: i64, hi: i64) -> i64 {
        let span = (i128::from(hi) - i128::from(lo) + 1) as u128;
        (i128::from(lo) + (u128::from(self.next_u64()) % span) as i128) as i64
    }

    /// A value of `1..=max_bits` significant bits (bit length uniform, then the value uniform):
    /// small and large magnitudes equally often.
    pub fn log_uniform(&mut self, max_bits: u32) -> u64 {
        let len = self.range(1, i64::from(max_bits)) as u32;
        let lo = 1u64 << (len - 1);
        self.range(lo as i64, ((lo - 1) | lo) as i64) as u64
    }

    /// A signed value of at most `mag_bits` magnitude bits, log-uniform, either sign (or 0).
    pub fn signed_log(&mut self, mag_bits: u32) -> i64 {
        if self.next_u64() & 63 == 0 {
            return 0;
        }
        let v = self.log_uniform(mag_bits) as i64;
        if self.next_u64() & 1 == 0 {
            v
        } else {
            -v
        }
    }
}

/// A stateless hash of `x` to [0, 1): the first draw of `SplitMix64(x)`.
#[must_use]
pub fn hash_unit(x: u64) -> f64 {
    SplitMix64(x).next_f64()
}
