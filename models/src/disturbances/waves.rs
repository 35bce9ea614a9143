//! Long-crested irregular waves: spectra, encounter frequency, two realisations, wave moments
//! and the wave-frequency (WF) motion of a DP vessel.
//!
//! # Spectra (`S_ζ(ω)`, one-sided, m²·s/rad, `m0 = ∫ S dω`, `H_s = 4 √m0`)
//! * **Bretschneider, 12th ITTC form of [Klugt1987, sec. 2.4.3, eq. (2.21)]**:
//!   `S = A ω⁻⁵ exp(−B ω⁻⁴)`, `B = 691 T̄⁻⁴`, `A = B (0.5 H_1/3)²` (= 172.75 H² T̄⁻⁴), with
//!   `T̄ = 2π m0/m1` the **mean** period (the constant 691 makes the spectrum's own T̄ equal the
//!   parameter to 0.01 %).
//! * **Pierson-Moskowitz** in the two-parameter (H_s, peak period T_p) form:
//!   `S = (5/16) H_s² ω_p⁴ ω⁻⁵ exp(−1.25 (ω_p/ω)⁴)`, `ω_p = 2π/T_p`. The fully developed
//!   one-parameter sea (α = 0.0081) has `ω_p = 0.4013 √(g/H_s)`: [`SeaState::fully_developed_pm`].
//! * **JONSWAP** (H_s, T_p, γ): `S = N · S_PM(ω) · γ^exp(−(ω−ω_p)²/(2σ²ω_p²))`, σ = 0.07 for
//!   ω ≤ ω_p and 0.09 above. The normalisation N is computed numerically so that `4√m0 = H_s`
//!   exactly (instead of the approximate `1 − 0.287 ln γ` of DNV-RP-C205).
//!
//! # Encounter frequency and angle [Klugt1987, eq. (2.22)]
//! `ω_e = ω0 − ω0² U cos γ / g`, with γ the angle between the ship's heading and the direction in
//! which the waves travel: **γ = 0 following seas, ±90° beam seas, 180° head seas** (the reading
//! taken from the sign of [Klugt1987, eq. (2.22)] and the trial descriptions of [Klugt1987, sec. 7.2.3 and 7.4];
//! [Klugt1987, Fig. 2.9] is lost). Here
//! `γ = wave_direction − heading` wrapped to (−π, π], both angles in the same earth-fixed frame and
//! `wave_direction` the direction the waves travel **towards**. In following seas at high speed
//! ω_e becomes negative for ω0 > g/(U cos γ) (the ship overtakes the waves); the signed value is
//! used in the phase, so such components run backwards, as they physically do.
//!
//! # Realisations
//! * **Sum of sinusoids** (default): `ζ(t) = Σ a_i cos(θ_i(t))`, `θ̇_i = ω_e,i`. The band holding
//!   99.8 % of m0 (0.1 % cut at each end) is split into `n` equal bins; ω_i is drawn uniformly
//!   inside bin i (so no common period: the record never repeats), φ_i uniformly in [0, 2π);
//!   `a_i = √(2 ∫_bin S dω)`, scaled so that `Σ a_i²/2 = m0` exactly. The phase
//!   `θ_i = φ_i + ∫ ω_e,i dt` is written as the earth-fixed phase minus a ship-position term,
//!   `θ_i = φ_i + ω_i (t − t0) − k_i x(t)`, with `k_i = ω_i²/g` and `x = ∫ U cos γ dt` the distance
//!   travelled along the wave direction (the same thing, since `ω_e = ω − k U cos γ`). Only the
//!   scalar x is updated when U or γ change (they are held over each communication step), so the
//!   elevation is **exact** at every time for piecewise-constant inputs, independent of the step
//!   size, and costs one vectorised cosine per component per step ([`sinusoids`](super::sinusoids)).
//! * **Shaping filter** ([Klugt1987, Fig. 2.10]; [Fossen1999, eq. (10)]): white noise through
//!   `ẍ + 2ζ_f ω_f ẋ + ω_f² x = g n`, generated on the fixed internal grid of
//!   [`shaping`](super::shaping) (exact discretisation, linear interpolation between grid points).
//!   Output form *low-pass* ([Klugt1987, Fig. 2.10]): ζ = x, or *band-pass* ([Fossen1999, eq. (10)]): ζ = ẋ. ω_f is the encounter
//!   frequency of the filter frequency ω0 (default: the spectrum's peak), floored at 0.05 rad/s;
//!   g is set so that the stationary variance is m0 (H_s exact in expectation):
//!   low-pass `g² = 4 ζ_f ω_f³ m0`, band-pass `g² = 4 ζ_f ω_f m0`.
//!
//! # Moments [Klugt1987, eqs. (2.23)-(2.24)]
//! `K = k_φ sin(γ) ζ(t)`, `N = k_ψ sin(2γ) ζ(t)`: the frequency responses H_gφ, H_gψ are not
//! given in the thesis, so they are constant gains (parameters; default 0). γ is signed, so waves from
//! the other side reverse the roll moment.
//!
//! # Wave-frequency motion for DP [Fossen1999, eqs. (10)-(11)]
//! Three independent band-pass processes `h_w(s) = σ_i s/(s² + 2ζ ω0 s + ω0²)` (surge, sway, yaw)
//! on the internal grid, default ζ = 0.1, ω0 = 0.8976 rad/s [Fossen1999, sec. 6]. σ_i are not given in the paper;
//! the defaults make the significant amplitude 2·std equal the "limited to" amplitudes of the
//! simulation study (surge 10 m, sway 10 m, yaw 1°; [Fossen1999, sec. 6.1]): std(η_w) = 1.669 σ, so
//! σ = (5 m, 5 m, 0.5°)/1.669 [assumption]. Superposed on the LF position (not fed through a
//! hull), in the earth frame, without encounter transformation (DP: U ≈ 0).
//!
//! # Sea state 4 of [Taylor2000] (preset [`SeaState::sea_state_4`])
//! [Taylor2000, sec. 5.3.3.2] models SS4 only as "a random disturbance ... filtered to preserve only the
//! low-frequency components", H_s 1.25-2.5 m, spectrum and filter not given. Preset:
//! Pierson-Moskowitz, H_s = 1.875 m (mid-range), T_p = 8.84 s (the thesis's design wave, 400 ft long:
//! ω = √(2πg/λ) = 0.711 rad/s, [Taylor2000, sec. 5.1.4]). Use `hs` 1.25 or 2.5 for the band's ends.

