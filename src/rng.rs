//! The crate's one pseudo-random generator: xorshift64* with SplitMix64 seeding, and the
//! few draws the crate needs (uniform, ranges, integers, normals).
//!
//! Everything random in momaro must be reproducible from a seed on any machine and
//! compiler: noisy pose feedback in `closed_loop` and the scenario generator
//! (`scenario::generate`). So the generator is written out here rather than taken from a
//! crate whose streams may change between versions: the same seed gives the same
//! sequence forever (unit tests pin the first values).
//!
//! - [`Rng::seeded`] scrambles the seed with SplitMix64 first, so neighbouring seeds
//!   (the generator's cases S, S+1, …) start unrelated streams;
//! - [`Rng::from_state`] takes the seed as the raw xorshift state, as the pose noise of
//!   `momaro run --noise` always has (its outputs are unchanged by the move to this
//!   module).

/// SplitMix64 (Steele, Lea & Flood 2014): advances `state` and returns the next output.
/// Used to turn a seed into a well-mixed, non-zero xorshift state.
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A xorshift64* generator (Marsaglia 2003; Vigna 2016). Small, fast, deterministic; not
/// for cryptography.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// A generator for `seed`, its state scrambled by SplitMix64 so that nearby seeds give
    /// unrelated streams.
    pub fn seeded(seed: u64) -> Self {
        let mut s = seed;
        Self::from_state(splitmix64(&mut s))
    }

    /// A generator whose xorshift state is `state` itself (0, a fixed point of xorshift,
    /// is replaced by 1).
    pub fn from_state(state: u64) -> Self {
        Self { state: state.max(1) }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        self.state.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in the open interval (0, 1), 53 bits.
    pub fn uniform(&mut self) -> f64 {
        let v = self.next_u64();
        ((v >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi] (for lo < hi strictly inside it).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Uniform integer in [0, n); 0 for n = 0.
    pub fn below(&mut self, n: u64) -> u64 {
        // Multiply-high: the bias is at most n / 2^64.
        ((u128::from(self.next_u64()) * u128::from(n)) >> 64) as u64
    }

    /// Uniform integer in [lo, hi] (both included); `lo` if hi < lo.
    pub fn int_range(&mut self, lo: u32, hi: u32) -> u32 {
        if hi <= lo {
            return lo;
        }
        lo + self.below(u64::from(hi - lo) + 1) as u32
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.uniform() < p
    }

    /// One of `items`, uniformly; `None` if there are none.
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> Option<&'a T> {
        items.get(self.below(items.len() as u64) as usize)
    }

    /// A standard normal sample (Box–Muller, cosine branch; two uniforms per sample).
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_matches_the_reference_values() {
        // Reference: the first outputs of SplitMix64 from state 0 (Vigna's splitmix64.c).
        let mut s = 0u64;
        assert_eq!(splitmix64(&mut s), 0xE220_A839_7B1D_CDAF);
        assert_eq!(splitmix64(&mut s), 0x6E78_9E6A_A1B9_65F4);
        assert_eq!(splitmix64(&mut s), 0x06C4_5D18_8009_454F);
    }

    #[test]
    fn from_state_is_the_pose_noise_stream() {
        // xorshift64* from state 1, written out: the stream `run --noise` has always used.
        let mut s = 1u64;
        let mut reference = || {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            s.wrapping_mul(0x2545_F491_4F6C_DD1D)
        };
        let mut r = Rng::from_state(0);
        for _ in 0..100 {
            assert_eq!(r.next_u64(), reference());
        }
        assert_eq!(Rng::from_state(7), Rng::from_state(7));
    }

    #[test]
    fn same_seed_same_stream_and_neighbours_differ() {
        let a: Vec<u64> = (0..8)
            .map({
                let mut r = Rng::seeded(42);
                move |_| r.next_u64()
            })
            .collect();
        let b: Vec<u64> = (0..8)
            .map({
                let mut r = Rng::seeded(42);
                move |_| r.next_u64()
            })
            .collect();
        assert_eq!(a, b);
        let mut r41 = Rng::seeded(41);
        let mut r43 = Rng::seeded(43);
        assert_ne!(r41.next_u64(), a[0]);
        assert_ne!(r43.next_u64(), a[0]);
    }

    #[test]
    fn uniform_and_ranges_stay_inside_their_bounds() {
        let mut r = Rng::seeded(1);
        let mut sum = 0.0;
        let n = 20_000;
        for _ in 0..n {
            let u = r.uniform();
            assert!(u > 0.0 && u < 1.0);
            sum += u;
            let x = r.range(-2.0, 3.0);
            assert!((-2.0..=3.0).contains(&x));
            let k = r.int_range(2, 8);
            assert!((2..=8).contains(&k));
            assert!(r.below(5) < 5);
        }
        assert!((sum / f64::from(n) - 0.5).abs() < 0.01, "mean {}", sum / f64::from(n));
        assert_eq!(r.below(0), 0);
        assert_eq!(r.int_range(3, 3), 3);
        assert_eq!(r.int_range(4, 3), 4);
    }

    #[test]
    fn int_range_reaches_both_ends() {
        let mut r = Rng::seeded(9);
        let mut seen = [false; 7];
        for _ in 0..1000 {
            seen[(r.int_range(2, 8) - 2) as usize] = true;
        }
        assert!(seen.iter().all(|&s| s), "{seen:?}");
    }

    #[test]
    fn normal_has_zero_mean_and_unit_variance() {
        let mut r = Rng::seeded(3);
        let n = 40_000;
        let v: Vec<f64> = (0..n).map(|_| r.normal()).collect();
        let mean = v.iter().sum::<f64>() / n as f64;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        assert!(mean.abs() < 0.02, "mean {mean}");
        assert!((var - 1.0).abs() < 0.03, "variance {var}");
    }

    #[test]
    fn pick_and_chance() {
        let mut r = Rng::seeded(5);
        let items = ["a", "b", "c"];
        let mut counts = [0; 3];
        for _ in 0..3000 {
            let p = r.pick(&items).copied();
            counts[items.iter().position(|&i| Some(i) == p).unwrap()] += 1;
        }
        assert!(counts.iter().all(|&c| c > 900), "{counts:?}");
        assert_eq!(r.pick::<u8>(&[]), None);
        let hits = (0..10_000).filter(|_| r.chance(0.25)).count();
        assert!((2300..2700).contains(&hits), "{hits}");
    }
}
