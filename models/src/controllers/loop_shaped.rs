//! Loop-shaped heading autopilot and cross-track controller of the DDG-51 thesis [Taylor2000, ch. 5],
//! discretised by Tustin at a fixed internal step in the nondimensional time base, with the
//! ±30° command limit and the reference generators of the thesis's manoeuvres.
//!
//! # Source
//! [Taylor2000]:
//! * plant [Taylor2000, sec. 5.2.1]: Nomoto P_ψ = K/(s(Ts+1)), T = 1.9287, K = 2.04 [Taylor2000, eqs. (5.24)–(5.27)], steering gear
//!   6/(s+6) [Taylor2000, eq. (5.28)], |δ_c| ≤ 30° [Taylor2000, sec. 5.2.1], track plant P_y = P/s [Taylor2000, eq. (5.39)];
//! * heading autopilot [Taylor2000, sec. 5.2.2]: the loop L = ω_n²/(s(s² + 2ζω_n s + ω_n²)), ω_n = √60, ζ = 2
//!   [Taylor2000, eqs. (5.32)–(5.34)], controller C = L/P [Taylor2000, eq. (5.30)] =
//!   ω_n²/(K·a) (Ts+1)(s+a)/(s² + 2ζω_n s + ω_n²) with a = 6;
//! * cross-track controller C_y = 20(s+0.5)²(s+6)(s+1000)/((s+11)(s+15)(s+30)²)
//!   [Taylor2000, sec. 5.3.2];
//! * the printed margins, the low-frequency gain criterion and the step criteria
//!   [Taylor2000, sec. 5.1.4, 5.2.2 and 5.3.2] are tested.
//!
//! # Readings taken
//! * OCR of [Taylor2000, eqs. (5.32)–(5.34)] (`L=PC= / s(s 2 + 2(wn + n2)`, `Wn = 0/-0`, `(= 2`) read as
//!   ω_n = √60, ζ = 2: the only reading that reproduces the printed margins exactly.
//! * Time base: everything in t′ = tU/L (L = 466 ft, U = 22 kn, L/U = 12.55 s): the printed margins
//!   hold only when the 6/(s+6) gear is in the same time base as the Nomoto model.
//!   The FMU interface is SI (s, rad, m) and converts.
//! * Cross-track y′ = y/L (so that ẏ′ = ψ, [Taylor2000, eq. (5.37)]).
//!
//! # Realisation
//! The continuous controller is realised in controllable canonical form and discretised by Tustin
//! (bilinear) at the internal step τ_s (default 0.01 ship lengths); the sampled output is held
//! between samples (no direct feedthrough at the co-simulation interface, so no algebraic loop
//! with the plant). Per sample: one fixed-size state update, no allocation.

pub mod presets;

use super::ControlError;
use crate::error::{check_finite, check_positive, check_positive_or_infinite};
use crate::math::{cos, ln, log10, powf, sin_cos};
use crate::memo::{bits, Bits, Memo};
use nalgebra::{Complex, DMatrix, SMatrix, SVector};
use serde::{Deserialize, Serialize};

/// A polynomial, highest power first.
pub type Poly = Vec<f64>;

/// Product of two polynomials.
pub fn poly_mul(a: &[f64], b: &[f64]) -> Poly {
    let mut c = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            c[i + j] += x * y;
        }
    }
    c
}

/// Polynomial ∏(s + r_i) times `gain`.
pub fn poly_from_roots(gain: f64, neg_roots: &[f64]) -> Poly {
    neg_roots
        .iter()
        .fold(vec![gain], |p, r| poly_mul(&p, &[1.0, *r]))
}

/// Evaluates a polynomial at complex `s`.
pub fn poly_eval(p: &[f64], s: Complex<f64>) -> Complex<f64> {
    p.iter().fold(Complex::new(0.0, 0.0), |acc, c| {
        acc * s + Complex::new(*c, 0.0)
    })
}

/// A rational transfer function num/den (highest power first).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransferFunction {
    pub num: Poly,
    pub den: Poly,
}

impl TransferFunction {
    pub fn eval(&self, s: Complex<f64>) -> Complex<f64> {
        poly_eval(&self.num, s) / poly_eval(&self.den, s)
    }

    pub fn series(&self, other: &TransferFunction) -> TransferFunction {
        TransferFunction {
            num: poly_mul(&self.num, &other.num),
            den: poly_mul(&self.den, &other.den),
        }
    }

    /// Frequency response at ω.
    pub fn freq(&self, w: f64) -> Complex<f64> {
        self.eval(Complex::new(0.0, w))
    }
}

/// Gain and phase margins of an open loop: (GM [dB], ω_pc, PM [deg], ω_gc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Margins {
    pub gain_margin_db: f64,
    pub phase_crossover: f64,
    pub phase_margin_deg: f64,
    pub gain_crossover: f64,
}

/// Bisection on a bracketing interval of a continuous function.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let flo = f(lo);
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if (f(mid) > 0.0) == (flo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi / lo - 1.0 < 1e-15 {
            break;
        }
    }
    (lo * hi).sqrt()
}

/// Margins of the loop `l` from a logarithmic scan of [w_lo, w_hi] refined by bisection: the first
/// gain crossover (|L| = 1) and the first phase crossover (unwrapped phase = −180°).
pub fn margins(l: &TransferFunction, w_lo: f64, w_hi: f64) -> Option<Margins> {
    let n = 4000;
    let ws: Vec<f64> = (0..=n)
        .map(|i| w_lo * powf(w_hi / w_lo, i as f64 / n as f64))
        .collect();
    // unwrapped phase along the scan
    let mut phase = Vec::with_capacity(ws.len());
    let mut last = l.freq(ws[0]).arg();
    let mut offset = 0.0;
    for w in &ws {
        let p = l.freq(*w).arg();
        let d = p - last;
        if d > std::f64::consts::PI {
            offset -= 2.0 * std::f64::consts::PI;
        } else if d < -std::f64::consts::PI {
            offset += 2.0 * std::f64::consts::PI;
        }
        last = p;
        phase.push(p + offset);
    }
    let unwrap_at = |w: f64, near: f64| {
        let p = l.freq(w).arg();
        let k = ((near - p) / (2.0 * std::f64::consts::PI)).round();
        p + k * 2.0 * std::f64::consts::PI
    };
    let mag = |w: f64| ln(l.freq(w).norm());
    let mut gc = None;
    let mut pc = None;
    for i in 0..n {
        if gc.is_none() && (mag(ws[i]) > 0.0) != (mag(ws[i + 1]) > 0.0) {
            gc = Some(bisect(mag, ws[i], ws[i + 1]));
        }
        let target = -std::f64::consts::PI;
        if pc.is_none() && (phase[i] > target) != (phase[i + 1] > target) {
            let near = phase[i];
            pc = Some(bisect(|w| unwrap_at(w, near) - target, ws[i], ws[i + 1]));
        }
    }
    let (gc, pc) = (gc?, pc?);
    let near_gc = {
        let i = ws.iter().position(|w| *w >= gc).unwrap_or(n);
        phase[i]
    };
    Some(Margins {
        gain_margin_db: -20.0 * log10(l.freq(pc).norm()),
        phase_crossover: pc,
        phase_margin_deg: 180.0 + unwrap_at(gc, near_gc).to_degrees(),
        gain_crossover: gc,
    })
}

