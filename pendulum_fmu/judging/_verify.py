"""Whether a received FMU is what its record says: `pendulum-fmu verify FMU`.

Four checks, each named in the answer, each passing, failing or saying why it could not run:

- checksums: every entry matches the SHA-256 its build record gives (_build_record.py), none
  added, none missing;
- signature: the record's Ed25519 signature (``export --sign``) under the key given;
- rebuild: the binary for this machine, made again from the FMU's own sources/ with the
  recorded compiler, flags and link order, is the same bytes (where that compiler, at the
  recorded version, is here);
- references: the FMI-LS-REF references the FMU carries (a scenario kit's, `pendulum-fmu
  scenarios`), replayed in fmpy and judged.
"""

from __future__ import annotations

import json
import os
import platform
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import zipfile
from dataclasses import asdict, dataclass
from pathlib import Path
from xml.etree import ElementTree

from .._errors import InvalidInput, MissingFile
from .._received_files import check_xml, open_fmu
from ..fmu._build_record import OBJECTS, RECORD_FILE, SIGNATURE_FILE, read_entries, sha256

PASS, FAIL, SKIP = "pass", "fail", "not checked"
LS_REF_MANIFEST = "extra/org.fmi-standard.fmi-ls-ref/fmi-ls-manifest.xml"
# How far fmpy's run of an FMU's default experiment may lie from a result it carries, as a share
# of each column's range (at least 1): a replay on the result's own grid differs by rounding only
# (a Modelica Reference FMU: 5e-13), a changed model by far more.
RESULT_TOLERANCE = 1e-6
# What the rebuild runs from a build record, which is the FMU author's word: the compilers and the
# shapes of the arguments fmu_build records for a Linux binary. A compiler named by a path, or an
# argument that loads or runs another program (-fplugin=, -wrapper, -B, -specs=, @FILE), would
# run the author's code here; the rebuild refuses the record instead (issue 38).
REBUILD_COMPILERS = frozenset({"cc", "gcc", "clang", "zig", "aarch64-linux-gnu-gcc", "x86_64-linux-gnu-gcc"})
REBUILD_ARGUMENT = re.compile(
    r"-D\w+|-O[0-3s]|-std=c\d\d|-W(?:all|extra|error)|-f(?:PIC|pic|lto=auto|no-fat-lto-objects|visibility=hidden"
    r"|fp-contract=off)|-shared|-s|-l[a-z]+|-static-libgcc|-Wl,-soname,[\w.-]+|-Wl,--version-script=exports\.map"
    r"|-target|-g0|-Xlinker|--version-script=exports\.map|--strip-debug|" + re.escape(OBJECTS)
)
# What follows -target (zig cc -target x86_64-linux-gnu.2.17), and a source's file name.
REBUILD_WORD = re.compile(r"[\w.-]+")
REBUILD_SOURCE = re.compile(r"[\w-]+\.c")
# FMI-LS-WASM's folder of the WebAssembly component, which no machine's folders hold.
WASM_BINARIES = "binaries/wasm32-wasip2/"
# This machine's binary folders, FMI 2.0's and FMI 3.0's.
HOST_FOLDERS = {
    ("linux", "x86_64"): ("linux64", "x86_64-linux"),
    ("linux", "aarch64"): ("aarch64-linux", "aarch64-linux"),
}


@dataclass(frozen=True)
class Check:
    """One check of a received FMU.

    Parameters
    ----------
    name : str
        checksums, signature, rebuild or references.
    status : str
        ``pass``, ``fail`` or ``not checked`` (with why in detail).
    detail : str
        What was found, naming the entry where one is at fault.
    """

    name: str
    status: str
    detail: str


def _checksums(entries: dict[str, bytes], record: dict | None) -> Check:
    if record is None:
        return Check("checksums", SKIP, f"no build record ({RECORD_FILE}): nothing to check the entries against")
    recorded = record.get("entries", {})
    carried = {name: data for name, data in entries.items() if name not in (RECORD_FILE, SIGNATURE_FILE)}
    problems = [
        f"{name}: changed since the build"
        for name in carried
        if name in recorded and sha256(carried[name]) != recorded[name]
    ]
    problems += [f"{name}: not in the record (added after the build)" for name in carried if name not in recorded]
    problems += [f"{name}: in the record, missing" for name in recorded if name not in carried]
    if problems:
        return Check("checksums", FAIL, "; ".join(problems))
    return Check("checksums", PASS, f"{len(recorded)} entries match their recorded SHA-256")


