"""The same bytes from the same commit, and `pendulum-fmu verify` on what a receiver may be sent:
our FMU, a tampered copy (a binary's byte, a reference), a signed one under the right and a wrong
key, a scenario kit's FMU whose references replay, and an FMU another tool made.

The checksums are checked against hashlib's of the bytes the test reads itself; the rebuild
against the binary the build put into the FMU.
"""

import hashlib
import json
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey

from pendulum_fmu.cli import main

ROOT = Path(__file__).resolve().parent.parent
RECORD = "extra/org.pendulum-fmu.build/build.json"


def _entries(fmu):
    with zipfile.ZipFile(fmu) as archive:
        return {item.filename: archive.read(item) for item in archive.infolist()}


def _changed(fmu, out, name, change):
    """A copy of fmu with entry name's bytes passed through change, the rest as they were."""
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(out, "w") as copy:
        for item in source.infolist():
            data = source.read(item)
            copy.writestr(item, change(data) if item.filename == name else data)
    return out


def _verified(capsys, *arguments):
    status = main(["verify", *map(str, arguments), "--json"])
    return status, {check["name"]: check for check in json.loads(capsys.readouterr().out)["checks"]}


@pytest.mark.build
@pytest.mark.skipif(not (ROOT / ".git").exists(), reason="clones the checkout's commit, which needs git")
def test_two_clones_of_one_commit_build_byte_identical_fmus(tmp_path):
    built = []
    for name in ("first", "second"):
        clone = tmp_path / name / "pendulum"  # at different depths, so no path can hide in a binary
        subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
        script = "from fmu_build import build_fmu; build_fmu('Pendulum.fmu'); build_fmu('Pendulum3.fmu', fmi_version=3)"
        subprocess.run([sys.executable, "-c", script], cwd=clone, check=True, capture_output=True)
        built.append([(clone / file).read_bytes() for file in ("Pendulum.fmu", "Pendulum3.fmu")])
    assert built[0] == built[1]
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    record = json.loads(_entries(tmp_path / "first/pendulum/Pendulum.fmu")[RECORD])
    assert (record["commit"], record["modified"]) == (commit.strip(), False)


def test_the_record_holds_every_entrys_sha256_and_each_binarys_toolchain(fmu):
    entries = _entries(fmu)
    record = json.loads(entries[RECORD])
    assert record["entries"] == {
        name: hashlib.sha256(data).hexdigest() for name, data in entries.items() if name != RECORD
    }
    binaries = sorted(name for name in entries if name.startswith("binaries/"))
    assert sorted(record["binaries"]) == binaries
    [linux] = record["binaries"]["binaries/linux64/Pendulum.so"]
    assert linux["compiler_id"] == "GNU" and "-ffp-contract=off" in linux["compile"]
    assert sorted(linux["sources"]) == sorted(
        name[8:] for name in entries if name.startswith("sources/") and name.endswith(".c")
    )


def test_our_fmu_verifies_and_its_binary_is_what_its_sources_make(fmu, capsys):
    status, checks = _verified(capsys, fmu)
    assert status == 0
    assert {name: check["status"] for name, check in checks.items()} == {
        "checksums": "pass",
        "signature": "not checked",
        "rebuild": "pass",
        "references": "not checked",
    }
    assert checks["rebuild"]["detail"].endswith("the same bytes")


def test_a_changed_byte_of_a_binary_fails_with_the_entry_named(fmu, tmp_path, capsys):
    flip = _changed(
        fmu,
        tmp_path / "tampered.fmu",
        "binaries/linux64/Pendulum.so",
        lambda d: d[:100] + bytes([d[100] ^ 1]) + d[101:],
    )
    status, checks = _verified(capsys, flip)
    assert status == 1
    assert checks["checksums"]["detail"] == "binaries/linux64/Pendulum.so: changed since the build"
    assert checks["rebuild"]["status"] == "fail"


def test_a_signed_fmu_verifies_under_its_key_and_fails_under_another_or_when_changed(tmp_path, capsys):
    keys = {}
    for name in ("ours", "theirs"):
        key = Ed25519PrivateKey.generate()
        keys[name] = tmp_path / f"{name}.pub"
        keys[name].write_bytes(
            key.public_key().public_bytes(serialization.Encoding.PEM, serialization.PublicFormat.SubjectPublicKeyInfo)
        )
        if name == "ours":
            private = tmp_path / "ours.pem"
            private.write_bytes(
                key.private_bytes(
                    serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
                )
            )
    signed = tmp_path / "Signed.fmu"
    assert main(["export", "--output", str(signed), "--sign", str(private)]) == 0
    capsys.readouterr()
    assert _verified(capsys, signed, "--public-key", keys["ours"], "--no-rebuild")[1]["signature"]["status"] == "pass"
    status, checks = _verified(capsys, signed, "--public-key", keys["theirs"], "--no-rebuild")
    assert (status, checks["signature"]["status"]) == (1, "fail")
    # A record changed to match a changed binary: the checksums agree, the signature does not.
    record = json.loads(_entries(signed)[RECORD])
    record["entries"]["binaries/linux64/Pendulum.so"] = "0" * 64
    forged = _changed(signed, tmp_path / "forged.fmu", RECORD, lambda _: json.dumps(record).encode())
    status, checks = _verified(capsys, forged, "--public-key", keys["ours"], "--no-rebuild")
    assert (status, checks["signature"]["status"]) == (1, "fail")


