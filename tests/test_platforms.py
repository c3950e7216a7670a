"""One FMU for every platform, in both FMI versions: the win64 binary (mingw-w64) run under wine
and the aarch64-linux binary (gcc-aarch64-linux-gnu) run under qemu-aarch64, each by the same bare
C master that runs the linux64 binary, with the same numbers; the macOS binaries (zig), which
nothing here can run, read slice by slice; zig's builds for Linux, which the wheels carry (for
glibc 2.17), run to show that zig compiles the sources to the same numbers; and a build that
skips a platform whose compiler is missing.
"""

import dataclasses
import hashlib
import os
import re
import shutil
import struct
import subprocess
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description

import fmu_build
from benchmarks.builds import build_bare_master, build_step_master
from build_wheels import MANYLINUX_GLIBC
from fmu_build import FMI_VERSIONS, PLATFORMS, WASM, BuildError, PlatformSkipped, build_fmu, find_zig
from pendulum_fmu.cli import main
from pendulum_fmu.oracle._reference import reference

STEPS, STEP_SIZE = 3000, 1e-3  # the tutorial case: 20 N.m, gravity on, 3 s
POW_INPUTS = 1_000_000
# How each platform's master runs here: natively, under wine, under qemu with the cross libc.
RUNNERS = {"linux64": [], "win64": ["wine"], "aarch64-linux": ["qemu-aarch64", "-L", "/usr/aarch64-linux-gnu"]}
# The marker (pyproject's) of the tests that build or run a platform's binary with its cross tools.
CROSS_MARKERS = {"win64": pytest.mark.wine, "aarch64-linux": pytest.mark.qemu}
CROSS = [
    pytest.param(
        platform,
        marks=[
            CROSS_MARKERS[platform],
            pytest.mark.skipif(
                shutil.which(PLATFORMS[platform].targets[0].cross_compiler) is None
                or shutil.which(RUNNERS[platform][0]) is None,
                reason=f"needs {PLATFORMS[platform].targets[0].package} and {RUNNERS[platform][0]} "
                "(.ci/run installs them)",
            ),
        ],
    )
    for platform in ("win64", "aarch64-linux")
]
POW_VERSIONS = Path(__file__).parent / "c/pow_versions.c"
RECORD_MASTER = Path(__file__).parent / "c/record_master.c"
EACH_FMI_VERSION = pytest.mark.parametrize("fmi_version", FMI_VERSIONS, ids=lambda version: f"fmi{version}")
# The value references benchmarks/bare_master.h hard-codes (VR_TORQUE, VR_THETA).
MASTER_VALUE_REFERENCES = {"torque": 0, "theta": 1}


@dataclass(frozen=True)
class UnzippedBuild:
    """A default build (every platform whose compiler is here) of one FMI version, unzipped into
    work/, where its masters and their trajectories go too.
    """

    fmi_version: int
    work: Path
    token: str  # the FMI 2.0 guid, the FMI 3.0 instantiationToken
    value_references: dict

    def library(self, platform, fmi3_folder=None):
        """The binary of an FMI 2.0 platform; in FMI 3.0, of its one folder or of fmi3_folder."""
        if self.fmi_version == 2:
            folder = platform
        else:
            [folder] = [fmi3_folder] if fmi3_folder else PLATFORMS[platform].fmi3_folders
        return self.work / "unzipped/binaries" / folder / f"Pendulum{PLATFORMS[platform].suffix}"


def _unzipped_build(fmu, work):
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(work / "unzipped")
    description = read_model_description(str(fmu))
    fmi_version = int(description.fmiVersion[0])
    return UnzippedBuild(
        fmi_version, work, description.guid, {v.name: v.valueReference for v in description.modelVariables}
    )