use super::shaping::{quantise_time, SecondOrderProcess, Start};
use super::sinusoids::Sinusoids;
use crate::error::{check_non_negative, check_positive, require};
use crate::math::{cos, exp, ln, powf, sin};
use crate::random::{channel, NoiseStream};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Standard gravity used by default [m/s²].
pub const GRAVITY: f64 = 9.81;

/// Spectrum family.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum SpectrumKind {
    /// [Klugt1987, eq. (2.21)], ITTC: parameterised by H_1/3 and the **mean** period T̄.
    Bretschneider,
    /// Parameterised by H_s and the **peak** period T_p.
    PiersonMoskowitz,
    /// Parameterised by H_s, the **peak** period T_p and γ.
    Jonswap,
}

/// Sea-state parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeaState {
    pub spectrum: SpectrumKind,
    /// Significant wave height H_s = 4 √m0 [m].
    pub hs: f64,
    /// Mean period T̄ (Bretschneider) or peak period T_p (PM, JONSWAP) [s].
    pub period: f64,
    /// JONSWAP peak-enhancement factor γ (ignored otherwise).
    pub gamma: f64,
}

impl SeaState {
    pub fn bretschneider(hs: f64, mean_period: f64) -> Self {
        SeaState {
            spectrum: SpectrumKind::Bretschneider,
            hs,
            period: mean_period,
            gamma: 3.3,
        }
    }
    pub fn pierson_moskowitz(hs: f64, peak_period: f64) -> Self {
        SeaState {
            spectrum: SpectrumKind::PiersonMoskowitz,
            hs,
            period: peak_period,
            gamma: 3.3,
        }
    }
    /// Fully developed PM sea for a given H_s: `ω_p = (16 α/5)^¼ √(g/H_s)`, α = 0.0081.
    pub fn fully_developed_pm(hs: f64) -> Self {
        let wp = powf(16.0 * 0.0081 / 5.0f64, 0.25) * (GRAVITY / hs).sqrt();
        Self::pierson_moskowitz(hs, 2.0 * PI / wp)
    }
    pub fn jonswap(hs: f64, peak_period: f64, gamma: f64) -> Self {
        SeaState {
            spectrum: SpectrumKind::Jonswap,
            hs,
            period: peak_period,
            gamma,
        }
    }
    /// Sea state 4 of [Taylor2000, sec. 5.3.3.2] (see the module documentation).
    pub fn sea_state_4() -> Self {
        Self::pierson_moskowitz(1.875, 8.84)
    }

    pub fn validate(&self) -> Result<(), String> {
        check_non_negative("significant_wave_height", self.hs)?;
        check_positive("wave_period", self.period)?;
        if self.spectrum == SpectrumKind::Jonswap {
            require(
                (1.0..=20.0).contains(&self.gamma),
                "jonswap_gamma",
                self.gamma,
                "must be in [1, 20]",
            )?;
        }
        Ok(())
    }
}

/// A spectrum ready for evaluation (JONSWAP normalisation precomputed).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spectrum {
    pub sea: SeaState,
    a: f64,
    b: f64,
    norm: f64,
    omega_peak: f64,
}

impl Spectrum {
    pub fn new(sea: &SeaState) -> Result<Self, String> {
        sea.validate()?;
        let (b, omega_peak) = match sea.spectrum {
            SpectrumKind::Bretschneider => {
                let b = 691.0 / sea.period.powi(4);
                (b, powf(0.8 * b, 0.25))
            }
            _ => {
                let wp = 2.0 * PI / sea.period;
                (1.25 * wp.powi(4), wp)
            }
        };
        let a = b * (0.5 * sea.hs).powi(2);
        let mut s = Spectrum {
            sea: sea.clone(),
            a,
            b,
            norm: 1.0,
            omega_peak,
        };
        if sea.spectrum == SpectrumKind::Jonswap && sea.hs > 0.0 {
            let m0 = s.moment(0);
            s.norm = sea.hs * sea.hs / 16.0 / m0;
        }
        Ok(s)
    }

    /// S(ω) [m² s/rad], ω in rad/s (0 for ω ≤ 0).
    pub fn density(&self, w: f64) -> f64 {
        if w <= 0.0 {
            return 0.0;
        }
        let base = self.a * w.powi(-5) * exp(-self.b * w.powi(-4));
        match self.sea.spectrum {
            SpectrumKind::Jonswap => {
                let wp = self.omega_peak;
                let sigma = if w <= wp { 0.07 } else { 0.09 };
                let r = exp(-(w - wp).powi(2) / (2.0 * sigma * sigma * wp * wp));
                self.norm * base * powf(self.sea.gamma, r)
            }
            _ => base,
        }
    }

