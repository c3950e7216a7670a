"""The C driver (tests/c/driver.c) links the FMU's sources and runs the bad calls and the loads
under AddressSanitizer + UndefinedBehaviorSanitizer, under valgrind memcheck, and natively for
the figures (10 million steps of energy drift, memory growth over 100,000 instances).
"""

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fmu_build import FMI_HEADERS, PLUMBING_DIR, assemble_sources

DRIVER = Path(__file__).resolve().parent / "c" / "driver.c"
# The loads, and the bounds the native runs must keep (tests/readme_figures.py shows them).
INSTANCES, THREADS, SANITIZED_CYCLES = 1000, 8, 20_000
ENERGY_STEPS, ENERGY_DRIFT_BOUND = 10_000_000, 1e-9
CYCLES, GROWTH_BOUND_KIB = 100_000, 256
pytestmark = [pytest.mark.sanitizers, pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc")]


def _compile(sources, out, flags):
    command = [
        "gcc",
        "-std=c99",
        "-D_DEFAULT_SOURCE",
        "-g",
        "-Wall",
        "-Wextra",
        "-Werror",
        *flags,
        f"-I{sources}",
        f"-I{FMI_HEADERS}",
        *map(str, sorted(sources.glob("*.c"))),
        str(DRIVER),
        "-lm",
        "-lpthread",
        "-o",
        str(out),
    ]
    subprocess.run(command, check=True, capture_output=True, text=True)
    return out


@pytest.fixture(scope="module")
def drivers(tmp_path_factory):
    work = tmp_path_factory.mktemp("driver")
    sources = assemble_sources(work / "sources")
    shutil.copy2(PLUMBING_DIR / "fmi3_functions.c", sources)  # both adapters over one core
    return {
        "asan": _compile(
            sources,
            work / "driver_asan",
            ["-O1", "-fno-omit-frame-pointer", "-fsanitize=address,undefined", "-fno-sanitize-recover=all"],
        ),
        "plain": _compile(sources, work / "driver", ["-O2"]),
    }


def _run(command, **kwargs):
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, **kwargs)
    assert result.returncode == 0, result.stderr[-3000:]
    return result.stdout


@pytest.mark.parametrize(
    "case",
    [
        ["bad-calls"],
        ["bad-calls-fmi3"],
        ["foreign-states"],
        ["instances", str(INSTANCES)],
        ["threads", str(THREADS)],
        ["energy", "100000"],
        ["churn", str(SANITIZED_CYCLES)],
        ["churn-fmi3", str(SANITIZED_CYCLES)],
    ],
)
def test_under_address_and_undefined_behavior_sanitizers(drivers, case):
    environment = {
        **os.environ,
        "ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0",
        "UBSAN_OPTIONS": "print_stacktrace=1",
    }
    out = _run([str(drivers["asan"]), *case], env=environment)
    assert out.startswith(case[0])


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="needs valgrind")
@pytest.mark.parametrize(
    "case",
    [
        ["bad-calls"],
        ["bad-calls-fmi3"],
        ["foreign-states"],
        ["instances", "100"],
        ["threads", "8"],
        ["churn", "2000"],
        ["churn-fmi3", "2000"],
    ],
)
def test_under_valgrind_memcheck(drivers, case):
    _run(
        [
            "valgrind",
            "-q",
            "--leak-check=full",
            "--errors-for-leak-kinds=all",
            "--error-exitcode=1",
            str(drivers["plain"]),
            *case,
        ]
    )


def test_energy_is_conserved_over_ten_million_steps(drivers):
    out = _run([str(drivers["plain"]), "energy", str(ENERGY_STEPS)])
    drift = float(re.search(r"drift ([0-9.e+-]+)", out).group(1))
    # The tolerance allows 1e-10 per internal step, 1e-3 over 1e7 steps; 1 ms steps do far better.
    assert drift < ENERGY_DRIFT_BOUND, out


def test_no_memory_growth_over_100000_instances(drivers):
    # The driver fails when resident memory grows by more than the bound.
    out = _run([str(drivers["plain"]), "churn", str(CYCLES), str(GROWTH_BOUND_KIB)])
    assert "resident memory grew" in out
