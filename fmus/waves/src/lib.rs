//! `Waves` FMU: long-crested irregular waves of `models::disturbances::waves` (spectra of 003
//! eq. 2.21 / PM / JONSWAP, encounter frequency 003 eq. 2.22, moments 003 eqs. 2.23-2.24, the
//! wave-frequency motion of 001) as an FMI 2.0 co-simulation FMU. No physics here.

use fmi2_export::{export_fmu, DefaultExperiment, FmuModel, Variable};
use models::disturbances::waves::{
    encounter_angle, wf_sigma_for_std, Realisation, ShapingForm, SpectrumKind, WaveParams, Waves,
};
use serde::{Deserialize, Serialize};

/// Parameters, inputs and state of one wave instance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WavesFmu {
    params: WaveParams,
    /// Standard deviations of the 001 WF motion (surge m, sway m, yaw rad); σ_i derived.
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

fn kind_to_int(k: SpectrumKind) -> i32 {
    match k {
        SpectrumKind::Bretschneider => 1,
        SpectrumKind::PiersonMoskowitz => 2,
        SpectrumKind::Jonswap => 3,
    }
}

type V = Variable<WavesFmu>;

static VARIABLES: [V; 30] = [
    V::integer_parameter(
        "seed",
        false,
        "Seed of this instance's ChaCha8 streams (same seed: bit-identical output)",
        0,
        i32::MAX,
        |m| m.params.seed as i32,
        |m, v| m.params.seed = v as u64,
    ),
    V::integer_parameter(
        "spectrum",
        false,
        "1: Bretschneider, ITTC form of 003 eq. 2.21 (wave_period = mean period T1); \
         2: Pierson-Moskowitz (wave_period = peak period Tp); 3: JONSWAP (Tp, jonswap_gamma)",
        1,
        3,
        |m| kind_to_int(m.params.sea.spectrum),
        |m, v| {
            m.params.sea.spectrum = match v {
                1 => SpectrumKind::Bretschneider,
                3 => SpectrumKind::Jonswap,
                _ => SpectrumKind::PiersonMoskowitz,
            }
        },
    ),
    V::real_parameter(
        "significant_wave_height",
        Some("m"),
        false,
        "Significant wave height Hs = 4 sqrt(m0) (default: sea state 4 of 000, 1.25-2.5 m, mid-range)",
        |m| m.params.sea.hs,
        |m, v| m.params.sea.hs = v,
    )
    .with_range(Some(0.0), Some(30.0)),
    V::real_parameter(
        "wave_period",
        Some("s"),
        false,
        "Mean period T1 = 2 pi m0/m1 (spectrum 1) or peak period Tp (spectra 2, 3); default 8.84 s \
         (000's 400-ft design wave)",
        |m| m.params.sea.period,
        |m, v| m.params.sea.period = v,
    )
    .with_range(Some(0.5), Some(40.0)),
    V::real_parameter(
        "jonswap_gamma",
        None,
        false,
        "JONSWAP peak-enhancement factor gamma (spectrum 3)",
        |m| m.params.sea.gamma,
        |m, v| m.params.sea.gamma = v,
    )
    .with_range(Some(1.0), Some(20.0)),
    V::integer_parameter(
        "realisation",
        false,
        "1: sum of sinusoids (random frequencies in equal bins, random phases; exact at every time); \
         2: white noise through a second-order shaping filter (003 Fig. 2.10 / 001 eq. 10)",
        1,
        2,
        |m| match m.params.realisation {
            Realisation::SumOfSinusoids => 1,
            Realisation::ShapingFilter => 2,
        },
        |m, v| {
            m.params.realisation = if v == 2 {
                Realisation::ShapingFilter
            } else {
                Realisation::SumOfSinusoids
            }
        },
    ),
    V::integer_parameter(
        "number_of_components",
        false,
        "Number of sinusoids (realisation 1), allocated at initialization",
        1,
        100_000,
        |m| m.params.components as i32,
        |m, v| m.params.components = v as usize,
    ),
    V::integer_parameter(
        "shaping_form",
        false,
        "Shaping-filter output (realisation 2): 1: low-pass x of x'' + 2 z w x' + w^2 x = g n \
         (003 Fig. 2.10); 2: band-pass x' (001 eq. 10, sigma s/(s^2 + 2 zeta w0 s + w0^2))",
        1,
        2,
        |m| match m.params.shaping_form {
            ShapingForm::LowPass => 1,
            ShapingForm::BandPass => 2,
        },
        |m, v| {
            m.params.shaping_form = if v == 1 {
                ShapingForm::LowPass
            } else {
                ShapingForm::BandPass
            }
        },
    ),
    V::real_parameter(
        "shaping_frequency",
        Some("rad/s"),
        false,
        "Shaping-filter frequency w0 before the encounter transformation; 0: the spectral peak",
        |m| m.params.shaping_frequency,
        |m, v| m.params.shaping_frequency = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "shaping_damping",
        None,
        false,
        "Shaping-filter relative damping (001: 0.1); the gain is set so that the variance is m0",
        |m| m.params.shaping_damping,
        |m, v| m.params.shaping_damping = v,
    )
    .with_range(Some(1e-3), Some(10.0)),
    V::real_parameter(
        "internal_step",
        Some("s"),
        false,
        "Fixed internal grid of the noise processes (shaping filter, WF motion); output linearly \
         interpolated between grid points, independent of the communication step",
        |m| m.params.internal_step,
        |m, v| m.params.internal_step = v,
    )
    .with_range(Some(1e-4), Some(10.0)),
    V::real_parameter(
        "wave_direction",
        Some("rad"),
        true,
        "Direction the waves travel towards, same earth frame as heading; encounter angle \
         gamma = wave_direction - heading: 0 following, +-pi/2 beam, pi head seas",
        |m| m.wave_direction,
        |m, v| m.wave_direction = v,
    ),
    V::real_parameter(
        "roll_gain",
        Some("N"),
        true,
        "k_phi in roll_moment = k_phi sin(gamma) zeta(t) [N.m per m of elevation] (003 eq. 2.23; \
         H_g_phi not given in 003)",
        |m| m.params.roll_gain,
        |m, v| m.params.roll_gain = v,
    ),
    V::real_parameter(
        "yaw_gain",
        Some("N"),
        true,
        "k_psi in yaw_moment = k_psi sin(2 gamma) zeta(t) [N.m per m of elevation] (003 eq. 2.24)",
        |m| m.params.yaw_gain,
        |m, v| m.params.yaw_gain = v,
    ),
    V::real_parameter(
        "gravity",
        Some("m/s2"),
        false,
        "Acceleration of gravity g in eq. 2.22",
        |m| m.params.gravity,
        |m, v| m.params.gravity = v,
    )
    .with_range(Some(1.0), Some(20.0)),
    V::real_parameter(
        "wf_omega0",
        Some("rad/s"),
        false,
        "Dominant wave frequency of the 001 WF model (001: 0.8976 rad/s, 7 s)",
        |m| m.params.wf_omega0,
        |m, v| m.params.wf_omega0 = v,
    )
    .with_range(Some(1e-3), None),
    V::real_parameter(
        "wf_damping",
        None,
        false,
        "Relative damping zeta of the 001 WF model (001: 0.1)",
        |m| m.params.wf_zeta,
        |m, v| m.params.wf_zeta = v,
    )
    .with_range(Some(1e-3), Some(10.0)),
    V::real_parameter(
        "wf_std_surge",
        Some("m"),
        false,
        "Standard deviation of the WF surge motion (sigma_1 = std sqrt(4 zeta w0)); default 5 m: \
         significant amplitude 10 m of 001's simulation [assumption]",
        |m| m.wf_std[0],
        |m, v| m.wf_std[0] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "wf_std_sway",
        Some("m"),
        false,
        "Standard deviation of the WF sway motion; default 5 m [assumption, see wf_std_surge]",
        |m| m.wf_std[1],
        |m, v| m.wf_std[1] = v,
    )
    .with_range(Some(0.0), None),
    V::real_parameter(
        "wf_std_yaw",
        Some("rad"),
        false,
        "Standard deviation of the WF yaw motion; default 0.5 deg (001: yaw amplitude 1 deg)",
        |m| m.wf_std[2],
        |m, v| m.wf_std[2] = v,
    )
    .with_range(Some(0.0), None),
    V::real_input(
        "ship_speed",
        Some("m/s"),
        "Ship speed U for the encounter frequency (held over the step)",
        |m| m.speed,
        |m, v| m.speed = v,
    ),
    V::real_input(
        "heading",
        Some("rad"),
        "Ship heading psi, same earth frame as wave_direction (held over the step)",
        |m| m.heading,
        |m, v| m.heading = v,
    ),
    V::real_output(
        "wave_elevation",
        Some("m"),
        "Wave elevation zeta(t) at the ship, in the encounter domain",
        |m| m.waves.elevation(),
    ),
    V::real_output(
        "roll_moment",
        Some("N.m"),
        "Wave roll moment roll_gain sin(gamma) zeta (003 eq. 2.23)",
        |m| m.waves.roll_moment(),
    ),
    V::real_output(
        "yaw_moment",
        Some("N.m"),
        "Wave yaw moment yaw_gain sin(2 gamma) zeta (003 eq. 2.24)",
        |m| m.waves.yaw_moment(),
    ),
    V::real_output(
        "encounter_angle",
        Some("rad"),
        "gamma in (-pi, pi]: 0 following, pi head seas",
        |m| m.gamma(),
    ),
    V::real_output(
        "peak_encounter_frequency",
        Some("rad/s"),
        "Encounter frequency of the spectral peak, w_p - w_p^2 U cos(gamma)/g (003 eq. 2.22), signed",
        |m| m.waves.peak_encounter_frequency(),
    ),
    V::real_output(
        "wf_motion_surge",
        Some("m"),
        "001 wave-frequency surge motion (add to the LF position measurement)",
        |m| m.waves.wf_motion()[0],
    ),
    V::real_output(
        "wf_motion_sway",
        Some("m"),
        "001 wave-frequency sway motion",
        |m| m.waves.wf_motion()[1],
    ),
    V::real_output(
        "wf_motion_yaw",
        Some("rad"),
        "001 wave-frequency yaw motion",
        |m| m.waves.wf_motion()[2],
    ),
];

impl FmuModel for WavesFmu {
    const MODEL_IDENTIFIER: &'static str = "Waves";
    const DESCRIPTION: &'static str = "Seeded long-crested irregular waves: Bretschneider-ITTC \
        (van der Klugt 1987 eq. 2.21), Pierson-Moskowitz and JONSWAP spectra, encounter frequency \
        (eq. 2.22), roll/yaw moments (eqs. 2.23-2.24), sum-of-sinusoids or shaping-filter \
        realisation, and the wave-frequency motion of Fossen & Strand (1999)";
    const DEFAULT_EXPERIMENT: DefaultExperiment = DefaultExperiment {
        start_time: 0.0,
        stop_time: 600.0,
        step_size: 0.1,
    };

    fn variables() -> &'static [Variable<Self>] {
        &VARIABLES
    }

    fn documentation_html() -> &'static str {
        include_str!("documentation.html")
    }

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
}

export_fmu!(WavesFmu);
