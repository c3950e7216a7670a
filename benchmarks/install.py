"""What a user's set-up costs: the wheel, `pip install` of it, the `[opensim]` extra, and the
first commands from that install.

Prints the paragraph the README's Set up shows (its wording is TEMPLATE; tests/readme_figures.py
holds the README to it):

    .venv/bin/python -m benchmarks.install

Everything happens in a temporary folder: the wheel built from this checkout with pip's build
isolation, a fresh virtual environment, the package installed from the wheel as a user installs
it. It downloads what pip's cache lacks, so it takes minutes, and the times say as much about
the network and the machine as about the package: the paragraph says when and where.
"""

from __future__ import annotations

import datetime
import os
import platform
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parent.parent

TEMPLATE = (
    "Measured by `.venv/bin/python -m benchmarks.install` on {date} ({machine}; pip's cache held "
    "{cache_mb} MB before): the wheel is {wheel_kb} kB and builds in {wheel_s} s; `pip install` of it takes "
    "{install_s} s and leaves a {environment_mb} MB environment, of which the package is "
    "{package_kb} kB and the largest parts are {largest}; `[opensim]` adds {opensim_s} s and "
    "{opensim_mb} MB. From that install, `pendulum-fmu simulate --torque 20` runs in {simulate_s} "
    "s and `pendulum-fmu demo` in {demo_s} s."
)


def render(figures: dict) -> str:
    """TEMPLATE filled in, wrapped as the README's prose is."""
    return textwrap.fill(TEMPLATE.format(**figures), width=98, break_long_words=False, break_on_hyphens=False)


def _size(path: Path) -> int:
    """Bytes of the files under path (a file's own size for a file)."""
    if path.is_file():
        return path.stat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file() and not p.is_symlink())


# A user's fresh shell: no package on the path but what the new environment installs.
_FRESH = {name: value for name, value in os.environ.items() if name not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}


def _timed(command: list[str], **options) -> float:
    started = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, env=_FRESH, **options)
    return time.perf_counter() - started


def _machine() -> str:
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            model = next(line.split(":", 1)[1].strip() for line in cpuinfo if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return f"{os.cpu_count()} cores, {model}, Python {platform.python_version()}"


def _cache_mb() -> str:
    """What pip's cache holds: the downloads the times below did not need to make."""
    done = subprocess.run([sys.executable, "-m", "pip", "cache", "dir"], capture_output=True, text=True)
    folder = Path(done.stdout.strip())
    return f"{_size(folder) / 1e6:.0f}" if done.returncode == 0 and folder.is_dir() else "0"


def measure() -> dict:
    """Every figure TEMPLATE names."""
    figures = {"date": datetime.date.today().isoformat(), "machine": _machine(), "cache_mb": _cache_mb()}
    with tempfile.TemporaryDirectory(prefix="pendulum-install-") as scratch:
        scratch = Path(scratch)
        wheels, venv, work = scratch / "wheels", scratch / "venv", scratch / "work"
        work.mkdir()
        figures["wheel_s"] = (
            f"{_timed([sys.executable, '-m', 'pip', 'wheel', '--no-deps', '-w', str(wheels), str(REPOSITORY)]):.0f}"
        )
        wheel = next(wheels.glob("pendulum_fmu-*.whl"))
        figures["wheel_kb"] = f"{wheel.stat().st_size / 1e3:.0f}"
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, env=_FRESH)
        pip = [str(venv / "bin" / "python"), "-m", "pip", "install", "--disable-pip-version-check"]
        figures["install_s"] = f"{_timed([*pip, str(wheel)]):.0f}"
        site = next(venv.glob("lib/python*/site-packages"))
        before = _size(venv)
        figures["environment_mb"] = f"{before / 1e6:.0f}"
        figures["package_kb"] = f"{_size(site / 'pendulum_fmu') / 1e3:.0f}"
        parts = sorted(
            (
                (_size(p), p.name)
                for p in site.iterdir()
                if p.is_dir() and not p.name.endswith((".dist-info", "__pycache__"))
            ),
            reverse=True,
        )[:3]
        figures["largest"] = ", ".join(f"{name} ({size / 1e6:.0f} MB)" for size, name in parts)
        program = str(venv / "bin" / "pendulum-fmu")
        figures["simulate_s"] = f"{_timed([program, 'simulate', '--torque', '20'], cwd=work):.1f}"
        figures["opensim_s"] = f"{_timed([*pip, f'{wheel}[opensim]']):.0f}"
        figures["opensim_mb"] = f"{(_size(venv) - before) / 1e6:.0f}"
        figures["demo_s"] = f"{_timed([program, 'demo', '--output-dir', str(work / 'demo')], cwd=work):.0f}"
    return figures


def main() -> int:
    print(render(measure()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
