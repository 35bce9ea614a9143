//! A small seeded generator (SplitMix64, Steele, Lea and Flood, "Fast splittable pseudorandom
//! number generators", OOPSLA 2014) and the seed derivation of every fuzz unit. Written out here
//! so that a seed names the same cases on every version of every dependency.

/// SplitMix64: 64 bits of state, every seed valid.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    /// An index drawn with the given relative weights.
    pub fn weighted(&mut self, weights: &[u32]) -> usize {
        let total: u32 = weights.iter().sum();
        let mut x = (self.next_u64() % u64::from(total.max(1))) as u32;
        for (i, w) in weights.iter().enumerate() {
            if x < *w {
                return i;
            }
            x -= w;
        }
        weights.len() - 1
    }
}

/// FNV-1a of a string (64 bits).
pub fn fnv(text: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// The generator of one unit: a function of the run's seed, the kind of case, the FMU (or file
/// family) and the unit's index only, so that any unit can be replayed alone.
pub fn unit_rng(seed: u64, kind: &str, target: &str, unit: u64) -> Rng {
    let mut r = Rng::new(seed ^ fnv(kind).rotate_left(17) ^ fnv(target).rotate_left(41));
    let skip = r.next_u64();
    Rng::new(skip ^ unit.wrapping_mul(0xd1b5_4a32_d192_ed03))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix_matches_the_reference_sequence() {
        // The first outputs of SplitMix64 seeded with 1234567: the test vector quoted for
        // Vigna's splitmix64.c, checked with an independent Python transcription.
        let mut r = Rng::new(1234567);
        assert_eq!(r.next_u64(), 6457827717110365317);
        assert_eq!(r.next_u64(), 3203168211198807973);
    }

    #[test]
    fn units_are_independent_of_order() {
        let a = unit_rng(7, "calls", "Waves", 3).next_u64();
        let _ = unit_rng(7, "calls", "Waves", 2).next_u64();
        assert_eq!(a, unit_rng(7, "calls", "Waves", 3).next_u64());
        assert_ne!(a, unit_rng(7, "calls", "Wind", 3).next_u64());
        assert_ne!(a, unit_rng(8, "calls", "Waves", 3).next_u64());
    }
}
