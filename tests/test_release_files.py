"""The sdist and the wheel are the same bytes from one commit: built in two fresh clones, in folders
of different depths, minutes apart, under different umasks, one wheel from the sdist and one from
the clone (the packaging test); and the parts that make it so, on their own: the sdist's tarball
(fmu_build/release_files.py) and the commit and time an sdist carries in place of .git
(fmu_build/build_record.py).
"""

import gzip
import io
import json
import os
import subprocess
import sys
import tarfile
import time
import zipfile
from pathlib import Path

import pytest
from elftools.elf.elffile import ELFFile

from fmu_build import build_fmu, build_record, find_zig
from fmu_build.release_files import normalize_modes, write_tarball
from pendulum_fmu.fmu._build_record import RECORD_FILE
from tests.test_platforms import _path_without_cross_gccs

ROOT = Path(__file__).resolve().parent.parent
EPOCH = 1_700_000_000  # 2023-11-14 22:13:20 UTC
# In a clean environment: no PYTHONPATH pointing back at the checkout, no date given.
ENVIRONMENT = {name: value for name, value in os.environ.items() if name not in ("PYTHONPATH", "SOURCE_DATE_EPOCH")}


def _tree(folder: Path, order: list[str], umask_mode: int, when: float) -> Path:
    """A tree of the same files, made in the given order, with the given permissions and time."""
    top = folder / "pendulum_fmu-0.1.0"
    contents = {"setup.py": b"setup()\n", "src/a.c": b"int a;\n", "src/a.b": b"x", ".ci/run": b"#!/bin/sh\n"}
    for name in order:
        path = top / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(contents[name])
        path.chmod(0o775 if name == ".ci/run" else umask_mode)
        os.utime(path, (when, when))
    return top


def test_two_trees_of_the_same_files_give_the_same_tarball_bytes(tmp_path):
    names = ["setup.py", "src/a.c", "src/a.b", ".ci/run"]
    first = _tree(tmp_path / "one", names, 0o644, time.time())
    second = _tree(tmp_path / "two" / "deeper", names[::-1], 0o664, 1e9)
    write_tarball(tmp_path / "one.tar.gz", first, EPOCH)
    write_tarball(tmp_path / "two.tar.gz", second, EPOCH)
    data = (tmp_path / "one.tar.gz").read_bytes()
    assert data == (tmp_path / "two.tar.gz").read_bytes()
    # gzip's header (RFC 1952): flags 0 (no file name), the time, little-endian.
    assert data[3] == 0 and int.from_bytes(data[4:8], "little") == EPOCH
    with tarfile.open(fileobj=io.BytesIO(gzip.decompress(data))) as tar:
        members = tar.getmembers()
    assert [member.name for member in members] == [
        "pendulum_fmu-0.1.0",
        "pendulum_fmu-0.1.0/.ci",
        "pendulum_fmu-0.1.0/.ci/run",
        "pendulum_fmu-0.1.0/setup.py",
        "pendulum_fmu-0.1.0/src",
        "pendulum_fmu-0.1.0/src/a.b",
        "pendulum_fmu-0.1.0/src/a.c",
    ]
    assert {(m.mtime, m.uid, m.gid, m.uname, m.gname) for m in members} == {(EPOCH, 0, 0, "", "")}
    assert {m.name.split("/", 1)[-1]: m.mode for m in members if m.isfile()} == {
        ".ci/run": 0o755,
        "setup.py": 0o644,
        "src/a.b": 0o644,
        "src/a.c": 0o644,
    }


def test_normalize_modes_keeps_only_whether_a_file_may_be_run(tmp_path):
    for name, mode in (("group_writable", 0o664), ("private", 0o600), ("script", 0o744)):
        (tmp_path / name).write_text(name)
        (tmp_path / name).chmod(mode)
    normalize_modes(tmp_path)
    modes = {path.name: path.stat().st_mode & 0o777 for path in tmp_path.iterdir()}
    assert modes == {"group_writable": 0o644, "private": 0o644, "script": 0o755}


def test_an_unpacked_sdist_gives_the_commit_and_time_it_records(tmp_path, monkeypatch):
    monkeypatch.setattr(build_record, "ROOT", tmp_path)  # no .git: an unpacked sdist
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    assert build_record.source_commit() == {"commit": None, "modified": False}
    assert build_record.source_date_epoch() == 315532800  # 1980-01-01, zip's first date
    recorded = {"commit": "0123abcd" * 5, "modified": True, "source_date_epoch": EPOCH}
    (tmp_path / build_record.SOURCE_RECORD_FILE).write_text(json.dumps(recorded))
    assert build_record.source_commit() == {"commit": "0123abcd" * 5, "modified": True}
    assert build_record.source_record() == recorded
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1234567890")  # a date given wins over the record
    assert build_record.source_date_epoch() == 1234567890


