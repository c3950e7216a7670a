"""An arm64 CPython that runs here, under qemu-aarch64: Debian bookworm's arm64 python3.11 packages
unpacked into a sysroot, and PyPI's aarch64 wheels installed by that Python's own pip.

Nothing is installed on the machine: apt reads the arm64 package lists into a private state folder
(no `dpkg --add-architecture`, no root), `apt-get download` fetches the .debs and `dpkg-deb -x`
unpacks them. Everything is cached under .cache/arm64-python/ (git-ignored), each piece renamed
into place whole, so a second use needs no network: the sysroot, and the aarch64 wheels of every
requirement asked for so far.

    python = Arm64Python()
    python.install([wheel], site)      # pip under qemu: the wheel and its dependencies
    python.run([site / "bin/pendulum-fmu", "simulate", ...], site=site, cwd=folder)

`Unavailable` says in one line what is missing here (qemu-user, Debian's apt, the network); the
tests turn it into a skip.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from email.parser import HeaderParser
from pathlib import Path

from filelock import FileLock

ROOT = Path(__file__).resolve().parent.parent
CACHE = ROOT / ".cache" / "arm64-python"
# Debian bookworm's, as its python3.11 needs them at run time: the interpreter and its standard
# library, the C and C++ runtimes the manylinux wheels link (numpy's OpenBLAS, matplotlib),
# zlib and expat (the interpreter itself), libffi (ctypes, which loads the FMU and the native
# loop), OpenSSL (hashlib, which pip uses), bz2, lzma and uuid (standard modules pip imports).
PACKAGES = (
    "python3.11-minimal",
    "libpython3.11-minimal",
    "libpython3.11-stdlib",
    "libc6",
    "libgcc-s1",
    "libstdc++6",
    "zlib1g",
    "libexpat1",
    "libffi8",
    "libssl3",
    "libbz2-1.0",
    "liblzma5",
    "libuuid1",
)
PYTHON_VERSION = "3.11"
GLIBC = (2, 36)  # bookworm's: the newest manylinux tag this Python takes
# Every manylinux tag a glibc 2.36 aarch64 takes; pip before 24 does not expand one into the older.
PLATFORM_TAGS = ("manylinux2014_aarch64", *(f"manylinux_2_{minor}_aarch64" for minor in range(17, GLIBC[1] + 1)))
# A run here sees neither the machine's pip configuration nor its Python settings.
CLEAN_ENVIRONMENT = {
    "PATH": os.defpath,
    "LC_ALL": "C.UTF-8",
    "PIP_CONFIG_FILE": os.devnull,
    "PIP_DISABLE_PIP_VERSION_CHECK": "1",
    "PIP_ROOT_USER_ACTION": "ignore",
    "PYTHONNOUSERSITE": "1",
}


class Unavailable(RuntimeError):
    """What this machine lacks to run an arm64 Python, in one line."""


def _run(command, what, timeout=900, **options):
    try:
        result = subprocess.run(
            [str(part) for part in command], capture_output=True, text=True, timeout=timeout, **options
        )
    except OSError as error:
        raise Unavailable(f"{what}: {command[0]}: {error.strerror}") from None
    if result.returncode != 0:
        last = (result.stderr.strip() or result.stdout.strip() or "no output").splitlines()[-1]
        raise Unavailable(f"{what} failed ({last})")
    return result


def _renamed_into_place(target: Path, make) -> Path:
    """make(folder) fills a fresh folder beside target, which is then renamed to target; when
    another process got there first, its copy stays.
    """
    if target.exists():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".partial", dir=target.parent))
    try:
        make(scratch)
        os.replace(scratch, target)
    except OSError:
        if not target.exists():
            raise
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return target


def requirements_of(wheel: Path) -> list[str]:
    """The wheel's Requires-Dist without the extras'."""
    with zipfile.ZipFile(wheel) as archive:
        [metadata] = [name for name in archive.namelist() if name.endswith(".dist-info/METADATA")]
        headers = HeaderParser().parsestr(archive.read(metadata).decode())
    return [requirement for requirement in headers.get_all("Requires-Dist", []) if "extra ==" not in requirement]


class Arm64Python:
    """Debian's arm64 python3.11 under qemu-aarch64, its sysroot and wheels cached under cache."""

    def __init__(self, cache: Path = CACHE):
        self.cache = Path(cache)
        for tool, package in (("qemu-aarch64", "qemu-user"), ("apt-get", "apt"), ("dpkg-deb", "dpkg")):
            if shutil.which(tool) is None:
                raise Unavailable(f"an arm64 Python under qemu needs {tool} (apt-get install {package})")
        self.sysroot = _renamed_into_place(self.cache / "sysroot", self._assemble)
        self.python = self.sysroot / "usr/bin" / f"python{PYTHON_VERSION}"
        self.wheels = self.cache / "wheels"

    def _assemble(self, sysroot: Path) -> None:
        """Debian's arm64 packages, unpacked into sysroot."""
        work = Path(tempfile.mkdtemp(prefix="arm64_apt_", dir=self.cache))
        try:
            state, debs = work / "state", work / "debs"
            for folder in (state / "lists/partial", work / "cache/archives/partial", debs):
                folder.mkdir(parents=True)
            (state / "status").touch()
            options = [
                "-o",
                "APT::Architecture=arm64",
                "-o",
                "APT::Architectures=arm64",
                "-o",
                f"Dir::State={state}",
                "-o",
                f"Dir::State::status={state / 'status'}",
                "-o",
                f"Dir::Cache={work / 'cache'}",
            ]
            _run(["apt-get", *options, "update"], "apt-get update for arm64")
            _run(
                ["apt-get", *options, "download", *(f"{name}:arm64" for name in PACKAGES)],
                "apt-get download of Debian's arm64 python3.11",
                cwd=debs,
            )
            for deb in sorted(debs.glob("*.deb")):
                _run(["dpkg-deb", "-x", deb, sysroot], f"dpkg-deb -x {deb.name}")
        finally:
            shutil.rmtree(work, ignore_errors=True)

    def download(self, requirements: list[str]) -> Path:
        """The aarch64 CPython 3.11 wheels of requirements and of everything they need, and pip's
        own, in self.wheels; pip is asked only when the wheels there do not satisfy them.
        """
        wanted = ["pip", *requirements]
        marker = self.wheels / "requirements.txt"
        self.cache.mkdir(parents=True, exist_ok=True)
        # Tests on other workers may download into the same folder at the same time.
        with FileLock(self.cache / "wheels.lock"):
            self._download_missing(wanted, marker)
        return self.wheels

    def _download_missing(self, wanted: list[str], marker: Path) -> None:
        have = set(marker.read_text().splitlines()) if marker.is_file() else set()
        if not set(wanted) <= have:
            self.wheels.mkdir(parents=True, exist_ok=True)
            platforms = [option for tag in PLATFORM_TAGS for option in ("--platform", tag)]
            _run(
                [
                    sys.executable,
                    "-m",
                    "pip",
                    "download",
                    "--quiet",
                    "--only-binary=:all:",
                    "--implementation",
                    "cp",
                    "--python-version",
                    PYTHON_VERSION,
                    *platforms,
                    "--dest",
                    self.wheels,
                    *wanted,
                ],
                "pip download of the aarch64 wheels",
            )
            marker.write_text("\n".join(sorted(have | set(wanted))) + "\n")

    def command(self, arguments) -> list[str]:
        return ["qemu-aarch64", "-L", str(self.sysroot), str(self.python), *map(str, arguments)]

    def run(self, arguments, *, cwd: Path, site: Path | None = None, timeout: float = 600):
        """Run this Python with arguments in cwd, site on its path; CompletedProcess (text)."""
        environment = {**CLEAN_ENVIRONMENT, **({"PYTHONPATH": str(site)} if site else {})}
        return subprocess.run(
            self.command(arguments), cwd=cwd, env=environment, capture_output=True, text=True, timeout=timeout
        )

    def install(self, wanted: list, site: Path) -> Path:
        """pip, run under qemu, installs wanted (wheel files and requirement strings) and what they
        need into site (--target), from the cached aarch64 wheels only: the arm64 interpreter
        itself judges each wheel's tag.
        """
        self.download(
            [
                requirement
                for item in wanted
                for requirement in (requirements_of(item) if isinstance(item, Path) else [item])
            ]
        )
        pip = max(self.wheels.glob("pip-*.whl"))
        result = self.run(
            [
                f"{pip}/pip",
                "install",
                "--no-index",
                "--find-links",
                self.wheels,
                "--no-compile",
                "--no-cache-dir",
                "--target",
                site,
                *wanted,
            ],
            cwd=self.cache,
        )
        if result.returncode != 0:
            raise AssertionError(
                f"pip under qemu-aarch64 exited {result.returncode}:\n{result.stdout}\n{result.stderr}"
            )
        return site