    /// Frequency of the spectral maximum [rad/s].
    pub fn peak_frequency(&self) -> f64 {
        self.omega_peak
    }

    /// `mₙ = ∫ ωⁿ S dω`, Simpson in ln ω over [0.05, 200]·ω_p (the tails beyond are < 1e-7 m0).
    pub fn moment(&self, n: i32) -> f64 {
        let (lo, hi) = (ln(0.05 * self.omega_peak), ln(200.0 * self.omega_peak));
        let m = 20_000;
        let h = (hi - lo) / m as f64;
        let f = |u: f64| {
            let w = exp(u);
            w.powi(n + 1) * self.density(w)
        };
        let mut sum = f(lo) + f(hi);
        for i in 1..m {
            sum += f(lo + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * h / 3.0
    }

    /// Mean period `T̄ = T1 = 2π m0/m1` [s].
    pub fn mean_period(&self) -> f64 {
        2.0 * PI * self.moment(0) / self.moment(1)
    }

    /// Zero-up-crossing period `T_z = 2π √(m0/m2)` [s].
    pub fn zero_crossing_period(&self) -> f64 {
        2.0 * PI * (self.moment(0) / self.moment(2)).sqrt()
    }

    /// ∫ S dω over [w0, w1] (Simpson, 16 intervals).
    pub fn band_energy(&self, w0: f64, w1: f64) -> f64 {
        let m = 16;
        let h = (w1 - w0) / m as f64;
        let mut sum = self.density(w0) + self.density(w1);
        for i in 1..m {
            sum += self.density(w0 + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * h / 3.0
    }

    /// Frequencies below which the fractions `lo` and `hi` of m0 lie.
    ///
    /// Bretschneider and Pierson-Moskowitz (`S = A ω⁻⁵ exp(−B ω⁻⁴)`) have the closed-form
    /// cumulative energy `∫₀^ω S dω' = (A/4B) exp(−B ω⁻⁴) = m0 exp(−B ω⁻⁴)`, inverted exactly:
    /// `ω = (B / −ln p)^¼`. JONSWAP: bisection on the cumulative energy (Simpson in ln ω).
    pub fn energy_band(&self, lo: f64, hi: f64) -> (f64, f64) {
        if self.sea.spectrum != SpectrumKind::Jonswap {
            let quantile = |p: f64| powf(self.b / -ln(p), 0.25);
            return (quantile(lo), quantile(hi));
        }
        self.energy_band_numeric(lo, hi)
    }

    /// [`energy_band`](Self::energy_band) by bisection on the cumulative energy (Simpson in ln ω
    /// from 0.05 ω_p), for any spectrum.
    fn energy_band_numeric(&self, lo: f64, hi: f64) -> (f64, f64) {
        let m0 = self.moment(0);
        let cdf = |w: f64| {
            let l = ln(0.05 * self.omega_peak);
            let u = ln(w);
            if u <= l {
                return 0.0;
            }
            let m = 2000;
            let h = (u - l) / m as f64;
            let f = |x: f64| {
                let w = exp(x);
                w * self.density(w)
            };
            let mut sum = f(l) + f(u);
            for i in 1..m {
                sum += f(l + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
            }
            sum * h / 3.0 / m0
        };
        let solve = |p: f64| {
            let (mut a, mut b) = (0.05 * self.omega_peak, 200.0 * self.omega_peak);
            for _ in 0..60 {
                let c = (a * b).sqrt();
                if cdf(c) < p {
                    a = c;
                } else {
                    b = c;
                }
            }
            (a * b).sqrt()
        };
        (solve(lo), solve(hi))
    }
}

/// Encounter frequency, [Klugt1987, eq. (2.22)]: `ω_e = ω0 − ω0² U cos γ / g`.
#[inline]
pub fn encounter_frequency(omega0: f64, speed: f64, gamma: f64, g: f64) -> f64 {
    omega0 - omega0 * omega0 * speed * cos(gamma) / g
}

/// Encounter angle γ = wave_direction − heading wrapped to (−π, π] (0 following, π head seas).
pub fn encounter_angle(wave_direction: f64, heading: f64) -> f64 {
    let mut g = (wave_direction - heading).rem_euclid(2.0 * PI);
    if g > PI {
        g -= 2.0 * PI;
    }
    g
}

/// σ of [Fossen1999, eq. (10)] that gives the standard deviation `std`: var = σ²/(4 ζ ω0).
pub fn wf_sigma_for_std(std: f64, zeta: f64, omega0: f64) -> f64 {
    std * (4.0 * zeta * omega0).sqrt()
}

/// Realisation of the elevation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Realisation {
    SumOfSinusoids,
    ShapingFilter,
}

/// Output form of the shaping filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ShapingForm {
    /// [Klugt1987, Fig. 2.10]: second-order low-pass, ζ = x.
    LowPass,
    /// [Fossen1999, eq. (10)]: σ s/(s² + 2ζω0 s + ω0²), ζ = ẋ.
    BandPass,
}

/// Parameters of [`Waves`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WaveParams {
    pub sea: SeaState,
    pub realisation: Realisation,
    /// Number of sinusoids (sum-of-sinusoids realisation).
    pub components: usize,
    pub shaping_form: ShapingForm,
    /// Filter frequency ω0 [rad/s] before the encounter transformation; ≤ 0: the spectral peak.
    pub shaping_frequency: f64,
    /// Filter damping ζ_f.
    pub shaping_damping: f64,
    /// Internal grid step of the noise processes [s].
    pub internal_step: f64,
    /// Roll-moment gain k_φ [N·m per m of elevation] [Klugt1987, eq. (2.23)].
    pub roll_gain: f64,
    /// Yaw-moment gain k_ψ [N·m per m of elevation] [Klugt1987, eq. (2.24)].
    pub yaw_gain: f64,
    /// WF model of [Fossen1999, eqs. (10)-(11)]: dominant frequency ω0 [rad/s], damping ζ, intensities σ (surge [m], sway
    /// [m], yaw [rad]) per √s.
    pub wf_omega0: f64,
    pub wf_zeta: f64,
    pub wf_sigma: [f64; 3],
    pub gravity: f64,
    pub seed: u64,
}

impl Default for WaveParams {
    fn default() -> Self {
        WaveParams {
            sea: SeaState::sea_state_4(),
            realisation: Realisation::SumOfSinusoids,
            components: 400,
            shaping_form: ShapingForm::BandPass,
            shaping_frequency: 0.0,
            shaping_damping: 0.1,
            internal_step: 0.05,
            roll_gain: 0.0,
            yaw_gain: 0.0,
            wf_omega0: 0.8976,
            wf_zeta: 0.1,
            wf_sigma: [
                wf_sigma_for_std(5.0, 0.1, 0.8976),
                wf_sigma_for_std(5.0, 0.1, 0.8976),
                wf_sigma_for_std(0.5f64.to_radians(), 0.1, 0.8976),
            ],
            gravity: GRAVITY,
            seed: 1,
        }
    }
}

impl WaveParams {
    pub fn validate(&self) -> Result<(), String> {
        self.sea.validate()?;
        if !(1..=100_000).contains(&self.components) {
            return Err(format!(
                "number_of_components = {} must be in [1, 100000]",
                self.components
            ));
        }
        check_positive("shaping_damping", self.shaping_damping)?;
        check_positive("internal_step", self.internal_step)?;
        check_positive("wf_omega0", self.wf_omega0)?;
        check_positive("wf_zeta", self.wf_zeta)?;
        check_positive("gravity", self.gravity)?;
        Ok(())
    }
}

/// The wave model (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Waves {
    params: WaveParams,
    spectrum: Spectrum,
    m0: f64,
    /// The sinusoids, with their phases at `t0`.
    comps: Sinusoids,
    t0: f64,
    time: f64,
    /// Distance the ship has travelled along the wave direction, `x = ∫ U cos γ dt`, at `t_ref`.
    x_ref: f64,
    /// Time of the last change of the inputs.
    t_ref: f64,
    speed: f64,
    gamma: f64,
    /// `U cos γ`, `sin γ` and `sin 2γ` of the inputs in use.
    speed_along: f64,
    sin_gamma: f64,
    sin_2gamma: f64,
    /// ζ at `time` (the sum is evaluated once per step, not once per output).
    elevation: f64,
    shaping: SecondOrderProcess,
    wf: [SecondOrderProcess; 3],
}

const MIN_FILTER_FREQUENCY: f64 = 0.05;

impl Waves {
    /// Builds the components (the only allocation) and the processes at `t0`, ship at rest in
    /// following seas (inputs set with [`set_inputs`](Self::set_inputs)).
    pub fn new(params: WaveParams, t0: f64) -> Result<Self, String> {
        let t0 = quantise_time(t0);
        params.validate()?;
        let spectrum = Spectrum::new(&params.sea)?;
        let m0 = params.sea.hs * params.sea.hs / 16.0;
        let mut rng = NoiseStream::new(params.seed, channel::WAVE_COMPONENTS);
        let n = params.components;
        let mut comps = Sinusoids::with_capacity(n);
        if m0 > 0.0 {
            let (lo, hi) = spectrum.energy_band(0.001, 0.999);
            let dw = (hi - lo) / n as f64;
            let mut energy = 0.0;
            for i in 0..n {
                let w0 = lo + i as f64 * dw;
                let e = spectrum.band_energy(w0, w0 + dw);
                energy += e;
                let w = w0 + rng.uniform() * dw;
                let phase = 2.0 * PI * rng.uniform();
                // the band energy until the set is complete; k = ω²/g (deep water)
                comps.push(e, w, w * w / params.gravity, phase);
            }
            comps.map_amplitudes(|e| (2.0 * e * m0 / energy).sqrt());
        }
        let shaping_w = if params.shaping_frequency > 0.0 {
            params.shaping_frequency
        } else {
            spectrum.peak_frequency()
        };
        let (fw, fg) = Self::filter(&params, shaping_w, m0, 0.0, 0.0);
        let shaping = SecondOrderProcess::new(
            fw,
            params.shaping_damping,
            fg,
            params.internal_step,
            t0,
            Start::Stationary,
            NoiseStream::new(params.seed, channel::WAVE_SHAPING),
        );
        let wf = std::array::from_fn(|i| {
            SecondOrderProcess::new(
                params.wf_omega0,
                params.wf_zeta,
                params.wf_sigma[i],
                params.internal_step,
                t0,
                Start::Stationary,
                NoiseStream::new(params.seed, channel::WAVE_WF_MOTION + i as u64),
            )
        });
        let mut waves = Waves {
            params,
            spectrum,
            m0,
            comps,
            t0,
            time: t0,
            x_ref: 0.0,
            t_ref: t0,
            speed: 0.0,
            gamma: 0.0,
            speed_along: 0.0,
            sin_gamma: 0.0,
            sin_2gamma: 0.0,
            elevation: 0.0,
            shaping,
            wf,
        };
        waves.elevation = waves.evaluate();
        Ok(waves)
    }

