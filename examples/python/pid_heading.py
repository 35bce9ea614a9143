"""A heading controller written in Python, in place of the HeadingAutopilot FMU.

examples/python/pid_heading.toml is systems/autopilot_current.toml (the DDG-51 keeping its
heading while a 5-kn beam current dies away) without the HeadingAutopilot instance `ap`, so
that the steering gear's rudder command is free: a PID below reads the sampled heading of the
`sensors` instance, as the FMU autopilot does, and sets `gear.rudder_command` from a stepping
session. The script then runs the original system with the FMU autopilot over the same time,
plots heading and rudder of both and prints a comparison.

The reference: systems/autopilot_current.toml gives its autopilot the heading reference 0
(`ap.heading_reference`, reference_mode = 0) and the ship starts on heading 0, so in the file
itself the autopilot only holds the heading against the sensor noise (the first-order Nomoto
hull has no sway, so the current moves the ship but does not turn it). To see the controllers
work, both runs get the same heading change at t = 0: --heading-step degrees (default 10; the
FMU autopilot through its `ap.heading_reference` input). --heading-step 0 runs the file as it is.

Run: target/venv/bin/python examples/python/pid_heading.py [--output pid_heading.png]
"""
import argparse
import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import shipsim  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent
PID_SYSTEM = HERE / "pid_heading.toml"
FMU_SYSTEM = HERE.parents[1] / "systems" / "autopilot_current.toml"

RUDDER_LIMIT = math.radians(30.0)  # HeadingAutopilot's command_limit in autopilot_current.toml


def nomoto_plant(system):
    """K [1/s] and T [s] of the ship's first-order Nomoto model r/delta = K/(1 + T s), from
    the nondimensional K', T' of the system file: K = K' U/L, T = T' L/U."""
    v = {name: float(text) for name, text in system.values.items() if name.startswith("ship.")}
    length, speed = v["ship.length"], v["ship.speed"]
    return v["ship.k_prime"] * speed / length, v["ship.t_prime"] * length / speed