/// Nomoto heading plant with the steering gear, P = K a / (s (T s + 1)(s + a)) [Taylor2000, eqs. (5.27)–(5.29)].
pub fn heading_plant(k: f64, t: f64, gear_pole: f64) -> TransferFunction {
    TransferFunction {
        num: vec![k * gear_pole],
        den: poly_mul(&poly_mul(&[1.0, 0.0], &[t, 1.0]), &[1.0, gear_pole]),
    }
}

/// Track plant P_y = P/s [Taylor2000, eq. (5.39)].
pub fn track_plant(k: f64, t: f64, gear_pole: f64) -> TransferFunction {
    let p = heading_plant(k, t, gear_pole);
    TransferFunction {
        num: p.num,
        den: poly_mul(&p.den, &[1.0, 0.0]),
    }
}

/// A biproper (or strictly proper) continuous SISO controller of order N discretised by Tustin,
/// with the output limited to ±`limit` and held between samples.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TustinController<const N: usize> {
    ad: SMatrix<f64, N, N>,
    bd: SVector<f64, N>,
    cd: SVector<f64, N>,
    dd: f64,
    x: SVector<f64, N>,
    pub limit: f64,
    /// Output of the last sample (held), after the limiter.
    pub output: f64,
    /// Output before the limiter.
    pub unlimited: f64,
}

impl<const N: usize> TustinController<N> {
    /// Realises `tf` (denominator of degree N, numerator degree ≤ N) at step `step`.
    pub fn new(tf: &TransferFunction, step: f64, limit: f64) -> Result<Self, ControlError> {
        if tf.den.len() != N + 1 || tf.num.len() > N + 1 || tf.den[0] == 0.0 {
            return Err(ControlError(format!(
                "controller of order {N}: denominator has {} coefficients, numerator {}",
                tf.den.len(),
                tf.num.len()
            )));
        }
        check_positive("sample step", step)?;
        check_positive_or_infinite("command limit", limit)?;
        // Normalised by a0 (computed where used: no allocation, the same divisions).
        let a0 = tf.den[0];
        let den = |i: usize| tf.den[i] / a0;
        let pad = N + 1 - tf.num.len();
        let num = |i: usize| if i < pad { 0.0 } else { tf.num[i - pad] / a0 };
        let d = num(0);
        // strictly proper remainder b(s) = num − d·den, coefficients of s^(N−1) … s^0
        let b: [f64; N] = std::array::from_fn(|k| num(k + 1) - d * den(k + 1));
        // controllable canonical form: x = (x1 … xN), ẋ_i = x_(i+1), ẋ_N = −Σ den_(N−j) x_(j+1) + u
        let mut a = SMatrix::<f64, N, N>::zeros();
        for i in 0..N - 1 {
            a[(i, i + 1)] = 1.0;
        }
        for j in 0..N {
            a[(N - 1, j)] = -den(N - j);
        }
        let mut bv = SVector::<f64, N>::zeros();
        bv[N - 1] = 1.0;
        let mut c = SVector::<f64, N>::zeros();
        for j in 0..N {
            c[j] = b[N - 1 - j];
        }
        // Tustin: M = (I − A T/2)⁻¹, Ad = M (I + A T/2), Bd = M B T, Cd = C M, Dd = D + C Bd / 2
        let eye = SMatrix::<f64, N, N>::identity();
        let m = (eye - a * (step / 2.0))
            .try_inverse()
            .ok_or_else(|| ControlError("Tustin: I − A T/2 singular".into()))?;
        let ad = m * (eye + a * (step / 2.0));
        let bd = m * bv * step;
        let cd = (c.transpose() * m).transpose();
        let dd = d + 0.5 * c.dot(&bd);
        Ok(TustinController {
            ad,
            bd,
            cd,
            dd,
            x: SVector::zeros(),
            limit,
            output: 0.0,
            unlimited: 0.0,
        })
    }

    /// The same controller discretised at another step, keeping the state and the held output.
    pub fn rediscretised(
        &self,
        tf: &TransferFunction,
        step: f64,
        limit: f64,
    ) -> Result<Self, ControlError> {
        Ok(Self::new(tf, step, limit)?.with_state_of(self))
    }

    /// This realisation with the state and the held output of `other`.
    fn with_state_of(mut self, other: &Self) -> Self {
        self.x = other.x;
        self.output = other.output;
        self.unlimited = other.unlimited;
        self
    }

    /// One sample: output for the error `e` (held until the next sample), then the state update.
    pub fn sample(&mut self, e: f64) -> f64 {
        let y = self.cd.dot(&self.x) + self.dd * e;
        self.x = self.ad * self.x + self.bd * e;
        self.unlimited = y;
        self.output = y.clamp(-self.limit, self.limit);
        self.output
    }

    /// Discrete frequency response at ω (z = e^{jωT}).
    pub fn freq(&self, w: f64, step: f64) -> Complex<f64> {
        let (sin_wt, cos_wt) = sin_cos(w * step);
        let z = Complex::new(cos_wt, sin_wt);
        let ad = DMatrix::from_fn(N, N, |i, j| Complex::new(self.ad[(i, j)], 0.0));
        let mut zi = DMatrix::from_fn(N, N, |i, j| if i == j { z } else { Complex::new(0.0, 0.0) });
        zi -= ad;
        let inv = zi.try_inverse().expect("z outside the spectrum");
        let b = nalgebra::DVector::from_fn(N, |i, _| Complex::new(self.bd[i], 0.0));
        let x = inv * b;
        (0..N).fold(Complex::new(self.dd, 0.0), |acc, i| acc + x[i] * self.cd[i])
    }
}

