"""Waves.fmu (models::disturbances::waves): the same seed gives bit-identical output in both
importers and a different seed gives an uncorrelated record; outputs independent of the
communication step; the disturbance FMUs in shipsim; encounter frequency. Its comparison with the
Rust model (cases `waves_sum_of_sinusoids` and `waves_shaping_filter`) in FMPy and libcosim is in
test_fmu_cases.py."""
import numpy as np
from fmpy import simulate_fmu

from cosim import run_libcosim


def test_same_seed_identical_across_importers_other_seed_uncorrelated(fmu_path):
    fmu = str(fmu_path("Waves"))
    h, n = 1.0, 100_000
    runs = {}
    for seed in (11, 12):
        runs[seed] = simulate_fmu(fmu, stop_time=n * h, step_size=h, output_interval=h,
                                  output=["wave_elevation"], start_values={"seed": seed})
    cosim = run_libcosim(fmu_path("Waves"), h, n, ["wave_elevation"], initial={"seed": 11})
    a = runs[11]["wave_elevation"]
    assert np.array_equal(cosim["wave_elevation"], a[1:])
    again = simulate_fmu(fmu, stop_time=n * h, step_size=h, output_interval=h,
                         output=["wave_elevation"], start_values={"seed": 11})
    assert np.array_equal(again["wave_elevation"], a)
    rho = np.corrcoef(a, runs[12]["wave_elevation"])[0, 1]
    assert abs(rho) < 0.05


def test_output_independent_of_communication_step(fmu_path):
    """Sum of sinusoids is exact at each time; the shaping filter runs on its own grid."""
    fmu = str(fmu_path("Waves"))
    for extra in ({}, {"realisation": 2}):
        fine = simulate_fmu(fmu, stop_time=60.0, step_size=0.01, output_interval=0.5,
                            output=["wave_elevation", "wf_motion_sway"], start_values=extra)
        coarse = simulate_fmu(fmu, stop_time=60.0, step_size=0.5, output_interval=0.5,
                              output=["wave_elevation", "wf_motion_sway"], start_values=extra)
        for name in ("wave_elevation", "wf_motion_sway"):
            np.testing.assert_allclose(fine[name], coarse[name], rtol=0, atol=1e-9, err_msg=name)


def test_disturbance_fmus_in_shipsim_equal_fmpy_and_libcosim(fmu_path, tmp_path):
    """Waves, Wind, Current and Sensors in our master: each seeded instance gives bit-identical
    output to the same FMU alone in FMPy, and the coupled system equals libcosim on the exported
    OspSystemStructure.xml (Jacobi) to 1e-12."""
    import shutil
    import textwrap
    from test_master_interop import assert_same_as_libcosim, read_csv, shipsim

    for name in ("Waves", "Wind", "Current", "Sensors"):
        shutil.copy(fmu_path(name), tmp_path / f"{name}.fmu")
    (tmp_path / "env.toml").write_text(textwrap.dedent("""
        connections = ["waves.wave_elevation -> sensors.cross_track", "wind.relative_wind_speed -> sensors.speed"]
        [simulation]
        stop_time = 60.0
        step_size = 0.1
        [[instances]]
        name = "waves"
        fmu = "Waves.fmu"
        parameters = { seed = 5, realisation = 2 }
        [[instances]]
        name = "wind"
        fmu = "Wind.fmu"
        parameters = { seed = 4 }
        [[instances]]
        name = "current"
        fmu = "Current.fmu"
        parameters = { seed = 6, white_sigma_n = 2e-5, passing_ship_factor = 4.0, passing_ship_time = 0.5 }
        [[instances]]
        name = "sensors"
        fmu = "Sensors.fmu"
        parameters = { seed = 8, speed_sigma = 0.1 }
        [output]
        variables = ["waves.wave_elevation", "wind.true_wind_speed", "current.n_prime",
                     "sensors.cross_track_measured", "sensors.speed_measured", "sensors.north_measured"]
    """))
    out = tmp_path / "env.csv"
    shipsim("run", tmp_path / "env.toml", "-o", out)
    header, rows = read_csv(out)
    col = lambda name: np.array([r[header.index(name)] for r in rows])
    for fmu, var, start in (("Waves", "wave_elevation", {"seed": 5, "realisation": 2}),
                            ("Wind", "true_wind_speed", {"seed": 4}),
                            ("Current", "n_prime", {"seed": 6, "white_sigma_n": 2e-5,
                                                    "passing_ship_factor": 4.0, "passing_ship_time": 0.5}),
                            ("Sensors", "north_measured", {"seed": 8})):
        alone = simulate_fmu(str(fmu_path(fmu)), stop_time=60.0, step_size=0.1, output_interval=0.1,
                             output=[var], start_values=start)
        ours = col(f"{fmu.lower()}.{var}")
        assert len(ours) == len(alone)
        diff = np.max(np.abs(ours - alone[var]))
        assert diff == 0.0, (fmu, diff, np.argmax(np.abs(ours - alone[var])))
    shipsim("export-osp", tmp_path / "env.toml", "-o", tmp_path / "OspSystemStructure.xml")
    assert_same_as_libcosim(tmp_path / "OspSystemStructure.xml", out)


def test_encounter_frequency_outputs_eq_2_22(fmu_path):
    """peak_encounter_frequency = wp - wp^2 U cos(gamma)/g at head, beam and following seas,
    including the sign change in following seas at high speed (default sea: Tp = 8.84 s)."""
    wp, g = 2 * np.pi / 8.84, 9.81
    for heading, speed, gamma in ((np.pi, 10.0, np.pi), (np.pi / 2, 10.0, -np.pi / 2),
                                  (0.0, 5.0, 0.0), (0.0, 25.0, 0.0)):
        r = simulate_fmu(str(fmu_path("Waves")), stop_time=1.0, step_size=0.5, output_interval=0.5,
                         output=["peak_encounter_frequency", "encounter_angle"],
                         start_values={"heading": heading, "ship_speed": speed})
        assert abs(abs(r["encounter_angle"][-1]) - abs(gamma)) < 1e-12
        expected = wp - wp ** 2 * speed * np.cos(gamma) / g
        assert abs(r["peak_encounter_frequency"][-1] - expected) < 1e-12
    # following seas: positive at 5 m/s, negative at 25 m/s (> g/wp = 13.8 m/s)
    assert wp - wp ** 2 * 5.0 / g > 0 > wp - wp ** 2 * 25.0 / g
