"""Independent reference calculations for the loop analysis of the master (issue 35).

What `shipsim loop` (and `System.loop_margins`, `frequency_response`, `describing_function`) must
measure, computed here in numpy only (no scipy in the venv, nothing installed), from the models'
and FMUs' sources and the system files, never from the tool. `python tests/python/loop_reference.py`
prints the term-by-term tables. The tests are in test_loop_verification.py.

The measurement (the spec of issue 35, coded here as `snap`, `phasor`, `ShipLoop.measure_loop`):
t_k = t0 + k h; d_k = A sin(w (t_k - T)) held over [t_k, t_k+1); w snapped so that P periods are
N = round(2 pi P/(w h)) steps; phasors X = (2/N) sum x_k exp(-j w (t_k - T)) over the N steps from
k0 = ceil(settle/h); a response is Y/D; the loop at a break "a.y -> b.u" is L = -R/U with r_k = a.y
published at t_k and u_k = r_k + d_k. Margins: first |L| = 1 (PM = 180 + angle L, delay margin =
PM[rad]/wc), first angle L = -180 deg (GM = -20 log10 |L|), peak of |1/(1 + L)|.
(The tool takes more than P periods where a period is shorter than 50 steps, see `shipsim loop
--help`; the tests accept that, checking that each frequency is 2 pi P'/(N h), P' >= P.)

FINDINGS
========

(a) FirstOrderLag (examples/first_order_lag: y+ = a y + (1 - a) K u, a = exp(-h/T), u held): the
response measured from d_k to the y published at t_k is exactly G = K (1 - a)/(z - a),
z = exp(j w h) (checked against the recursion with the correlation, 1e-9). The tool agrees to
1e-13 relative at 10 frequencies 0.05 ... 20 rad/s (h = 0.1 s, K = 2.5, T = 1.5 s).

(b) Rate limiter [Klugt1987, sec. 5.2.2]: `rate_limiter_df(ab/R)` is the exact fundamental of the
steady-state output of y' = sat(k (x - y), +-R), k -> inf, for x = a sin(bt): 1 for ab/R <= 1; a
trapezoid-like wave (the output tracks the input between the meeting point theta1 and
theta2 = pi - acos(R/ab), ramps in between) for 1 < ab/R < sqrt(1 + pi^2/4) = 1.862; a triangle
of amplitude pi R/(2b) beyond, |N| = 4R/(pi a b), lag pi/2 - asin(pi R/(2ab)). At ab = 3R:
0.424413 a, lag 58.426 deg (the 0.4244 and 58.4 deg of the models' test). Checked against a
simulated rate limiter (0.05 %). Through the SteeringGear FMU (time_constant 0.001 s, 15 deg/s,
angle_max 3 rad, h = 0.005 s, w = 0.63 -> 0.629984 rad/s, P = 4, settle 200 s):

    ab/R      ideal |N|  ideal deg   FMU measured |N|  deg      (tool = this to 1e-14)
    0.8       1.000000     0.000     1.000000        -0.185
    1.2       0.966867    -4.073     0.966796        -4.280
    1.5       0.838358   -15.814     0.838304       -16.022
    2.0       0.636620   -38.243     0.636620       -38.405
    3.0       0.424413   -58.426     0.424413       -58.541
    5.0       0.254648   -71.690     0.254648       -71.777

The extra 0.09-0.21 deg are the step: y published at t_k is the gear after the command held over
the step before (omega h = 0.18 deg at h = 0.005 s). The rate-limited start leaves a decaying offset:
the fundamental moves by 3e-7 between settle 100 s and 200 s, by < 1e-9 after.

(c) The DDG-51 heading loop of systems/autopilot_current.toml, at the break
"ap.rudder_command -> gear.rudder_command".

Settings: --set sensors.noise_scale=0 (noise off), current.current_speed_initial=0 and
current.current_speed_final=0 (the current enters only the ship's kinematics x, y, never the
heading loop; it is switched off so that the operating point is exactly the zero state); no --at
(the start time, the zero state; every element is linear there, the +-30 deg limits are far).

The elements, as the FMUs integrate them (every one read from its source):
* SteeringGear (models/src/steering_gear.rs, first order, no rate limit): exact exponential over
  the step for the held command, delta+ = u - (u - delta) exp(-h/tau). The file's
  time_constant = 2.0916473591203615 s is exactly L/(6U) (L = 142.0368 m, U = 11.3178 m/s): the
  6/(s+6) of the issue is in t' = tU/L, in seconds it is 1/(2.0916 s + 1), a pole at 0.478 rad/s.
  So the file's gear IS the design's gear: its term in the table is zero.
* NomotoShip (models/src/hull/nomoto.rs, model 1): T' r'' + r' = K' delta in t', psi' = r'
  (T' = 1.9287, K' = 2.04), RK4 with ceil(h/0.1) = 1 sub-step of 0.05 s, rudder held; the track
  loop adds y' = U sin(psi), linearised (U psi).
* Sensors (models/src/sensors.rs): sample-and-hold every heading_interval = 1 s = M = 20 steps
  (noise off). Under the Jacobi master the outputs published at t_k are read BEFORE the inputs
  of t_k are set, so: at an instant t_k = j*1 s the sample is taken when the step ending at t_k
  reaches it, from the input held over that step, i.e. the heading of t_(k-1); at t_k+1 ...
  t_k+19 the published value is the sample re-taken at t_k with the heading set there. Delays
  behind the published heading over one period: 1, 1, 2, 3, ..., 19 steps (mean 9.55 steps).
  Seen in a plain `shipsim run` (heading_measured at t = 1.0 is the heading of 0.95).
* HeadingAutopilot (models/src/controllers/loop_shaped.rs): C(s') = w_n^2/(K a)(T s' + 1)(s' + a)/
  (s'^2 + 2 zeta w_n s' + w_n^2), w_n = sqrt 60, zeta = 2, a = 6 (the FMU's defaults, read from
  its modelDescription), Tustin (controllable canonical form) at tau' = h U/L = 0.003984 t'
  (below sample_step 0.01: one sample per communication step, so the autopilot's own sampling
  is the master's), the error taken from the input held at t_k, the output published at t_k+1.
* Jacobi master (master/src/run/algorithm.rs): every instance steps from the outputs published at
  t_k; so r_k+1 from m_k, delta_k+1 from u_k, psi_k+1 from delta_k, m_k+1 from psi_k.

This discretised loop (`ShipLoop.simulate`) reproduces a plain `shipsim run` of the system (a
0.05 rad heading-reference step, every signal of the loop at every step) to 1e-15 (heading loop)
and 3e-9 (track loop, the linearised sin psi).

What the correlation measures. The sensor's hold makes the loop periodically time-varying (period
1 s): a sinusoid at w comes back at w and at its aliases w + 2 pi m/(1 s). Two parts:
* the fundamental (m = 0) term of the hold's harmonic transfer function: the mean over the period
  of exp(-j w h delay) = (exp(-j w h) + sum_{i=1}^{19} exp(-j w h i))/20; the loop through it is
  `loop_sampled(w, "full")` (exact, a z-domain product of the elements);
* the aliases, which re-enter the fundamental through the plant only at the 1e-6 level (the gear
  and the ship filter 2 pi rad/s by 1e-5), but which are large in r and u themselves (the
  controller's high-frequency gain on the hold's steps: 30 % of the fundamental at 0.6 rad/s) and
  leak into the correlation when N is not a whole number of sensor periods: up to 0.02 dB /
  0.1 deg near the heading loop's phase crossover, 0.05 dB / 0.4 deg for the track loop, varying
  with N and with where the window starts.
Hence the reference for the tool is the time-domain simulation of the same loop with the same
injection and window (`measure_loop`); the margins (`measured_margins`) are found on the exact
fundamental term and corrected by the simulated measurement at the crossings. When N is a
multiple of 20 the leakage vanishes: the simulated measurement equals the fundamental term to
1e-6 dB / 4e-5 deg (tested) - a tool that snapped N to whole periods of the slowest hold as well
would measure the fundamental term exactly, independent of the window.

Term by term (each row adds one effect to the one above; w in rad/s; Ms = peak |1/(1 + L)|):

    heading loop                                              GM dB   w180    PM deg   wc      DM s   Ms     w_Ms
    continuous design [Taylor2000] (gear a/(s'+a), a = 6)     29.823  0.6172  64.406  0.07288  15.42  1.3038 0.1429
    + the file's gear, time_constant = 2.0916 s (= L/(6U))    29.823  0.6172  64.406  0.07288  15.42  1.3038 0.1429
    + master sampling h = 0.05 s: Tustin, gear + ship ZOH     29.304  0.5990  64.302  0.07288  15.40  1.3062 0.1426
    + ship fed the held gear angle (gear exact, ship RK4)     28.813  0.5823  64.197  0.07288  15.37  1.3086 0.1424
    + Jacobi: one step in the autopilot, one in the sensor    27.107  0.5271  63.779  0.07288  15.27  1.3182 0.1416
    + sensor sample-and-hold every 1 s (fundamental term)     22.317  0.3942  61.999  0.07287  14.85  1.3609 0.1380
    measured (P = 4, settle 300 s, A = 0.01 rad): reference   22.293  0.3939  61.996  0.07287  14.849 1.3609 0.1380
    measured: the tool (same settings, Ms = max over grid)    22.295  0.3940  61.996  0.07287  14.849 1.3611 0.1385

Each row is an added delay at an unchanged crossover: the command held over the step h/2 (0.104
deg at wc = 0.0729 rad/s), the gear angle held into the ship h/2 (0.105 deg), the autopilot's and
the sensor's Jacobi steps 2h (0.418 deg), the 1 s hold 8.55 h more (1.785 deg). In all an
equivalent delay of 0.5775 s: the continuous design times exp(-0.5775 s) has 22.26 dB / 61.99 deg.
The phase lost is small at the crossover (0.073 rad/s) but large at the phase crossover
(0.62 rad/s: 20 deg), which moves down to 0.394 rad/s where |L| is 7.5 dB larger: the gain
margin falls 29.82 -> 22.32 dB (the 1 s hold alone 4.8 dB), the phase margin only
64.41 -> 62.00 deg, the delay margin 15.42 -> 14.85 s (by the 0.5775 s). The issue's hand
measurement without the sensor's hold (PM about 62, GM 27-28 dB) matches the "Jacobi" row's
27.1 dB.

The tool's table (34 rows: the 30 frequencies and 4 refinement points) equals the simulated
measurement at every row to 1e-13 dB and 1e-12 deg: the same loop, injection and window.

(d) The track loop (AT-2) of systems/autopilot_track_offset.toml at "ctl.rudder_command ->
gear.rudder_command" (TrackController C_y = 20 (s'+0.5)^2 (s'+6)(s'+1000)/((s'+11)(s'+15)
(s'+30)^2) on y/L, the cross-track position sampled every 1 s). Settings: those of the heading
loop plus waves.yaw_gain=0 (no wave moment) and ctl.reference_mode=0 (no lateral-offset
manoeuvre; external reference 0); P = 8 (its aliases leak more).

    track loop                                                GM dB   w180    PM deg   wc      DM s   Ms     w_Ms
    continuous design [Taylor2000]                            21.574  0.5798  50.990  0.07581  11.74  1.2512 0.1266
    + the file's gear (= L/(6U))                              21.574  0.5798  50.990  0.07581  11.74  1.2512 0.1266
    + master sampling h = 0.05 s: Tustin, gear + ship ZOH     21.410  0.5731  50.882  0.07581  11.71  1.2539 0.1264
    + ship fed the held gear angle (gear exact, ship RK4)     21.251  0.5665  50.773  0.07581  11.69  1.2567 0.1262
    + Jacobi: one step in the controller, one in the sensor   20.648  0.5420  50.338  0.07581  11.59  1.2678 0.1255
    + sensor sample-and-hold every 1 s (fundamental term)     18.576  0.4588  48.480  0.07579  11.16  1.3175 0.1221
    measured (P = 8, settle 300 s, A = 0.01 rad): reference   18.526  0.4576  48.516  0.07582  11.17  1.3182 0.1216
    measured: the tool (same settings, Ms = max over grid)    18.529  0.4580  48.397  0.07572  11.16  1.3165 0.1194

The same 0.5775 s (continuous design times exp(-0.5775 s): 18.50 dB / 48.48 deg). The tool's
phase margin differs from the reference's by 0.12 deg: its refinement measures at other N, whose
leakage differs (the fundamental term's 48.48 deg lies between). Its table rows equal the
simulated measurement to 3e-4 dB / 1e-5 deg (the reference linearises U sin psi; the tool's own
linearity check shows 4e-4 dB at twice the amplitude).
"""
from __future__ import annotations