@pytest.mark.skipif(find_zig() is None, reason="needs zig (pip install ziglang)")
def test_zigs_linux_binaries_name_no_folder_of_the_build(tmp_path):
    # zig links its glibc stubs in with their DWARF, naming zig's folder and the build's: a
    # build in a fresh environment (pip's isolated one, another clone) gave other bytes.
    fmu = build_fmu(tmp_path / "Pendulum.fmu", platforms=("linux64", "aarch64-linux"), linux_glibc="2.17")
    zig_folder = str(Path(find_zig()).resolve().parent).encode()
    with zipfile.ZipFile(fmu) as archive:
        record = json.loads(archive.read(RECORD_FILE))
        for name in ("binaries/linux64/Pendulum.so", "binaries/aarch64-linux/Pendulum.so"):
            binary = archive.read(name)
            sections = [section.name for section in ELFFile(io.BytesIO(binary)).iter_sections()]
            assert not [section for section in sections if section.startswith(".debug")], name
            assert b"/tmp/" not in binary and zig_folder not in binary and str(ROOT).encode() not in binary
            [made] = record["binaries"][name]
            assert [flag for flag in made["link"] if "/" in flag] == [], name


@pytest.mark.skipif(find_zig() is None, reason="needs zig (pip install ziglang)")
def test_zigs_windows_dll_is_the_same_bytes_built_twice(tmp_path, monkeypatch):
    # Where the mingw gcc is missing zig builds win64, and its linker writes the link time into
    # the PE header unless given -Brepro (it refuses GNU ld's --no-insert-timestamp).
    monkeypatch.setenv("PATH", _path_without_cross_gccs(tmp_path / "bin"))
    built = []
    for name in ("first", "second"):
        fmu = build_fmu(tmp_path / name / "Pendulum.fmu", platforms=("win64",))
        with zipfile.ZipFile(fmu) as archive:
            built.append(archive.read("binaries/win64/Pendulum.dll"))
            [made] = json.loads(archive.read(RECORD_FILE))["binaries"]["binaries/win64/Pendulum.dll"]
        assert made["compiler"][0] == "zig" and "-Brepro" in made["link"]
        time.sleep(2)  # a PE header's time counts seconds
    assert built[0] == built[1]


def _run(command: list, cwd: Path, umask: int) -> None:
    done = subprocess.run(
        [str(part) for part in command], cwd=cwd, env=ENVIRONMENT, capture_output=True, text=True, umask=umask
    )
    assert done.returncode == 0, f"{' '.join(map(str, command))}:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"


@pytest.mark.packaging
@pytest.mark.skipif(not (ROOT / ".git").exists(), reason="clones the checkout's commit, which needs git")
def test_two_clones_of_one_commit_build_byte_identical_sdists_and_wheels(tmp_path):
    built = {}
    # The first builds the sdist and the wheel from it (as pip installs an sdist), the second
    # the wheel from its clone, deeper, under another umask.
    for name, umask, builds in (
        ("first", 0o022, [[]]),
        ("second/deeper", 0o002, [["--sdist"], ["--wheel"]]),
    ):
        clone, out = tmp_path / name / "pendulum", tmp_path / name / "dist"
        _run(["git", "clone", "-q", ROOT, clone], tmp_path, umask)
        for options in builds:
            _run([sys.executable, "-m", "build", *options, "--outdir", out, "."], clone, umask)
        [wheel], [sdist] = out.glob("*.whl"), out.glob("*.tar.gz")
        built[name] = (sdist.name, sdist.read_bytes(), wheel.name, wheel.read_bytes())
    first, second = built.values()
    assert first[0] == second[0] and first[1] == second[1], "the sdists differ"
    assert first[2] == second[2] and first[3] == second[3], "the wheels differ"

    # Dated by the commit (zip keeps even seconds), and the wheel built from the sdist knows it.
    commit, seconds = subprocess.run(
        ["git", "-C", str(ROOT), "log", "-1", "--format=%H %ct"], capture_output=True, text=True, check=True
    ).stdout.split()
    with tarfile.open(fileobj=io.BytesIO(first[1])) as tar:
        assert {member.mtime for member in tar.getmembers()} == {int(seconds)}
    with zipfile.ZipFile(io.BytesIO(first[3])) as wheel:
        assert {entry.date_time for entry in wheel.infolist()} == {time.gmtime(int(seconds) // 2 * 2)[:6]}
        with zipfile.ZipFile(io.BytesIO(wheel.read("pendulum_fmu/data/Pendulum.fmu"))) as fmu:
            record = json.loads(fmu.read(RECORD_FILE))
    assert (record["commit"], record["modified"], record["source_date_epoch"]) == (commit, False, int(seconds))
