"""A minimal Gymnasium-style environment over the RRS system: an agent that stabilises roll
with the rudder while the RRS autopilot keeps the course.

The system is examples/python/rrs_env.toml: systems/rrs.toml (the van der Klugt ship in a
beam sea of 16 deg^2 open-loop roll variance, roll and yaw filters, RRS autopilot) with the
autopilot's roll stabilisation switched off (roll_mode = 0) and its rudder command not
connected to the steering gear. Every 0.1 s Python sets

    gear.rudder_command = clip(autopilot.rudder_command + roll_rudder, +-22 deg)
    filter.roll_rudder  = roll_rudder          (the roll filter's model input)

where roll_rudder is the agent's action: the autopilot is left the course, the agent takes
the place of the RRS roll controller. (The rudder command input must be unconnected for
this: a value set on a connected input is overwritten by the connection at the next step.)

API, as Gymnasium's (``gymnasium`` is not imported; wrap the class to use one):

- ``reset(seed=None, options=None) -> (observation, info)``
- ``step(action) -> (observation, reward, terminated, truncated, info)``

- action: the roll rudder [rad], a float or an array of shape (1,), clipped to
  [action_low, action_high] = +-22 deg (the autopilot's angle_max); held for one control
  interval of ``macro_steps`` macro steps of 0.05 s (default 2: 0.1 s, the rate of the RRS
  filter and autopilot).
- observation: float32 array of shape (4,): the roll filter's roll [rad] and roll rate
  [rad/s] (steady heel removed), the yaw filter's heading error [rad] and the rudder angle
  [rad] of the gear, all at the end of the interval: what the RRS autopilot itself sees.
- reward: -(roll^2 + rudder_weight * roll_rudder^2) / horizon, roll the true ship.roll and
  roll_rudder the action, both in deg: the return of an episode is minus its mean cost in
  deg^2 (rudder_weight 0.1 is the ratio r/q_phi = 1/10 of the RRS autopilot's criterion).
- episode: ``horizon`` control intervals (default 600: 60 s) after a warm-up of ``warmup``
  seconds (default 60 s) with the roll rudder at 0; ``truncated`` is True at the end of the
  horizon, ``terminated`` is always False (there is no failure state).

Seeds and a cheap reset: the sea is fixed by the seed of the Waves FMU (and those of the wind
and sensors): the session takes one checkpoint after the warm-up, and ``reset()`` restores it,
so that every episode of one seed meets the same waves, and the same actions give the same
trajectory bit for bit. ``reset(seed=s)`` with a new s starts a new session (waves.seed = s,
sensors.seed = s + 1, wind.seed = s + 2; s = 1 is the file's sea), warms it up and takes its
checkpoint: a new sea costs a warm-up, a reset to the same sea costs a restore.

Memory: a session keeps a journal of every value set from Python (for System.replay), also
when no journal file is asked for, and a restore does not shorten it: about 125 kB per episode
of 600 actions. For a training of millions of steps, start a new session now and then (a
reset with a new seed does).

Run: target/venv/bin/python examples/python/rrs_env.py
"""
import argparse
import math
import pathlib

import numpy as np

import shipsim

SYSTEM = pathlib.Path(__file__).resolve().parent / "rrs_env.toml"

# Sensors, filter and autopilot step every 2 macro steps (step_multiple = 2): Python reads and
# sets only at the communication points where every instance is at the same time. (Between
# them Session.get of a multi-rate instance gives the value at the end of its current step,
# ahead of what its connections and the recorded rows hold.)
SYNC = 2


