"""What the build records in an FMU (pendulum_fmu/fmu/_build_record.py): the commit and the time its
entries carry, and for each binary the toolchain and the commands that make it from the FMU's own
sources/, read from the CMake build that made it.

A command is recorded without the build's paths: each source by its name in sources/, the
include folders left out (the FMU's sources/ and the FMI headers take their place), the export
list by its content. So the record is the same in any folder, and `pendulum-fmu verify` can run
the commands again on the FMU's sources/ (tested: the same bytes on linux64).

An sdist has no .git: setup.py writes SOURCE_RECORD_FILE into it (source_record()), the commit
and the time, so that what is built from the unpacked sdist, the FMUs and the wheel, records the
same commit and carries the same time as a build from the clone.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
from pathlib import Path

from pendulum_fmu.fmu._build_record import OBJECTS, ZIP_EPOCH

from .sources import ROOT

# What a build's inputs are, for whether the tree differs from its commit.
BUILD_INPUTS = ("fmu_src", "modelDescription.xml", "CMakeLists.txt", "cmake", "fmu_build")
# What marks the line of link.txt that links: a shared library's flag, or the WebAssembly core
# module's (a reactor, cmake/wasm.cmake).
LINKS = ("-shared", "-dynamiclib", "-mexec-model=reactor")
# What an sdist carries in place of .git, at its top: source_record() as JSON.
SOURCE_RECORD_FILE = "source_commit.json"


def _git(*arguments: str) -> str | None:
    try:
        done = subprocess.run(["git", "-C", str(ROOT), *arguments], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def _sdist_record() -> dict:
    """The unpacked sdist's SOURCE_RECORD_FILE, or {} (a clone, or no such file)."""
    try:
        recorded = json.loads((ROOT / SOURCE_RECORD_FILE).read_text())
    except (OSError, ValueError):
        return {}
    return recorded if isinstance(recorded, dict) else {}


def source_commit() -> dict:
    """{"commit": the checkout's commit, or the one the sdist records, or None; "modified":
    whether the build's inputs differ from it (in an sdist: as they did when it was made)}.
    """
    if not (ROOT / ".git").exists():
        recorded = _sdist_record()
        return {"commit": recorded.get("commit"), "modified": bool(recorded.get("modified", False))}
    commit = _git("rev-parse", "HEAD")
    changes = _git("status", "--porcelain", "--", *BUILD_INPUTS)
    return {"commit": commit, "modified": bool(changes)}


def source_date_epoch() -> int:
    """The time every entry carries: $SOURCE_DATE_EPOCH (reproducible-builds.org), else the
    commit's, else the one the sdist records, else 1980-01-01 (zip's first date).
    """
    given = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    if given.isdigit():
        return int(given)
    committed = _git("log", "-1", "--format=%ct") if (ROOT / ".git").exists() else None
    if committed and committed.isdigit():
        return int(committed)
    recorded = _sdist_record().get("source_date_epoch")
    return recorded if isinstance(recorded, int) and recorded >= 0 else ZIP_EPOCH


def source_record() -> dict:
    """What an sdist records of its source (SOURCE_RECORD_FILE): source_commit() and
    "source_date_epoch", source_date_epoch().
    """
    return {**source_commit(), "source_date_epoch": source_date_epoch()}


def write_source_record(folder: str | os.PathLike) -> None:
    """Write source_record() into folder's SOURCE_RECORD_FILE (setup.py: into the sdist's tree)."""
    Path(folder, SOURCE_RECORD_FILE).write_text(json.dumps(source_record(), indent=1, sort_keys=True) + "\n")


def _cmake_variable(text: str, name: str) -> str:
    found = re.search(rf'set\({name} "([^"]*)"\)', text)
    return found[1] if found else ""


def _without_paths(arguments: list[str], drop_next: tuple[str, ...] = ("-o", "-c", "-MF", "-MT")) -> list[str]:
    """The flags of a command, without what names the build's files: include folders, outputs,
    inputs and dependency files.
    """
    kept, skip = [], False
    for argument in arguments:
        if skip:
            skip = False
        elif argument in drop_next:
            skip = True
        elif not (argument.startswith(("-I", "/", "@")) or argument.endswith((".c", ".o", ".obj"))):
            kept.append(argument)
    return kept


def _link_flags(arguments: list[str]) -> list[str]:
    """The link's flags without the build's paths, OBJECTS where the objects go (mingw's archive
    of them too): the libraries after them must stay after them.
    """
    flags: list[str] = []
    output = False
    for argument in arguments:
        if output or argument == "-o":  # the output, named by the FMU's entry
            output = argument == "-o"
        elif argument.endswith((".o", ".obj")) or argument.endswith("/objects.a"):
            if OBJECTS not in flags:
                flags.append(OBJECTS)
        elif argument.startswith(("-Wl,--version-script=", "--version-script=")):
            # gcc's -Wl,--version-script=PATH, or clang's (zig's) -Xlinker --version-script=PATH.
            flags.append(argument.split("=", 1)[0] + "=exports.map")
        else:
            flags.extend(_without_paths([argument]))
    return flags


def toolchain(build: Path, cmake_target: str) -> dict:
    """The toolchain and commands of cmake_target in the CMake build folder build (configured with
    CMAKE_EXPORT_COMPILE_COMMANDS): the compiler, its kind and version, the sources in link order,
    the compile and link flags, and the export list.
    """
    [compiler_file] = build.glob("CMakeFiles/*/CMakeCCompiler.cmake")
    compiler = compiler_file.read_text()
    commands = json.loads((build / "compile_commands.json").read_text())
    mine = [
        entry for entry in commands if f"/{cmake_target}.dir/" in entry["output" if "output" in entry else "command"]
    ]
    first = shlex.split(mine[0]["command"])
    driver = [Path(first[0]).name]
    # zig's driver and its target (CMAKE_C_COMPILER_ARG1, "cc -target ..."), which come before the flags.
    extra = shlex.split(_cmake_variable(compiler, "CMAKE_C_COMPILER_ARG1"))
    # The line of link.txt that links (mingw's first archive the objects, listed in a response file).
    folder = build / "CMakeFiles" / f"{cmake_target}.dir"
    [link] = [
        words
        for words in map(shlex.split, (folder / "link.txt").read_text().splitlines())
        if words and words[0] == first[0] and any(word in words for word in LINKS)
    ]
    listed = [word for path in sorted(folder.glob("objects*.rsp")) for word in shlex.split(path.read_text())]
    exports = sorted(build.glob(f"{cmake_target}.exports.map"))
    # The link's order of the objects (a response file's, where the toolchain uses one), each by its source.
    objects = [
        Path(argument).name.removesuffix(".o").removesuffix(".obj")
        for argument in listed or link
        if argument.endswith((".o", ".obj"))
    ]
    return {
        "compiler": driver + extra,
        "compiler_id": _cmake_variable(compiler, "CMAKE_C_COMPILER_ID"),
        "compiler_version": _cmake_variable(compiler, "CMAKE_C_COMPILER_VERSION"),
        "sources": objects or [Path(entry["file"]).name for entry in mine],
        "compile": _without_paths(first[1 + len(extra) :]),
        "link": _link_flags(link[1 + len(extra) :]),
        "exports_map": exports[0].read_text() if exports else None,
    }