/// The common frame of both FMUs: ship scale, Nomoto plant for the design, sample step, limit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LoopShapingCommon {
    /// Nomoto K′ and T′ [Taylor2000, eqs. (5.25)–(5.26)] and the steering-gear pole a of a/(s+a) [Taylor2000, eq. (5.28)],
    /// all in t′ = tU/L.
    pub nomoto_k: f64,
    pub nomoto_t: f64,
    pub gear_pole: f64,
    /// Internal Tustin step τ_s in ship lengths (t′).
    pub sample_step: f64,
    /// Rudder command limit [rad] (30°).
    pub limit: f64,
    /// Ship length L [m] and speed U [m/s] of the time base (466 ft, 22 kn).
    pub length: f64,
    pub speed: f64,
}

impl Default for LoopShapingCommon {
    fn default() -> Self {
        LoopShapingCommon {
            nomoto_k: 2.04,
            nomoto_t: 1.9287,
            gear_pole: 6.0,
            sample_step: 0.01,
            limit: 30f64.to_radians(),
            length: 466.0 * 0.3048,
            speed: 22.0 * 1852.0 / 3600.0,
        }
    }
}

impl LoopShapingCommon {
    fn validate(&self) -> Result<(), ControlError> {
        for (n, v) in [
            ("nomoto_k", self.nomoto_k),
            ("nomoto_t", self.nomoto_t),
            ("gear_pole", self.gear_pole),
            ("sample_step", self.sample_step),
            ("limit", self.limit),
            ("length", self.length),
            ("speed", self.speed),
        ] {
            check_positive(n, v)?;
        }
        Ok(())
    }
}

/// Heading autopilot design parameters [Taylor2000, sec. 5.2.2].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HeadingDesign {
    pub common: LoopShapingCommon,
    /// Target loop ω_n and ζ (√60, 2).
    pub omega_n: f64,
    pub zeta: f64,
}

impl Default for HeadingDesign {
    fn default() -> Self {
        HeadingDesign {
            common: LoopShapingCommon::default(),
            omega_n: 60f64.sqrt(),
            zeta: 2.0,
        }
    }
}

impl HeadingDesign {
    /// C = L/P = ω_n²/(K a) (T s + 1)(s + a)/(s² + 2ζω_n s + ω_n²) [Taylor2000, eq. (5.30)].
    pub fn controller(&self) -> Result<TransferFunction, ControlError> {
        let c = &self.common;
        c.validate()?;
        check_positive("omega_n", self.omega_n)?;
        check_positive("zeta", self.zeta)?;
        let w2 = self.omega_n * self.omega_n;
        Ok(TransferFunction {
            num: poly_mul(
                &[
                    c.nomoto_t * w2 / (c.nomoto_k * c.gear_pole),
                    w2 / (c.nomoto_k * c.gear_pole),
                ],
                &[1.0, c.gear_pole],
            ),
            den: vec![1.0, 2.0 * self.zeta * self.omega_n, w2],
        })
    }

    /// The open loop P·C of the implemented controller.
    pub fn open_loop(&self) -> Result<TransferFunction, ControlError> {
        let c = &self.common;
        Ok(heading_plant(c.nomoto_k, c.nomoto_t, c.gear_pole).series(&self.controller()?))
    }
}

/// Cross-track controller design parameters [Taylor2000, sec. 5.3.2]: C_y = gain ∏(s + z_i)/∏(s + p_i).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrackDesign {
    pub common: LoopShapingCommon,
    pub gain: f64,
    pub zeros: [f64; 4],
    pub poles: [f64; 4],
}

impl Default for TrackDesign {
    fn default() -> Self {
        TrackDesign {
            common: LoopShapingCommon::default(),
            gain: 20.0,
            zeros: [0.5, 0.5, 6.0, 1000.0],
            poles: [11.0, 15.0, 30.0, 30.0],
        }
    }
}

impl TrackDesign {
    pub fn controller(&self) -> Result<TransferFunction, ControlError> {
        self.common.validate()?;
        check_finite("gain", self.gain)?;
        for v in &self.zeros {
            check_finite("zeros", *v)?;
        }
        for v in &self.poles {
            check_finite("poles", *v)?;
        }
        Ok(TransferFunction {
            num: poly_from_roots(self.gain, &self.zeros),
            den: poly_from_roots(1.0, &self.poles),
        })
    }

    pub fn open_loop(&self) -> Result<TransferFunction, ControlError> {
        let c = &self.common;
        Ok(track_plant(c.nomoto_k, c.nomoto_t, c.gear_pole).series(&self.controller()?))
    }
}

/// Smooth 90° track-change heading profile of [Taylor2000, sec. 5.2.3.2]: steady, turn at `turn_rate` by `angle`,
/// steady leg of `leg` seconds, turn back. Times in seconds, angles in rad (negative angle = left).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrackChange {
    pub start: f64,
    pub angle: f64,
    pub turn_rate: f64,
    pub leg: f64,
}

impl Default for TrackChange {
    fn default() -> Self {
        TrackChange {
            start: 60.0,
            angle: -std::f64::consts::FRAC_PI_2,
            turn_rate: 1f64.to_radians(),
            leg: 600.0,
        }
    }
}

impl TrackChange {
    /// Heading reference at time `t` [s] (relative to the initial course).
    pub fn heading(&self, t: f64) -> f64 {
        let dur = self.angle.abs() / self.turn_rate.abs().max(1e-12);
        let s = self.angle.signum();
        let t1 = self.start;
        let t2 = t1 + dur;
        let t3 = t2 + self.leg;
        let t4 = t3 + dur;
        if t <= t1 {
            0.0
        } else if t < t2 {
            s * self.turn_rate.abs() * (t - t1)
        } else if t <= t3 {
            self.angle
        } else if t < t4 {
            self.angle - s * self.turn_rate.abs() * (t - t3)
        } else {
            0.0
        }
    }
}