@pytest.fixture(scope="module")
def every_platform(tmp_path_factory, fmu, fmu3):
    """{FMI version: its UnzippedBuild}, of the session's default builds (conftest's fmu, fmu3)."""
    builds = {}
    for fmi_version, built in zip(FMI_VERSIONS, (fmu, fmu3), strict=True):
        work = tmp_path_factory.mktemp(f"platforms_fmi{fmi_version}")
        builds[fmi_version] = _unzipped_build(built, work)
        assert builds[fmi_version].fmi_version == fmi_version
    return builds


def _exports_of_dll(dll):
    table = subprocess.run(
        ["x86_64-w64-mingw32-objdump", "-p", str(dll)], capture_output=True, text=True, check=True
    ).stdout
    names = table.split("[Ordinal/Name Pointer] Table", 1)[1].split("\n\n", 1)[0]
    return set(re.findall(r"\]\s+(\w+)", names))


def _exports_of_so(library, nm="nm"):
    symbols = subprocess.run(
        [nm, "-D", "--defined-only", str(library)], capture_output=True, text=True, check=True
    ).stdout
    return {line.split()[-1] for line in symbols.splitlines()}


def _exports(platform, library):
    if platform == "win64":
        return _exports_of_dll(library)
    return _exports_of_so(library, "aarch64-linux-gnu-nm" if platform == "aarch64-linux" else "nm")


def _wine_environment(build):
    # One wine prefix for both FMI versions: making one takes wine seconds.
    return {**os.environ, "WINEPREFIX": str(build.work.parent / "wineprefix"), "WINEDEBUG": "-all"}


def _theta_by_step_master(build, platform, master=None):
    """Theta at every communication point, from the C master of build's FMI version built for and
    run on platform (or master, built before).
    """
    assert {name: build.value_references[name] for name in MASTER_VALUE_REFERENCES} == MASTER_VALUE_REFERENCES
    master = master or build_step_master(build.work, platform, build.fmi_version)
    trajectory = build.work / f"theta_{platform}.txt"
    subprocess.run(
        [
            *RUNNERS[platform],
            str(master),
            str(build.library(platform)),
            build.token,
            str(STEPS),
            repr(STEP_SIZE),
            "0",
            str(trajectory),
        ],
        check=True,
        capture_output=True,
        env=_wine_environment(build),
        timeout=300,
    )
    return np.loadtxt(trajectory)


@pytest.mark.parametrize("platform", CROSS)
@EACH_FMI_VERSION
def test_binary_exports_exactly_the_functions_of_the_linux_binary(every_platform, fmi_version, platform):
    build = every_platform[fmi_version]
    exports = _exports(platform, build.library(platform))
    assert exports == _exports_of_so(build.library("linux64"))
    assert all(name.startswith(f"fmi{fmi_version}") for name in exports) and f"fmi{fmi_version}DoStep" in exports


@pytest.mark.parametrize("platform", ["linux64", *CROSS])
def test_each_platforms_binary_writes_its_record_only_into_a_record_of_its_own(every_platform, platform, tmp_path):
    """The record file's rules (tests/test_record_file.py) where each binary's own C library opens the
    file: a user's file refused, a new record made and appended to, the instance name escaped.
    """
    build = every_platform[2]
    master = build_bare_master(build.work, RECORD_MASTER, platform)

    def run(record, name='x\\y"%s'):
        command = [*RUNNERS[platform], str(master), str(build.library(platform)), build.token, name, record]
        done = subprocess.run(
            command, cwd=tmp_path, capture_output=True, text=True, env=_wine_environment(build), timeout=300
        )
        assert done.returncode == 0, done.stderr
        return done.stdout

    (tmp_path / "bashrc").write_text("export PATH=$HOME/bin:$PATH\n")
    assert "is not a call record" in run("bashrc")
    assert (tmp_path / "bashrc").read_text() == "export PATH=$HOME/bin:$PATH\n"
    for _ in range(2):
        assert "WARNING" not in run("calls.log")
    assert (tmp_path / "calls.log").read_text().splitlines() == [
        '[pendulum-calls] instance="x\\\\y\\"\\x25s" fmi2SetString(file="calls.log") time=0->0 status=OK',
        '[pendulum-calls] instance="x\\\\y\\"\\x25s" fmi2FreeInstance() time=0->0 status=OK',
    ] * 2
    if platform == "win64":
        # wine shows Windows a host's symbolic link as the file it points to, no reparse point, so
        # the link is opened as its target (a real Windows link is opened as itself and refused, by
        # FILE_FLAG_OPEN_REPARSE_POINT: inspected, not run). A link to the user's file is refused
        # as what that file is.
        (tmp_path / "link.log").symlink_to(tmp_path / "bashrc")
        assert "is not a call record" in run("link.log")
    else:
        (tmp_path / "link.log").symlink_to(tmp_path / "calls.log")
        assert "is a symbolic link" in run("link.log")


