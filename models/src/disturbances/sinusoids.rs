//! The sum of sinusoids of the wave elevation, `ζ = Σ a_i cos(φ_i + ω_i τ − k_i x)`, evaluated
//! near its arithmetic limit.
//!
//! The components are stored four to a block (structure of arrays inside each block, padded with
//! zero amplitudes), and the cosine is a branch-free polynomial, so that the compiler turns the
//! loop into SIMD code. Every operation is a plain IEEE-754 multiply or add in a fixed order (Rust
//! never fuses them), so the result is the same bit for bit on every x86-64 and aarch64 machine and
//! in every importer, whatever SIMD width the loop runs at.
//!
//! # The cosine
//! `θ = n π + r` with `n` the nearest integer to `θ/π` (the 1.5·2⁵² shift rounds it and leaves
//! `n mod 2` in the lowest mantissa bit), `r = θ − n π` by Cody and Waite's three-part reduction
//! (π = P1 + P2 + P3, P1 and P2 with at most 32 significant bits, so `n P1` and `n P2` are
//! exact for |n| < 2²¹, |θ| < 6.5·10⁶), and `cos θ = (−1)ⁿ cos r` with `cos r` the Taylor polynomial to r²⁰ on
//! |r| ≤ π/2 (truncation below 2·10⁻¹⁷). The absolute error is below 5·10⁻¹⁶ (about two units in the last place of 1) for |θ| < 10⁷
//! (tested against libm); beyond, the reduction error grows like the rounding of θ itself.
//! Valid for |θ| < 2⁵⁰ (a 10⁸ s run of 3 rad/s waves reaches 3·10⁸); beyond, the result is
//! meaningless but stays finite and within [−1, 1] (a hostile ship speed cannot make the
//! elevation overflow).

use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_1_PI;

/// Components per block (the SIMD width the loop is written for).
const LANES: usize = 4;

/// Four components: amplitude a [m], wave frequency ω [rad/s], wave number k = ω²/g [rad/m] and
/// phase φ [rad] at the reference time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Block {
    amplitude: [f64; LANES],
    frequency: [f64; LANES],
    wavenumber: [f64; LANES],
    phase: [f64; LANES],
}

/// The components of a sum of sinusoids.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Sinusoids {
    blocks: Vec<Block>,
    len: usize,
}

impl Sinusoids {
    /// Room for `n` components (the only allocation).
    pub fn with_capacity(n: usize) -> Self {
        Sinusoids {
            blocks: Vec::with_capacity(n.div_ceil(LANES)),
            len: 0,
        }
    }

    /// Appends a component.
    pub fn push(&mut self, amplitude: f64, frequency: f64, wavenumber: f64, phase: f64) {
        let lane = self.len % LANES;
        if lane == 0 {
            self.blocks.push(Block {
                amplitude: [0.0; LANES],
                frequency: [0.0; LANES],
                wavenumber: [0.0; LANES],
                phase: [0.0; LANES],
            });
        }
        let b = self.blocks.last_mut().expect("a block was just pushed");
        b.amplitude[lane] = amplitude;
        b.frequency[lane] = frequency;
        b.wavenumber[lane] = wavenumber;
        b.phase[lane] = phase;
        self.len += 1;
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Component `i`: (a, ω, k, φ).
    pub fn get(&self, i: usize) -> (f64, f64, f64, f64) {
        let (b, l) = (&self.blocks[i / LANES], i % LANES);
        (b.amplitude[l], b.frequency[l], b.wavenumber[l], b.phase[l])
    }

    /// Replaces every amplitude a by `f(a)` (used once, to normalise the set).
    pub fn map_amplitudes(&mut self, f: impl Fn(f64) -> f64) {
        for i in 0..self.len {
            let a = &mut self.blocks[i / LANES].amplitude[i % LANES];
            *a = f(*a);
        }
    }

    /// `Σ a_i cos(φ_i + ω_i τ − k_i x)`: time `τ` [s] since the reference time and distance `x`
    /// [m] travelled along the wave direction since then. Four partial sums, one per lane, added
    /// pairwise at the end. On x86-64 machines with AVX2 the same code runs four lanes wide instead
    /// of two (the same operations in the same order, so the same bits).
    pub fn sum(&self, tau: f64, x: f64) -> f64 {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above), the only requirement of a
            // `#[target_feature(enable = "avx2")]` function.
            return unsafe { sum_avx(&self.blocks, tau, x) };
        }
        sum_blocks(&self.blocks, tau, x)
    }
}