    /// Filter frequency and gain for the shaping realisation at encounter conditions (U, γ).
    fn filter(p: &WaveParams, w0: f64, m0: f64, speed: f64, gamma: f64) -> (f64, f64) {
        let we = encounter_frequency(w0, speed, gamma, p.gravity)
            .abs()
            .max(MIN_FILTER_FREQUENCY);
        let z = p.shaping_damping;
        let g2 = match p.shaping_form {
            ShapingForm::LowPass => 4.0 * z * we * we * we * m0,
            ShapingForm::BandPass => 4.0 * z * we * m0,
        };
        (we, g2.sqrt())
    }

    pub fn params(&self) -> &WaveParams {
        &self.params
    }
    pub fn spectrum(&self) -> &Spectrum {
        &self.spectrum
    }

    /// Sets ship speed U [m/s] and encounter angle γ [rad] from the current time on (inputs held
    /// until the next call). The phases need no rebasing: the distance travelled along the wave
    /// direction up to now is carried in `x_ref`.
    pub fn set_inputs(&mut self, speed: f64, gamma: f64) {
        if speed == self.speed && gamma == self.gamma {
            return;
        }
        self.x_ref = self.position();
        self.t_ref = self.time;
        self.speed = speed;
        self.gamma = gamma;
        self.speed_along = speed * cos(gamma);
        self.sin_gamma = sin(gamma);
        self.sin_2gamma = sin(2.0 * gamma);
        if self.params.realisation == Realisation::ShapingFilter {
            let w0 = if self.params.shaping_frequency > 0.0 {
                self.params.shaping_frequency
            } else {
                self.spectrum.peak_frequency()
            };
            let (fw, fg) = Self::filter(&self.params, w0, self.m0, speed, gamma);
            self.shaping.set_params(fw, self.params.shaping_damping, fg);
        }
    }