# linux64 too: there the master of each FMI version checks the other's, and the reference, with no cross tools.
@pytest.mark.parametrize("platform", ["linux64", *CROSS])
@EACH_FMI_VERSION
def test_binary_on_its_platform_matches_linux64_in_both_fmi_versions(every_platform, fmi_version, platform):
    run = _theta_by_step_master(every_platform[fmi_version], platform)
    assert len(run) == STEPS + 1
    # Both versions are the same plumbing and model behind other entry points, so the same numbers.
    for version, build in every_platform.items():
        assert np.max(np.abs(run - _theta_by_step_master(build, "linux64"))) <= 1e-15, version
    # And the pendulum: the reference on the same held torque.
    expected = reference(20.0, stop_time=STEPS * STEP_SIZE, step_size=STEP_SIZE)["theta"]
    assert np.max(np.abs(run - expected)) < 1e-9


# Every Mach-O slice: its FMI 3.0 folder and the oldest macOS it loads on (Apple Silicon began
# with 11.0; 10.13 is what the Reference FMUs' x86_64 binaries ask for).
MACOS_SLICES = {"x86_64": ("x86_64-darwin", "10.13"), "arm64": ("aarch64-darwin", "11.0")}
LLVM_TOOLS = ("llvm-objdump-14", "llvm-lipo-14")
READS_MACH_O = pytest.mark.skipif(
    find_zig() is None or not all(map(shutil.which, LLVM_TOOLS)),
    reason="needs zig (pip install ziglang) and llvm-objdump-14, llvm-lipo-14 (apt-get install llvm-14)",
)
CS_ADHOC, CS_HASHTYPE_SHA256 = 0x2, 2
ZIG_HEADER_SYMBOLS = {"__mh_dylib_header", "___dso_handle"}


def _llvm(tool, *arguments):
    return subprocess.run([f"llvm-{tool}-14", *map(str, arguments)], capture_output=True, text=True, check=True).stdout


def _macho_slices(build, work):
    """{architecture: the slice as a file of its own}: FMI 2.0's universal darwin64 binary cut
    into its slices, FMI 3.0's two binaries as they are.
    """
    if build.fmi_version == 3:
        return {architecture: build.library("darwin64", folder) for architecture, (folder, _) in MACOS_SLICES.items()}
    universal = build.library("darwin64")
    assert set(_llvm("lipo", "-archs", universal).split()) == set(MACOS_SLICES)
    slices = {}
    for architecture in MACOS_SLICES:
        slices[architecture] = work / f"Pendulum_{architecture}.dylib"
        _llvm("lipo", universal, "-thin", architecture, "-output", slices[architecture])
    return slices


def _load_commands(slice_):
    """Each load command as {field: value}, in the order of the file."""
    commands = []
    for line in _llvm("objdump", "--macho", "--private-headers", slice_).splitlines():
        if line.startswith("Load command"):
            commands.append({})
        elif commands and line.strip():
            field, _, value = line.strip().partition(" ")
            commands[-1].setdefault(field, value.strip())
    return commands


