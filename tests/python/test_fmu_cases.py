"""Every FMU in FMPy and in libcosim reproduces its Rust model for the inputs of a `model-reference`
case (tests/src/reference): one row of `CASES` per (FMU, case).

For each row:
* `test_fmpy_matches_rust_model`: FMPy over the reference's time grid with its inputs and the
  row's start values gives, at every row, the reference's outputs to 1e-12 x the output's scale
  (same time grid, finite reference values; Boolean outputs exactly).
* `test_libcosim_matches_rust_model`: libcosim (fixed step, override manipulator for the inputs)
  gives the same after every step, to 1e-12 x scale absolute (and `libcosim_rtol` relative where
  libcosim's integer-nanosecond clock makes the step differ from the reference's t_(k+1) - t_k in
  the last bit).
* `test_reference_case_exercises_the_model`: the case's own check on the reference rows, which
  guards against vacuous agreement (the case reaches the limiters, the filter learns, ...).

Test ids are `<model identifier>-<reference case>`, e.g.
`test_fmpy_matches_rust_model[SteeringGear-steering_gear_sine]`.

Reference rows: `time`, the inputs set at that time, the outputs as an importer samples them
before setting that row's inputs (row 0: after initialization). Outputs with direct feedthrough
(DpController, DgpsKalman's drift angle and body velocities) are therefore those of the previous
row's inputs, in both importers as in the reference.

Other tests of single FMUs that are not reference comparisons (seeds, noise statistics,
communication-step independence) are in test_current.py, test_sensors.py, test_wind.py,
test_waves.py and test_hulls.py; checks of every FMU in test_fmus.py.
"""
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np
import pytest

from cosim import column, fmpy_on_reference, libcosim_on_reference, variables_by_name

ATOL = 1e-12


# --- scale of an output: the comparison is to ATOL x scale absolute ---

def unit_scale(ref, name):
    return 1.0


def fixed_scale(scales):
    """Scale per output name (1 for the others): dimensional outputs such as moments in N.m."""
    def scale(ref, name):
        return scales.get(name, 1.0)
    return scale


def reference_scale(floor):
    """The largest magnitude of the output in the reference, at least `floor`."""
    def scale(ref, name):
        return max(floor, max(abs(r[name]) for r in ref))
    return scale


@dataclass(frozen=True)
class FmuCase:
    fmu: str                                # model identifier (target/fmu/<fmu>.fmu)
    case: str                               # model-reference case
    inputs: Optional[tuple] = None          # None: the reference columns that are FMU inputs
    outputs: Optional[tuple] = None         # None: the reference columns that are FMU outputs
    params: dict = field(default_factory=dict)  # start values in FMPy, initial values in libcosim
    scale: Callable = unit_scale            # (ref, output name) -> scale of the 1e-12 tolerance
    libcosim_rtol: float = 0.0              # relative tolerance in libcosim (FMPy: always 0)
    booleans: tuple = ()                    # Boolean outputs, compared exactly (FMPy)
    check: Optional[Callable] = None        # (ref) -> None: asserts the case exercises the model

    @property
    def id(self):
        return f"{self.fmu}-{self.case}"

    def columns(self, fmu, ref):
        """The (inputs, outputs) compared. Cases without lists take them from the reference's
        header: every column but `time` must be a variable of the FMU, its causality says which
        is an input and which an output."""
        if self.inputs is not None and self.outputs is not None:
            return list(self.inputs), list(self.outputs)
        variables = variables_by_name(fmu)
        names = [n for n in ref[0] if n != "time"]
        for n in names:
            assert n in variables, f"reference column {n} is not a variable of {fmu.name}"
        inputs = [n for n in names if variables[n].causality == "input"]
        outputs = [n for n in names if variables[n].causality == "output"]
        assert inputs and outputs
        return inputs, outputs


# --- per-case checks of the reference rows (the case exercises what it is meant to) ---