/// [`sum_blocks`] with 256-bit AVX2 vectors: one block per iteration, the same IEEE operations in
/// the same order lane by lane (no fused multiply-add), hence the same bits.
///
/// # Safety
/// The CPU must support AVX2. (An `unsafe fn`, not a safe `#[target_feature]` function: those
/// need rustc 1.86, and the win64 FMUs are built with Debian bookworm's rustc 1.85.)
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sum_avx(blocks: &[Block], tau: f64, x: f64) -> f64 {
    use std::arch::x86_64::*;
    let load = |a: &[f64; LANES]| {
        // SAFETY: `a` is a valid, readable [f64; 4], the 32 bytes an unaligned load reads.
        unsafe { _mm256_loadu_pd(a.as_ptr()) }
    };
    let (tau, x) = (_mm256_set1_pd(tau), _mm256_set1_pd(x));
    let (inv_pi, shift) = (_mm256_set1_pd(FRAC_1_PI), _mm256_set1_pd(SHIFT));
    let (p1, p2, p3) = (_mm256_set1_pd(P1), _mm256_set1_pd(P2), _mm256_set1_pd(P3));
    let one = _mm256_set1_epi64x(1);
    let mut acc = _mm256_setzero_pd();
    for b in blocks {
        let theta = _mm256_sub_pd(
            _mm256_add_pd(load(&b.phase), _mm256_mul_pd(load(&b.frequency), tau)),
            _mm256_mul_pd(load(&b.wavenumber), x),
        );
        let shifted = _mm256_add_pd(_mm256_mul_pd(theta, inv_pi), shift);
        let n = _mm256_sub_pd(shifted, shift);
        let r = _mm256_sub_pd(
            _mm256_sub_pd(
                _mm256_sub_pd(theta, _mm256_mul_pd(n, p1)),
                _mm256_mul_pd(n, p2),
            ),
            _mm256_mul_pd(n, p3),
        );
        // min(R2_MAX, r²) with a NaN r² kept, as in `cos`
        let r2 = _mm256_min_pd(_mm256_set1_pd(R2_MAX), _mm256_mul_pd(r, r));
        let mut c = _mm256_set1_pd(COS_TAYLOR[0]);
        for &k in &COS_TAYLOR[1..] {
            c = _mm256_add_pd(_mm256_mul_pd(c, r2), _mm256_set1_pd(k));
        }
        let sign = _mm256_slli_epi64::<63>(_mm256_and_si256(_mm256_castpd_si256(shifted), one));
        let c = _mm256_castsi256_pd(_mm256_xor_si256(_mm256_castpd_si256(c), sign));
        acc = _mm256_add_pd(acc, _mm256_mul_pd(load(&b.amplitude), c));
    }
    let mut lanes = [0.0; LANES];
    // SAFETY: `lanes` is a writable [f64; 4], the 32 bytes an unaligned store writes.
    unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), acc) };
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
}