def test_a_kits_references_replay_and_a_changed_reference_is_named(tmp_path, capsys):
    assert main(["scenarios", "--output-dir", str(tmp_path / "kit")]) == 0
    capsys.readouterr()
    kit_fmu = tmp_path / "kit" / "Pendulum.fmu"
    status, checks = _verified(capsys, kit_fmu, "--no-rebuild")
    assert (status, checks["checksums"]["status"], checks["references"]["status"]) == (0, "pass", "pass")
    assert checks["references"]["detail"].startswith("4 of 4 scenarios replayed in fmpy pass the judge")
    reference = "extra/org.fmi-standard.fmi-ls-ref/constant_torque_ref.csv"
    # One reference value changed after the kit was made: the checksums name the entry.
    changed = _changed(kit_fmu, tmp_path / "changed.fmu", reference, lambda d: d.replace(b"\n0.01,", b"\n0.01,1", 1))
    status, checks = _verified(capsys, changed, "--no-rebuild")
    assert status == 1
    assert checks["checksums"]["detail"] == f"{reference}: changed since the build"
    # Its binary is not loaded to replay references that its own record refuses.
    assert checks["references"] == {
        "name": "references",
        "status": "not checked",
        "detail": "not replayed: its checksums failed",
    }


def test_an_fmu_another_tool_made_says_what_it_could_not_check(tmp_path, capsys):
    builder = pytest.importorskip("pythonfmu3.builder")
    theirs = builder.FmuBuilder.build_FMU(ROOT / "tests" / "fmus" / "degrees_pendulum.py", dest=tmp_path)
    status, checks = _verified(capsys, theirs)
    assert status == 0
    assert {name: check["status"] for name, check in checks.items()} == dict.fromkeys(checks, "not checked")
    assert checks["checksums"]["detail"].startswith("no build record")


@pytest.mark.parametrize(
    ("content", "message"),
    [(b"not a zip", "not an FMU"), (None, "no such file")],
    ids=["not-a-zip", "missing"],
)
def test_what_is_not_an_fmu_is_one_line_and_exit_2(tmp_path, capsys, content, message):
    path = tmp_path / "x.fmu"
    if content is not None:
        path.write_bytes(content)
    assert main(["verify", str(path)]) == 2
    [line] = capsys.readouterr().err.strip().splitlines()
    assert message in line


