"""The FMU's Gymnasium environment beside Gymnasium's and EnvPool's Pendulum-v1 (issue 47).

Steps per second, one environment and a batch of N, taking turns, each the median of the repeats:
Gymnasium's Pendulum-v1 and PendulumFMU-v0, each made by gymnasium.make (its TimeLimit and
checkers as a user gets them), stepped with a fixed torque and reset when an episode ends; at N =
256 and 1,024, EnvPool's Pendulum-v1 (envpool.make_gymnasium) and PendulumFMU-v0's vector env
(gymnasium.make_vec), each on 1 and 2 threads, and Gymnasium's SyncVectorEnv of Pendulum-v1 at 256.
A step of a batch counts N steps. Then what a reset costs against a step, one environment, and the
process's memory over 100,000 resets (the FMU restarted in place each time).

    .venv/bin/python -m benchmarks.gym_speed [--repeats 5] [--resets 100000]

It prints TEMPLATE, the block docs/reinforcement_learning.md holds.
"""

from __future__ import annotations

import argparse
import datetime
import os
import sys
import time

import gymnasium
import numpy as np
import psutil

import pendulum_fmu.gym

from .report import cpu_model
from .timing import interleaved, median, timed

FMU_ENV = "pendulum_fmu.gym:PendulumFMU-v0"
SIZES = (256, 1024)
THREADS = (1, 2)

TEMPLATE = """Measured by `.venv/bin/python -m benchmarks.gym_speed` on {date}, on {machine} ({cores}
cores; python {python}, gymnasium {gymnasium}, envpool {envpool}; load average {load} before),
taking turns, medians of {repetitions}; steps per second (a batch's step counts N):

| environments | Gymnasium Pendulum-v1 | EnvPool Pendulum-v1 | PendulumFMU-v0 | FMU / best peer |
| --- | --- | --- | --- | --- |
| 1 | {single_gymnasium} | | {single_fmu} | {single_ratio} |
| 256, sync vector env | {sync_gymnasium} | | | |
| 256, 1 thread | | {envpool_256_1} | {fmu_256_1} | {ratio_256_1} |
| 256, 2 threads | | {envpool_256_2} | {fmu_256_2} | {ratio_256_2} |
| 1,024, 1 thread | | {envpool_1024_1} | {fmu_1024_1} | {ratio_1024_1} |
| 1,024, 2 threads | | {envpool_1024_2} | {fmu_1024_2} | {ratio_1024_2} |

One environment: a reset takes {reset_us} µs, a step {step_us} µs (medians of 1,000 each); over
{resets} resets the process's memory went from {memory_before} to {memory_after}.
"""


def _single(env_id: str, steps: int):
    env = gymnasium.make(env_id)
    env.reset(seed=0)
    action = np.array([0.5], np.float32)

    def run() -> float:
        def loop():
            for _ in range(steps):
                if env.step(action)[3]:
                    env.reset()

        return timed(loop)[0] / steps

    return env, run


def _batch(make, size: int, steps: int):
    envs = make()
    envs.reset()  # EnvPool's seed is make's
    actions = np.full((size, 1), 0.5, np.float32)

    def run() -> float:
        def loop():
            for _ in range(steps):
                envs.step(actions)

        return timed(loop)[0] / (steps * size)

    return envs, run


def _per_second(seconds: list[float]) -> float:
    return 1 / median(seconds)


def _rate(value: float) -> str:
    return f"{value:,.0f}"


def measure(repetitions: int, resets: int) -> dict[str, str]:
    import envpool

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    figures: dict[str, str] = {}
    made = []

    single = {}
    for name, env_id in (("gymnasium", "Pendulum-v1"), ("fmu", FMU_ENV)):
        env, single[name] = _single(env_id, 20_000)
        made.append(env)
    seconds = interleaved(single, repetitions)
    rates = {name: _per_second(values) for name, values in seconds.items()}
    figures.update(single_gymnasium=_rate(rates["gymnasium"]), single_fmu=_rate(rates["fmu"]))
    figures["single_ratio"] = f"{rates['fmu'] / rates['gymnasium']:.1f}"

    sync, run = _batch(lambda: gymnasium.make_vec("Pendulum-v1", num_envs=256, vectorization_mode="sync"), 256, 40)
    figures["sync_gymnasium"] = _rate(_per_second(interleaved({"sync": run}, repetitions)["sync"]))
    made.append(sync)

    for size in SIZES:
        for threads in THREADS:
            steps = 400_000 // size
            contenders = {}
            peer, contenders["envpool"] = _batch(
                lambda size=size, threads=threads: envpool.make_gymnasium(
                    "Pendulum-v1", num_envs=size, num_threads=threads, seed=0
                ),
                size,
                steps,
            )
            ours, contenders["fmu"] = _batch(
                lambda size=size, threads=threads: gymnasium.make_vec(FMU_ENV, num_envs=size, num_threads=threads),
                size,
                steps,
            )
            made += [peer, ours]
            rates = {name: _per_second(values) for name, values in interleaved(contenders, repetitions).items()}
            key = f"{size}_{threads}"
            figures[f"envpool_{key}"] = _rate(rates["envpool"])
            figures[f"fmu_{key}"] = _rate(rates["fmu"])
            figures[f"ratio_{key}"] = f"{rates['fmu'] / rates['envpool']:.1f}"
    for env in made:
        env.close()

    figures.update(_resets(resets))
    figures.update(
        date=datetime.date.today().isoformat(),
        machine=cpu_model(),
        cores=str(len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()),
        python=sys.version.split()[0],
        gymnasium=gymnasium.__version__,
        envpool=envpool.__version__,
        load=f"{load:.2f}",
        repetitions=str(repetitions),
    )
    return figures


def _resets(resets: int) -> dict[str, str]:
    """A reset's cost against a step's, and the memory over many resets, of one environment."""
    env = pendulum_fmu.gym.PendulumFmuEnv()
    env.reset(seed=0)
    action = np.array([0.5])
    reset_seconds, step_seconds = [], []
    for _ in range(1_000):
        started = time.perf_counter()
        env.reset()
        reset_seconds.append(time.perf_counter() - started)
        started = time.perf_counter()
        env.step(action)
        step_seconds.append(time.perf_counter() - started)
    process = psutil.Process()
    before = process.memory_info().rss
    for _ in range(resets):
        env.reset()
    after = process.memory_info().rss
    env.close()
    return {
        "reset_us": f"{median(reset_seconds) * 1e6:.1f}",
        "step_us": f"{median(step_seconds) * 1e6:.1f}",
        "resets": f"{resets:,}",
        "memory_before": f"{before / 2**20:.1f} MiB",
        "memory_after": f"{after / 2**20:.1f} MiB",
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.gym_speed", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--repeats", type=int, default=5, help="repetitions of each measurement (default 5)")
    parser.add_argument("--resets", type=int, default=100_000, help="resets of the memory check (default 100,000)")
    args = parser.parse_args(argv)
    print(TEMPLATE.format(**measure(args.repeats, args.resets)), end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