import math
import pathlib
import tomllib
import xml.etree.ElementTree as ET
import zipfile
from dataclasses import dataclass, field

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
FMU_DIR = ROOT / "target" / "fmu"
EXAMPLE_FMU_DIR = ROOT / "target" / "fmu-examples"
HEADING_SYSTEM = ROOT / "systems" / "autopilot_current.toml"
TRACK_SYSTEM = ROOT / "systems" / "autopilot_track_offset.toml"

DEG = math.pi / 180.0


# --------------------------------------------------------------------------------------------
# Generic pieces: the measurement of the spec, margins, small linear algebra
# --------------------------------------------------------------------------------------------

def snap(omega: float, periods: float, h: float) -> tuple[float, int]:
    """The spec's snapping: N = round(2 pi P / (omega h)), omega = 2 pi P / (N h)."""
    n = int(round(2.0 * math.pi * periods / (omega * h)))
    n = max(n, 1)
    return 2.0 * math.pi * periods / (n * h), n


def window_of(omega: float, h: float, min_periods: int, max_periods: int = 100000) -> tuple[int, int]:
    """(P, N) of a snapped frequency: the smallest whole number of periods P >= min_periods that
    spans a whole number N of steps (the tool may take more periods than asked, e.g. where a
    period is short)."""
    per = 2.0 * math.pi / (omega * h)
    for p in range(int(min_periods), max_periods):
        n = p * per
        if abs(n - round(n)) < 1e-6:
            return p, int(round(n))
    raise ValueError(f"{omega} rad/s is not 2 pi P/(N h) for P < {max_periods}")