def test_the_kit_fmu_is_written_with_the_time_its_record_gives(tmp_path, capsys):
    assert main(["scenarios", "--output-dir", str(tmp_path)]) == 0
    record = json.loads(_entries(tmp_path / "Pendulum.fmu")[RECORD])
    with zipfile.ZipFile(tmp_path / "Pendulum.fmu") as archive:
        times = {item.date_time for item in archive.infolist()}
    *day, seconds = time.gmtime(max(record["source_date_epoch"], 315532800))[:6]
    assert times == {(*day, seconds // 2 * 2)}  # a zip entry's time counts seconds in twos


def _with_result(fmu, out, rows):
    """A copy of fmu as another tool would make it, without our build record, carrying an
    FMI-LS-REF manifest that names one result CSV of the default experiment, as the Modelica
    Reference FMUs carry theirs (BouncingBall: BouncingBall_out.csv, role "result").
    """
    folder = "extra/org.fmi-standard.fmi-ls-ref/"
    manifest = (
        '<fmiReferences xmlns:fmi-ls="http://fmi-standard.org/fmi-ls-manifest" fmi-ls:fmi-ls-name='
        '"org.fmi-standard.fmi-ls-ref" fmi-ls:fmi-ls-version="1.0.0-alpha.1"><Related type="text/csv" '
        'source="Pendulum_out.csv" role="result" description="Output of the default experiment"/></fmiReferences>'
    )
    csv = "time,theta\n" + "".join(f"{t!r},{theta!r}\n" for t, theta in rows)
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(out, "w") as copy:
        for item in source.infolist():
            if item.filename != RECORD:
                copy.writestr(item, source.read(item))
        copy.writestr(folder + "fmi-ls-manifest.xml", manifest)
        copy.writestr(folder + "Pendulum_out.csv", csv)
    return out


def test_a_result_an_fmu_carries_is_replayed_from_its_default_experiment(fmu, tmp_path, capsys):
    # The default experiment (3 s, no torque, at rest) keeps theta at 0: the analytic solution.
    grid = [k * 0.01 for k in range(301)]
    carried = _with_result(fmu, tmp_path / "carried.fmu", [(t, 0.0) for t in grid])
    checks = _verified(capsys, carried, "--no-rebuild")[1]
    assert checks["references"]["status"] == "pass"
    assert checks["references"]["detail"].startswith("1 result(s) replayed in fmpy (the default experiment)")
    assert checks["checksums"]["status"] == "not checked"
    wrong = _with_result(fmu, tmp_path / "wrong.fmu", [(t, 0.5 if t == 1.0 else 0.0) for t in grid])
    checks = _verified(capsys, wrong, "--no-rebuild")[1]
    assert checks["references"]["status"] == "fail"
    assert "largest difference 0.5 (Pendulum_out.csv, theta)" in checks["references"]["detail"]


@pytest.mark.parametrize(
    ("change", "refused"),
    [
        ({"compiler": ["sh", "-c", "touch {marker}"]}, "the compiler 'sh'"),
        ({"compiler": ["/usr/bin/cc"]}, "the compiler '/usr/bin/cc'"),
        ({"compile": ["-O3", "-wrapper", "sh,-c,touch {marker}"]}, "the argument '-wrapper'"),
        ({"compile": ["-fplugin=/tmp/plugin.so"]}, "the argument '-fplugin=/tmp/plugin.so'"),
        ({"link": ["@{marker}"]}, "the argument '@"),
        ({"sources": ["../../../x.c"]}, "the source '../../../x.c'"),
        ({"compiler": "cc"}, "commands no build of this package records"),
    ],
)
def test_a_build_record_cannot_make_the_rebuild_run_another_program(change, refused, fmu, tmp_path, capsys):
    # Issue 38: the record is the FMU author's; before, `verify` ran its compiler command as given.
    marker = tmp_path / "ran"
    linux = "binaries/linux64/Pendulum.so"

    def crafted(data):
        record = json.loads(data)
        [made] = record["binaries"][linux]
        made.update(json.loads(json.dumps(change).replace("{marker}", str(marker))))
        return json.dumps(record).encode()

    status, checks = _verified(capsys, _changed(fmu, tmp_path / "crafted.fmu", RECORD, crafted))
    assert status == 1
    assert checks["rebuild"]["status"] == "fail"
    assert checks["rebuild"]["detail"].startswith(f"{linux}: its record asks the rebuild to run {refused}")
    assert not marker.exists()


def test_a_kits_reference_naming_a_file_elsewhere_is_refused_before_anything_is_replayed(tmp_path, capsys):
    # Issue 38: before, the replay wrote its result over the file a reference's "output" named.
    assert main(["scenarios", "--output-dir", str(tmp_path / "kit")]) == 0
    capsys.readouterr()
    precious = tmp_path / "precious.txt"
    precious.write_text("mine\n")
    name = "extra/org.fmi-standard.fmi-ls-ref/constant_torque.json"

    def elsewhere(data):
        return json.dumps({**json.loads(data), "output": str(precious)}).encode()

    changed = _changed(tmp_path / "kit" / "Pendulum.fmu", tmp_path / "changed.fmu", name, elsewhere)
    # Its author made the record agree (nothing signs it), so the checksums pass and the replay runs.
    record = json.loads(_entries(changed)[RECORD])
    record["entries"][name] = hashlib.sha256(_entries(changed)[name]).hexdigest()
    crafted = _changed(changed, tmp_path / "crafted.fmu", RECORD, lambda _: json.dumps(record).encode())
    assert main(["verify", str(crafted), "--no-rebuild"]) == 2
    [line] = capsys.readouterr().err.strip().splitlines()
    # The value quoted is cut to its first 80 characters, which a long temporary path passes.
    assert line.startswith(f"pendulum-fmu verify: error: {crafted}'s {name}: output is \"/")
    assert "it must be the name of a file in the kit's folder" in line
    assert precious.read_text() == "mine\n"


@pytest.mark.build
def test_the_wheels_zig_built_binary_is_rebuilt_from_its_sources_too(tmp_path, capsys):
    # The wheels carry Linux binaries zig builds for glibc 2.17: verify rebuilds them with zig from PyPI.
    pytest.importorskip("ziglang")
    from fmu_build import build_fmu

    built = build_fmu(tmp_path / "Pendulum.fmu", platforms=("linux64",), linux_glibc="2.17")
    status, checks = _verified(capsys, built)
    assert (status, checks["rebuild"]["status"]) == (0, "pass")
    assert "with Clang" in checks["rebuild"]["detail"]
