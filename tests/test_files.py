"""files.py: an output path nothing can be written to is refused before the work, naming the
user's path, and the check leaves nothing behind."""

import os
import sys

import pytest

from pendulum_fmu.files import NotWritable, check_writable, replacing

# A folder that exists and in which nothing can be created, whoever runs the tests (root too).
UNWRITABLE = "/proc/self"
needs_proc = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs Linux's /proc")


@needs_proc
@pytest.mark.parametrize("target, reason", [
    (f"{UNWRITABLE}/out.csv", f"no file can be created in {UNWRITABLE}"),
    (f"{UNWRITABLE}/study/out.csv", f"the folder {UNWRITABLE}/study cannot be created"),
])
def test_an_unwritable_target_is_refused_with_the_users_path(target, reason):
    for attempt in (lambda: check_writable(target), lambda: replacing(target).__enter__()):
        with pytest.raises(NotWritable) as refused:
            attempt()
        message = str(refused.value)
        assert message.startswith(f"cannot write {target}: {reason}") and "partial" not in message


def test_a_folder_is_refused_as_a_target(tmp_path):
    with pytest.raises(NotWritable, match=f"cannot write {tmp_path}: it is a folder"):
        check_writable(tmp_path)


def test_the_check_leaves_nothing_behind(tmp_path):
    check_writable(tmp_path / "out.csv", tmp_path / "new" / "deeper" / "out.png")
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "kept.csv").write_text("a finished result")
    check_writable(tmp_path / "kept.csv")
    assert os.listdir(tmp_path) == ["kept.csv"] and (tmp_path / "kept.csv").read_text() == "a finished result"

