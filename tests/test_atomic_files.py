"""Files that appear whole or not at all, locally and on fsspec file systems; an output path
nothing can be written to is refused before the work, naming the user's path.
"""

import os
import subprocess
import sys

import fsspec
import pytest
from fsspec.implementations.local import LocalFileSystem

from pendulum_fmu._atomic_files import LocalFolders, check_writable, replacing, replacing_on
from pendulum_fmu._errors import CannotWrite, PendulumFmuError


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "out.csv"
    target.write_text("old\n")
    with pytest.raises(RuntimeError), replacing(target) as file:
        file.write("half")
        raise RuntimeError("interrupted")
    assert target.read_text() == "old\n" and [p.name for p in tmp_path.iterdir()] == ["out.csv"]
    with replacing(target) as file:
        file.write("new\n")
    assert target.read_text() == "new\n" and [p.name for p in tmp_path.iterdir()] == ["out.csv"]


def test_a_place_that_cannot_hold_the_file_is_the_users_error_in_one_line(tmp_path):
    (tmp_path / "notes.txt").write_text("a file, not a folder\n")
    with pytest.raises(CannotWrite, match=r"notes\.txt is a file, not a folder; choose another output path"):
        with replacing(tmp_path / "notes.txt" / "out.csv") as file:
            file.write("x")
    (tmp_path / "folder").mkdir()
    with pytest.raises(CannotWrite, match=r"cannot write .*folder: Is a directory") as refused:
        with replacing(tmp_path / "folder") as file:  # a folder where the file would go
            file.write("x")
    assert isinstance(refused.value, PendulumFmuError) and "\n" not in str(refused.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder", "notes.txt"]


def test_an_error_about_another_file_goes_on_as_it_is(tmp_path):
    with pytest.raises(FileNotFoundError) as raised, replacing(tmp_path / "copy.bin", "wb") as file:
        file.write((tmp_path / "absent.bin").read_bytes())
    assert not isinstance(raised.value, PendulumFmuError) and list(tmp_path.iterdir()) == []


def test_a_failed_write_to_a_url_leaves_neither_file_nor_temporary():
    filesystem = fsspec.filesystem("memory")
    with replacing_on(filesystem, "/writes/kept.bin") as file:
        file.write(b"whole")
    with pytest.raises(RuntimeError), replacing_on(filesystem, "/writes/lost.bin") as file:
        file.write(b"half")
        raise RuntimeError("interrupted")
    assert filesystem.find("/writes") == ["/writes/kept.bin"]
    assert filesystem.cat("/writes/kept.bin") == b"whole"


def _a_store_s_calls(filesystem, folder) -> list:
    """What a sweep's store asks of a file system, in a folder of a study's kinds of entries
    (parts, staged parts, temporaries, a hidden folder, a link to nothing), and what it got.
    """
    for name in ("cases", "trajectories", ".overwrite.1.partial"):
        filesystem.makedirs(f"{folder}/{name}", exist_ok=True)
    names = ["cases/part-000001.parquet", "cases/part-000000.parquet", "cases/_part-000002.run.staged"]
    names += ["cases/.part-000003.parquet.4.partial.parquet", ".study.json.5.partial", "cases/notes.txt"]
    for name in names:
        with replacing_on(filesystem, f"{folder}/{name}") as file:
            file.write(name.encode())
    os.symlink(f"{folder}/nowhere", f"{folder}/cases/part-000009.parquet")
    patterns = [".*.partial*", "cases/.*.partial*", "cases/_part-*.staged", "cases/part-*.parquet", "none/*"]
    got: list = [sorted(filesystem.glob(f"{folder}/{pattern}")) for pattern in patterns]
    got += [filesystem.exists(f"{folder}/{name}") for name in ("cases", "cases/part-000009.parquet", "none")]
    filesystem.mv(f"{folder}/cases/_part-000002.run.staged", f"{folder}/cases/part-000002.parquet")
    filesystem.mv(f"{folder}/.overwrite.1.partial", f"{folder}/moved", recursive=True)
    for path, recursive in (("cases", False), ("none", True), ("moved", True), ("cases/notes.txt", False)):
        try:
            filesystem.rm(f"{folder}/{path}", recursive=recursive)
        except (ValueError, FileNotFoundError) as error:
            got.append(type(error).__name__)
    with filesystem.open(f"{folder}/cases/part-000002.parquet", "r") as file:
        got.append(file.read())
    got.append(sorted(str(path.relative_to(folder)) for path in folder.rglob("*")))
    # The paths relative to the folder, so that two folders' answers compare.
    return [[str(item).removeprefix(f"{folder}/") for item in each] if isinstance(each, list) else each for each in got]


def test_the_local_folders_answer_a_store_as_fsspec_s_local_file_system_does(tmp_path):
    (tmp_path / "fsspec").mkdir()
    (tmp_path / "ours").mkdir()
    ours = _a_store_s_calls(LocalFolders(), tmp_path / "ours")
    assert ours == _a_store_s_calls(LocalFileSystem(), tmp_path / "fsspec")
    assert ours[3] == ["cases/part-000000.parquet", "cases/part-000001.parquet", "cases/part-000009.parquet"]


# A folder that exists and in which nothing can be created, whoever runs the tests (root too).
UNWRITABLE = "/proc/self"
needs_proc = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs Linux's /proc")


@needs_proc
@pytest.mark.parametrize(
    "target, reason",
    [
        (f"{UNWRITABLE}/out.csv", f"no file can be created in {UNWRITABLE}"),
        (f"{UNWRITABLE}/study/out.csv", f"the folder {UNWRITABLE}/study cannot be created"),
    ],
)
def test_an_unwritable_target_is_refused_with_the_users_path(target, reason):
    for attempt in (lambda: check_writable(target), lambda: replacing(target).__enter__()):
        with pytest.raises(CannotWrite) as refused:
            attempt()
        message = str(refused.value)
        assert message.startswith(f"cannot write {target}: {reason}") and "partial" not in message


def test_a_folder_is_refused_as_a_target(tmp_path):
    with pytest.raises(CannotWrite, match=f"cannot write {tmp_path}: it is a folder"):
        check_writable(tmp_path)


def test_the_check_leaves_nothing_behind(tmp_path):
    check_writable(tmp_path / "out.csv", tmp_path / "new" / "deeper" / "out.png")
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "kept.csv").write_text("a finished result")
    check_writable(tmp_path / "kept.csv")
    assert os.listdir(tmp_path) == ["kept.csv"] and (tmp_path / "kept.csv").read_text() == "a finished result"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are POSIX")