    /// Distance travelled along the wave direction at the current time [m], exact for inputs held
    /// since `t_ref`.
    fn position(&self) -> f64 {
        self.x_ref + self.speed_along * (self.time - self.t_ref)
    }

    /// ζ at the current time: the encounter-frequency phase `φ + ω_e (t − t0)` of
    /// [Klugt1987, eq. (2.22)] written as the earth-fixed phase `φ + ω τ` minus the ship-position
    /// term `k x`, since `ω_e = ω − k U cos γ` with `k = ω²/g`; with varying inputs `x` is the
    /// integral of `U cos γ`, so the elevation is exact at every time for inputs held over each step.
    fn evaluate(&self) -> f64 {
        match self.params.realisation {
            Realisation::SumOfSinusoids => self.comps.sum(self.time - self.t0, self.position()),
            Realisation::ShapingFilter => {
                let x = self.shaping.value(self.time);
                match self.params.shaping_form {
                    ShapingForm::LowPass => x[0],
                    ShapingForm::BandPass => x[1],
                }
            }
        }
    }

    /// Changes the moment gains (tunable; no effect on the random processes).
    pub fn set_gains(&mut self, roll_gain: f64, yaw_gain: f64) {
        self.params.roll_gain = roll_gain;
        self.params.yaw_gain = yaw_gain;
    }

    /// Advances to time `t` (≥ the current time) with the inputs held.
    /// `t` is rounded to a whole nanosecond ([`quantise_time`]).
    pub fn advance_to(&mut self, t: f64) {
        let t = quantise_time(t);
        self.time = t;
        if self.params.realisation == Realisation::ShapingFilter {
            self.shaping.advance_to(t);
        }
        for p in &mut self.wf {
            p.advance_to(t);
        }
        self.elevation = self.evaluate();
    }

    pub fn time(&self) -> f64 {
        self.time
    }

    /// The noise grids' work of [`advance_to`](Self::advance_to)`(t)`: `each("internal_step",
    /// grid step, passes)` per process (for the bound on the work of one FMU step).
    pub fn internal_steps(&self, t: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        let t = quantise_time(t);
        if self.params.realisation == Realisation::ShapingFilter {
            let (dt, passes) = self.shaping.grid_passes(t);
            each("internal_step", dt, passes);
        }
        for p in &self.wf {
            let (dt, passes) = p.grid_passes(t);
            each("internal_step", dt, passes);
        }
    }

    /// Wave elevation at the ship ζ(t) [m].
    pub fn elevation(&self) -> f64 {
        self.elevation
    }

    /// Encounter angle in use [rad].
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// Roll moment `k_φ sin γ ζ` [N·m].
    pub fn roll_moment(&self) -> f64 {
        self.params.roll_gain * self.sin_gamma * self.elevation
    }

    /// Yaw moment `k_ψ sin 2γ ζ` [N·m].
    pub fn yaw_moment(&self) -> f64 {
        self.params.yaw_gain * self.sin_2gamma * self.elevation
    }

    /// Encounter frequency of the spectral peak [rad/s] (signed, [Klugt1987, eq. (2.22)]).
    pub fn peak_encounter_frequency(&self) -> f64 {
        encounter_frequency(
            self.spectrum.peak_frequency(),
            self.speed,
            self.gamma,
            self.params.gravity,
        )
    }