def _check_ad_hoc_signature(slice_, signature):
    """The code directory of an ad-hoc signature whose page hashes are those of the slice's bytes:
    what macOS checks, page by page, before it runs code on Apple Silicon.
    """
    data = slice_.read_bytes()
    offset = int(signature["dataoff"])
    blob = data[offset : offset + int(signature["datasize"])]
    magic, _, count = struct.unpack_from(">III", blob)
    assert magic == 0xFADE0CC0  # an embedded signature's super blob
    [directory] = [
        blob[at:] for kind, at in (struct.unpack_from(">II", blob, 12 + 8 * i) for i in range(count)) if kind == 0
    ]
    (magic, _, _, flags, hash_offset, _, _, code_slots, code_limit, hash_size, hash_type, _, page_shift) = (
        struct.unpack_from(">9I4B", directory)
    )
    assert magic == 0xFADE0C02 and flags & CS_ADHOC and hash_type == CS_HASHTYPE_SHA256
    assert code_limit == offset  # it covers every byte before it
    page = 1 << page_shift
    assert code_slots == -(-code_limit // page)
    for index in range(code_slots):
        expected = directory[hash_offset + index * hash_size : hash_offset + (index + 1) * hash_size]
        assert hashlib.sha256(data[index * page : min((index + 1) * page, code_limit)]).digest() == expected


@READS_MACH_O
@EACH_FMI_VERSION
def test_every_macos_slice_exports_the_fmi_functions_and_loads_only_libsystem(every_platform, fmi_version, tmp_path):
    """Read, not run: no Mac is available here."""
    build = every_platform[fmi_version]
    linux_exports = _exports_of_so(build.library("linux64"))
    for architecture, slice_ in _macho_slices(build, tmp_path).items():
        assert _llvm("lipo", "-archs", slice_).split() == [architecture]
        exports = {
            line.split()[-1]
            for line in _llvm("objdump", "--macho", "--exports-trie", slice_).splitlines()
            if line.startswith("0x")
        }
        # C names take a _ on Mach-O. zig's Mach-O linker also exports the two symbols it makes
        # for the image's header (Apple's ld64 and LLVM's keep them private): nothing else may leak.
        assert exports == {f"_{name}" for name in linux_exports} | ZIG_HEADER_SYMBOLS, architecture
        commands = _load_commands(slice_)
        by_kind = {}
        for command in commands:
            by_kind.setdefault(command["cmd"], []).append(command)
        [identity] = by_kind["LC_ID_DYLIB"]
        assert identity["name"].split(" (")[0] == "Pendulum.dylib"
        assert [load["name"].split(" (")[0] for load in by_kind["LC_LOAD_DYLIB"]] == ["/usr/lib/libSystem.B.dylib"]
        assert not {"LC_LOAD_WEAK_DYLIB", "LC_REEXPORT_DYLIB", "LC_RPATH"} & by_kind.keys()
        # macOS 10.13 binaries say their minimum in LC_VERSION_MIN_MACOSX, 11.0 ones in LC_BUILD_VERSION.
        [minimum] = [build_version["minos"] for build_version in by_kind.get("LC_BUILD_VERSION", [])] or [
            old["version"] for old in by_kind["LC_VERSION_MIN_MACOSX"]
        ]
        assert minimum == MACOS_SLICES[architecture][1], architecture
        if architecture == "arm64":
            [signature] = by_kind["LC_CODE_SIGNATURE"]
            _check_ad_hoc_signature(slice_, signature)


RUNS_ZIG = [
    pytest.param(
        platform,
        marks=[
            *([CROSS_MARKERS[platform]] if platform in CROSS_MARKERS else []),
            pytest.mark.skipif(
                find_zig() is None
                or shutil.which(RUNNERS[platform][0] if RUNNERS[platform] else "true") is None
                or shutil.which(PLATFORMS[platform].targets[0].compiler()[0]) is None,
                reason=f"needs zig (pip install ziglang) and {PLATFORMS[platform].targets[0].compiler()[0]}, "
                f"{(RUNNERS[platform] or ['nothing'])[0]} to build and run the master",
            ),
        ],
    )
    for platform in ("linux64", "aarch64-linux")
]


def _readelf(library, *options):
    return subprocess.run(["readelf", *options, str(library)], capture_output=True, text=True, check=True).stdout


def _glibc_versions(library):
    """{symbol: (major, minor[, patch])}: the glibc symbol version each function the ELF library
    imports is bound to.
    """
    return {
        name: tuple(map(int, version.split(".")))
        for name, version in re.findall(r" UND (\w+)@GLIBC_([\d.]+)", _readelf(library, "--dyn-syms", "--wide"))
    }


@pytest.mark.build
@pytest.mark.parametrize("platform", RUNS_ZIG)
@EACH_FMI_VERSION
def test_zig_builds_for_the_wheels_glibc_give_the_gcc_builds_theta_bit_for_bit(
    every_platform, tmp_path, fmi_version, platform
):
    """The wheels' Linux binaries come from zig's C compiler for glibc 2.17 (build_wheels.py), the
    macOS ones from the same zig, and nothing here can run those: the same build, through the same
    CMake description (cmake/linux.cmake, cmake/zig.cmake), whose binaries the bare C masters run
    here (qemu for arm64). Their theta is the gcc build's at every point, bit for bit. Without FMA
    contraction (cmake/flags.cmake) clang and gcc round every operation alike. Both call this
    machine's libm, zig's build through the older symbol versions (pow@GLIBC_2.2.5 on x86_64,
    pow@GLIBC_2.17 on arm64, where gcc's build against Debian 12's glibc binds pow@GLIBC_2.29):
    glibc keeps those as a wrapper around the same pow that only reports errors the old way
    (math/w_pow_compat.c), so a finite result is the same bits, which tests/c/pow_versions.c
    checks on a million inputs here. What this cannot show is another libm: an old glibc's own
    (its sin, cos and pow predate glibc 2.28's rewrite) or a Mac's.
    """
    master = build_step_master(tmp_path, platform, fmi_version)  # by gcc
    build = _unzipped_build(
        build_fmu(
            tmp_path / "Pendulum.fmu", platforms=(platform,), fmi_version=fmi_version, linux_glibc=MANYLINUX_GLIBC
        ),
        tmp_path,
    )
    library = build.library(platform)
    comment = _readelf(library, "-p", ".comment")
    assert "clang" in comment and "GCC" not in comment, comment  # zig's clang built it, not gcc
    versions = _glibc_versions(library)
    assert "pow" in versions and max(versions.values()) <= tuple(map(int, MANYLINUX_GLIBC.split("."))), versions
    # This machine's libm: the pow zig's build binds gives pow@GLIBC_2.29's bits.
    pow_version = "GLIBC_" + ".".join(map(str, versions["pow"]))
    compared = subprocess.run(
        [*RUNNERS[platform], build_bare_master(tmp_path, POW_VERSIONS, platform), pow_version, str(POW_INPUTS)],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    ).stdout
    assert compared.splitlines()[-1] == f"0 of {POW_INPUTS} differ", compared
    run = _theta_by_step_master(build, platform, master)
    assert len(run) == STEPS + 1
    gcc = _theta_by_step_master(every_platform[fmi_version], "linux64")
    assert np.array_equal(run, gcc), np.max(np.abs(run - gcc))


@pytest.mark.build
@pytest.mark.skipif(find_zig() is None, reason="needs zig (pip install ziglang)")
def test_build_command_builds_for_any_glibc_floor_and_refuses_a_malformed_one_in_one_line(tmp_path, capsys):
    # Older than the wheels' 2.17: then x86-64's memcpy binds GLIBC_2.2.5, not GLIBC_2.14.
    fmu = tmp_path / "Pendulum.fmu"
    assert main(["build", "--platforms", "linux64", "--linux-glibc", "2.12", "--output", str(fmu)]) == 0
    build = _unzipped_build(fmu, tmp_path)
    versions = _glibc_versions(build.library("linux64"))
    assert "clang" in _readelf(build.library("linux64"), "-p", ".comment")
    assert {"pow", "memcpy"} <= versions.keys() and max(versions.values()) <= (2, 12), versions
    capsys.readouterr()
    assert main(["build", "--linux-glibc", "17", "--output", str(tmp_path / "Other.fmu")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        "pendulum-fmu build: error: glibc floor '17': give a glibc version such as 2.17"
    ]
    assert not (tmp_path / "Other.fmu").exists()


def _without_compiler(monkeypatch, platform):
    """Neither the platform's cross gcc nor zig, which stands in for a missing one."""
    targets = tuple(
        dataclasses.replace(target, cross_compiler="no-such-cross-gcc")
        for target in PLATFORMS[platform].targets
        if target.cross_compiler != fmu_build.ZIG
    )
    if targets:
        monkeypatch.setitem(fmu_build.PLATFORMS, platform, dataclasses.replace(PLATFORMS[platform], targets=targets))
    monkeypatch.setattr(fmu_build.platforms, "find_zig", lambda: None)  # where the compilers look for it
    monkeypatch.setenv(
        "PATH",
        os.pathsep.join(
            folder for folder in os.environ["PATH"].split(os.pathsep) if not Path(folder, fmu_build.ZIG).exists()
        ),
    )


@pytest.mark.build
@pytest.mark.parametrize(
    "platform, missing",
    [
        ("win64", "no-such-cross-gcc not found (apt-get install gcc-mingw-w64-x86-64, or pip install ziglang)"),
        (
            "aarch64-linux",
            "no-such-cross-gcc not found (apt-get install gcc-aarch64-linux-gnu, or pip install ziglang)",
        ),
        ("darwin64", "zig cc not found (pip install ziglang)"),
    ],
)
def test_default_build_skips_a_platform_without_its_compiler_in_one_line(tmp_path, monkeypatch, platform, missing):
    _without_compiler(monkeypatch, platform)
    with pytest.warns(PlatformSkipped) as skipped:
        fmu = build_fmu(tmp_path / "Pendulum.fmu")
    [message] = [str(warning.message) for warning in skipped if str(warning.message).startswith(platform)]
    assert message == f"{platform}: C compiler {missing}; skipped"
    with zipfile.ZipFile(fmu) as archive:
        folders = {name.split("/")[1] for name in archive.namelist() if name.startswith("binaries/")}
    assert "linux64" in folders and platform not in folders


@pytest.mark.build
def test_a_platform_named_explicitly_must_build(tmp_path, monkeypatch):
    _without_compiler(monkeypatch, "aarch64-linux")
    with pytest.raises(BuildError, match="apt-get install gcc-aarch64-linux-gnu, or pip install ziglang"):
        build_fmu(tmp_path / "Pendulum.fmu", platforms=("linux64", "aarch64-linux"))
    assert not (tmp_path / "Pendulum.fmu").exists()


@pytest.mark.build
def test_build_command_says_what_it_skipped_in_one_line(tmp_path, monkeypatch, capsys):
    _without_compiler(monkeypatch, "aarch64-linux")
    assert main(["build", "--output", str(tmp_path / "Pendulum.fmu")]) == 0
    # Without zig the macOS binaries are skipped too.
    assert capsys.readouterr().err.splitlines() == [
        "pendulum-fmu build: aarch64-linux: C compiler no-such-cross-gcc not found "
        "(apt-get install gcc-aarch64-linux-gnu, or pip install ziglang); skipped",
        "pendulum-fmu build: darwin64: C compiler zig cc not found (pip install ziglang); skipped",
    ]


CROSS_GCC_PREFIXES = ("x86_64-w64-mingw32-", "aarch64-linux-gnu-")
# What each Windows DLL may import: the mingw gcc's build imports KERNEL32 and msvcrt; zig's links
# the Universal C Runtime, whose api-ms-win-crt-* sets every Windows 10 and later carries.
WINDOWS_10_DLLS = re.compile(r"KERNEL32\.dll|msvcrt\.dll|api-ms-win-crt-\w+-l1-1-0\.dll")


def _path_without_cross_gccs(folder):
    """A PATH of links to every program on this one but the Debian cross gccs' tools."""
    folder.mkdir()
    for directory in os.environ["PATH"].split(os.pathsep):
        for program in Path(directory).glob("*") if Path(directory).is_dir() else ():
            if not program.name.startswith(CROSS_GCC_PREFIXES) and not (folder / program.name).exists():
                (folder / program.name).symlink_to(program)
    return str(folder)


def _imported_dlls(dll):
    return re.findall(r"DLL Name: (\S+)", _llvm("objdump", "-p", dll))


@pytest.mark.skipif(
    find_zig() is None
    or not all(shutil.which(RUNNERS[platform][0]) for platform in RUNNERS if RUNNERS[platform])
    or shutil.which("llvm-objdump-14") is None,
    reason="needs zig (pip install ziglang), wine, qemu-aarch64 and llvm-objdump-14",
)
@pytest.mark.parametrize("platform", CROSS)
@EACH_FMI_VERSION
def test_zig_stands_in_for_a_missing_cross_gcc_with_the_gcc_builds_theta(
    every_platform, tmp_path, monkeypatch, fmi_version, platform
):
    """A source build on a machine without Debian's cross gccs (pip wheel ., an sdist, an editable
    install) has zig, a build requirement, build win64 (x86_64-windows-gnu) and aarch64-linux
    (aarch64-linux-gnu.2.17): the FMU holds every platform's binary, which the bare C master (built
    by the cross gcc before it is hidden) runs under qemu to the linux64 gcc build's theta at every
    point, bit for bit, and under wine to within the last bit (Windows' C runtime is not glibc).
    """
    master = build_step_master(tmp_path, platform, fmi_version)
    monkeypatch.setenv("PATH", _path_without_cross_gccs(tmp_path / "bin"))
    assert shutil.which(PLATFORMS[platform].targets[0].cross_compiler) is None
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlatformSkipped)
        fmu = build_fmu(tmp_path / "Pendulum.fmu", fmi_version=fmi_version)
    monkeypatch.undo()
    build = _unzipped_build(fmu, tmp_path)
    expected = {
        folder
        for platform_ in PLATFORMS.values()
        for folder in ((platform_.fmi2_folder,) if fmi_version == 2 else platform_.fmi3_folders)
    } | ({WASM} if fmi_version == 3 else set())  # the WebAssembly component, zig's and wasm-tools' too
    assert {path.name for path in (tmp_path / "unzipped/binaries").iterdir()} == expected
    library = build.library(platform)
    if platform == "win64":
        imported = _imported_dlls(library)
        assert "KERNEL32.dll" in imported and all(WINDOWS_10_DLLS.fullmatch(name) for name in imported), imported
    else:
        assert "clang" in _readelf(library, "-p", ".comment")  # zig's clang built it, not gcc
        assert max(_glibc_versions(library).values()) <= (2, 17)
    assert _exports(platform, library) == _exports_of_so(every_platform[fmi_version].library("linux64"))
    run = _theta_by_step_master(build, platform, master)
    gcc = _theta_by_step_master(every_platform[fmi_version], "linux64")
    assert len(run) == STEPS + 1
    if platform == "win64":
        # zig's DLL takes sin and cos from zig's own mingw-w64 runtime and pow from the UCRT (here
        # wine's), which round differently from glibc in the last bit now and then; the mingw
        # build's sin, cos and pow happen to give glibc's bits on this case. So: the tolerance of
        # test_binary_on_its_platform_matches_linux64_in_both_fmi_versions, and the reference's pendulum.
        assert np.max(np.abs(run - gcc)) <= 1e-15
        expected = reference(20.0, stop_time=STEPS * STEP_SIZE, step_size=STEP_SIZE)["theta"]
        assert np.max(np.abs(run - expected)) < 1e-9
    else:
        assert np.array_equal(run, gcc), np.max(np.abs(run - gcc))