def moves(*names):
    """Each named column moves by more than 1e-3 over the case."""
    def check(ref):
        for name in names:
            assert np.ptp(column(ref, name)) > 1e-3, f"{name} does not move"
    check.__name__ = f"moves({', '.join(names)})"
    return check


def steering_gear_reaches_both_limiters(ref):
    assert max(abs(r["rudder_angle"]) for r in ref) > 0.38
    assert ref[-1]["rate_saturated_time"] > 1.0


def waves_have_elevation(ref):
    assert np.std([r["wave_elevation"] for r in ref]) > 0.1


def dgps_kalman_follows_the_turn(ref):
    # speed over ground near 7 m/s at the end
    assert abs(ref[-1]["speed_over_ground"] - 7.0) < 0.5


def passive_observer_wave_filter_active(ref):
    # the wave filter has picked up the 3 m, 0.9 rad/s motion
    assert max(abs(r["north_wf_estimate"]) for r in ref[300:]) > 1.0


def parameter_ekf_learns(ref):
    # -Y_v moved from half the [Taylor2000, Table 2.3] value towards 0.0244
    assert ref[-1]["neg_y_v_estimate"] > 0.018
    assert ref[-1]["update_count"] == 900


def path_kalman_filter_follows_cross_track(ref):
    # the cross-track estimate follows the 5 m + ramp measurement
    assert abs(ref[-1]["cross_track_estimate"] - ref[-1]["cross_track_measured"]) < 5.0


def rrs_filter_finds_heel_and_adapts(ref):
    # the roll filter has found the 0.02 rad heel, the yaw filter adapted E[w3^2]
    assert abs(ref[-1]["heel_offset_estimate"] - 0.02) < 5e-3
    assert ref[-1]["yaw_e_w3_used"] != ref[0]["yaw_e_w3_used"]


def dp_controller_acts(ref):
    # the PID and the test input both act
    assert max(abs(r["tau_surge"]) for r in ref) > 1e5


def heading_autopilot_follows_the_turn(ref):
    assert min(r["heading_reference_used"] for r in ref) == pytest.approx(-np.pi / 2, abs=1e-12)


def track_controller_reaches_the_limit(ref):
    # +-30 deg rudder limit
    assert max(abs(r["rudder_command"]) for r in ref) == pytest.approx(np.radians(30.0), abs=1e-15)


def path_controller_dithers_and_adapts(ref):
    # the dither (+-0.5 rad) and two gain updates
    commands = {r["rudder_command"] for r in ref}
    assert 0.5 in commands and -0.5 in commands
    assert ref[-1]["gain_updates"] == 2.0


def path_estimator_moves_toward_truth(ref):
    # f23 moves from the deep-water value (3.1591) toward the truth (5.7359)
    assert ref[-1]["f23_estimate"] > 4.0


def path_wls_three_fits(ref):
    # three fits, each near the deep-water truth (f23 = 3.1591) from the 1.89 start (5.7359)
    assert ref[-1]["updates"] == 3.0
    assert abs(ref[-1]["f23_estimate"] - 3.1591) < 0.01


def rrs_autopilot_agc_and_adaptation(ref):
    # the AGC (attenuation below 1) and the criterion adaptation (q_phi moves)
    assert min(r["attenuation"] for r in ref) < 0.9
    assert len({r["q_phi"] for r in ref}) > 100


# libcosim keeps time as integer nanoseconds, so its steps can differ from the reference's
# t_(k+1) - t_k in the last bit: where outputs integrate h (RK4 hulls over hundreds of steps move
# positions of ~1e3 m by a few 1e-12 m; RrsAutopilot's q_phi ~ 40 by up to 1.3e-12; the loop-shaped
# controllers' sample step h'/n follows h) the libcosim tolerance is also 1e-12 relative.
INTEGER_NS_RTOL = 1e-12

