"""Files that appear whole or not at all, locally and on fsspec file systems."""

import fsspec
import pytest

from pendulum_fmu.atomic_files import replacing, replacing_on
from pendulum_fmu.errors import CannotWrite, PendulumFmuError


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
    with pytest.raises(CannotWrite, match="notes.txt is a file, not a folder; choose another output path"):
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
