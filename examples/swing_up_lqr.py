"""Swing the pendulum up with an energy controller and hold it upright with an LQR designed on the
FMU's own linearisation, in the FMU's Gymnasium environment and in Gymnasium's Pendulum-v1.

The LQR is designed on linearize(...) at the upright point (the FMU's theta = pi) with the FMU
environment's physics (Pendulum-v1's rod), held over each 0.05 s step (discretised with a zero-order
hold) and weighted as the environments' reward weighs angle, rate and torque. The same controller,
reading Pendulum-v1's observation [cos theta, sin theta, omega] (theta from the top), runs with the
same seeds in both environments: Pendulum-v1 steps by semi-implicit Euler, the FMU exactly.

Needs gymnasium and python-control: pip install "pendulum-fmu[gym,control]".
"""

import argparse
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pendulum_fmu import linearize

ENVIRONMENTS = {"FMU (PendulumFMU-v0)": "pendulum_fmu.gym:PendulumFMU-v0", "Gymnasium Pendulum-v1": "Pendulum-v1"}
# The reward's weights: -(theta^2 + 0.1 omega^2 + 0.001 torque^2), theta from the top.
STATE_WEIGHTS, TORQUE_WEIGHT = np.diag([1.0, 0.1]), 0.001


@dataclass(frozen=True)
class SwingUpLqr:
    """The controller: the action for an observation [cos theta, sin theta, omega].

    Within switch_angle of the top, the LQR: torque = -gain . (theta, omega). Elsewhere the
    energy controller: the energy E = I omega^2 / 2 + G (cos theta - 1) is 0 at rest upright and
    changes at dE/dt = torque omega, so torque = energy_gain (0 - E) omega pumps it towards 0 in
    every swing. Both clipped to max_torque.
    """

    gain: np.ndarray  # (2,) on (theta from the top, omega)
    inertia: float  # about the pivot, kg.m^2
    gravity_moment: float  # m g L, N.m
    max_torque: float
    energy_gain: float = 0.5
    switch_angle: float = 0.6

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        """The action, shape (1,) float32 as the environments' action space, for an observation."""
        cos, sin, omega = (float(value) for value in observation)
        theta = math.atan2(sin, cos)
        if abs(theta) < self.switch_angle:
            torque = -float(self.gain @ (theta, omega))
        else:
            energy = 0.5 * self.inertia * omega**2 + self.gravity_moment * (cos - 1)
            torque = -self.energy_gain * energy * omega
        return np.array([np.clip(torque, -self.max_torque, self.max_torque)], dtype=np.float32)


def design(parameters: dict, dt: float, max_torque: float) -> SwingUpLqr:
    """The controller for a pendulum of these FMU parameters stepped every dt s.

    The FMU's theta is measured from the bottom, Pendulum-v1's from the top: at the upright point
    their deviations are the same angle, so the LQR's gain on the FMU's (theta - pi, omega) is the
    gain on Pendulum-v1's (theta, omega), with the torque's sign unchanged.
    """
    import control

    upright = linearize(theta=math.pi, parameters=parameters)
    held = control.c2d(upright.to_statespace(), dt)  # the torque is held over each step
    gain, _, _ = control.dlqr(held.A, held.B, STATE_WEIGHTS, TORQUE_WEIGHT)
    # Upright, d(alpha)/d(torque) = 1 / I and d(alpha)/d(theta) = m g L / I.
    inertia = 1.0 / upright.B[1, 0]
    return SwingUpLqr(np.asarray(gain)[0], inertia, upright.A[1, 0] * inertia, max_torque)


def episode(env, controller: SwingUpLqr, seed: int) -> dict:
    """One episode until the environment truncates it: its return, and per step the time, theta
    (from the top, in (-pi, pi]), omega and the torque applied.
    """
    observation, _ = env.reset(seed=seed)
    states, torques, total = [observation], [], 0.0
    while True:
        action = controller(observation)
        observation, reward, terminated, truncated, _ = env.step(action)
        states.append(observation)
        torques.append(float(action[0]))
        total += float(reward)
        if terminated or truncated:
            break
    cos, sin, omega = np.array(states).T
    dt = env.unwrapped.dt
    return {
        "return": total,
        "time": dt * np.arange(len(states)),
        "theta": np.arctan2(sin, cos),
        "omega": omega,
        "torque": np.array(torques),
    }


def run(seeds=(0, 1, 2, 3, 4), output_dir="out/swing_up_lqr"):
    """{environment: [episode per seed]} with the controller designed on the FMU environment's
    physics, after printing each return and drawing the first seed's trajectories.
    """
    import gymnasium  # "pendulum_fmu.gym:..." imports pendulum_fmu.gym, which registers PendulumFMU-v0

    environments = {label: gymnasium.make(name) for label, name in ENVIRONMENTS.items()}
    fmu_env = environments["FMU (PendulumFMU-v0)"].unwrapped
    controller = design(fmu_env.settings.parameters, fmu_env.dt, fmu_env.max_torque)
    print(f"LQR gain on (theta, omega) upright: {controller.gain.round(3).tolist()}")
    episodes = {}
    try:
        for label, env in environments.items():
            episodes[label] = [episode(env, controller, seed) for seed in seeds]
    finally:
        for env in environments.values():
            env.close()
    for label, runs in episodes.items():
        returns = [run["return"] for run in runs]
        finals = [abs(run["theta"][-1]) for run in runs]
        print(
            f"{label}: returns {', '.join(f'{value:.1f}' for value in returns)} (seeds {', '.join(map(str, seeds))}; "
            f"mean {np.mean(returns):.1f}), final |theta| at most {max(finals):.1e} rad"
        )
    figure = plot(episodes, seeds[0], Path(output_dir) / "swing_up_lqr.png")
    print(f"wrote {figure}")
    return episodes


def plot(episodes: dict, seed: int, path: Path) -> Path:
    """Theta and the torque over time of the first episode in each environment, one over the other."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(8, 6), dpi=100, layout="constrained")
    FigureCanvasAgg(figure)
    theta_axes, torque_axes = figure.subplots(2, 1, sharex=True)
    for index, (label, runs) in enumerate(episodes.items()):
        run = runs[0]
        style = {"label": label, "linestyle": "-" if index == 0 else "--"}
        theta_axes.plot(run["time"], run["theta"], **style)
        torque_axes.step(run["time"][:-1], run["torque"], where="post", **style)
    theta_axes.set_ylabel("theta from the top (rad)")
    torque_axes.set_ylabel("torque (N.m)")
    torque_axes.set_xlabel("time (s)")
    theta_axes.legend()
    figure.suptitle(f"Energy swing-up, then an LQR on linearize(theta=pi): seed {seed}")
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path)
    return path


def main(argv=None):
    """The command line: run() with its options."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument(
        "--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4], help="reset seeds (default: %(default)s)"
    )
    parser.add_argument("--output-dir", default="out/swing_up_lqr", help="where the figure goes")
    args = parser.parse_args(argv)
    run(tuple(args.seeds), args.output_dir)


if __name__ == "__main__":
    main()
