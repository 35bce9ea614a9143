//! `Waves` FMU: long-crested irregular waves of `models::disturbances::waves` (spectra of
//! [Klugt1987, eq. (2.21)] / PM / JONSWAP, encounter frequency [Klugt1987, eq. (2.22)], moments
//! [Klugt1987, eqs. (2.23)-(2.24)], the wave-frequency motion of [Fossen1999, eqs. (10)-(11)]) as an FMI 2.0 co-simulation FMU. No physics here.

use fmi2_export::FmuModel;
use models::disturbances::waves::{
    encounter_angle, wf_sigma_for_std, Realisation, ShapingForm, SpectrumKind, WaveParams, Waves,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one wave instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WavesFmu {
    params: WaveParams,
    /// Standard deviations of the WF motion of [Fossen1999, eqs. (10)-(11)] (surge m, sway m, yaw rad); σ_i derived.
    wf_std: [f64; 3],
    wave_direction: f64,
    speed: f64,
    heading: f64,
    waves: Waves,
}

impl Default for WavesFmu {
    fn default() -> Self {
        let params = WaveParams::default();
        WavesFmu {
            waves: Waves::new(params.clone(), 0.0).expect("preset parameters are valid"),
            params,
            wf_std: [5.0, 5.0, 0.5f64.to_radians()],
            wave_direction: 0.0,
            speed: 0.0,
            heading: 0.0,
        }
    }
}

impl WavesFmu {
    fn gamma(&self) -> f64 {
        encounter_angle(self.wave_direction, self.heading)
    }
    fn apply_inputs(&mut self) {
        let g = self.gamma();
        self.waves.set_inputs(self.speed, g);
    }
    /// The model parameters with the FMU's derived σ_i.
    pub fn model_params(&self) -> WaveParams {
        let mut p = self.params.clone();
        for i in 0..3 {
            p.wf_sigma[i] = wf_sigma_for_std(self.wf_std[i], p.wf_zeta, p.wf_omega0);
        }
        p
    }
}

fmi2_export::fmu! {
    WavesFmu => "Waves",
    description: "Seeded long-crested irregular waves: Bretschneider-ITTC \
        (van der Klugt 1987 eq. 2.21), Pierson-Moskowitz and JONSWAP spectra, encounter frequency \
        (eq. 2.22), roll/yaw moments (eqs. 2.23-2.24), sum-of-sinusoids or shaping-filter \
        realisation, and the wave-frequency motion of Fossen & Strand (1999)",
    experiment: (0.0, 600.0, 0.1),
    documentation: "documentation.html",
    variables: {
        fixed int(0, i32::MAX) "seed" (params.seed as u64),
            "Seed of this instance's ChaCha8 streams (same seed: bit-identical output)";
        fixed int "spectrum" (params.sea.spectrum => {
            1: SpectrumKind::Bretschneider, 2: SpectrumKind::PiersonMoskowitz, 3: SpectrumKind::Jonswap
        }),
            "1: Bretschneider, ITTC form of [Klugt1987, eq. (2.21)] (wave_period = mean period T1); \
            2: Pierson-Moskowitz (wave_period = peak period Tp); 3: JONSWAP (Tp, jonswap_gamma)";
        fixed real "significant_wave_height" ["m"] (params.sea.hs).range(0.0, 30.0),
            "Significant wave height Hs = 4 sqrt(m0) (default: sea state 4 of [Taylor2000], 1.25-2.5 m, mid-range)";
        fixed real "wave_period" ["s"] (params.sea.period).range(0.5, 40.0),
            "Mean period T1 = 2 pi m0/m1 (spectrum 1) or peak period Tp (spectra 2, 3); default 8.84 s \
            (the 400-ft design wave of [Taylor2000])";
        fixed real "jonswap_gamma" (params.sea.gamma).range(1.0, 20.0),
            "JONSWAP peak-enhancement factor gamma (spectrum 3)";
        fixed int "realisation"
            (params.realisation => { 1: Realisation::SumOfSinusoids, 2: Realisation::ShapingFilter }),
            "1: sum of sinusoids (random frequencies in equal bins, random phases; exact at every time); \
            2: white noise through a second-order shaping filter ([Klugt1987, Fig. 2.10] / [Fossen1999, eq. (10)])";
        fixed int(1, 100_000) "number_of_components" (params.components as usize),
            "Number of sinusoids (realisation 1), allocated at initialization";
        fixed int "shaping_form"
            (params.shaping_form => { 1: ShapingForm::LowPass, 2: ShapingForm::BandPass }),
            "Shaping-filter output (realisation 2): 1: low-pass x of x'' + 2 z w x' + w^2 x = g n \
            ([Klugt1987, Fig. 2.10]); 2: band-pass x' ([Fossen1999, eq. (10)], sigma s/(s^2 + 2 zeta w0 s + w0^2))";
        fixed real "shaping_frequency" ["rad/s"] (params.shaping_frequency).min(0.0),
            "Shaping-filter frequency w0 before the encounter transformation; 0: the spectral peak";
        fixed real "shaping_damping" (params.shaping_damping).range(1e-3, 10.0),
            "Shaping-filter relative damping ([Fossen1999]: 0.1); the gain is set so that the variance is m0";
        fixed real "internal_step" ["s"] (params.internal_step).range(1e-4, 10.0),
            "Fixed internal grid of the noise processes (shaping filter, WF motion); output linearly \
            interpolated between grid points, independent of the communication step";
        tunable real "wave_direction" ["rad"] (wave_direction),
            "Direction the waves travel towards, same earth frame as heading; encounter angle \
            gamma = wave_direction - heading: 0 following, +-pi/2 beam, pi head seas";
        tunable real "roll_gain" ["N"] (params.roll_gain),
            "k_phi in roll_moment = k_phi sin(gamma) zeta(t) [N.m per m of elevation] ([Klugt1987, eq. (2.23)]; \
            H_g_phi not given in [Klugt1987]). Default 0: roll_moment is 0 until set. Choose k_phi so that \
            the moment's standard deviation k_phi |sin gamma| Hs/4 is the one you want (in the \
            units of the input it drives, e.g. rad per m for a rudder-equivalent input; \
            systems/rrs.toml tunes it to an open-loop roll variance)";
        tunable real "yaw_gain" ["N"] (params.yaw_gain),
            "k_psi in yaw_moment = k_psi sin(2 gamma) zeta(t) [N.m per m of elevation] ([Klugt1987, eq. (2.24)]). \
            Default 0: yaw_moment is 0 until set. Choose k_psi so that the moment's standard \
            deviation k_psi |sin 2 gamma| Hs/4 is the one you want (in the units of the input it \
            drives; systems/autopilot_track_offset.toml: 0.0745 rad per m for a 2 deg rudder-equivalent)";
        fixed real "gravity" ["m/s2"] (params.gravity).range(1.0, 20.0),
            "Acceleration of gravity g in eq. 2.22";
        fixed real "wf_omega0" ["rad/s"] (params.wf_omega0).min(1e-3),
            "Dominant wave frequency of the [Fossen1999] WF model ([Fossen1999]: 0.8976 rad/s, 7 s)";
        fixed real "wf_damping" (params.wf_zeta).range(1e-3, 10.0),
            "Relative damping zeta of the [Fossen1999] WF model ([Fossen1999]: 0.1)";
        fixed real "wf_std_surge" ["m"] (wf_std[0]).min(0.0),
            "Standard deviation of the WF surge motion (sigma_1 = std sqrt(4 zeta w0)); default 5 m: \
            significant amplitude 10 m of the simulation of [Fossen1999] [assumption]";
        fixed real "wf_std_sway" ["m"] (wf_std[1]).min(0.0),
            "Standard deviation of the WF sway motion; default 5 m [assumption, see wf_std_surge]";
        fixed real "wf_std_yaw" ["rad"] (wf_std[2]).min(0.0),
            "Standard deviation of the WF yaw motion; default 0.5 deg ([Fossen1999]: yaw amplitude 1 deg)";
        input real "ship_speed" ["m/s"] (speed),
            "Ship speed U for the encounter frequency (held over the step)";
        input real "heading" ["rad"] (heading),
            "Ship heading psi, same earth frame as wave_direction (held over the step)";
        output real "wave_elevation" ["m"] (|m| m.waves.elevation()),
            "Wave elevation zeta(t) at the ship, in the encounter domain";
        output real "roll_moment" ["N.m"] (|m| m.waves.roll_moment()).gated_by("roll_gain"),
            "Wave roll moment roll_gain sin(gamma) zeta ([Klugt1987, eq. (2.23)]); 0 while roll_gain = 0 (its default)";
        output real "yaw_moment" ["N.m"] (|m| m.waves.yaw_moment()).gated_by("yaw_gain"),
            "Wave yaw moment yaw_gain sin(2 gamma) zeta ([Klugt1987, eq. (2.24)]); 0 while yaw_gain = 0 (its default)";
        output real "encounter_angle" ["rad"] (|m| m.gamma()),
            "gamma in (-pi, pi]: 0 following, pi head seas";
        output real "peak_encounter_frequency" ["rad/s"] (|m| m.waves.peak_encounter_frequency()),
            "Encounter frequency of the spectral peak, w_p - w_p^2 U cos(gamma)/g ([Klugt1987, eq. (2.22)]), signed";
        output real "wf_motion_surge" ["m"] (|m| m.waves.wf_motion()[0]),
            "[Fossen1999] wave-frequency surge motion (add to the LF position measurement)";
        output real "wf_motion_sway" ["m"] (|m| m.waves.wf_motion()[1]),
            "[Fossen1999] wave-frequency sway motion";
        output real "wf_motion_yaw" ["rad"] (|m| m.waves.wf_motion()[2]),
            "[Fossen1999] wave-frequency yaw motion";
    }
}

impl FmuModel for WavesFmu {
    fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.waves = Waves::new(self.model_params(), start_time)?;
        self.apply_inputs();
        Ok(())
    }

    fn parameters_changed(&mut self) -> Result<(), String> {
        self.waves
            .set_gains(self.params.roll_gain, self.params.yaw_gain);
        self.apply_inputs();
        Ok(())
    }

    fn calculate_outputs(&mut self) {
        self.apply_inputs();
    }

    fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        self.apply_inputs();
        self.waves.advance_to(t + h);
        Ok(())
    }

    fn internal_steps(&self, t: f64, h: f64, each: &mut dyn FnMut(&'static str, f64, f64)) {
        self.waves.internal_steps(t + h, each);
    }
}