def _signature(entries: dict[str, bytes], public_key: str | os.PathLike | None) -> Check:
    if public_key is None:
        signed = SIGNATURE_FILE in entries
        return Check("signature", SKIP, "signed: give --public-key to check it" if signed else "not signed")
    if SIGNATURE_FILE not in entries or RECORD_FILE not in entries:
        return Check("signature", FAIL, f"not signed ({SIGNATURE_FILE} missing)")
    from cryptography.exceptions import InvalidSignature

    from ..fmu._signing import load_public_key

    try:
        load_public_key(public_key).verify(entries[SIGNATURE_FILE], entries[RECORD_FILE])
    except InvalidSignature:
        return Check("signature", FAIL, f"{RECORD_FILE}: its signature does not match under {public_key}")
    return Check("signature", PASS, f"{RECORD_FILE} signed by the key {public_key}")


def _compiler_version(command: list[str], compiler_id: str) -> str:
    """The version the compiler reports, as CMake records it (GCC's -dumpfullversion, clang's --version)."""
    flag = ["-dumpfullversion"] if compiler_id == "GNU" else ["--version"]
    try:
        done = subprocess.run([*command, *flag], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    return done.stdout.strip()


def _rebuild_commands(made: dict, compiler: list[str], sources: Path, headers: Path, out: Path) -> list[list[str]]:
    objects = [str(out / f"{source}.o") for source in made["sources"]]
    # A dependency file, as CMake's Makefiles ask for one (compile_commands.json leaves it out):
    # zig's driver compiles another way without (no .llvm_addrsig), to other bytes.
    flags = [*compiler, *made["compile"], f"-I{sources}", f"-I{headers}", "-MD", "-MF"]
    compile_commands = [
        [*flags, f"{obj}.d", "-o", obj, "-c", str(sources / source)]
        for source, obj in zip(made["sources"], objects, strict=True)
    ]
    link = []
    for argument in made["link"]:
        if argument == OBJECTS:
            link.extend(objects)
        elif argument in ("-Wl,--version-script=exports.map", "--version-script=exports.map"):
            link.append(argument.replace("exports.map", str(out / "exports.map")))
        else:
            link.append(argument)
    return [*compile_commands, [*compiler, *link, "-o", str(out / "binary")]]


def _rebuilt(entries: dict[str, bytes], made: dict, compiler: list[str]) -> bytes | str:
    """The binary the recorded commands make from the FMU's sources/, or why they failed."""
    import fmpy

    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_verify_") as tmp:
        work = Path(tmp)
        sources = work / "sources"
        sources.mkdir()
        for entry, data in entries.items():
            if entry.startswith("sources/") and "/" not in entry[len("sources/") :]:
                (sources / entry[len("sources/") :]).write_bytes(data)
        if made.get("exports_map"):
            (work / "exports.map").write_text(made["exports_map"])
        for command in _rebuild_commands(made, compiler, sources, Path(fmpy.__file__).parent / "c-code", work):
            try:
                done = subprocess.run(command, capture_output=True, text=True, timeout=600)
            except (OSError, subprocess.TimeoutExpired) as error:
                return f"{shlex.join(command[:2])} ...: {error}"
            if done.returncode != 0:
                last = (done.stderr.strip().splitlines() or ["no message"])[-1]
                return f"{Path(command[-1]).name if '-c' in command else 'the link'} failed: {last}"
        return (work / "binary").read_bytes()


def _find_compiler(name: str) -> str:
    """The compiler's executable: zig from the ziglang package (pip install ziglang==VERSION) or
    PATH, any other from PATH; "" where it is not here.
    """
    if name == "zig":
        try:
            import ziglang

            bundled = Path(ziglang.__file__).parent / ("zig.exe" if os.name == "nt" else "zig")
            if bundled.is_file():
                return str(bundled)
        except ImportError:
            pass
    return shutil.which(name) or ""


def _unsafe_rebuild(made: dict, entries: dict[str, bytes]) -> str:
    """What in a binary's record of its build the rebuild will not run ('' where nothing is);
    TypeError where the record is not of the shape fmu_build writes.
    """
    commands = ("compiler", "compile", "link", "sources")
    if not all(isinstance(made[key], list) and all(isinstance(a, str) for a in made[key]) for key in commands):
        raise TypeError("the commands are lists of text")
    compiler, *options = made["compiler"]
    if compiler not in REBUILD_COMPILERS:
        return f"the compiler {compiler!r}, which no build of this package records"
    arguments = [*options, *made["compile"], *made["link"]]
    for before, argument in zip(["", *arguments], arguments, strict=False):
        allowed = REBUILD_ARGUMENT.fullmatch(argument) or (
            REBUILD_WORD.fullmatch(argument) and (before == "-target" or (before, compiler) == ("", "zig"))
        )
        if not allowed:
            return f"the argument {argument!r}, which no build of this package records"
    for source in made["sources"]:
        if not (REBUILD_SOURCE.fullmatch(source) and f"sources/{source}" in entries):
            return f"the source {source!r}, which is no C file of its sources/"
    if not all(isinstance(made[key], str) for key in ("compiler_id", "compiler_version")):
        raise TypeError("the compiler's name and version are text")
    return ""


def _rebuild(entries: dict[str, bytes], record: dict | None) -> Check:
    folders = HOST_FOLDERS.get((sys.platform, platform.machine()))
    binaries = [name for name in entries if name.startswith("binaries/") and name.split("/")[1] in (folders or ())]
    if not binaries:
        return Check("rebuild", SKIP, f"no binary for this machine ({sys.platform} {platform.machine()})")
    name = binaries[0]
    if not any(entry.startswith("sources/") for entry in entries):
        return Check("rebuild", SKIP, f"{name}: the FMU carries no sources/")
    if record is None or name not in record.get("binaries", {}):
        return Check("rebuild", SKIP, f"{name}: carries sources/ but no record of the toolchain that made it")
    try:
        [made] = record["binaries"][name]
        refused = _unsafe_rebuild(made, entries)
    except (KeyError, TypeError, ValueError):  # a record no build of this package wrote
        refused = "commands no build of this package records"
    if refused:
        return Check("rebuild", FAIL, f"{name}: its record asks the rebuild to run {refused}: not run")
    compiler = [_find_compiler(made["compiler"][0]), *made["compiler"][1:]]
    if not compiler[0]:
        return Check("rebuild", SKIP, f"{name}: its compiler {made['compiler'][0]} is not here")
    found = _compiler_version(compiler, made["compiler_id"])
    if made["compiler_version"] not in found:
        here = found.splitlines()[0] if found else "no version"
        return Check("rebuild", SKIP, f"{name}: recorded {made['compiler_id']} {made['compiler_version']}, here {here}")
    rebuilt = _rebuilt(entries, made, compiler)
    what = f"{name}: rebuilt from sources/ with {made['compiler_id']} {made['compiler_version']}"
    if isinstance(rebuilt, str):
        return Check("rebuild", FAIL, f"{what}: {rebuilt}")
    if rebuilt != entries[name]:
        return Check(
            "rebuild", FAIL, f"{what}: differs (SHA-256 {sha256(rebuilt)[:16]}, carried {sha256(entries[name])[:16]})"
        )
    # The WebAssembly component is built from sources/ plus glue generated from its WIT, which
    # sources/ does not carry (a native build of sources/ must not compile it): said, not failed.
    component = [entry for entry in entries if entry.startswith(WASM_BINARIES)]
    unchecked = f"; {component[0]} is not rebuilt (its glue is not in sources/)" if component else ""
    return Check("rebuild", PASS, f"{what}: the same bytes{unchecked}")


def _references(fmu: Path, entries: dict[str, bytes]) -> Check:
    if LS_REF_MANIFEST not in entries:
        return Check("references", SKIP, "the FMU carries no FMI-LS-REF references")
    from ..scenarios._scenarios import LS_REF_FOLDER

    kit_files = {
        name[len(LS_REF_FOLDER) :]: data
        for name, data in entries.items()
        if name.startswith(LS_REF_FOLDER) and "/" not in name[len(LS_REF_FOLDER) :]
    }
    if not any(name.endswith(".json") for name in kit_files):
        return _replay_results(fmu, entries)
    from ..scenarios._scenario_settings import KIT_FMU, read_settings
    from ._judge import judge_kit

    with tempfile.TemporaryDirectory(prefix="pendulum_fmu_verify_") as tmp:
        kit = Path(tmp)
        for name, data in kit_files.items():
            (kit / name).write_bytes(data)
        # The FMU author's settings: checked as a kit's (files in the kit's folder, numbers
        # finite, one line naming the file otherwise) before a replay writes the output they name.
        paths = {name[: -len(".json")]: kit / name for name in kit_files if name.endswith(".json")}
        for path in paths.values():
            try:
                read_settings(path)
            except InvalidInput as error:  # named as the FMU holds it, not as the folder it was put in
                raise InvalidInput(str(error).replace(f"{kit}{os.sep}", f"{fmu}'s {LS_REF_FOLDER}")) from None
        settings = {name: json.loads(path.read_text(encoding="utf-8")) for name, path in paths.items()}
        shutil.copyfile(fmu, kit / KIT_FMU)
        # fmpy can neither send input derivatives nor keep an FMU state: the held scenarios only.
        held = [name for name, s in settings.items() if not s["ramp"] and s["resume_time"] is None]
        for name in held:
            _replay(kit, settings[name])
        verdicts = judge_kit(kit)
    failed = [name for name in held if not getattr(verdicts[name], "passed", False)]
    left = sorted(set(settings) - set(held))
    detail = f"{len(held) - len(failed)} of {len(held)} scenarios replayed in fmpy pass the judge"
    detail += f" ({', '.join(left)} need input derivatives or an FMU state: not replayed)" if left else ""
    return Check("references", FAIL if failed else PASS, detail + (f"; failing: {', '.join(failed)}" if failed else ""))


def _replay_results(fmu: Path, entries: dict[str, bytes]) -> Check:
    """Each result (role "result", a CSV) of any FMU's FMI-LS-REF manifest against fmpy's run of
    the FMU's default experiment on the result's own time grid, column by column.
    """
    import io

    import numpy as np
    from fmpy import simulate_fmu

    folder = LS_REF_MANIFEST.rsplit("/", 1)[0] + "/"
    check_xml(entries[LS_REF_MANIFEST], f"{fmu}'s {LS_REF_MANIFEST}", InvalidInput)
    manifest = ElementTree.fromstring(entries[LS_REF_MANIFEST])
    results = [e.get("source", "") for e in manifest.iter() if e.tag.endswith("Related") and e.get("role") == "result"]
    results = [source for source in results if source.endswith(".csv") and folder + source in entries]
    if not results:
        return Check("references", SKIP, "FMI-LS-REF references, none a CSV result: not replayed")
    worst = []
    for source in results:
        reference = np.genfromtxt(io.BytesIO(entries[folder + source]), delimiter=",", names=True, deletechars="")
        times, columns = reference["time"], reference.dtype.names or ()
        run = simulate_fmu(
            str(fmu), start_time=times[0], stop_time=times[-1], output_interval=float(np.median(np.diff(times)))
        )
        for column in columns[1:]:
            if column in run.dtype.names:
                difference = np.max(np.abs(np.interp(times, run["time"], run[column]) - reference[column]))
                worst.append((difference / max(1.0, float(np.ptp(reference[column]))), source, column, difference))
    if not worst:
        return Check("references", SKIP, f"{', '.join(results)}: no column fmpy's run has")
    scaled, source, column, difference = max(worst)
    detail = (
        f"{len(results)} result(s) replayed in fmpy (the default experiment): largest difference "
        f"{difference:.3g} ({source}, {column}), tolerance {RESULT_TOLERANCE:g} of each column's range"
    )
    return Check("references", PASS if scaled <= RESULT_TOLERANCE else FAIL, detail)


def _replay(kit: Path, settings: dict) -> None:
    """One held scenario through fmpy.simulate_fmu, its NAME_out.csv written beside it."""
    import numpy as np
    from fmpy import simulate_fmu

    from ..scenarios._scenario_settings import KIT_FMU

    signal = np.genfromtxt(kit / settings["input"], delimiter=",", names=True)
    run = simulate_fmu(
        str(kit / KIT_FMU),
        start_time=settings["start_time"],
        stop_time=settings["stop_time"],
        step_size=settings["step_size"],
        output_interval=settings["step_size"],
        relative_tolerance=settings["relative_tolerance"],
        input=signal,
        start_values={**settings["parameters"], "theta": settings["theta0"], "omega": settings["omega0"]},
        output=["theta", "omega"],
    )
    rows = np.column_stack([run["time"], run["theta"], run["omega"]])
    np.savetxt(kit / settings["output"], rows, delimiter=",", header="time,theta,omega", comments="", fmt="%.17g")


def verify_fmu(
    fmu: str | os.PathLike, *, public_key: str | os.PathLike | None = None, rebuild: bool = True
) -> list[Check]:
    """Check a received FMU against its build record, its signature, its sources and its references.

    Parameters
    ----------
    fmu : str or os.PathLike
        Any FMU: one of this project's carries a build record; another is checked as far as what
        it carries allows, each check saying what it could not do.
    public_key : str or os.PathLike, optional
        An Ed25519 public key (PEM) to check the record's signature with.
    rebuild : bool
        Rebuild this machine's binary from the FMU's sources/ where its compiler is here.

    Returns
    -------
    list of Check
        checksums, signature, rebuild and references, in that order.

    Raises
    ------
    MissingFile
        When there is no such file.
    InvalidInput
        When it is not an FMU (no zip, no modelDescription.xml), or its record is not JSON.

    Examples
    --------
    >>> from pendulum_fmu import default_fmu
    >>> [check.status for check in verify_fmu(default_fmu(), rebuild=False)][:2]  # doctest: +SKIP
    ['pass', 'not checked']
    """
    fmu = Path(fmu)
    if not fmu.is_file():
        raise MissingFile(f"{fmu}: no such file (give an .fmu)")
    try:
        open_fmu(fmu, str(fmu), InvalidInput).close()  # before its entries are read whole
        entries = read_entries(fmu)
    except (zipfile.BadZipFile, OSError) as error:
        raise InvalidInput(f"{fmu}: not an FMU ({error}); give an .fmu, a zip archive") from None
    if "modelDescription.xml" not in entries:
        raise InvalidInput(f"{fmu}: not an FMU (no modelDescription.xml at its top)")
    try:
        record = json.loads(entries[RECORD_FILE]) if RECORD_FILE in entries else None
    except (ValueError, RecursionError) as error:
        raise InvalidInput(f"{fmu}: {RECORD_FILE} is not JSON ({error})") from None
    if record is not None and not (
        isinstance(record, dict) and all(isinstance(record.get(key, {}), dict) for key in ("entries", "binaries"))
    ):
        raise InvalidInput(f"{fmu}: {RECORD_FILE} is not a build record (an object of entries and binaries)")
    checked = [_checksums(entries, record), _signature(entries, public_key)]
    rebuilt = _rebuild(entries, record) if rebuild else Check("rebuild", SKIP, "--no-rebuild")
    # Replaying loads the FMU's binary: not one that its own record or signature already refuses.
    if any(check.status == FAIL for check in checked):
        replayed = Check(
            "references",
            SKIP,
            f"not replayed: its {checked[0].name if checked[0].status == FAIL else 'signature'} failed",
        )
    else:
        replayed = _references(fmu, entries)
    return [*checked, rebuilt, replayed]


def format_checks(fmu: str | os.PathLike, checks: list[Check]) -> str:
    """The lines `pendulum-fmu verify` prints: a verdict, then one line per check.

    Examples
    --------
    >>> print(format_checks("P.fmu", [Check("checksums", "pass", "22 entries match")]))
    P.fmu: verified (1 passed, 0 failed, 0 not checked)
      checksums    pass          22 entries match
    """
    counts = {status: sum(check.status == status for check in checks) for status in (PASS, FAIL, SKIP)}
    verdict = "FAILED" if counts[FAIL] else "verified" if counts[PASS] else "nothing could be checked"
    lines = [f"{fmu}: {verdict} ({counts[PASS]} passed, {counts[FAIL]} failed, {counts[SKIP]} not checked)"]
    lines += [f"  {check.name:<12} {check.status:<13} {check.detail}" for check in checks]
    return "\n".join(lines)


def checks_json(fmu: str | os.PathLike, checks: list[Check]) -> str:
    """The same as JSON: {"fmu", "passed", "checks": [{name, status, detail}]}."""
    return json.dumps(
        {"fmu": os.fspath(fmu), "passed": all(c.status != FAIL for c in checks), "checks": [asdict(c) for c in checks]},
        indent=2,
    )
