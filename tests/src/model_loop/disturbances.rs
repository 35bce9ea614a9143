//! The `waves` and `wind` instances of the model loops: each FMU's wrapper without the export
//! layer (`fmus/waves/src/lib.rs`, `fmus/wind/src/lib.rs`), used only through the models'
//! public API as the FMU uses it, so a faster wave or wind model changes the FMU systems and the
//! loops alike. A loop builds the model parameters from its system file.

use models::disturbances::waves::{
    encounter_angle, wf_sigma_for_std, SeaState, SpectrumKind, WaveParams, Waves,
};
use models::disturbances::wind::{Wind, WindParams};

/// A disturbance's published outputs (`waves.*`, `wind.*`): the rudder-equivalent moments.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    pub roll_moment: f64,
    pub yaw_moment: f64,
}

/// The parameters of the `Waves` FMU with a Bretschneider sea of significant height `hs` [m]
/// and mean period `period` [s], the rudder-equivalent gains and the seed of a system file; the
/// FMU's defaults otherwise.
pub(super) fn bretschneider(
    hs: f64,
    period: f64,
    (roll_gain, yaw_gain): (f64, f64),
    seed: u64,
) -> WaveParams {
    WaveParams {
        sea: SeaState {
            spectrum: SpectrumKind::Bretschneider,
            hs,
            period,
            ..WaveParams::default().sea
        },
        roll_gain,
        yaw_gain,
        seed,
        ..WaveParams::default()
    }
}

/// `waves` (`fmus/waves`): the model with the FMU's derived σ_i (`WavesFmu::model_params`: the
/// σ_i of its default standard deviations of the WF motion, surge, sway and yaw), its encounter
/// angle from the ship's heading.
pub(super) struct WavesInstance {
    params: WaveParams,
    wave_direction: f64,
    /// Input `ship_speed`.
    pub speed: f64,
    /// Input `heading`.
    pub heading: f64,
    waves: Waves,
}

impl WavesInstance {
    /// The instance of `params` (its σ_i replaced as the FMU derives them), with the parameter
    /// `wave_direction` and the start value `speed` of the input `ship_speed`.
    pub fn new(
        mut params: WaveParams,
        wave_direction: f64,
        speed: f64,
        start_time: f64,
    ) -> Result<WavesInstance, String> {
        let wf_std = [5.0, 5.0, 0.5f64.to_radians()];
        for (sigma, std) in params.wf_sigma.iter_mut().zip(wf_std) {
            *sigma = wf_sigma_for_std(std, params.wf_zeta, params.wf_omega0);
        }
        Ok(WavesInstance {
            waves: Waves::new(params.clone(), start_time)?,
            params,
            wave_direction,
            speed,
            heading: 0.0,
        })
    }

    pub fn apply_inputs(&mut self) {
        let gamma = encounter_angle(self.wave_direction, self.heading);
        self.waves.set_inputs(self.speed, gamma);
    }

    pub fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.waves = Waves::new(self.params.clone(), start_time)?;
        self.apply_inputs();
        Ok(())
    }

    pub fn calculate_outputs(&mut self) {
        self.apply_inputs();
    }

    pub fn do_step(&mut self, t: f64, h: f64) {
        self.apply_inputs();
        self.waves.advance_to(t + h);
    }

    pub fn outputs(&self) -> Moments {
        Moments {
            roll_moment: self.waves.roll_moment(),
            yaw_moment: self.waves.yaw_moment(),
        }
    }
}

/// `wind` (`fmus/wind`): the model and its inputs.
pub(super) struct WindInstance {
    params: WindParams,
    /// Input `ship_speed`.
    pub speed: f64,
    /// Input `heading`.
    pub heading: f64,
    model: Wind,
}

impl WindInstance {
    /// The instance of `params`, with the start value `speed` of the input `ship_speed`.
    pub fn new(params: WindParams, speed: f64, start_time: f64) -> Result<WindInstance, String> {
        Ok(WindInstance {
            model: Wind::new(params.clone(), start_time)?,
            params,
            speed,
            heading: 0.0,
        })
    }

    pub fn initialize(&mut self, start_time: f64) -> Result<(), String> {
        self.model = Wind::new(self.params.clone(), start_time)?;
        self.model.set_inputs(self.speed, self.heading);
        Ok(())
    }

    pub fn calculate_outputs(&mut self) {
        self.model.set_inputs(self.speed, self.heading);
    }

    pub fn do_step(&mut self, t: f64, h: f64) {
        self.model.set_inputs(self.speed, self.heading);
        self.model.advance_to(t + h);
    }

    /// The FMU's outputs, from the relative wind computed once (`WindFmu::relative`;
    /// `Wind::roll_moment` is `roll_moment_at(relative())`, the same bits).
    pub fn outputs(&self) -> Moments {
        let wind = self.model.relative();
        Moments {
            roll_moment: self.model.roll_moment_at(wind),
            yaw_moment: self.model.yaw_moment_at(wind),
        }
    }
}