class RrsEnv:
    """The RRS ship with a Python roll-stabilising rudder; see the module's docstring."""

    observation_names = ("roll", "roll_rate", "heading_error", "rudder_angle")

    def __init__(self, *, seed=1, horizon=600, macro_steps=SYNC, warmup=60.0, rudder_weight=0.1):
        if macro_steps % SYNC:
            raise ValueError(f"macro_steps must be a multiple of {SYNC}")
        self.horizon, self.macro_steps = horizon, macro_steps
        self.warmup, self.rudder_weight = warmup, rudder_weight
        self.system = shipsim.System.load(SYSTEM)
        self.angle_max = float(self.system.values["autopilot.angle_max"])  # 22 deg
        self.action_low = np.array([-self.angle_max], dtype=np.float32)
        self.action_high = np.array([self.angle_max], dtype=np.float32)
        self.observation_shape = (4,)
        self.dt = macro_steps * self.system.step_size  # control interval [s]
        self.seed, self.session, self._checkpoint = seed, None, None
        self._steps = None

    # -- Gymnasium API ------------------------------------------------------------------
    def reset(self, seed=None, options=None):
        """Back to the start of an episode: restores the checkpoint after the warm-up, or,
        for a seed other than the current one (or at the first reset), starts a new session
        on that sea."""
        if self.session is None or (seed is not None and seed != self.seed):
            self._start(self.seed if seed is None else seed)
        else:
            self.session.restore(self._checkpoint)
        self._steps = 0
        return self._observation(), self._info()

    def step(self, action):
        if self._steps is None or self._steps >= self.horizon:
            raise RuntimeError("call reset() first: the episode has ended")
        roll_rudder = float(np.clip(np.asarray(action, dtype=np.float64).reshape(-1)[0],
                                    -self.angle_max, self.angle_max))
        for _ in range(self.macro_steps // SYNC):
            self._apply(roll_rudder)
            self.session.step(SYNC)
        self._steps += 1
        roll = math.degrees(self.session.get("ship.roll"))
        cost = roll**2 + self.rudder_weight * math.degrees(roll_rudder) ** 2
        reward = -cost / self.horizon
        truncated = self._steps >= self.horizon
        return self._observation(), reward, False, truncated, self._info()

    def close(self):
        if self.session is not None:
            self.session.close()
            self.session = None

    # -- the coupling -------------------------------------------------------------------
    def _apply(self, roll_rudder):
        """The course rudder of the autopilot plus the agent's roll rudder to the gear, the
        roll rudder to the roll filter: set at this communication point, before the next
        step."""
        course = self.session.get("autopilot.rudder_command")
        command = min(max(course + roll_rudder, -self.angle_max), self.angle_max)
        self.session.set("gear.rudder_command", command)
        self.session.set("filter.roll_rudder", roll_rudder)

    def _start(self, seed):
        self.close()
        self.seed = seed
        self.system.set("waves.seed", seed).set("sensors.seed", seed + 1).set("wind.seed", seed + 2)
        stop = self.warmup + self.horizon * self.dt
        self.session = self.system.start(stop_time=stop, variables=["ship.roll", "gear.rudder_angle"])
        while self.session.time < self.warmup - 1e-9:  # course keeping only
            self._apply(0.0)
            self.session.step(SYNC)
        self._checkpoint = self.session.checkpoint()

    def _observation(self):
        get = self.session.get
        return np.array([get("filter.roll_estimate"), get("filter.roll_rate_estimate"),
                         get("filter.heading_estimate"), get("gear.rudder_angle")], dtype=np.float32)

    def _info(self):
        return {"time": self.session.time, "seed": self.seed, "roll": self.session.get("ship.roll")}


# --- policies and a demonstration ----------------------------------------------------------
def zero_policy(observation):
    """No roll stabilisation: the rudder keeps the course only."""
    return np.zeros(1, dtype=np.float32)


def roll_damping_policy(observation, k_roll=1.0, k_rate=4.0):
    """A hand-written roll stabiliser: rudder against roll and, mainly, roll rate (extra roll
    damping), delta = k_roll phi + k_rate p (positive rudder rolls this ship to port, so the
    rudder follows the roll to oppose it)."""
    roll, roll_rate = float(observation[0]), float(observation[1])
    return np.array([k_roll * roll + k_rate * roll_rate], dtype=np.float32)


def destabilising_policy(observation):
    """The hand-written stabiliser with its sign turned: it drives the roll."""
    return -roll_damping_policy(observation)


def run_episode(env, policy, seed=None):
    """One episode; returns the return and the trajectory (observations, rewards)."""
    observation, info = env.reset(seed=seed)
    observations, rewards = [observation], []
    truncated = terminated = False
    while not (terminated or truncated):
        observation, reward, terminated, truncated, info = env.step(policy(observation))
        observations.append(observation)
        rewards.append(reward)
    return float(np.sum(rewards)), np.array(observations), np.array(rewards)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=2, help="episodes per policy and sea (default 2)")
    parser.add_argument("--horizon", type=int, default=600, help="actions per episode (default 600: 60 s)")
    parser.add_argument("--seeds", default="1,2", help="seas, comma-separated (default 1,2)")
    args = parser.parse_args(argv)

    env = RrsEnv(horizon=args.horizon)
    print(f"RrsEnv: {args.horizon} actions of {env.dt:g} s after a {env.warmup:g} s warm-up; "
          f"return = -(mean roll^2 + {env.rudder_weight:g} mean roll rudder^2) [deg^2]")
    policies = {"zero": zero_policy, "roll damping": roll_damping_policy,
                "destabilising": destabilising_policy}
    for seed in (int(s) for s in args.seeds.split(",")):
        for name, policy in policies.items():
            # the first reset of a sea starts a session; the others restore its checkpoint
            returns = [run_episode(env, policy, seed=seed)[0] for _ in range(args.episodes)]
            print(f"  seed {seed}  {name:<14} returns " + "  ".join(f"{r:9.4f}" for r in returns))
    env.close()


if __name__ == "__main__":
    main()