/// Lateral-offset manoeuvre for the track controller: the reference moves by `offset` [m] from
/// `start` over `duration` seconds (a cosine ramp; 0 = a step).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LateralOffset {
    pub start: f64,
    pub offset: f64,
    pub duration: f64,
}

impl Default for LateralOffset {
    fn default() -> Self {
        LateralOffset {
            start: 60.0,
            offset: 0.1 * 466.0 * 0.3048,
            duration: 0.0,
        }
    }
}

impl LateralOffset {
    pub fn cross_track(&self, t: f64) -> f64 {
        if t < self.start {
            0.0
        } else if self.duration <= 0.0 || t >= self.start + self.duration {
            self.offset
        } else {
            let x = (t - self.start) / self.duration;
            self.offset * 0.5 * (1.0 - cos(std::f64::consts::PI * x))
        }
    }
}

/// Wraps an angle to (−π, π].
fn wrap(a: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    let w = a - two_pi * ((a + std::f64::consts::PI) / two_pi).floor();
    if w <= -std::f64::consts::PI {
        w + two_pi
    } else {
        w
    }
}

/// Step-aligned sampling shared by both controllers: each communication step h′ (in t′) is split
/// into n = ⌈h′/τ_max⌉ equal samples of τ = h′/n, so the samples lie exactly on the communication
/// grid. The controller is re-discretised (Tustin at τ, state kept) only when τ changes.
///
/// Why aligned: the cross-track controller's zero at −1000 lies far above the Nyquist frequency of
/// τ_max = 0.01 (π/τ = 314), so its Tustin form has a zero at z = −1.5 and a large gain at the
/// Nyquist frequency; sampling instants that drift against the (held) measurement grid then leave
/// a residue of that alternating component and change the step overshoot by several percent
/// (found while testing: 24.7–27.1 % instead of 28.5 % for non-integer h′/τ). Aligned samples
/// give the design's response for every communication step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Sampler {
    /// Time since the start [s].
    time: f64,
    /// Tustin sample step τ of the current discretisation (t′).
    sample_step: f64,
}

/// A realisation kept for the (sample step, limit) it was built for (derived, see
/// [`crate::memo`]).
type Spare<const N: usize> = Memo<Bits<2>, TustinController<N>>;

/// The sampling work of a communication step of `h` seconds for the work bound of one FMU step:
/// `each("sample_step", sample step in seconds, samples)` ([`Sampler::split`] takes
/// ⌈h U/L / τ_max⌉ samples).
fn sampling_work(c: &LoopShapingCommon, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
    let scale = c.speed / c.length;
    let samples = if c.sample_step > 0.0 {
        h * scale / c.sample_step
    } else {
        f64::INFINITY
    };
    each("sample_step", c.sample_step / scale, samples);
}

impl Sampler {
    /// (n, τ) for a communication step of `h_prime`.
    fn split(h_prime: f64, tau_max: f64) -> (usize, f64) {
        let n = ((h_prime / tau_max) * (1.0 - 1e-12)).ceil().max(1.0);
        (n as usize, h_prime / n)
    }

    /// Splits a communication step of `h` seconds into n equal samples of at most the design's
    /// sample step (in t′) and re-discretises `discrete` when the sample step changes (keeping
    /// the old realisation if the new one cannot be built). Returns n.
    ///
    /// A master's steps t_(k+1) − t_k differ in their last bits (the grid times are rounded), so
    /// the sample step alternates between a few values: the realisation it replaces is kept in
    /// `spare` and reused when its step comes back.
    fn prepare<const N: usize>(
        &mut self,
        discrete: &mut TustinController<N>,
        spare: &mut Spare<N>,
        transfer_function: &TransferFunction,
        c: &LoopShapingCommon,
        h: f64,
    ) -> usize {
        let scale = c.speed / c.length;
        let (n, tau) = Sampler::split(h * scale, c.sample_step);
        if tau != self.sample_step {
            let key = bits([tau, c.limit]);
            let next = match spare.take(&key) {
                Some(kept) => Ok(kept),
                None => TustinController::new(transfer_function, tau, c.limit),
            };
            if let Ok(next) = next {
                spare.put(bits([self.sample_step, discrete.limit]), *discrete);
                *discrete = next.with_state_of(discrete);
                self.sample_step = tau;
            }
        }
        n
    }
}

/// Reference source of the heading autopilot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum HeadingReference {
    /// The `heading_reference` input.
    External,
    /// [`TrackChange`] relative to the heading at the start.
    TrackChange,
}

/// The heading autopilot: δ_c = sat(C(z)·(ψ_ref − ψ)), sampled at τ_s, output held.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HeadingAutopilot {
    pub design: HeadingDesign,
    pub reference: HeadingReference,
    pub track_change: TrackChange,
    /// The continuous controller C(s) of the design.
    transfer_function: TransferFunction,
    /// Its Tustin realisation at the current sample step.
    discrete: TustinController<2>,
    /// The realisation at the previous sample step.
    #[serde(skip)]
    spare: Spare<2>,
    sampler: Sampler,
    initial_heading: f64,
    last_reference: f64,
}

impl HeadingAutopilot {
    pub fn new(design: HeadingDesign) -> Result<Self, ControlError> {
        let tf = design.controller()?;
        Ok(HeadingAutopilot {
            discrete: TustinController::new(&tf, design.common.sample_step, design.common.limit)?,
            transfer_function: tf,
            design,
            reference: HeadingReference::External,
            track_change: TrackChange::default(),
            sampler: Sampler {
                time: 0.0,
                sample_step: design.common.sample_step,
            },
            spare: Spare::default(),
            initial_heading: 0.0,
            last_reference: 0.0,
        })
    }

    /// Re-discretises after a design change (controller state kept).
    pub fn set_design(&mut self, design: HeadingDesign) -> Result<(), ControlError> {
        let tf = design.controller()?;
        self.discrete =
            self.discrete
                .rediscretised(&tf, self.sampler.sample_step, design.common.limit)?;
        self.transfer_function = tf;
        self.spare.clear();
        self.design = design;
        Ok(())
    }

    /// Starts at t = 0 with the ship's heading (the track-change generator is relative to it).
    pub fn start(&mut self, heading: f64, external_reference: f64) {
        self.initial_heading = heading;
        self.last_reference = self.reference_at(0.0, external_reference);
    }