WAVES_PARAMS = {"seed": 5, "roll_gain": 1.0e6, "yaw_gain": 3.0e5, "wave_direction": 0.4}
# Waves' outputs are functions of absolute time; the model rounds every time to a whole
# nanosecond, so libcosim's clock and FMPy's k*h give the same instants (rtol 0).
WAVES_SCALE = fixed_scale({"roll_moment": 1.0e6, "yaw_moment": 3.0e5})
WAVES_OUTPUTS = ("wave_elevation", "roll_moment", "yaw_moment", "wf_motion_surge", "wf_motion_yaw")

DGPS_KALMAN_INPUTS = ("north_measured", "east_measured", "heading", "current_speed",
                      "current_direction")
DGPS_KALMAN_OUTPUTS = (
    "velocity_north_estimate", "velocity_east_estimate", "north_estimate", "east_estimate",
    "speed_over_ground", "course_over_ground", "drift_angle", "gain_velocity", "gain_position",
    "surge_velocity_ground", "sway_velocity_ground", "surge_velocity_water", "sway_velocity_water",
    "drift_angle_water")

SENSOR_CHANNELS = ("heading", "yaw_rate", "roll", "roll_rate", "north", "east", "cross_track",
                   "speed", "sway_velocity")

CASES = [
    # --- hulls and manoeuvres (models::hull, models::manoeuvre): columns from the reference ---
    FmuCase("ContainerShip", "container_ship_nonlinear", libcosim_rtol=INTEGER_NS_RTOL,
            check=moves("heading", "roll", "sway_velocity")),
    FmuCase("ContainerShip", "container_ship_linear", params={"variant": 2},
            libcosim_rtol=INTEGER_NS_RTOL, check=moves("heading", "roll", "sway_velocity")),
    FmuCase("Mariner", "mariner_trimmed", libcosim_rtol=INTEGER_NS_RTOL,
            check=moves("heading", "sway_velocity")),
    FmuCase("RrsShip", "rrs_ship_simulation", params={"model": 1}, libcosim_rtol=INTEGER_NS_RTOL,
            check=moves("roll", "yaw_rate", "heading")),
    FmuCase("RrsShip", "rrs_ship_control", params={"model": 2}, libcosim_rtol=INTEGER_NS_RTOL,
            check=moves("roll", "yaw_rate", "heading")),
    FmuCase("TokyoMaru", "tokyo_maru_design_depth", params={"depth_ratio": 1.89},
            libcosim_rtol=INTEGER_NS_RTOL, check=moves("heading", "cross_track")),
    FmuCase("TokyoMaru", "tokyo_maru_gear_deep",
            params={"deep_water": True, "internal_steering_gear": True},
            libcosim_rtol=INTEGER_NS_RTOL, check=moves("heading", "cross_track")),
    FmuCase("NomotoShip", "nomoto_ship_ddg51", params={"model": 1}, libcosim_rtol=INTEGER_NS_RTOL,
            check=moves("heading", "yaw_rate")),
    FmuCase("NomotoShip", "nomoto_ship_esso_osaka", params={"model": 2},
            libcosim_rtol=INTEGER_NS_RTOL, check=moves("heading", "yaw_rate")),
    FmuCase("SupplyVessel", "supply_vessel_thrust", libcosim_rtol=INTEGER_NS_RTOL,
            check=moves("x", "y", "heading", "measured_x")),
    FmuCase("Manoeuvre", "manoeuvre_zigzag",
            params={"kind": 2, "rudder_angle": 0.17453292519943295,
                    "check_angle": 0.17453292519943295, "execute_time": 10.0},
            libcosim_rtol=INTEGER_NS_RTOL, check=moves("rudder_command")),
    FmuCase("Manoeuvre", "manoeuvre_pull_out",
            params={"kind": 3, "rudder_angle": 0.3490658503988659, "hold_time": 60.0,
                    "execute_time": 10.0},
            libcosim_rtol=INTEGER_NS_RTOL, check=moves("rudder_command")),

    # --- steering gear (models::steering_gear) ---
    FmuCase("SteeringGear", "steering_gear_sine", inputs=("rudder_command",),
            outputs=("rudder_angle", "rudder_rate", "rate_saturated_time"),
            check=steering_gear_reaches_both_limiters),

    # --- disturbances (models::disturbances) ---
    FmuCase("Waves", "waves_sum_of_sinusoids", inputs=("ship_speed", "heading"),
            outputs=WAVES_OUTPUTS, params=WAVES_PARAMS, scale=WAVES_SCALE,
            check=waves_have_elevation),
    FmuCase("Waves", "waves_shaping_filter", inputs=("ship_speed", "heading"),
            outputs=WAVES_OUTPUTS, params={**WAVES_PARAMS, "realisation": 2, "shaping_form": 1},
            scale=WAVES_SCALE, check=waves_have_elevation),
    FmuCase("Wind", "wind_gusts", inputs=("ship_speed", "heading"),
            outputs=("true_wind_speed", "relative_wind_speed", "relative_wind_angle",
                     "roll_moment", "yaw_moment"),
            params={"seed": 4, "roll_coefficient": 2.0e3, "yaw_coefficient": 5.0e3,
                    "wind_direction": 1.0},
            scale=fixed_scale({"true_wind_speed": 10.0, "relative_wind_speed": 10.0,
                               "roll_moment": 1e6, "yaw_moment": 1e6})),
    FmuCase("Current", "current_parsons1980", inputs=("heading",),
            outputs=("current_sway", "n_prime", "y_prime", "yaw_moment", "side_force",
                     "bias_surge", "bias_n"),
            params={"seed": 6, "current_speed_final": 5.0 * 1852.0 / 3600.0,
                    "current_direction": np.pi / 2, "current_start_time": 30.0,
                    "design_current": True, "passing_ship_factor": 4.0,
                    "passing_ship_time": 20.0, "white_sigma_n": 2e-5,
                    "shaping_sigma_y": 21.178e-5, "walk_q_y": 1.25e-7, "bias_psi_x": 10.0,
                    "bias_initial_n": 1.0e5},
            # dimensional N, Y are ~1e8 N.m, ~1e6 N
            scale=fixed_scale({"yaw_moment": 1e9, "side_force": 1e7, "bias_surge": 1e3,
                               "bias_n": 1e5})),

    # --- sensors (models::sensors) ---
    FmuCase("Sensors", "sensors_default", inputs=SENSOR_CHANNELS,
            outputs=tuple(c + "_measured" for c in SENSOR_CHANNELS),
            params={"seed": 8, "roll_sigma": 0.3}),

    # --- observers (models::observers) ---
    FmuCase("DgpsKalman", "dgps_kalman_steady", inputs=DGPS_KALMAN_INPUTS,
            outputs=DGPS_KALMAN_OUTPUTS, params={"initial_velocity_north": 7.0},
            scale=reference_scale(1.0e-3), check=dgps_kalman_follows_the_turn),
    FmuCase("DgpsKalman", "dgps_kalman_full_recursion", inputs=DGPS_KALMAN_INPUTS,
            outputs=DGPS_KALMAN_OUTPUTS,
            params={"initial_velocity_north": 7.0, "full_recursion": True,
                    "process_noise_level": 0.1},
            scale=reference_scale(1.0e-3), check=dgps_kalman_follows_the_turn),
    FmuCase("PassiveObserver", "passive_observer",
            inputs=("north_measured", "east_measured", "heading_measured", "tau_surge",
                    "tau_sway", "tau_yaw"),
            outputs=("north_estimate", "east_estimate", "heading_estimate",
                     "surge_velocity_estimate", "north_wf_estimate", "bias_north_estimate",
                     "bias_yaw_estimate"),
            scale=reference_scale(1.0e-3), check=passive_observer_wave_filter_active),
    FmuCase("ParameterEkf", "parameter_ekf",
            inputs=("surge_velocity_measured", "sway_velocity_measured", "yaw_rate_measured",
                    "shaft_speed_measured", "rudder_angle"),
            outputs=("surge_velocity_estimate", "sway_velocity_estimate", "yaw_rate_estimate",
                     "shaft_speed_estimate", "neg_y_v_estimate", "m_minus_y_r_estimate",
                     "neg_n_v_estimate", "mxg_minus_n_r_estimate", "neg_y_v_mean",
                     "m_minus_y_r_mean", "neg_n_v_mean", "mxg_minus_n_r_mean", "neg_y_v_std",
                     "neg_n_v_std", "nomoto_time_constant_prime", "nomoto_gain_prime",
                     "innovation_sway", "innovation_yaw_rate", "update_count"),
            scale=reference_scale(1.0e-6), check=parameter_ekf_learns),
    FmuCase("PathKalmanFilter", "path_kalman_filter",
            inputs=("heading_measured", "yaw_rate_measured", "cross_track_measured",
                    "rudder_command"),
            outputs=("heading_estimate", "yaw_rate_estimate", "drift_angle_estimate",
                     "cross_track_estimate", "yaw_moment_prime_estimate",
                     "sway_force_prime_estimate", "innovation_cross_track"),
            scale=reference_scale(1.0e-3), check=path_kalman_filter_follows_cross_track),
    FmuCase("RrsFilter", "rrs_filter",
            inputs=("roll_measured", "heading_measured", "speed_measured", "roll_rudder",
                    "course_rudder"),
            outputs=("roll_estimate", "roll_rate_estimate", "heel_offset_estimate",
                     "heading_estimate", "yaw_rate_estimate", "yaw_bias_estimate",
                     "yaw_e_w3_used", "yaw_k1", "speed_estimate"),
            scale=reference_scale(1.0e-3), check=rrs_filter_finds_heel_and_adapts),

    # --- controllers and estimators (models::controllers) ---
    FmuCase("DpController", "dp_controller",
            inputs=("north_estimate", "east_estimate", "heading_estimate",
                    "surge_velocity_estimate", "sway_velocity_estimate", "yaw_rate_estimate",
                    "north_setpoint", "east_setpoint", "heading_setpoint"),
            outputs=("tau_surge", "tau_sway", "tau_yaw", "error_surge", "error_sway",
                     "error_yaw"),
            params={"test_amplitude_surge": 1e5, "test_amplitude_sway": 1e5,
                    "test_amplitude_yaw": 1e7},
            scale=reference_scale(1.0e-3), check=dp_controller_acts),
    FmuCase("HeadingAutopilot", "heading_autopilot_track_change", inputs=("heading",),
            outputs=("rudder_command", "unlimited_command", "heading_reference_used"),
            params={"reference_mode": 1, "turn_angle": -np.pi / 2, "turn_rate": 0.05,
                    "leg_time": 60.0, "turn_start": 10.0},
            libcosim_rtol=INTEGER_NS_RTOL, check=heading_autopilot_follows_the_turn),
    FmuCase("TrackController", "track_controller_offset",
            inputs=("cross_track", "cross_track_reference"),
            outputs=("rudder_command", "unlimited_command"),
            libcosim_rtol=INTEGER_NS_RTOL, check=track_controller_reaches_the_limit),
    FmuCase("PathController", "path_controller_adaptive",
            inputs=("heading", "yaw_rate", "drift_angle", "cross_track", "rudder_angle",
                    "yaw_moment_prime", "sway_force_prime", "f22_estimate", "f23_estimate",
                    "f25_estimate", "f32_estimate", "f33_estimate", "f35_estimate"),
            outputs=("rudder_command", "gain_yaw_moment", "design_f23", "gain_updates"),
            params={"adaptation": 2, "dither_enabled": True, "dither_start": 1.0,
                    "dither_window": 1.0, "dither_cycle": 3.0},
            check=path_controller_dithers_and_adapts),
    # h = 0.25 s is exact in libcosim's integer-ns clock and in FMPy's t_k = k h (rtol 0)
    FmuCase("PathEstimator", "path_estimator_dither",
            inputs=("heading", "yaw_rate", "drift_angle", "cross_track", "rudder_angle"),
            outputs=("f22_estimate", "f23_estimate", "f25_estimate", "f32_estimate",
                     "f33_estimate", "f35_estimate"),
            check=path_estimator_moves_toward_truth),
    FmuCase("PathWlsEstimator", "path_wls_windows",
            inputs=("heading", "yaw_rate", "drift_angle", "cross_track", "rudder_angle",
                    "heading_estimate", "yaw_rate_estimate", "drift_angle_estimate",
                    "cross_track_estimate"),
            outputs=("f22_estimate", "f23_estimate", "f25_estimate", "f32_estimate",
                     "f33_estimate", "f35_estimate", "yaw_moment_prime_estimate",
                     "sway_force_prime_estimate", "validity", "evaluations", "final_cost",
                     "residual_sum_of_squares", "updates"),
            booleans=("estimate_valid", "loading"),
            # tests/src/reference/path_wls.rs: WINDOW_START, WINDOW_LENGTH, UPDATE_CYCLE
            params={"window_start": 0.5, "window_length": 1.0, "update_cycle": 1.5},
            check=path_wls_three_fits),
    FmuCase("RrsAutopilot", "rrs_autopilot_adaptive",
            inputs=("roll", "roll_rate", "sway_rudder", "heading_error", "yaw_rate",
                    "yaw_offset", "speed"),
            outputs=("rudder_command", "attenuation", "q_phi", "roll_gain_1"),
            params={"adaptation_enabled": True, "q_phi_initial": 40.0, "rate_max": 0.12},
            libcosim_rtol=INTEGER_NS_RTOL, check=rrs_autopilot_agc_and_adaptation),
]


