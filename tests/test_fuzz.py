"""libFuzzer on the state deserializer and on random call sequences, for a bounded time.

Run longer with FUZZ_SECONDS=3600 pytest tests/test_fuzz.py -rP (-rP shows what each printed).
"""

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from fmu_build import FMI_HEADERS, PLUMBING_DIR, assemble_sources

HARNESSES = Path(__file__).resolve().parent / "fuzz"
DEFAULT_SECONDS = 15  # per harness, as CI runs it
SECONDS = int(os.environ.get("FUZZ_SECONDS", DEFAULT_SECONDS))
pytestmark = [
    pytest.mark.fuzz,
    pytest.mark.skipif(
        shutil.which("clang") is None, reason="needs clang with libFuzzer (apt-get install clang libclang-rt-14-dev)"
    ),
]


@pytest.fixture(scope="module")
def sources(tmp_path_factory):
    sources = assemble_sources(tmp_path_factory.mktemp("fuzz") / "sources")
    shutil.copy2(PLUMBING_DIR / "fmi3_functions.c", sources)  # fuzz_calls drives both standards
    return sources


@pytest.mark.parametrize("harness", ["fuzz_state", "fuzz_calls"])
def test_fuzz(sources, tmp_path, harness):
    binary = tmp_path / harness
    subprocess.run(
        [
            "clang",
            "-std=c99",
            "-g",
            "-O1",
            "-fsanitize=fuzzer,address,undefined",
            "-fno-sanitize-recover=all",
            "-Wall",
            "-Wextra",
            "-Werror",
            f"-I{sources}",
            f"-I{FMI_HEADERS}",
            *map(str, sorted(sources.glob("*.c"))),
            str(HARNESSES / f"{harness}.c"),
            "-lm",
            "-o",
            str(binary),
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    result = subprocess.run(
        [str(binary), f"-max_total_time={SECONDS}", "-print_final_stats=1", str(corpus)],
        capture_output=True,
        text=True,
        timeout=SECONDS + 120,
    )
    assert result.returncode == 0, result.stderr[-4000:]
    runs = int(re.search(r"stat::number_of_executed_units: (\d+)", result.stderr).group(1))
    print(f"{harness}: {runs} inputs in {SECONDS} s, no crash, leak or undefined behaviour")
    assert runs > 1000