    /// Time since the start [s].
    pub fn time(&self) -> f64 {
        self.sampler.time
    }

    /// The Tustin step τ (t′) in use.
    pub fn sample_step(&self) -> f64 {
        self.sampler.sample_step
    }

    fn reference_at(&self, t: f64, external: f64) -> f64 {
        match self.reference {
            HeadingReference::External => external,
            HeadingReference::TrackChange => self.initial_heading + self.track_change.heading(t),
        }
    }

    /// Rudder command δ_c [rad] (held output of the last sample).
    pub fn command(&self) -> f64 {
        self.discrete.output
    }

    /// Command before the ±limit.
    pub fn unlimited_command(&self) -> f64 {
        self.discrete.unlimited
    }

    /// Heading reference used at the last sample [rad].
    pub fn heading_reference(&self) -> f64 {
        self.last_reference
    }

    /// The sampling work of a step of `h` seconds (see `sampling_work`).
    pub fn internal_steps(&self, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        sampling_work(&self.design.common, h, each);
    }

    /// Advances `h` seconds with the measured heading and external reference held.
    pub fn step(&mut self, heading: f64, external_reference: f64, h: f64) {
        if !(h > 0.0) || !h.is_finite() {
            return;
        }
        let c = self.design.common;
        let n = self.sampler.prepare(
            &mut self.discrete,
            &mut self.spare,
            &self.transfer_function,
            &c,
            h,
        );
        for i in 0..n {
            let t = self.sampler.time + i as f64 * h / n as f64;
            let r = self.reference_at(t, external_reference);
            self.last_reference = r;
            self.discrete.sample(wrap(r - heading));
        }
        self.sampler.time += h;
    }

    pub fn controller(&self) -> &TustinController<2> {
        &self.discrete
    }
}

/// Reference source of the track controller.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum TrackReference {
    External,
    LateralOffset,
}

/// The cross-track controller: δ_c = sat(C_y(z)·(y_ref − y)/L), sampled at τ_s, output held.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrackController {
    pub design: TrackDesign,
    pub reference: TrackReference,
    pub lateral_offset: LateralOffset,
    /// The continuous controller C(s) of the design.
    transfer_function: TransferFunction,
    /// Its Tustin realisation at the current sample step.
    discrete: TustinController<4>,
    /// The realisation at the previous sample step.
    #[serde(skip)]
    spare: Spare<4>,
    sampler: Sampler,
    last_reference: f64,
}

impl TrackController {
    pub fn new(design: TrackDesign) -> Result<Self, ControlError> {
        let tf = design.controller()?;
        Ok(TrackController {
            discrete: TustinController::new(&tf, design.common.sample_step, design.common.limit)?,
            transfer_function: tf,
            design,
            reference: TrackReference::External,
            lateral_offset: LateralOffset::default(),
            spare: Spare::default(),
            sampler: Sampler {
                time: 0.0,
                sample_step: design.common.sample_step,
            },
            last_reference: 0.0,
        })
    }

    pub fn set_design(&mut self, design: TrackDesign) -> Result<(), ControlError> {
        let tf = design.controller()?;
        self.discrete =
            self.discrete
                .rediscretised(&tf, self.sampler.sample_step, design.common.limit)?;
        self.transfer_function = tf;
        self.spare.clear();
        self.design = design;
        Ok(())
    }

    /// Time since the start [s].
    pub fn time(&self) -> f64 {
        self.sampler.time
    }

    /// The Tustin step τ (t′) in use.
    pub fn sample_step(&self) -> f64 {
        self.sampler.sample_step
    }

    pub fn start(&mut self, external_reference: f64) {
        self.last_reference = self.reference_at(0.0, external_reference);
    }

    fn reference_at(&self, t: f64, external: f64) -> f64 {
        match self.reference {
            TrackReference::External => external,
            TrackReference::LateralOffset => self.lateral_offset.cross_track(t),
        }
    }

    pub fn command(&self) -> f64 {
        self.discrete.output
    }

    pub fn unlimited_command(&self) -> f64 {
        self.discrete.unlimited
    }

    /// Cross-track reference used at the last sample [m].
    pub fn cross_track_reference(&self) -> f64 {
        self.last_reference
    }

    /// The sampling work of a step of `h` seconds (see `sampling_work`).
    pub fn internal_steps(&self, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        sampling_work(&self.design.common, h, each);
    }

    /// Advances `h` seconds with the measured cross-track position y [m] and reference held.
    pub fn step(&mut self, cross_track: f64, external_reference: f64, h: f64) {
        if !(h > 0.0) || !h.is_finite() {
            return;
        }
        let c = self.design.common;
        let n = self.sampler.prepare(
            &mut self.discrete,
            &mut self.spare,
            &self.transfer_function,
            &c,
            h,
        );
        for i in 0..n {
            let t = self.sampler.time + i as f64 * h / n as f64;
            let r = self.reference_at(t, external_reference);
            self.last_reference = r;
            self.discrete.sample((r - cross_track) / c.length);
        }
        self.sampler.time += h;
    }