def _params(cases):
    return [pytest.param(c, id=c.id) for c in cases]


def test_case_ids_are_unique():
    ids = [c.id for c in CASES]
    assert len(ids) == len(set(ids))


@pytest.mark.parametrize("c", _params(CASES))
def test_fmpy_matches_rust_model(c, fmu_path, reference):
    fmu = fmu_path(c.fmu)
    ref = reference(c.case)
    inputs, outputs = c.columns(fmu, ref)
    result = fmpy_on_reference(fmu, ref, inputs, outputs + list(c.booleans), c.params)
    assert len(result) == len(ref)
    np.testing.assert_array_equal(result["time"], column(ref, "time"))
    for name in outputs:
        expected = column(ref, name)
        assert np.all(np.isfinite(expected)), name
        np.testing.assert_allclose(result[name], expected, rtol=0, atol=ATOL * c.scale(ref, name),
                                   err_msg=name)
    for name in c.booleans:
        np.testing.assert_array_equal(result[name].astype(float), column(ref, name), err_msg=name)


@pytest.mark.parametrize("c", _params(CASES))
def test_libcosim_matches_rust_model(c, fmu_path, reference):
    fmu = fmu_path(c.fmu)
    ref = reference(c.case)
    inputs, outputs = c.columns(fmu, ref)
    result = libcosim_on_reference(fmu, ref, inputs, outputs, c.params)
    for name in outputs:
        expected = column(ref, name)[1:]
        np.testing.assert_allclose(result[name], expected, rtol=c.libcosim_rtol,
                                   atol=ATOL * c.scale(ref, name), err_msg=name)


@pytest.mark.parametrize("c", _params([c for c in CASES if c.check is not None]))
def test_reference_case_exercises_the_model(c, reference):
    """Guards against vacuous agreement: the case reaches what it is meant to exercise."""
    c.check(reference(c.case))