def wrap(angle):
    """An angle in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


# --- the controller ----------------------------------------------------------------------
# Gains by pole placement on the Nomoto model psi/delta = K/(s (1 + T s)), the textbook PID
# autopilot (e.g. Fossen, Handbook of Marine Craft Hydrodynamics and Motion Control): with
# delta = Kp e - Kd r (r the yaw rate), the closed loop is T psi'' + (1 + K Kd) psi' + K Kp psi
# = K Kp psi_ref, so Kp = T wn^2/K and Kd = (2 zeta wn T - 1)/K; Ki = wn Kp/10 puts the
# integral action a decade below wn. For the DDG-51 at 22 kn (K = 0.163 1/s, T = 24.2 s) we
# take wn = 0.1 rad/s: faster than the hull (1/T = 0.04 rad/s), yet 5 times below the steering
# gear (1/2.09 s = 0.48 rad/s) and 30 times below the Nyquist frequency of the 1 s heading
# samples, whose lags the design then ignores; zeta = 0.8 for a well-damped turn. A 10 deg
# error asks for Kp 10 deg = 15 deg of rudder, half the 30 deg limit. The ship's heading is
# already an integral, so an integral term would overshoot every turn: it only integrates
# within 1 deg of the reference, where it removes a constant yaw moment (wind, a rudder bias;
# this system has none) without winding up during a turn.
WN, ZETA, INTEGRAL_BAND = 0.1, 0.8, math.radians(1.0)


class PidHeading:
    def __init__(self, K, T, reference, dt):
        self.kp = T * WN**2 / K
        self.kd = (2.0 * ZETA * WN * T - 1.0) / K
        self.ki = WN * self.kp / 10.0
        self.reference, self.dt = reference, dt
        self.integral, self.previous = 0.0, None

    def __call__(self, heading):
        """One sample: measured heading [rad] -> rudder command [rad]."""
        error = wrap(self.reference - heading)
        # derivative on the measurement (no kick when the reference changes)
        rate = 0.0 if self.previous is None else wrap(heading - self.previous) / self.dt
        self.previous = heading
        if abs(error) < INTEGRAL_BAND:
            self.integral += error * self.dt
        command = self.kp * error + self.ki * self.integral - self.kd * rate
        return min(max(command, -RUDDER_LIMIT), RUDDER_LIMIT)


def run_pid(reference, stop_time):
    """pid_heading.toml stepped from Python: the PID runs at the sensor's 1 s sampling
    interval and holds its command in between, as a digital autopilot does."""
    system = shipsim.System.load(PID_SYSTEM)
    K, T = nomoto_plant(system)
    with system.start(stop_time=stop_time) as session:
        dt = float(system.values["sensors.heading_interval"])  # 1 s
        steps = round(dt / session.step_size)  # 20 macro steps of 0.05 s
        pid = PidHeading(K, T, reference, dt)
        while session.state == "open":
            command = pid(session.get("sensors.heading_measured"))
            session.set("gear.rudder_command", command)
            session.step(steps)
        rows = session.rows()
    return rows, pid


# --- the comparison ----------------------------------------------------------------------
def run_fmu(reference, stop_time):
    """The original system with its HeadingAutopilot FMU, given the same reference."""
    system = shipsim.System.load(FMU_SYSTEM)
    system.set("ap.heading_reference", reference)
    return system.run(stop_time=stop_time)


def metrics(rows, reference):
    """Overshoot [deg] and 2 % settling time [s] of the turn (None without a turn), RMS heading
    error and RMS rudder angle over the second half of the run [deg], largest rudder [deg]."""
    t = rows.index.to_numpy()
    error = np.degrees(rows["ship.heading"].to_numpy() - reference)
    rudder = np.degrees(rows["gear.rudder_angle"].to_numpy())
    late = t >= t[-1] / 2
    out = {
        "overshoot": None,
        "settling": None,
        "rms_error": float(np.sqrt(np.mean(error[late] ** 2))),
        "rms_rudder": float(np.sqrt(np.mean(rudder[late] ** 2))),
        "max_rudder": float(np.max(np.abs(rudder))),
    }
    step = math.degrees(reference)
    if step != 0.0:
        out["overshoot"] = float(max(0.0, np.max(error * np.sign(step))))
        outside = np.nonzero(np.abs(error) > 0.02 * abs(step))[0]  # outside the 2 % band
        last = outside[-1] + 1 if len(outside) else 0
        out["settling"] = float(t[last]) if last < len(t) else math.inf  # inf: never settles
    return out


def plot(pid_rows, fmu_rows, reference, path):
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    for rows, label in ((pid_rows, "Python PID"), (fmu_rows, "HeadingAutopilot FMU")):
        ax1.plot(rows.index, np.degrees(rows["ship.heading"]), label=label)
        ax2.plot(rows.index, np.degrees(rows["gear.rudder_angle"]), label=label)
    ax1.axhline(math.degrees(reference), color="k", ls="--", lw=0.8, label="reference")
    ax1.set_ylabel("heading [deg]")
    ax2.set_ylabel("rudder angle [deg]")
    ax2.set_xlabel("time [s]")
    ax1.legend()
    ax1.set_title("DDG-51 heading control: Python PID vs HeadingAutopilot FMU")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", default="pid_heading.png", help="PNG file (default: %(default)s)")
    parser.add_argument("--heading-step", type=float, default=10.0, help="heading change at t = 0 [deg]")
    parser.add_argument("--stop-time", type=float, default=None, help="end time [s] (default: the file's 400 s)")
    args = parser.parse_args(argv)

    reference = math.radians(args.heading_step)
    pid_rows, pid = run_pid(reference, args.stop_time)
    fmu_rows = run_fmu(reference, args.stop_time)
    plot(pid_rows, fmu_rows, reference, args.output)

    print(f"PID gains: Kp = {pid.kp:.3f} rad/rad, Ki = {pid.ki:.4f} 1/s, Kd = {pid.kd:.2f} s")
    print(f"heading step {args.heading_step:g} deg, {pid_rows.index[-1]:g} s")
    print(f"{'controller':<22}{'overshoot':>11}{'settling':>10}{'RMS error':>11}{'RMS rudder':>12}{'max rudder':>12}")
    print(f"{'':<22}{'[deg]':>11}{'[s]':>10}{'[deg]':>11}{'[deg]':>12}{'[deg]':>12}")
    for label, rows in (("Python PID", pid_rows), ("HeadingAutopilot FMU", fmu_rows)):
        m = metrics(rows, reference)
        overshoot = "-" if m["overshoot"] is None else f"{m['overshoot']:.3f}"
        settling = "-" if m["settling"] is None else f"{m['settling']:.1f}"
        print(f"{label:<22}{overshoot:>11}{settling:>10}{m['rms_error']:>11.4f}"
              f"{m['rms_rudder']:>12.3f}{m['max_rudder']:>12.2f}")
    print("(RMS over the second half of the run; settling: to within 2 % of the step)")
    print(f"plot: {args.output}")


if __name__ == "__main__":
    main()