    pub fn controller(&self) -> &TustinController<4> {
        &self.discrete
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{exp, sin};

    /// Closed-loop unit step of the (heading or track) loop with the Nomoto plant + gear, in t′:
    /// continuous controller (RK4 on the joint state, dt′ = 1e-3) or the sampled Tustin controller
    /// (ZOH output at τ_s, plant integrated by RK4 in between). Returns (t′, y) samples every
    /// 0.01 t′ up to `t_end`. `track`: the output is y′ (ẏ′ = ψ).
    fn step_response(
        design_tf: &TransferFunction,
        sampled: Option<(TustinController<4>, f64)>,
        c: &LoopShapingCommon,
        track: bool,
        t_end: f64,
    ) -> Vec<(f64, f64)> {
        // plant state: δ, r, ψ, y
        let (k, t, a) = (c.nomoto_k, c.nomoto_t, c.gear_pole);
        let plant = |x: &[f64; 4], u: f64| -> [f64; 4] {
            [a * (u - x[0]), (k * x[0] - x[1]) / t, x[1], x[2]]
        };
        let out = |x: &[f64; 4]| if track { x[3] } else { x[2] };
        // continuous controller: realise via a Tustin controller with a tiny step is not
        // "continuous"; instead integrate its canonical form directly
        let n = design_tf.den.len() - 1;
        let a0 = design_tf.den[0];
        let den: Vec<f64> = design_tf.den.iter().map(|v| v / a0).collect();
        let mut num = vec![0.0; n + 1 - design_tf.num.len()];
        num.extend(design_tf.num.iter().map(|v| v / a0));
        let d = num[0];
        let b: Vec<f64> = (1..=n).map(|i| num[i] - d * den[i]).collect();
        let ctl_out =
            |z: &[f64], e: f64| -> f64 { (0..n).map(|j| b[n - 1 - j] * z[j]).sum::<f64>() + d * e };
        let ctl_der = |z: &[f64], e: f64| -> Vec<f64> {
            let mut dz = vec![0.0; n];
            for i in 0..n - 1 {
                dz[i] = z[i + 1];
            }
            dz[n - 1] = e - (0..n).map(|j| den[n - j] * z[j]).sum::<f64>();
            dz
        };
        let mut x = [0.0; 4];
        let mut z = vec![0.0; n];
        let mut res = Vec::new();
        let dt = 1e-3;
        let steps = (t_end / dt).round() as usize;
        let mut sampled = sampled;
        let mut u_held = 0.0;
        for s in 0..=steps {
            let tt = s as f64 * dt;
            if s % 10 == 0 {
                res.push((tt, out(&x)));
            }
            if s == steps {
                break;
            }
            if let Some((ctl, ts)) = sampled.as_mut() {
                let per = (*ts / dt).round() as usize;
                if s % per == 0 {
                    u_held = ctl.sample(1.0 - out(&x));
                }
                let f = |x: &[f64; 4]| plant(x, u_held);
                let k1 = f(&x);
                let k2 = f(&std::array::from_fn(|i| x[i] + 0.5 * dt * k1[i]));
                let k3 = f(&std::array::from_fn(|i| x[i] + 0.5 * dt * k2[i]));
                let k4 = f(&std::array::from_fn(|i| x[i] + dt * k3[i]));
                x = std::array::from_fn(|i| {
                    x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                });
            } else {
                // joint RK4 of plant + controller (no limiter: the linear design)
                let f = |x: &[f64; 4], z: &[f64]| {
                    let e = 1.0 - out(x);
                    (plant(x, ctl_out(z, e)), ctl_der(z, e))
                };
                let (k1, l1) = f(&x, &z);
                let x2 = std::array::from_fn(|i| x[i] + 0.5 * dt * k1[i]);
                let z2: Vec<f64> = (0..n).map(|i| z[i] + 0.5 * dt * l1[i]).collect();
                let (k2, l2) = f(&x2, &z2);
                let x3 = std::array::from_fn(|i| x[i] + 0.5 * dt * k2[i]);
                let z3: Vec<f64> = (0..n).map(|i| z[i] + 0.5 * dt * l2[i]).collect();
                let (k3, l3) = f(&x3, &z3);
                let x4 = std::array::from_fn(|i| x[i] + dt * k3[i]);
                let z4: Vec<f64> = (0..n).map(|i| z[i] + dt * l3[i]).collect();
                let (k4, l4) = f(&x4, &z4);
                x = std::array::from_fn(|i| {
                    x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                });
                for i in 0..n {
                    z[i] += dt / 6.0 * (l1[i] + 2.0 * l2[i] + 2.0 * l3[i] + l4[i]);
                }
            }
        }
        res
    }

    fn overshoot_and_settling(r: &[(f64, f64)]) -> (f64, f64) {
        let peak = r.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let settle = r
            .iter()
            .rev()
            .find(|p| (p.1 - 1.0).abs() > 0.02)
            .map_or(0.0, |p| p.0);
        (100.0 * (peak - 1.0), settle)
    }

    /// Printed margins of the heading autopilot's loop [Taylor2000, sec. 5.2.2]: GM 29.82 dB at
    /// 7.746, PM 64.41° at 0.9146, within ±0.05 (computed 29.8226 dB, 64.406°).
    #[test]
    fn at1_heading_margins() {
        let l = HeadingDesign::default().open_loop().unwrap();
        let m = margins(&l, 1e-3, 1e3).unwrap();
        eprintln!("AT-1: {m:?}");
        assert!((m.gain_margin_db - 29.82).abs() <= 0.05);
        assert!((m.phase_margin_deg - 64.41).abs() <= 0.05);
        assert!((m.phase_crossover - 7.746).abs() < 1e-3);
        assert!((m.gain_crossover - 0.91463).abs() < 1e-4);
    }

    /// Printed margins of the track loop [Taylor2000, sec. 5.3.2]: GM 21.57 dB at 7.277, PM 50.99° at 0.9514 (±0.05).
    #[test]
    fn at2_track_margins() {
        let l = TrackDesign::default().open_loop().unwrap();
        let m = margins(&l, 1e-3, 1e3).unwrap();
        eprintln!("AT-2: {m:?}");
        assert!((m.gain_margin_db - 21.57).abs() <= 0.05);
        assert!((m.phase_margin_deg - 50.99).abs() <= 0.05);
        assert!((m.phase_crossover - 7.2766).abs() < 1e-3);
        assert!((m.gain_crossover - 0.95135).abs() < 1e-4);
    }

    /// Low-frequency criterion [Taylor2000, sec. 5.2.2]: |L(j0.01)| ≥ 40 dB. The loop gives
    /// 39.9999 dB (a test of ≥ 40 dB must allow that rounding): asserted ≥ 39.99 dB, and ≥ 40 dB
    /// for every ω ≤ 0.0099.
    #[test]
    fn at5_low_frequency_gain() {
        let l = HeadingDesign::default().open_loop().unwrap();
        let db = |w: f64| 20.0 * log10(l.freq(w).norm());
        eprintln!("AT-5: |L(j0.01)| = {:.5} dB", db(0.01));
        assert!(db(0.01) >= 39.99 && db(0.01) < 40.0);
        for w in [1e-4, 1e-3, 0.005, 0.0099] {
            assert!(db(w) >= 40.0);
        }
        // track loop: 72.3 dB
        let ly = TrackDesign::default().open_loop().unwrap();
        assert!((20.0 * log10(ly.freq(0.01).norm()) - 72.3).abs() < 0.05);
    }

    /// Heading step overshoot 4.81 % (printed "5 %", criterion ≤ 5 % [Taylor2000, sec. 5.2.2]),
    /// 2 % settling 4.20 ship lengths (< 5; printed "= 4"). Track step overshoot 28.46 % computed
    /// from the documented controller and plant whose margins match exactly; the printed 25 %
    /// [Taylor2000, Fig. 5-17] is most likely a rounded read-off label, so the test accepts 25–29 % and
    /// asserts the computed value to ±0.05 %.
    #[test]
    fn at3_at4_step_criteria() {
        let hd = HeadingDesign::default();
        let r = step_response(&hd.controller().unwrap(), None, &hd.common, false, 15.0);
        let (os, ts) = overshoot_and_settling(&r);
        eprintln!("AT-3: overshoot {os:.3} %, 2 % settling {ts:.3} L");
        assert!((os - 4.81).abs() < 0.05 && os <= 5.0);
        assert!((ts - 4.20).abs() < 0.05 && ts < 5.0);
        let td = TrackDesign::default();
        let r = step_response(&td.controller().unwrap(), None, &td.common, true, 20.0);
        let (os, ts) = overshoot_and_settling(&r);
        eprintln!("AT-4: overshoot {os:.3} %, 2 % settling {ts:.3} L");
        assert!((os - 28.46).abs() < 0.05 && (25.0..=29.0).contains(&os));
        assert!((ts - 6.84).abs() < 0.05);
    }

    /// The Tustin-discretised controllers (τ_s = 0.01 L, output held between samples) reproduce
    /// the continuous designs' closed-loop step responses within 1 % of the final value, and the
    /// discrete frequency response is within 1 % of the continuous one up to ω = 2.
    #[test]
    fn tustin_matches_continuous_step_response() {
        let hd = HeadingDesign::default();
        let tf = hd.controller().unwrap();
        let cont = step_response(&tf, None, &hd.common, false, 15.0);
        // embed the 2nd-order controller as a 4th-order one with two cancelling dummy states:
        // simpler: compare with the HeadingAutopilot's own TustinController<2> via a local loop
        let mut ctl2 = TustinController::<2>::new(&tf, 0.01, 1e9).unwrap();
        let mut worst: f64 = 0.0;
        {
            let c = &hd.common;
            let (k, t, a) = (c.nomoto_k, c.nomoto_t, c.gear_pole);
            let mut x = [0.0f64; 3];
            let dt = 1e-3;
            let mut u = 0.0;
            for s in 0..15000usize {
                if s % 10 == 0 {
                    u = ctl2.sample(1.0 - x[2]);
                    let ref_y = cont[s / 10].1;
                    worst = worst.max((x[2] - ref_y).abs());
                }
                let f = |x: &[f64; 3]| [a * (u - x[0]), (k * x[0] - x[1]) / t, x[1]];
                let k1 = f(&x);
                let k2 = f(&std::array::from_fn(|i| x[i] + 0.5 * dt * k1[i]));
                let k3 = f(&std::array::from_fn(|i| x[i] + 0.5 * dt * k2[i]));
                let k4 = f(&std::array::from_fn(|i| x[i] + dt * k3[i]));
                x = std::array::from_fn(|i| {
                    x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                });
            }
        }
        eprintln!("heading: max |sampled − continuous| = {worst:.5}");
        assert!(worst < 0.01, "{worst}");
        let td = TrackDesign::default();
        let tfy = td.controller().unwrap();
        let cont = step_response(&tfy, None, &td.common, true, 20.0);
        // (no limiter: the comparison is with the linear design; the unit step asks for 20 rad)
        let ctl4 = TustinController::<4>::new(&tfy, 0.01, 1e9).unwrap();
        let disc = step_response(&tfy, Some((ctl4, 0.01)), &td.common, true, 20.0);
        let worst = cont
            .iter()
            .zip(&disc)
            .map(|(a, b)| (a.1 - b.1).abs())
            .fold(0.0, f64::max);
        eprintln!("track: max |sampled − continuous| = {worst:.5}");
        assert!(worst < 0.01, "{worst}");
        // frequency responses
        for w in [0.01, 0.1, 0.5, 0.9146, 2.0] {
            let (c, d) = (tf.freq(w), ctl2.freq(w, 0.01));
            assert!((c - d).norm() / c.norm() < 0.01, "heading at {w}");
            let (c, d) = (tfy.freq(w), ctl4.freq(w, 0.01));
            assert!((c - d).norm() / c.norm() < 0.01, "track at {w}");
        }
    }

    /// The controller of [Taylor2000, sec. 5.2.2] expands to the printed polynomial form; the track controller to
    /// its printed expansion.
    #[test]
    fn controller_polynomials() {
        let c = HeadingDesign::default().controller().unwrap();
        for (g, w) in c.num.iter().zip([9.454412, 61.628431, 29.411765]) {
            assert!((g - w).abs() < 1e-5, "{g} vs {w}");
        }
        assert!((c.den[1] - 30.983867).abs() < 1e-6);
        let cy = TrackDesign::default().controller().unwrap();
        assert_eq!(cy.num, vec![20.0, 20140.0, 140125.0, 125030.0, 30000.0]);
        assert_eq!(cy.den, vec![1.0, 86.0, 2625.0, 33300.0, 148500.0]);
    }

    /// The ±30° limit, the held sampled output, the heading-error wrap and the reference
    /// generators.
    #[test]
    fn limit_sampling_and_references() {
        let mut ap = HeadingAutopilot::new(HeadingDesign::default()).unwrap();
        ap.start(0.0, 0.0);
        // 90° heading error: the biproper controller asks for 9.45·1.57 rad; limited to 30°
        ap.step(0.0, std::f64::consts::FRAC_PI_2, 0.2);
        assert_eq!(ap.command(), 30f64.to_radians());
        assert!(ap.unlimited_command() > 10.0);
        // heading error wraps: reference 179°, heading −179° is a −2° error
        let mut ap = HeadingAutopilot::new(HeadingDesign::default()).unwrap();
        ap.step((-179f64).to_radians(), 179f64.to_radians(), 0.01);
        assert!(ap.command() < 0.0 && ap.command() > -0.5);
        // L/U = 12.55 s: a communication step of 1 s (0.0797 t′) holds 8 samples of 0.00996 t′
        let mut ap = HeadingAutopilot::new(HeadingDesign::default()).unwrap();
        ap.step(0.0, 0.1, 1.0);
        let c = LoopShapingCommon::default();
        assert!((ap.sample_step() - c.speed / c.length / 8.0).abs() < 1e-15);
        // a step of 0.05 s (0.004 t′ < τ_max) is sampled once per step
        ap.step(0.0, 0.1, 0.05);
        assert!((ap.sample_step() - 0.05 * c.speed / c.length).abs() < 1e-15);
        // generators
        let track_change = TrackChange::default();
        assert_eq!(track_change.heading(0.0), 0.0);
        assert!((track_change.heading(60.0 + 45.0) + 45f64.to_radians()).abs() < 1e-12);
        assert_eq!(track_change.heading(200.0), -std::f64::consts::FRAC_PI_2);
        assert_eq!(track_change.heading(2000.0), 0.0);
        let lo = LateralOffset {
            duration: 100.0,
            ..Default::default()
        };
        assert_eq!(lo.cross_track(10.0), 0.0);
        assert!((lo.cross_track(110.0) - lo.offset / 2.0).abs() < 1e-9);
        assert_eq!(lo.cross_track(1000.0), lo.offset);
    }

    /// The TrackController in SI on the DDG-51 Nomoto ship (NomotoShip, the 6/(s+6) gear as a
    /// 2.09 s lag): a lateral offset of 0.001 L (small enough that the ±30° limit stays inactive:
    /// the controller's gain peaks near 100 rad per ship length between its poles at 30 and its
    /// zero at 1000) gives the design's step overshoot for any communication step: 28.46 %
    /// continuous; ±0.5 % for the sampling and the separately simulated gear. The measurement is
    /// held over each communication step, so that step must stay small against L/U: at h = 0.3 s
    /// (0.024 t′, three samples on one held measurement) the overshoot is 34.1 % (observed).
    #[test]
    fn track_controller_closes_the_loop_in_si() {
        use crate::hull::nomoto::{NomotoInputs, NomotoShip};
        for h in [0.005, 0.0125, 0.05] {
            let mut ship = NomotoShip::ddg51();
            let c = LoopShapingCommon::default();
            let gear_tau = c.length / (c.gear_pole * c.speed);
            let mut controller = TrackController::new(TrackDesign::default()).unwrap();
            controller.reference = TrackReference::LateralOffset;
            controller.lateral_offset = LateralOffset {
                start: 0.0,
                offset: 0.142,
                duration: 0.0,
            };
            controller.start(0.0);
            let (mut delta, mut peak, mut max_cmd, mut y) = (0.0, 0.0f64, 0.0f64, 0.0);
            for _ in 0..(300.0 / h) as usize {
                controller.step(y, 0.0, h);
                max_cmd = max_cmd.max(controller.unlimited_command().abs());
                // exact first-order gear over the step for the held command, sub-stepped with the ship
                let n = ((h / 0.005f64).ceil() as usize).max(1);
                for _ in 0..n {
                    delta +=
                        (controller.command() - delta) * (1.0 - exp(-(h / n as f64) / gear_tau));
                    ship.step(
                        &NomotoInputs {
                            rudder: delta,
                            ..Default::default()
                        },
                        h / n as f64,
                    );
                }
                y = ship.outputs().y;
                peak = peak.max(y);
            }
            let os = 100.0 * (peak / 0.142 - 1.0);
            eprintln!("SI loop h = {h} s: overshoot {os:.2} %, final y {y:.4} m, max |command| {max_cmd:.3} rad");
            assert!((os - 28.46).abs() < 0.5, "h = {h}: {os}");
            assert!((y - 0.142).abs() < 0.0005);
            assert!(max_cmd < 30f64.to_radians());
        }
    }

    /// Steering-gear time constant of 6/(s+6) in t′, in seconds: L/(6U) = 2.09 s at 22 kn.
    #[test]
    fn gear_time_constant_in_seconds() {
        let c = LoopShapingCommon::default();
        assert!((c.length / (c.gear_pole * c.speed) - 2.0916).abs() < 1e-3);
    }

    /// A master's steps t_(k+1) − t_k on a rounded time grid alternate in their last bits; the
    /// realisation kept for the previous sample step gives bit for bit the commands of one
    /// rebuilt at every change (`set_design` with the same design rebuilds it and forgets the
    /// kept one).
    #[test]
    fn kept_realisation_equals_a_rebuilt_one() {
        let grid = |k: u64| (k * 50_000_000) as f64 / 1e9;
        let steps: Vec<f64> = (0..3000).map(|k| grid(k + 1) - grid(k)).collect();
        assert!(steps.windows(2).filter(|w| w[0] != w[1]).count() > 1000);
        let mut kept = HeadingAutopilot::new(HeadingDesign::default()).unwrap();
        let mut rebuilt = kept.clone();
        let mut track = TrackController::new(TrackDesign::default()).unwrap();
        let mut track_rebuilt = track.clone();
        for (k, &h) in steps.iter().enumerate() {
            let y = sin(k as f64 * 0.01);
            rebuilt.set_design(rebuilt.design).unwrap();
            track_rebuilt.set_design(track_rebuilt.design).unwrap();
            kept.step(y, 0.3, h);
            rebuilt.step(y, 0.3, h);
            track.step(y, 0.0, h);
            track_rebuilt.step(y, 0.0, h);
            assert_eq!(
                kept.command().to_bits(),
                rebuilt.command().to_bits(),
                "k = {k}"
            );
            assert_eq!(track.command().to_bits(), track_rebuilt.command().to_bits());
            assert_eq!(kept.controller(), rebuilt.controller());
        }
    }

    #[test]
    fn snapshot_continues_identically() {
        let mut a = TrackController::new(TrackDesign::default()).unwrap();
        a.step(3.0, 0.0, 2.0);
        let mut b: TrackController =
            bincode::deserialize(&bincode::serialize(&a).unwrap()).unwrap();
        for k in 0..100 {
            let y = sin(k as f64 * 0.1);
            a.step(y, 0.0, 0.5);
            b.step(y, 0.0, 0.5);
            assert_eq!(a.command().to_bits(), b.command().to_bits());
        }
    }
}
