//! Spectral estimation for checking realisations: radix-2 FFT, Welch's averaged periodogram and
//! spectral moments. Used by the tests (and by users who want to look at a recorded signal).

use crate::math::{cos, sin_cos};
use std::f64::consts::PI;

/// In-place radix-2 complex FFT (forward, no scaling). `re.len()` must be a power of two.
pub fn fft(re: &mut [f64], im: &mut [f64]) {
    let n = re.len();
    assert!(n.is_power_of_two() && im.len() == n);
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let ang = -2.0 * PI / len as f64;
        for start in (0..n).step_by(len) {
            for k in 0..len / 2 {
                let (s, c) = sin_cos(ang * k as f64);
                let (a, b) = (start + k, start + k + len / 2);
                let tr = re[b] * c - im[b] * s;
                let ti = re[b] * s + im[b] * c;
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
            }
        }
        len <<= 1;
    }
}

/// Welch estimate of the one-sided power spectral density of `x` sampled every `dt` seconds,
/// per unit **angular** frequency: returns (ω [rad/s], S(ω)) with `Σ S Δω ≈ var(x)`.
/// Hann window, segments of `nseg` (power of two) samples, 50 % overlap, mean removed per segment.
pub fn welch(x: &[f64], dt: f64, nseg: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(nseg.is_power_of_two() && x.len() >= nseg);
    let w: Vec<f64> = (0..nseg)
        .map(|i| 0.5 - 0.5 * cos(2.0 * PI * i as f64 / nseg as f64))
        .collect();
    let wss: f64 = w.iter().map(|v| v * v).sum();
    let nf = nseg / 2 + 1;
    let mut acc = vec![0.0; nf];
    let mut count = 0;
    let mut start = 0;
    let (mut re, mut im) = (vec![0.0; nseg], vec![0.0; nseg]);
    while start + nseg <= x.len() {
        let seg = &x[start..start + nseg];
        let m = seg.iter().sum::<f64>() / nseg as f64;
        for i in 0..nseg {
            re[i] = (seg[i] - m) * w[i];
            im[i] = 0.0;
        }
        fft(&mut re, &mut im);
        for k in 0..nf {
            acc[k] += re[k] * re[k] + im[k] * im[k];
        }
        count += 1;
        start += nseg / 2;
    }
    let fs = 1.0 / dt;
    let dw = 2.0 * PI * fs / nseg as f64;
    let omega: Vec<f64> = (0..nf).map(|k| k as f64 * dw).collect();
    let s: Vec<f64> = acc
        .iter()
        .enumerate()
        .map(|(k, a)| {
            let one_sided = if k == 0 || k == nf - 1 { 1.0 } else { 2.0 };
            one_sided * a / (count as f64 * fs * wss) / (2.0 * PI)
        })
        .collect();
    (omega, s)
}

/// n-th spectral moment `Σ ωⁿ S(ω) Δω` of a uniformly sampled spectrum.
pub fn moment(omega: &[f64], s: &[f64], n: i32) -> f64 {
    let dw = omega[1] - omega[0];
    omega
        .iter()
        .zip(s)
        .map(|(w, v)| if *w > 0.0 { w.powi(n) * v } else { 0.0 })
        .sum::<f64>()
        * dw
}

/// Robust peak frequency of a (noisy) spectrum: the centroid of Sᵏ,
/// `ω_p ≈ Σ ω Sᵏ / Σ Sᵏ` (Young 1995 uses k = 4). Biased high for broad spectra (PM: +4.9 % at
/// k = 4, +1.2 % at k = 8; analytic: (1.25k)^¼ Γ(5k/4 − ½)/Γ(5k/4 − ¼)), so compare it with the
/// same estimator applied to the target spectrum on the same grid.
pub fn peak_frequency_centroid(omega: &[f64], s: &[f64], k: i32) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (w, v) in omega.iter().zip(s) {
        let v4 = v.powi(k);
        num += w * v4;
        den += v4;
    }
    num / den
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::NoiseStream;

    #[test]
    fn fft_of_a_cosine() {
        let n = 64;
        let mut re: Vec<f64> = (0..n)
            .map(|i| cos(2.0 * PI * 5.0 * i as f64 / n as f64))
            .collect();
        let mut im = vec![0.0; n];
        fft(&mut re, &mut im);
        assert!((re[5] - 32.0).abs() < 1e-9 && (re[59] - 32.0).abs() < 1e-9);
        assert!(re[4].abs() < 1e-9 && im[5].abs() < 1e-9);
    }

    #[test]
    fn welch_of_white_noise_integrates_to_the_variance() {
        let mut r = NoiseStream::new(3, 0);
        let x: Vec<f64> = (0..65536).map(|_| 2.0 * r.normal()).collect();
        let (w, s) = welch(&x, 0.5, 1024);
        let m0 = moment(&w, &s, 0);
        assert!((m0 / 4.0 - 1.0).abs() < 0.03, "{m0}");
        // flat: 4 / (π/0.5) per rad/s
        let level = 4.0 / (PI / 0.5);
        let mid: f64 = s[100..400].iter().sum::<f64>() / 300.0;
        assert!((mid / level - 1.0).abs() < 0.03);
    }
}