def phasor(x: np.ndarray, t_rel: np.ndarray, omega: float) -> complex:
    """X = (2/N) sum x_k exp(-j omega (t_k - T))."""
    return complex(2.0 / len(x) * np.sum(x * np.exp(-1j * omega * t_rel)))


def expm(a: np.ndarray) -> np.ndarray:
    """Matrix exponential by scaling and squaring of a Taylor series (small, well-scaled
    matrices only; no scipy in the venv)."""
    a = np.asarray(a, dtype=float)
    norm = np.max(np.sum(np.abs(a), axis=1)) if a.size else 0.0
    s = max(0, int(math.ceil(math.log2(norm / 0.25))) if norm > 0.25 else 0)
    x = a / 2.0 ** s
    result = np.eye(len(a))
    term = np.eye(len(a))
    for k in range(1, 30):
        term = term @ x / k
        result = result + term
        if np.max(np.abs(term)) < 1e-18:
            break
    for _ in range(s):
        result = result @ result
    return result


def zoh(a: np.ndarray, b: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretisation (Van Loan block exponential)."""
    n, m = b.shape
    blk = np.zeros((n + m, n + m))
    blk[:n, :n] = a
    blk[:n, n:] = b
    e = expm(blk * h)
    return e[:n, :n], e[:n, n:]


def rk4_matrices(a: np.ndarray, b: np.ndarray, h: float, h_max: float) -> tuple[np.ndarray, np.ndarray]:
    """One communication step of `models::integrate::rk4_advance` on x' = A x + B u with u held:
    n = ceil(h/h_max (1 - 1e-12)) classical RK4 sub-steps of h/n. For a linear system each
    sub-step is x+ = (I + Ah + (Ah)^2/2 + (Ah)^3/6 + (Ah)^4/24) x
    + (h + A h^2/2 + A^2 h^3/6 + A^3 h^4/24) B u."""
    n = max(1, int(math.ceil(h / h_max * (1.0 - 1e-12))))
    hs = h / n
    eye = np.eye(len(a))
    ah = a * hs
    phi1 = eye + ah + ah @ ah / 2 + ah @ ah @ ah / 6 + ah @ ah @ ah @ ah / 24
    gam1 = (eye * hs + ah * hs / 2 + ah @ ah * hs / 6 + ah @ ah @ ah * hs / 24) @ b
    phi, gam = np.eye(len(a)), np.zeros_like(b)
    for _ in range(n):
        phi, gam = phi1 @ phi, phi1 @ gam + gam1
    return phi, gam


def ss_freq(a, b, c, d, z):
    """c (zI - a)^-1 b + d at complex z (scalar input and output)."""
    z = np.atleast_1d(z)
    out = np.empty(len(z), dtype=complex)
    n = len(a)
    for i, zi in enumerate(z):
        out[i] = (c @ np.linalg.solve(zi * np.eye(n) - a, b)).item() + d
    return out


def unwrap_deg(phase_rad: np.ndarray) -> np.ndarray:
    return np.degrees(np.unwrap(phase_rad))


@dataclass
class Margins:
    gain_margin_db: float
    gain_margin_rad_s: float
    phase_margin_deg: float
    crossover_rad_s: float
    delay_margin_s: float
    sensitivity_peak: float
    sensitivity_peak_rad_s: float

    def as_dict(self):
        return dict(self.__dict__)


def _bisect(f, lo, hi, iters=100):
    flo = f(lo)
    for _ in range(iters):
        mid = math.sqrt(lo * hi)
        if (f(mid) > 0) == (flo > 0):
            lo = mid
        else:
            hi = mid
        if hi / lo - 1 < 1e-13:
            break
    return math.sqrt(lo * hi)


def margins(loop, w_lo: float, w_hi: float, n: int = 4000) -> Margins:
    """Margins of a loop given as a vectorised function omega -> L(j omega): first gain crossover
    (|L| = 1), first phase crossover (unwrapped phase = -180 deg), both refined by bisection;
    delay margin PM[rad]/omega_c; the peak of |1/(1 + L)| over the scan, refined by a golden
    section search."""
    ws = w_lo * (w_hi / w_lo) ** (np.arange(n + 1) / n)
    lv = loop(ws)
    ph = np.unwrap(np.angle(lv))

    def phase_at(w, near):
        p = np.angle(loop(np.array([w]))[0])
        return p + 2 * math.pi * round((near - p) / (2 * math.pi))

    mag = np.log(np.abs(lv))
    i_gc = np.nonzero(np.diff(np.sign(mag)))[0]
    i_pc = np.nonzero(np.diff(np.sign(ph + math.pi)))[0]
    if len(i_gc) == 0 or len(i_pc) == 0:
        raise ValueError("no crossover in the scan")
    i, j = i_gc[0], i_pc[0]
    wc = _bisect(lambda w: math.log(abs(loop(np.array([w]))[0])), ws[i], ws[i + 1])
    wp = _bisect(lambda w: phase_at(w, ph[j]) + math.pi, ws[j], ws[j + 1])
    pm = 180.0 + math.degrees(phase_at(wc, ph[i]))
    gm = -20.0 * math.log10(abs(loop(np.array([wp]))[0]))
    s = np.abs(1.0 / (1.0 + lv))
    k = int(np.argmax(s))
    a, b = ws[max(k - 1, 0)], ws[min(k + 1, n)]
    f = lambda w: -abs(1.0 / (1.0 + loop(np.array([w]))[0]))
    g = (math.sqrt(5) - 1) / 2
    for _ in range(80):
        c, d = b - g * (b - a), a + g * (b - a)
        if f(c) < f(d):
            b = d
        else:
            a = c
    wm = 0.5 * (a + b)
    return Margins(gm, wp, pm, wc, math.radians(pm) / wc, -f(wm), wm)


# --------------------------------------------------------------------------------------------
# Parameters: the FMUs' start values (modelDescription.xml), the system file, the --set values
# --------------------------------------------------------------------------------------------

def fmu_start_values(fmu: pathlib.Path) -> dict:
    """Start values of every Real, Integer and Boolean variable of an FMU's modelDescription.xml."""
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    values = {}
    for sv in root.iter("ScalarVariable"):
        for child in sv:
            start = child.get("start")
            if start is None:
                continue
            if child.tag == "Real":
                values[sv.get("name")] = float(start)
            elif child.tag == "Integer":
                values[sv.get("name")] = int(start)
            elif child.tag == "Boolean":
                values[sv.get("name")] = start == "true"
    return values


def system_instances(path: pathlib.Path, overrides: dict | None = None) -> tuple[dict, dict]:
    """(simulation section, {instance: {variable: value}}) of a native system file: the FMU's start
    values, then the file's parameters, then `overrides` ({"inst.var": value})."""
    spec = tomllib.loads(path.read_text())
    inst = {}
    for i in spec["instances"]:
        fmu = (path.parent / i["fmu"]).resolve()
        values = fmu_start_values(fmu)
        values.update(i.get("parameters", {}))
        inst[i["name"]] = values
    for key, v in (overrides or {}).items():
        name, var = key.split(".", 1)
        inst[name][var] = v
    return spec["simulation"], inst


# --------------------------------------------------------------------------------------------
# (a) FirstOrderLag through a zero-order hold
# --------------------------------------------------------------------------------------------

def first_order_lag_response(omega, h: float, gain: float = 1.0, time_constant: float = 2.0):
    """Y/D of the FirstOrderLag FMU (examples/first_order_lag: y+ = a y + (1 - a) K u, a =
    exp(-h/T), u held over the step), with d_k the input over [t_k, t_k+1) and y_k the output
    published at t_k: G = (1 - a) K / (z - a), z = exp(j omega h)."""
    a = math.exp(-h / time_constant)
    z = np.exp(1j * np.asarray(omega, dtype=float) * h)
    return (1.0 - a) * gain / (z - a)


# --------------------------------------------------------------------------------------------
# (b) The rate limiter's describing function
# --------------------------------------------------------------------------------------------

def rate_limiter_df(ratio: float) -> complex:
    """Describing function N = Y1/a of the ideal rate limiter (y' = sat(large gain (x - y), +-R),
    the servo time constant -> 0) for x = a sin(theta), theta = b t, as a function of
    ratio = a b / R (the input's largest rate over the limit). Y1 is the fundamental of the
    steady-state output, as a complex amplitude relative to sin(theta) (angle = phase lead).

    Steady state (half-wave antisymmetric, rho = 1/ratio):
    * ratio <= 1: y = x, N = 1.
    * rho <= 1/sqrt(1 + pi^2/4) (ratio >= 1.862): a triangle wave of slope +-R and amplitude
      R pi/(2b) that turns where it meets the falling input, sin(theta*) = pi rho/2: lag
      pi/2 - asin(pi rho/2), |N| = 8/pi^2 * (pi rho/2) = 4 rho/pi.
    * otherwise a trapezoid-like wave: the output tracks the input from theta1 (where the rising
      ramp meets it) until the input falls faster than R at theta2 = pi - acos(rho), then ramps
      down at -R until it meets -x at theta1 + pi. theta1 solves
      sqrt(1 - rho^2) - rho (theta1 + acos rho) + sin theta1 = 0 on [acos rho, theta2].
    The fundamental is computed in closed form piece by piece (tracking: sin; ramps: linear)."""
    if ratio <= 1.0:
        return 1.0 + 0j
    rho = 1.0 / ratio
    if rho * math.sqrt(1.0 + math.pi ** 2 / 4.0) <= 1.0:
        # triangle: peak A = pi rho/2 (in units of a) at theta* = pi - asin(A)
        amp = math.pi * rho / 2.0
        lag = math.pi / 2.0 - math.asin(amp)
        return 8.0 / math.pi ** 2 * amp * complex(math.cos(-lag), math.sin(-lag))
    th2 = math.pi - math.acos(rho)
    g = lambda th: math.sqrt(1.0 - rho * rho) - rho * (th + math.acos(rho)) + math.sin(th)
    lo, hi = math.acos(rho), th2
    if g(lo) * g(hi) > 0:
        raise ValueError("no meeting point")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if (g(mid) > 0) == (g(lo) > 0):
            lo = mid
        else:
            hi = mid
    th1 = 0.5 * (lo + hi)
    return _fundamental_piecewise(th1, th2, rho)


def _fundamental_piecewise(th1: float, th2: float, rho: float) -> complex:
    """Fundamental (relative to sin) of the half-wave antisymmetric wave: y = sin(theta) on
    [th1, th2], y = sin(th2) - rho (theta - th2) on [th2, th1 + pi]; the other half is -y."""
    # b1 = (1/pi) int_0^2pi y sin, a1 = (1/pi) int y cos = (2/pi) over one half-wave
    def int_sin_sin(p, q):
        return 0.5 * (q - p) - 0.25 * (math.sin(2 * q) - math.sin(2 * p))

    def int_sin_cos(p, q):
        return 0.5 * (math.sin(q) ** 2 - math.sin(p) ** 2)

    def int_lin(c0, c1, p, q, trig):
        # int (c0 + c1 theta) trig(theta) d theta
        if trig == "sin":
            f = lambda t: -c0 * math.cos(t) + c1 * (math.sin(t) - t * math.cos(t))
        else:
            f = lambda t: c0 * math.sin(t) + c1 * (math.cos(t) + t * math.sin(t))
        return f(q) - f(p)

    y2 = math.sin(th2)
    c0, c1 = y2 + rho * th2, -rho
    b1 = (2 / math.pi) * (int_sin_sin(th1, th2) + int_lin(c0, c1, th2, th1 + math.pi, "sin"))
    a1 = (2 / math.pi) * (int_sin_cos(th1, th2) + int_lin(c0, c1, th2, th1 + math.pi, "cos"))
    # y1 = b1 sin + a1 cos = Im{(b1 + j a1) e^{j theta}}
    return complex(b1, a1)


def steering_gear_step(angle, command, h, tau, rate_max, angle_max, rate_limited=True):
    """One exact step of `models::steering_gear::SteeringGear::step_first_order` (vectorised
    over numpy arrays): command clamped to +-angle_max; a ramp at +-rate_max while
    |e| > rate_max tau, then the exponential approach; the result clamped."""
    c = np.clip(command, -angle_max, angle_max)
    e = c - angle
    remaining = np.full_like(angle, h)
    if rate_limited:
        band = rate_max * tau
        ramping = np.abs(e) > band
        t_ramp = np.where(ramping, (np.abs(e) - band) / rate_max, 0.0)
        t = np.minimum(t_ramp, remaining)
        angle = angle + np.sign(e) * rate_max * t
        remaining = remaining - t
        angle = np.where(ramping & (remaining > 0), c - np.sign(e) * band, angle)
    decay = np.exp(-remaining / tau)
    angle = np.where(remaining > 0, c - (c - angle) * decay, angle)
    return np.clip(angle, -angle_max, angle_max)


def steering_gear_df_measured(omega: float, amplitudes, h: float, periods: float, settle: float,
                              tau: float, rate_max: float, angle_max: float):
    """What the tool measures for a describing function of the SteeringGear FMU alone (input
    gear.rudder_command unconnected, u0 = 0, output gear.rudder_angle): d_k = A sin(omega t_k)
    held over [t_k, t_k+1), the gear integrated exactly, phasors over N steps after the settling
    time. Returns (snapped omega, N, complex Y/D per amplitude)."""
    w, n = snap(omega, periods, h)
    amps = np.asarray(amplitudes, dtype=float)
    k0 = int(math.ceil(settle / h - 1e-9))
    angle = np.zeros_like(amps)
    ys = np.zeros((k0 + n, len(amps)))
    for k in range(k0 + n):
        ys[k] = angle  # published at t_k
        d = amps * math.sin(w * k * h)
        angle = steering_gear_step(angle, d, h, tau, rate_max, angle_max)
    t = np.arange(k0, k0 + n) * h
    e = np.exp(-1j * w * t)
    y = 2.0 / n * (ys[k0:].T @ e)
    d = 2.0 / n * (amps[:, None] * np.sin(w * t)[None, :]) @ e
    return w, n, y / d


# --------------------------------------------------------------------------------------------
# (c) The DDG-51 heading loop of systems/autopilot_current.toml
# --------------------------------------------------------------------------------------------

def tustin(num, den, step):
    """`models::controllers::loop_shaped::TustinController::new`: controllable canonical form of
    num/den (normalised by den[0]), Tustin at `step`: M = (I - A T/2)^-1, Ad = M (I + A T/2),
    Bd = M B T, Cd = C M, Dd = D + C Bd / 2."""
    n = len(den) - 1
    a0 = den[0]
    den = [x / a0 for x in den]
    num = [0.0] * (n + 1 - len(num)) + [x / a0 for x in num]
    d = num[0]
    b = [num[k + 1] - d * den[k + 1] for k in range(n)]  # s^(n-1) ... s^0
    a = np.zeros((n, n))
    for i in range(n - 1):
        a[i, i + 1] = 1.0
    for j in range(n):
        a[n - 1, j] = -den[n - j]
    bv = np.zeros((n, 1))
    bv[n - 1, 0] = 1.0
    c = np.array([[b[n - 1 - j] for j in range(n)]])
    eye = np.eye(n)
    m = np.linalg.inv(eye - a * step / 2)
    ad = m @ (eye + a * step / 2)
    bd = m @ bv * step
    cd = c @ m
    dd = d + 0.5 * (c @ bd).item()
    return ad, bd, cd, dd


def poly_mul(p, q):
    return list(np.convolve(p, q))


def polyval(p, s):
    return np.polyval(np.asarray(p, dtype=float), s)


@dataclass
class ShipLoop:
    """A DDG-51 loop of a system file as the FMUs integrate it: NomotoShip (model 1) ->
    Sensors (one channel, sample-and-hold) -> controller (HeadingAutopilot or TrackController,
    Tustin) -> SteeringGear (first order, no rate limit) -> NomotoShip, under the Jacobi master.
    kind "heading": the controller sees the heading psi; "track": the cross-track position y
    (the controller's input is (y_ref - y)/L). Parameters: the FMUs' start values, the system
    file, then the overrides."""
    kind: str
    h: float
    t0: float
    length: float        # ship (NomotoShip) length and speed
    speed: float
    k_prime: float
    t_prime: float
    max_substep: float
    gear_tau: float      # SteeringGear time_constant [s]
    gear_angle_max: float
    ctl: dict            # the controller's design parameters (FMU variable names)
    sensor_interval: float
    overrides: dict = field(default_factory=dict)

    CONTROLLER = {"heading": "ap", "track": "ctl"}

    @classmethod
    def from_system(cls, path: pathlib.Path = HEADING_SYSTEM, overrides: dict | None = None,
                    kind: str | None = None):
        kind = kind or ("track" if "track" in path.name else "heading")
        sim, inst = system_instances(path, overrides)
        ship, gear, sensors = inst["ship"], inst["gear"], inst["sensors"]
        ctl = inst[cls.CONTROLLER[kind]]
        assert sim.get("algorithm", "jacobi").lower() == "jacobi"
        assert ship["model"] == 1 and not gear["rate_limited"] and gear.get("servo_order", 1) == 1
        assert ctl.get("preset", 0) == 0 and ctl["reference_mode"] == 0
        assert ship.get("initial_heading", 0.0) == 0.0 and ship.get("initial_yaw_rate", 0.0) == 0.0
        channel = "heading" if kind == "heading" else "cross_track"
        assert sensors["noise_scale"] == 0.0 or sensors[f"{channel}_sigma"] == 0.0, \
            "the analysis needs the noise off: sensors.noise_scale=0"
        return cls(
            kind=kind, h=sim["step_size"], t0=sim["start_time"], length=ship["length"],
            speed=ship["speed"], k_prime=ship["k_prime"], t_prime=ship["t_prime"],
            max_substep=ship["max_substep"], gear_tau=gear["time_constant"],
            gear_angle_max=gear["angle_max"], ctl=ctl,
            sensor_interval=sensors[f"{channel}_interval"], overrides=dict(overrides or {}),
        )

    # -- the elements -----------------------------------------------------------------------
    @property
    def scale(self):
        """dt'/dt = U/L of the ship."""
        return self.speed / self.length

    @property
    def input_scale(self):
        """The controller's error per unit of the measured signal: 1 (heading, rad), 1/L of the
        controller's ship_length (track: (y_ref - y)/L)."""
        return 1.0 if self.kind == "heading" else 1.0 / self.ctl["ship_length"]

    def controller_tf(self):
        """Heading: C(s') = omega_n^2/(K a) (T s' + 1)(s' + a)/(s'^2 + 2 zeta omega_n s' +
        omega_n^2) [Taylor2000, eq. (5.30)]; track: C_y = gain prod(s' + z_i)/prod(s' + p_i)
        [Taylor2000, sec. 5.3.2]. In t' of the controller's ship_length and ship_speed."""
        p = self.ctl
        if self.kind == "track":
            num, den = [p["gain"]], [1.0]
            for i in range(1, 5):
                num = poly_mul(num, [1.0, p[f"zero{i}"]])
                den = poly_mul(den, [1.0, p[f"pole{i}"]])
            return num, den
        w2 = p["omega_n"] ** 2
        ka = p["nomoto_k"] * p["gear_pole"]
        num = poly_mul([p["nomoto_t"] * w2 / ka, w2 / ka], [1.0, p["gear_pole"]])
        den = [1.0, 2.0 * p["zeta"] * p["omega_n"], w2]
        return num, den

    def ctl_samples(self):
        """(n, tau') of the controller's sampler for one communication step: n = ceil(h' /
        sample_step), tau' = h'/n, h' = h U/L of its own ship_length and ship_speed."""
        hp = self.h * self.ctl["ship_speed"] / self.ctl["ship_length"]
        n = max(1, int(math.ceil(hp / self.ctl["sample_step"] * (1.0 - 1e-12))))
        return n, hp / n

    def ctl_step_matrices(self):
        """The controller over one communication step with its input e held: n Tustin samples;
        (A, B, C, D) of x_{k+1} = A x_k + B e_k, y = C x_k + D e_k, y the output of the last
        sample (published at t_{k+1})."""
        n, tau = self.ctl_samples()
        ad, bd, cd, dd = tustin(*self.controller_tf(), tau)
        a, b = np.eye(len(ad)), np.zeros_like(bd)
        c_out, d_out = cd, dd
        for _ in range(n):
            c_out, d_out = cd @ a, (cd @ b).item() + dd
            a, b = ad @ a, ad @ b + bd
        return a, b, c_out, d_out

    def ship_continuous(self):
        """(A, B, C) of the ship from the rudder angle to the measured signal: states [r', psi]
        (heading) or [r', psi, y] (track), r'' = s (K' delta - r')/T', psi' = s r', y' = U psi
        (the kinematics U sin psi linearised at psi = 0, no sway, no current), s = U/L."""
        s = self.scale
        if self.kind == "heading":
            a = np.array([[-s / self.t_prime, 0.0], [s, 0.0]])
            c = np.array([[0.0, 1.0]])
        else:
            a = np.array([[-s / self.t_prime, 0.0, 0.0], [s, 0.0, 0.0], [0.0, self.speed, 0.0]])
            c = np.array([[0.0, 0.0, 1.0]])
        b = np.zeros((len(a), 1))
        b[0, 0] = s * self.k_prime / self.t_prime
        return a, b, c

    def ship_matrices(self, exact=False):
        """The ship over one step with the rudder held: RK4 as models::hull::nomoto (or the
        exact ZOH)."""
        a, b, c = self.ship_continuous()
        if exact:
            return zoh(a, b, self.h) + (c,)
        return rk4_matrices(a, b, self.h, self.max_substep) + (c,)

    def gear_decay(self):
        return math.exp(-self.h / self.gear_tau)

    def sensor_period(self) -> int:
        m = self.sensor_interval / self.h
        if abs(m - round(m)) > 1e-9:
            raise ValueError("the sensor interval is not a whole number of steps")
        return int(round(m))

    def sensor_delays(self) -> list[int]:
        """Delay (in steps) of the published measurement behind the published true value, for
        each step k mod M of the sensor period M = interval/h (the Sensors model under the
        Jacobi master, see FINDINGS): k = 0 mod M: 1 step (the sample taken as the step ending at
        t_k reaches the instant uses the input held over that step); else k mod M steps (the
        sample re-taken at the instant with the value set there)."""
        m = self.sensor_period()
        return [1] + list(range(1, m))

    # -- frequency responses of the levels of the term-by-term table -------------------------
    def loop_continuous(self, w, gear="file"):
        """Continuous loop in real time, s' = s L/U: C(s') K'/(s'(T's' + 1)) [/s' for the track,
        y' = y/L] times the gear: "design" a/(s' + a) (the thesis), "file" 1/(tau s + 1)."""
        s = 1j * np.asarray(w, dtype=float)
        sp = s / self.scale
        num, den = self.controller_tf()
        c = polyval(num, sp) / polyval(den, sp)
        ship = self.k_prime / (sp * (self.t_prime * sp + 1.0))
        if self.kind == "track":
            ship = ship / sp * self.length * self.input_scale
        if gear == "design":
            a = self.ctl["gear_pole"]
            g = a / (sp + a)
        else:
            g = 1.0 / (self.gear_tau * s + 1.0)
        return c * ship * g

    def loop_sampled(self, w, level: str):
        """Loop transfer functions of the sampled levels (z = exp(j w h)):
        "zoh":    the ideal single-rate digital loop: the controller's step map (Tustin) with its
                  output held into the exact ZOH equivalent of gear + ship (one system);
        "split":  + the ship fed the gear angle published at t_k, held over the step (two FMUs),
                  the gear exact, the ship by RK4;
        "jacobi": + one step in the controller (its output at t_k+1 from the input at t_k) and
                  one in the sensor (sampling at every step, published one step later);
        "full":   + the sensor's sample-and-hold every interval: the fundamental (m = 0) term of
                  its periodically time-varying map, the mean of exp(-j w h delay) over the
                  period's delays (sensor_delays)."""
        w = np.asarray(w, dtype=float)
        z = np.exp(1j * w * self.h)
        ca, cb, cc, cd = self.ctl_step_matrices()
        ctl = ss_freq(ca, cb, cc, cd, z) * self.input_scale
        sa, sb, sc = self.ship_continuous()
        if level == "zoh":
            n = len(sa)
            a = np.zeros((n + 1, n + 1))
            a[0, 0] = -1.0 / self.gear_tau
            a[1:, 1:] = sa
            a[1:, :1] = sb
            b = np.zeros((n + 1, 1))
            b[0, 0] = 1.0 / self.gear_tau
            phi, gam = zoh(a, b, self.h)
            c = np.hstack([[[0.0]], sc])
            return ctl * ss_freq(phi, gam, c, 0.0, z)
        a = self.gear_decay()
        gear = (1.0 - a) / (z - a)
        phi, gam, c = self.ship_matrices()
        ship = ss_freq(phi, gam, c, 0.0, z)
        if level == "split":
            return ctl * gear * ship
        if level == "jacobi":
            return ctl * gear * ship * z ** -2
        if level == "full":
            delays = np.array(self.sensor_delays())
            sensor = np.mean(np.exp(-1j * np.outer(w, delays) * self.h), axis=1)
            return ctl * gear * ship * sensor / z
        raise ValueError(level)

    # -- the time-domain loop of the master -----------------------------------------------
    def simulate(self, n_steps: int, injection=None, reference: float = 0.0, n_freq: int = 1,
                 start_step: int = 0):
        """The coupled system stepped as the master's Jacobi algorithm does, from the zero
        operating point, vectorised over `n_freq` parallel runs.

        Published at t_k (k = 0 ... n_steps): r_k (controller rudder_command), delta_k
        (gear.rudder_angle), x_k (ship.heading or ship.y), m_k (the sensor's measured value).
        Step k: u_k = r_k + d_k (the break), gear from u_k, ship from delta_k, sensor from x_k
        (sample-and-hold, see sensor_delays), controller from e_k = (reference - m_k) scaled.
        `injection(k)` gives d_k (an array of n_freq) or None. `start_step`: the run starts from
        the zero state at t0 + start_step h (a fork at T of a loop that is still at rest: only
        the phase of the sensor's sampling instants t0 + j interval changes; k counts from T).
        Returns dict of arrays (n_steps + 1, n_freq): r, u, delta, x, m."""
        ca, cb, cc, cd = self.ctl_step_matrices()
        phi, gam, sc = self.ship_matrices()
        a = self.gear_decay()
        lim = self.ctl["command_limit"]
        amax = self.gear_angle_max
        m_per = self.sensor_period()
        x_ctl = np.zeros((len(ca), n_freq))
        xs = np.zeros((len(phi), n_freq))
        r = np.zeros(n_freq)
        delta = np.zeros(n_freq)
        held = np.zeros(n_freq)
        out = {k: np.zeros((n_steps + 1, n_freq)) for k in ("r", "u", "delta", "x", "m")}
        for k in range(n_steps + 1):
            x = (sc @ xs)[0]
            d = injection(k) if injection is not None else 0.0
            u = r + d
            out["r"][k], out["u"][k], out["delta"][k], out["x"][k], out["m"][k] = (
                r, u, delta, x, held)
            if k == n_steps:
                break
            ka = k + start_step
            new_held = x if (ka % m_per == 0 or (ka + 1) % m_per == 0) else held
            e = (reference - held) * self.input_scale
            y = (cc @ x_ctl)[0] + cd * e
            x_ctl = ca @ x_ctl + cb * e
            c = np.clip(u, -amax, amax)
            new_delta = np.clip(c - (c - delta) * a, -amax, amax)
            xs = phi @ xs + gam * delta
            r, delta, held = np.clip(y, -lim, lim), new_delta, new_held
        return out

    def measure_loop(self, omegas, amplitude: float, periods: float, settle: float, steps=None,
                     at: float | None = None):
        """What `shipsim loop --break "<controller>.rudder_command -> gear.rudder_command"`
        measures at each frequency (operating point: the start time, the zero state):
        d_k = A sin(omega (t_k - t0)) on the connection, phasors of r_k and u_k over the N steps
        from k0 = ceil(settle/h) after T, L = -R/U (`at`: T, default the start). Returns (snapped omegas, N, L). With `steps` (N per
        frequency) the omegas are taken as they are (already snapped) with those windows."""
        if steps is None:
            snapped = [snap(w, periods, self.h) for w in omegas]
            ws = np.array([s[0] for s in snapped])
            ns = np.array([s[1] for s in snapped])
        else:
            ws, ns = np.asarray(omegas, dtype=float), np.asarray(steps, dtype=int)
        k0 = int(math.ceil(settle / self.h - 1e-9))
        start = 0 if at is None else int(round((at - self.t0) / self.h))
        assert at is None or abs(self.t0 + start * self.h - at) < 1e-9, "T off the step grid"
        run = self.simulate(k0 + int(ns.max()), n_freq=len(ws), start_step=start,
                            injection=lambda k: amplitude * np.sin(ws * (k * self.h)))
        # the analysis must stay linear: neither the command limit nor the rudder limit reached
        peak_r, peak_u = np.abs(run["r"]).max(), np.abs(run["u"]).max()
        assert peak_r < self.ctl["command_limit"] and peak_u < self.gear_angle_max, (
            f"amplitude {amplitude} saturates the loop: max |r| = {peak_r}, max |u| = {peak_u}")
        L = np.empty(len(ws), dtype=complex)
        for i, (w, n) in enumerate(zip(ws, ns)):
            k = np.arange(k0, k0 + n)
            t = k * self.h
            L[i] = -phasor(run["r"][k, i], t, w) / phasor(run["u"][k, i], t, w)
        return ws, ns, L



def measured_margins(loop: ShipLoop, amplitude: float, periods: float, settle: float):
    """The margins the tool must report: those of the sampled loop at the exact crossing
    frequencies, as its sinusoidal correlation measures the loop there.

    The crossings are found on the fundamental term of the loop (loop_sampled "full", exact);
    the time-domain loop (measure_loop) is then measured at those frequencies (snapped), and its
    ratio q = L_measured/L_full there (the aliases of the sensor's hold leaking into the
    correlation over N steps that are not a whole number of sensor periods; 1e-3 relative or
    less below 0.8 rad/s) corrects the loop near each crossing: GM from L_full q(w180), PM and
    the crossover from L_full q(wc), the peak of |1/(1 + L)| from L_full q(w_Ms).
    Returns (Margins, the Margins of the fundamental term, {name: (omega, q)})."""
    full = lambda w: loop.loop_sampled(w, "full")
    base = margins(full, 1e-4, math.pi / loop.h * 0.999)
    probes = [base.crossover_rad_s, base.gain_margin_rad_s, base.sensitivity_peak_rad_s]
    ws, _, lm = loop.measure_loop(probes, amplitude, periods, settle)
    q = lm / full(ws)
    one = lambda w, qi: full(np.array([w]))[0] * qi

    def unwrapped(w, qi, near_rad):
        p = np.angle(one(w, qi))
        return p + 2 * math.pi * round((near_rad - p) / (2 * math.pi))

    pc_near = math.radians(base.phase_margin_deg - 180.0)
    wc = _bisect(lambda w: math.log(abs(one(w, q[0]))), base.crossover_rad_s * 0.95,
                 base.crossover_rad_s * 1.05)
    pm = 180.0 + math.degrees(unwrapped(wc, q[0], pc_near))
    wp = _bisect(lambda w: unwrapped(w, q[1], -math.pi) + math.pi,
                 base.gain_margin_rad_s * 0.95, base.gain_margin_rad_s * 1.05)
    gm = -20.0 * math.log10(abs(one(wp, q[1])))
    lo, hi = base.sensitivity_peak_rad_s * 0.7, base.sensitivity_peak_rad_s * 1.3
    f = lambda w: -abs(1.0 / (1.0 + one(w, q[2])))
    g = (math.sqrt(5) - 1) / 2
    for _ in range(80):
        c, d = hi - g * (hi - lo), lo + g * (hi - lo)
        if f(c) < f(d):
            hi = d
        else:
            lo = c
    wm = 0.5 * (lo + hi)
    result = Margins(gm, wp, pm, wc, math.radians(pm) / wc, -f(wm), wm)
    return result, base, {n: (float(w), complex(qi)) for n, w, qi in
                          zip(("crossover", "phase_crossover", "sensitivity_peak"), ws, q)}

HeadingLoop = ShipLoop

#: The settings of the analysis: noise off, current off, waves off (track system), external
#: reference 0 (track system; the heading system already has it).
HEADING_SETTINGS = {
    "sensors.noise_scale": 0.0,
    "current.current_speed_initial": 0.0,
    "current.current_speed_final": 0.0,
}
TRACK_SETTINGS = {
    "sensors.noise_scale": 0.0,
    "current.current_speed_initial": 0.0,
    "current.current_speed_final": 0.0,
    "waves.yaw_gain": 0.0,
    "ctl.reference_mode": 0,
}


def loop_levels(loop: ShipLoop):
    """The term-by-term table: [(label, Margins)], each level adding one effect."""
    nyq = math.pi / loop.h * 0.999
    levels = [
        ("continuous design [Taylor2000]: gear a/(s'+a), a = 6 in t'",
         lambda w: loop.loop_continuous(w, gear="design"), 3.0),
        (f"+ the file's gear, time_constant = {loop.gear_tau:.4f} s",
         lambda w: loop.loop_continuous(w), 3.0),
        (f"+ master sampling h = {loop.h} s: Tustin controller, gear + ship ZOH",
         lambda w: loop.loop_sampled(w, "zoh"), nyq),
        ("+ ship fed the held gear angle (gear exact, ship RK4)",
         lambda w: loop.loop_sampled(w, "split"), nyq),
        ("+ Jacobi: one step in the controller, one in the sensor",
         lambda w: loop.loop_sampled(w, "jacobi"), nyq),
        (f"+ sensor sample-and-hold every {loop.sensor_interval} s (fundamental term)",
         lambda w: loop.loop_sampled(w, "full"), nyq),
    ]
    return [(label, margins(f, 1e-4, hi)) for label, f, hi in levels]


def format_levels(rows) -> str:
    lines = [f"{'level':66s} {'GM dB':>7s} {'w180':>7s} {'PM deg':>7s} {'wc':>7s} "
             f"{'DM s':>6s} {'Ms':>6s} {'w_Ms':>6s}"]
    for label, m in rows:
        lines.append(f"{label:66s} {m.gain_margin_db:7.3f} {m.gain_margin_rad_s:7.4f} "
                     f"{m.phase_margin_deg:7.3f} {m.crossover_rad_s:7.5f} "
                     f"{m.delay_margin_s:6.2f} {m.sensitivity_peak:6.4f} "
                     f"{m.sensitivity_peak_rad_s:6.4f}")
    return "\n".join(lines)


if __name__ == "__main__":
    for path, settings in [(HEADING_SYSTEM, HEADING_SETTINGS), (TRACK_SYSTEM, TRACK_SETTINGS)]:
        loop = ShipLoop.from_system(path, settings)
        print(path.name, loop.kind)
        print(format_levels(loop_levels(loop)))