def test_a_named_pipe_is_written_into_and_stays_a_pipe(tmp_path):
    # Renaming a temporary over it would replace it with a regular file (as it did /dev/null).
    import stat
    import threading

    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    received = []
    reader = threading.Thread(target=lambda: received.append(pipe.read_text()))
    reader.start()
    check_writable(pipe)
    with replacing(pipe) as file:
        file.write("time,theta\n0,0\n")
    reader.join(timeout=10)
    assert received == ["time,theta\n0,0\n"] and stat.S_ISFIFO(os.stat(pipe).st_mode)
    assert [p.name for p in tmp_path.iterdir()] == ["pipe"]


@pytest.mark.skipif(sys.platform == "win32", reason="symbolic links need privileges on Windows")
def test_an_output_is_never_written_through_a_link(tmp_path):
    # Before, a link named as an output had the file it leads to replaced: `judge --plot j.png`
    # with j.png a link to /etc/passwd, run as root, wrote a PNG over it.
    (tmp_path / "results").mkdir()
    real = tmp_path / "results" / "run.csv"
    real.write_text("old\n")
    link = tmp_path / "latest.csv"
    link.symlink_to(real)
    dangling = tmp_path / "next.csv"
    dangling.symlink_to(tmp_path / "results" / "next_run.csv")
    for named in (link, dangling):
        with pytest.raises(CannotWrite, match=f"cannot write {named}: it is a symbolic link .*never written through"):
            check_writable(named)
        with pytest.raises(CannotWrite, match="it is a symbolic link"), replacing(named) as file:
            file.write("new\n")
    assert real.read_text() == "old\n" and not (tmp_path / "results" / "next_run.csv").exists()
    assert link.is_symlink() and dangling.is_symlink()
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["latest.csv", "next.csv", "results", "run.csv"]


def test_the_command_refuses_a_link_as_its_output_and_leaves_what_it_leads_to(tmp_path):
    settings = tmp_path / "bashrc"
    settings.write_text("echo my settings\n")
    (tmp_path / "out.png").symlink_to(settings)
    done = subprocess.run(
        [sys.executable, "-m", "pendulum_fmu", "simulate", "--torque", "1", "--stop-time", "0.01", "--plot", "out.png"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert "out.png: it is a symbolic link" in done.stderr
    assert settings.read_text() == "echo my settings\n"


def test_a_name_as_long_as_the_file_system_allows_is_written_and_a_longer_one_refused(tmp_path):
    longest = tmp_path / ("a" * 251 + ".csv")  # 255 bytes: the temporary's name must be shorter
    check_writable(longest)
    with replacing(longest) as file:
        file.write("x\n")
    assert longest.read_text() == "x\n" and [p.name for p in tmp_path.iterdir()] == [longest.name]
    with pytest.raises(CannotWrite, match=r"cannot write .*a\.csv: .*; choose"):
        check_writable(tmp_path / ("a" * 300 + ".csv"))