    /// Wave-frequency motion of [Fossen1999, eqs. (10)-(11)] (surge [m], sway [m], yaw [rad]).
    pub fn wf_motion(&self) -> [f64; 3] {
        std::array::from_fn(|i| self.wf[i].value(self.time)[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::disturbances::spectral::{moment, peak_frequency_centroid, welch};
    use crate::random::{correlation, mean_variance};

    const DT: f64 = 0.5;
    const N3H: usize = 21_600; // 3 h at 0.5 s

    fn record(w: &mut Waves, dt: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| {
                w.advance_to(k as f64 * dt);
                w.elevation()
            })
            .collect()
    }

    fn params(sea: SeaState, seed: u64) -> WaveParams {
        WaveParams {
            sea,
            seed,
            ..WaveParams::default()
        }
    }

    #[test]
    fn spectra_have_the_stated_hs_and_periods() {
        // Bretschneider-ITTC: T̄ from the spectrum equals the parameter (691 = (2π/Γ(3/4))⁴ rounded)
        let s = Spectrum::new(&SeaState::bretschneider(4.0, 8.0)).unwrap();
        assert!((4.0 * s.moment(0).sqrt() / 4.0 - 1.0).abs() < 1e-6);
        assert!(
            (s.mean_period() / 8.0 - 1.0).abs() < 2e-4,
            "{}",
            s.mean_period()
        );
        // A = 172.75 H² T̄⁻⁴
        assert!((s.a - 172.75 * 16.0 / 8.0f64.powi(4)).abs() < 1e-12);
        let pm = Spectrum::new(&SeaState::pierson_moskowitz(3.0, 10.0)).unwrap();
        assert!((4.0 * pm.moment(0).sqrt() / 3.0 - 1.0).abs() < 1e-6);
        // PM: T1 = 0.772 Tp, Tz = 0.710 Tp
        assert!((pm.mean_period() / 10.0 - 0.7718).abs() < 1e-3);
        assert!((pm.zero_crossing_period() / 10.0 - 0.7104).abs() < 1e-3);
        let js = Spectrum::new(&SeaState::jonswap(3.0, 10.0, 3.3)).unwrap();
        assert!((4.0 * js.moment(0).sqrt() / 3.0 - 1.0).abs() < 1e-6);
        // normalisation close to DNV's 1 − 0.287 ln γ
        assert!((js.norm / (1.0 - 0.287 * ln(3.3f64)) - 1.0).abs() < 0.03);
        // peak of JONSWAP at ωp
        let wp = js.peak_frequency();
        assert!(js.density(wp) > js.density(wp * 0.98) && js.density(wp) > js.density(wp * 1.02));
        // fully developed PM: Hs = 0.21 U²/g ⇔ ωp = 0.4013 √(g/Hs)
        let fd = SeaState::fully_developed_pm(4.0);
        assert!((2.0 * PI / fd.period / (GRAVITY / 4.0f64).sqrt() - 0.4013).abs() < 1e-4);
    }

    #[test]
    fn closed_form_energy_band_is_the_numeric_one() {
        for sea in [
            SeaState::bretschneider(3.0, 7.7),
            SeaState::bretschneider(0.5, 4.0),
            SeaState::pierson_moskowitz(3.0, 10.0),
            SeaState::sea_state_4(),
        ] {
            let s = Spectrum::new(&sea).unwrap();
            let (lo, hi) = s.energy_band(0.001, 0.999);
            let (nlo, nhi) = s.energy_band_numeric(0.001, 0.999);
            // the numeric quantile is accurate to ~2e-7 in the thin upper tail (Simpson's error
            // of the cumulative energy divided by the small density there)
            assert!((lo / nlo - 1.0).abs() < 1e-9, "{sea:?}: {lo} vs {nlo}");
            assert!((hi / nhi - 1.0).abs() < 1e-6, "{sea:?}: {hi} vs {nhi}");
        }
    }

    /// The acceptance test of issue 5: over a 3-hour realisation at 0.5 s, Hs = 4√m0 and the
    /// period within 3 % of the target for each spectrum, and the Welch estimate matches the
    /// target shape.
    #[test]
    fn three_hour_realisations_have_the_target_hs_periods_and_shape() {
        let cases = [
            (SeaState::bretschneider(4.0, 8.0), "Bretschneider"),
            (SeaState::pierson_moskowitz(3.0, 10.0), "PM"),
            (SeaState::jonswap(3.0, 10.0, 3.3), "JONSWAP"),
            (SeaState::sea_state_4(), "SS4"),
        ];
        for (sea, name) in cases {
            let mut w = Waves::new(params(sea.clone(), 17), 0.0).unwrap();
            let x = record(&mut w, DT, N3H);
            let (mean, var) = mean_variance(&x);
            let hs = 4.0 * var.sqrt();
            let target = w.spectrum().clone();
            assert!(mean.abs() < 0.02 * sea.hs, "{name}: mean {mean}");
            let e_hs = hs / sea.hs - 1.0;
            assert!(e_hs.abs() < 0.03, "{name}: Hs {hs} vs {}", sea.hs);
            let (om, s) = welch(&x, DT, 1024);
            let t1 = 2.0 * PI * moment(&om, &s, 0) / moment(&om, &s, 1);
            let e_t1 = t1 / target.mean_period() - 1.0;
            assert!(
                e_t1.abs() < 0.03,
                "{name}: T1 {t1} vs {}",
                target.mean_period()
            );
            // peak period: S⁴ centroid of the estimate vs of the target on the same grid
            let st: Vec<f64> = om.iter().map(|&v| target.density(v)).collect();
            let tp = 2.0 * PI / peak_frequency_centroid(&om, &s, 4);
            let tp_target = 2.0 * PI / peak_frequency_centroid(&om, &st, 4);
            let e_tp = tp / tp_target - 1.0;
            assert!(e_tp.abs() < 0.03, "{name}: Tp {tp} vs {tp_target}");
            // directly against the nominal peak period, with the sharper S⁸ centroid
            let tp8 = 2.0 * PI / peak_frequency_centroid(&om, &s, 8);
            let tp_nominal = 2.0 * PI / target.peak_frequency();
            let e_tp8 = tp8 / tp_nominal - 1.0;
            assert!(e_tp8.abs() < 0.03, "{name}: Tp(S⁸) {tp8} vs {tp_nominal}");
            // the centroid estimator itself is within 3 % of the nominal peak period
            // shape: cumulative energy distributions agree within 0.03 everywhere, and the
            // energy in each band of width 0.2 ωp around the peak agrees within 15 %
            let (m0e, m0t) = (s.iter().sum::<f64>(), st.iter().sum::<f64>());
            let (mut ce, mut ct, mut dmax) = (0.0, 0.0, 0.0f64);
            for k in 0..om.len() {
                ce += s[k] / m0e;
                ct += st[k] / m0t;
                dmax = dmax.max((ce - ct).abs());
            }
            assert!(dmax < 0.03, "{name}: max CDF difference {dmax}");
            let wp = target.peak_frequency();
            let mut worst = 0.0f64;
            for b in 0..5 {
                let (lo, hi) = (wp * (0.8 + 0.2 * b as f64), wp * (1.0 + 0.2 * b as f64));
                let band = |v: &[f64]| -> f64 {
                    om.iter()
                        .zip(v)
                        .filter(|(w, _)| **w >= lo && **w < hi)
                        .map(|(_, v)| v)
                        .sum()
                };
                worst = worst.max((band(&s) / band(&st) - 1.0).abs());
            }
            assert!(worst < 0.15, "{name}: worst band error {worst}");
            println!(
                "{name}: Hs {hs:.4} ({:+.2} %), T1 {t1:.3} ({:+.2} %), Tp(S⁴) {tp:.3} ({:+.2} % vs \
                 target's S⁴), Tp(S⁸) {tp8:.3} ({:+.2} % vs nominal {tp_nominal:.3}), \
                 CDF {dmax:.4}, bands {:.1} %",
                100.0 * e_hs,
                100.0 * e_t1,
                100.0 * e_tp,
                100.0 * e_tp8,
                100.0 * worst
            );
        }
    }

    #[test]
    fn shaping_filter_realisation_matches_its_analytic_variance() {
        for form in [ShapingForm::LowPass, ShapingForm::BandPass] {
            let p = WaveParams {
                realisation: Realisation::ShapingFilter,
                shaping_form: form,
                internal_step: 0.5,
                ..params(SeaState::pierson_moskowitz(3.0, 10.0), 23)
            };
            let mut w = Waves::new(p, 0.0).unwrap();
            // 100 h at 0.5 s (relative std of the variance estimate ≈ 1 %)
            let x = record(&mut w, 0.5, 720_000);
            let (_, var) = mean_variance(&x);
            let target = 9.0 / 16.0;
            let e = var / target - 1.0;
            println!(
                "shaping {form:?}: variance {var:.5} vs {target:.5} ({:+.2} %)",
                100.0 * e
            );
            assert!(e.abs() < 0.03, "{form:?}: {var} vs {target}");
            // the filter peaks at the spectral peak
            let (om, s) = welch(&x, 0.5, 4096);
            let k = (0..s.len()).max_by(|&a, &b| s[a].total_cmp(&s[b])).unwrap();
            assert!(
                (om[k] / (2.0 * PI / 10.0) - 1.0).abs() < 0.1,
                "peak at {}",
                om[k]
            );
        }
    }

    #[test]
    fn wf_motion_has_the_fossen1999_variance() {
        let mut w = Waves::new(WaveParams::default(), 0.0).unwrap();
        let n = 400_000;
        let mut x = [Vec::new(), Vec::new(), Vec::new()];
        for k in 0..n {
            w.advance_to(k as f64 * 0.5);
            let m = w.wf_motion();
            for i in 0..3 {
                x[i].push(m[i]);
            }
        }
        let expected = [5.0, 5.0, 0.5f64.to_radians()];
        for i in 0..3 {
            let (_, v) = mean_variance(&x[i]);
            assert!(
                (v.sqrt() / expected[i] - 1.0).abs() < 0.03,
                "{i}: {}",
                v.sqrt()
            );
        }
        assert!(correlation(&x[0], &x[1]).abs() < 0.05);
    }

    #[test]
    fn encounter_frequency_eq_2_22() {
        let g = GRAVITY;
        let (w0, u) = (0.6, 10.0);
        // head seas: ω_e = ω0 + ω0² U/g
        let head = encounter_frequency(w0, u, PI, g);
        assert!((head - (0.6 + 0.36 * 10.0 / g)).abs() < 1e-15);
        assert!((head - 0.966_972_477).abs() < 1e-8);
        // beam seas: ω_e = ω0
        assert!((encounter_frequency(w0, u, PI / 2.0, g) - w0).abs() < 1e-15);
        // following seas: ω_e = ω0 − ω0² U/g; zero at ω0 = g/U, negative above
        assert!((encounter_frequency(w0, u, 0.0, g) - (0.6 - 0.36 * 10.0 / g)).abs() < 1e-15);
        assert!(encounter_frequency(g / u, u, 0.0, g).abs() < 1e-15);
        assert!(encounter_frequency(1.5, u, 0.0, g) < 0.0);
        assert!(encounter_frequency(1.5, 2.0, 0.0, g) > 0.0);
        // maximum of ω_e in following seas at ω0 = g/(2U), value g/(4U)
        let wmax = encounter_frequency(g / (2.0 * u), u, 0.0, g);
        assert!((wmax - g / (4.0 * u)).abs() < 1e-15);
        // angle convention
        assert!((encounter_angle(0.3, 0.3)).abs() < 1e-15); // following
        assert!((encounter_angle(0.0, PI).abs() - PI).abs() < 1e-15); // head
        assert!((encounter_angle(PI / 2.0, 0.0) - PI / 2.0).abs() < 1e-15);
        assert!((encounter_angle(-3.0, 3.0) - (2.0 * PI - 6.0)).abs() < 1e-12);
    }

    #[test]
    fn realisation_runs_at_the_encounter_frequency() {
        // a single sinusoid: the zero crossings of ζ(t) happen at the encounter frequency
        let mut p = params(SeaState::pierson_moskowitz(2.0, 8.0), 3);
        p.components = 1;
        for (gamma, u) in [(PI, 8.0), (PI / 2.0, 8.0), (0.0, 4.0), (0.0, 15.0)] {
            let mut w = Waves::new(p.clone(), 0.0).unwrap();
            w.set_inputs(u, gamma);
            let (a, frequency, _, theta0) = w.comps.get(0);
            let we = encounter_frequency(frequency, u, gamma, GRAVITY);
            for k in 0..100 {
                let t = k as f64 * 0.77;
                w.advance_to(t);
                assert!((w.elevation() - a * cos(theta0 + we * t)).abs() < 1e-12);
            }
            if gamma == 0.0 && u == 15.0 {
                assert!(
                    we < 0.0,
                    "following seas at 15 m/s: the ship overtakes ({we})"
                );
            }
        }
    }

    #[test]
    fn moments_scale_with_sin_gamma_and_sin_2gamma() {
        let mut p = WaveParams::default();
        p.roll_gain = 2.0e6;
        p.yaw_gain = 5.0e5;
        let mut w = Waves::new(p, 0.0).unwrap();
        for gamma in [0.0, 0.5, PI / 4.0, PI / 2.0, 2.0, PI, -1.0] {
            w.set_inputs(5.0, gamma);
            w.advance_to(w.time() + 1.3);
            let z = w.elevation();
            assert!((w.roll_moment() - 2.0e6 * sin(gamma) * z).abs() < 1e-6);
            assert!((w.yaw_moment() - 5.0e5 * sin(2.0 * gamma) * z).abs() < 1e-6);
        }
    }

    #[test]
    fn same_seed_bit_identical_different_seeds_uncorrelated() {
        for real in [Realisation::SumOfSinusoids, Realisation::ShapingFilter] {
            let mk = |seed| {
                let mut p = params(SeaState::jonswap(2.0, 9.0, 3.3), seed);
                p.realisation = real;
                p.internal_step = 0.5;
                Waves::new(p, 0.0).unwrap()
            };
            let n = 100_000;
            let (a, b, c) = (
                record(&mut mk(5), 0.5, n),
                record(&mut mk(5), 0.5, n),
                record(&mut mk(6), 0.5, n),
            );
            assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
            let rho = correlation(&a, &c);
            println!("{real:?}: rho(seed 5, seed 6) = {rho:.4}");
            assert!(rho.abs() < 0.05, "{real:?}: {rho}");
        }
    }

    #[test]
    fn output_does_not_depend_on_the_step_size() {
        for real in [Realisation::SumOfSinusoids, Realisation::ShapingFilter] {
            let mk = || {
                let mut p = params(SeaState::pierson_moskowitz(2.0, 9.0), 8);
                p.realisation = real;
                let mut w = Waves::new(p, 0.0).unwrap();
                w.set_inputs(6.0, 2.5);
                w
            };
            let (mut fine, mut coarse) = (mk(), mk());
            for k in 1..=2000 {
                let t = k as f64 * 0.3;
                // fine: 30 steps of 0.01 on FMPy's grid t_j = j h
                for j in 1..=30 {
                    fine.advance_to((30 * (k - 1) + j) as f64 * 0.01);
                }
                coarse.advance_to(t);
                let (a, b) = (fine.elevation(), coarse.elevation());
                assert!(a == b, "{real:?} t = {t}: {a} vs {b}");
                let (ma, mb) = (fine.wf_motion(), coarse.wf_motion());
                assert!(ma == mb, "{t} {ma:?} {mb:?}");
            }
        }
    }

    #[test]
    fn snapshot_restores_the_following_output_bit_for_bit() {
        let mut p = WaveParams::default();
        p.realisation = Realisation::ShapingFilter;
        let mut w = Waves::new(p, 0.0).unwrap();
        w.set_inputs(4.0, 1.0);
        w.advance_to(100.0);
        let snap = w.clone();
        let run = |w: &mut Waves| -> Vec<u64> {
            (1..200)
                .flat_map(|k| {
                    w.advance_to(100.0 + k as f64 * 0.1);
                    [w.elevation().to_bits(), w.wf_motion()[2].to_bits()]
                })
                .collect()
        };
        let first = run(&mut w);
        let mut again = snap;
        assert_eq!(first, run(&mut again));
    }
}