/// The portable sum (the compiler vectorises it two lanes wide on x86-64's baseline SSE2).
#[inline(always)]
fn sum_blocks(blocks: &[Block], tau: f64, x: f64) -> f64 {
    let mut acc = [0.0; LANES];
    for b in blocks {
        for (l, acc) in acc.iter_mut().enumerate() {
            let theta = b.phase[l] + b.frequency[l] * tau - b.wavenumber[l] * x;
            *acc += b.amplitude[l] * cos(theta);
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

/// π = P1 + P2 + P3 (P1, P2: at most 32 significant bits; Cody-Waite).
const P1: f64 = 3.141_592_653_468_251_2;
const P2: f64 = 1.215_420_101_260_793_2e-10;
const P3: f64 = 4.044_532_497_591_901e-21;
/// 1.5·2⁵²: adding it rounds to an integer and leaves that integer in the low mantissa bits.
const SHIFT: f64 = 6_755_399_441_055_744.0;
/// Bound on r² = (θ − nπ)², above (π/2)² ≈ 2.467 so that it never acts on a valid argument.
const R2_MAX: f64 = 2.5;
/// (−1)^j/(2j)!, j = 10 .. 0 (Horner order).
const COS_TAYLOR: [f64; 11] = [
    1.0 / 2_432_902_008_176_640_000.0,
    -1.0 / 6_402_373_705_728_000.0,
    1.0 / 20_922_789_888_000.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 479_001_600.0,
    -1.0 / 3_628_800.0,
    1.0 / 40_320.0,
    -1.0 / 720.0,
    1.0 / 24.0,
    -0.5,
    1.0,
];

/// cos θ, branch-free (see the module documentation).
#[inline(always)]
pub fn cos(theta: f64) -> f64 {
    let shifted = theta * FRAC_1_PI + SHIFT;
    let n = shifted - SHIFT;
    let odd = (shifted.to_bits() & 1) << 63;
    let r = ((theta - n * P1) - n * P2) - n * P3;
    let r2 = r * r;
    // |r| ≤ π/2 for |θ| < 2⁵⁰; beyond, r is meaningless and the bound keeps the result within
    // [−1, 1] instead of the polynomial's overflow (NaN stays NaN: the comparison is false)
    let r2 = if R2_MAX < r2 { R2_MAX } else { r2 };
    let mut c = COS_TAYLOR[0];
    for k in &COS_TAYLOR[1..] {
        c = c * r2 + k;
    }
    f64::from_bits(c.to_bits() ^ odd)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{channel, NoiseStream};
    use std::f64::consts::PI;

    #[test]
    fn constants_are_the_stated_values() {
        // P1 + P2 rounds to π; P1 and P2 have at most 32 significant bits
        assert_eq!(P1 + P2, PI);
        for p in [P1, P2] {
            assert_eq!(p.to_bits() & ((1 << 21) - 1), 0, "{p:e}");
        }
    }

    #[test]
    fn cosine_agrees_with_libm() {
        let mut rng = NoiseStream::new(11, channel::WAVE_COMPONENTS);
        // |θ| < 10⁷: 5e-16 absolute
        for scale in [1.0, 10.0, 1e3, 1e5, 1e7] {
            let mut worst = 0.0f64;
            for _ in 0..200_000 {
                let t = (2.0 * rng.uniform() - 1.0) * scale;
                worst = worst.max((cos(t) - t.cos()).abs());
            }
            assert!(worst < 5e-16, "|θ| < {scale:e}: {worst:e}");
        }
        assert_eq!(cos(0.0), 1.0);
        assert_eq!(cos(PI), -1.0);
        // up to 3·10⁸ (10⁸ s of 3 rad/s waves): the error stays near the rounding of θ itself
        // (one unit in the last place of 3·10⁸ is 6·10⁻⁸)
        let mut worst = 0.0f64;
        for _ in 0..100_000 {
            let t = rng.uniform() * 3e8;
            worst = worst.max((cos(t) - t.cos()).abs());
        }
        assert!(worst < 1.2e-7, "|θ| < 3e8: {worst:e}");
        assert!(cos(f64::NAN).is_nan());
        // out of range: meaningless but bounded, never an overflow
        for t in [1e16, -3e17, 1e100, f64::MAX, -f64::MAX] {
            assert!(cos(t).abs() <= 1.0, "cos({t:e}) = {}", cos(t));
        }
    }

    /// The AVX2 path and the portable path give the same bits (on a machine without AVX2 there
    /// is only the portable path, and `sum` is it).
    #[test]
    fn every_path_gives_the_same_bits() {
        let mut s = Sinusoids::with_capacity(401);
        let mut rng = NoiseStream::new(5, channel::WAVE_COMPONENTS);
        for _ in 0..401 {
            let w = 0.2 + 3.0 * rng.uniform();
            s.push(rng.uniform(), w, w * w / 9.81, 2.0 * PI * rng.uniform());
        }
        // ordinary arguments, and out-of-range ones (bounded the same way on both paths)
        let far = [(0.0, 1e300), (1e18, -2e17), (1e300, 0.0)];
        for k in 0..2000 + far.len() {
            let (tau, x) = far.get(k.wrapping_sub(2000)).copied().unwrap_or((
                k as f64 * 0.05,
                3.0 * (k as f64 * 0.01).sin() - 7e3 * rng.uniform(),
            ));
            let portable = sum_blocks(&s.blocks, tau, x);
            assert_eq!(s.sum(tau, x).to_bits(), portable.to_bits(), "{tau} {x}");
            assert!(portable.abs() <= 401.0, "{tau} {x}: {portable}");
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: AVX2 is available (checked).
                let wide = unsafe { sum_avx(&s.blocks, tau, x) };
                assert_eq!(wide.to_bits(), portable.to_bits(), "{tau} {x}");
            }
        }
    }

    #[test]
    fn sum_is_the_sum_of_the_components() {
        let mut s = Sinusoids::with_capacity(7);
        let mut rng = NoiseStream::new(3, channel::WAVE_COMPONENTS);
        let comps: Vec<[f64; 4]> = (0..7)
            .map(|_| {
                let w = 0.3 + 2.0 * rng.uniform();
                [rng.uniform(), w, w * w / 9.81, 2.0 * PI * rng.uniform()]
            })
            .collect();
        for c in &comps {
            s.push(c[0], c[1], c[2], c[3]);
        }
        assert_eq!(s.len(), 7);
        assert_eq!(
            s.get(5),
            (comps[5][0], comps[5][1], comps[5][2], comps[5][3])
        );
        for (tau, x) in [(0.0, 0.0), (12.5, -3.0), (1e4, 2e4)] {
            let direct: f64 = comps
                .iter()
                .map(|c| c[0] * (c[3] + c[1] * tau - c[2] * x).cos())
                .sum();
            assert!((s.sum(tau, x) - direct).abs() < 1e-12, "{tau} {x}");
        }
    }
}
