"""Every bad input a user can give the command line and the Python API, as data: run by
tests/test_bad_inputs.py, and written as the tables in docs/bad_inputs.md by
`python tests/bad_inputs.py docs/bad_inputs.md`.

Each case is a `pendulum-fmu` command line, with `{files}` standing for a folder of the input
files below, the exit code it must give and a part of the one line it must print. Each call is a
Python expression a user of the API writes (with API_IMPORTS done), the PendulumFmuError subclass
it must raise and a part of its one-line message.
"""

from __future__ import annotations

import contextlib
import io
import json
import re
import stat
import sys
import warnings
import zipfile
from dataclasses import dataclass
from pathlib import Path

if __name__ == "__main__":  # a script documents the clone it is in, whatever package is installed
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def _zip(members: dict[str, str]) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, text in members.items():
            archive.writestr(name, text)
    return buffer.getvalue()


# A valid FMI 2.0 model description of another model: a spring, no torque and no theta.
SPRING = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Spring" guid="{5b8e0d1c-0000-4000-8000-000000000001}">
  <CoSimulation modelIdentifier="Spring"/>
  <ModelVariables>
    <ScalarVariable name="force" valueReference="0" causality="input" variability="continuous"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="x" valueReference="1" causality="output" variability="continuous"><Real/></ScalarVariable>
    <ScalarVariable name="k" valueReference="2" causality="parameter" variability="fixed" initial="exact"><Real start="1"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2"/></Outputs></ModelStructure>
</fmiModelDescription>
"""
FMI1 = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="1.0" modelName="Pendulum" modelIdentifier="Pendulum"
  guid="{5b8e0d1c-0000-4000-8000-000000000002}" numberOfContinuousStates="2" numberOfEventIndicators="0">
  <ModelVariables>
    <ScalarVariable name="torque" valueReference="0" causality="input"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="theta" valueReference="1" causality="output"><Real/></ScalarVariable>
  </ModelVariables>
</fmiModelDescription>
"""


def _settings(**changes) -> str:
    """A scenario's NAME.json as `pendulum-fmu scenarios` writes it (the fields the judge reads),
    with fields edited by hand.
    """
    settings = {
        "input": "s_in.csv",
        "output": "s_out.csv",
        "start_time": 0.0,
        "stop_time": 1.0,
        "step_size": 0.001,
        "ramp": False,
        "parameters": {},
        "theta0": 0.0,
        "omega0": 0.0,
        "tolerance": 1e-9,
    }
    return json.dumps({**settings, **changes}) + "\n"


# Files a user may have received, crafted to harm whoever opens them (issue 38): refused before
# anything unpacks, parses or searches them.
LAUGHS = (  # a billion laughs: 10^9 "lol" from a few hundred bytes
    '<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol0 "lol">'
    + "".join(f'<!ENTITY lol{k} "{f"&lol{k - 1};" * 10}">' for k in range(1, 10))
    + "]>\n"
)
EXTERNAL = '<?xml version="1.0"?>\n<!DOCTYPE m [<!ENTITY secret SYSTEM "file:///etc/hostname">]>\n'


def _link_entry() -> zipfile.ZipInfo:
    """An archive's entry that unpacks (with unzip or tar) as a symbolic link."""
    entry = zipfile.ZipInfo("resources/link")
    entry.create_system, entry.external_attr = 3, (stat.S_IFLNK | 0o777) << 16
    return entry


def _zip_entries(entries: list[tuple[str | zipfile.ZipInfo, bytes | str]], level: int = 1) -> bytes:
    """A deflated archive; level 1 (fastest) shrinks a MiB of zeros 229 times, level 6 1000 times."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED, compresslevel=level) as archive:
        for entry, data in entries:
            archive.writestr(entry, data)
    return buffer.getvalue()


def _ssp(pendulum_set: str) -> bytes:
    """A closed loop's SSP whose pendulum parameter set is pendulum_set."""
    from pendulum_fmu.ssp._ssp import parameter_set_xml, system_structure_xml

    return _zip(
        {
            "SystemStructure.ssd": system_structure_xml(3.0, 1e-3).decode(),
            "resources/controller.ssv": parameter_set_xml("controller", {"kp": 1.0}).decode(),
            "resources/pendulum.ssv": pendulum_set,
        }
    )


def received_files() -> dict[str, bytes | str]:
    """The crafted files, by name."""
    bomb = _zip_entries([("modelDescription.xml", SPRING), ("resources/zeros", bytes(8 * 2**20))], level=6)
    record = '[pendulum-calls] instance="p" fmi2DoStep(currentCommunicationPoint=0, communicationStepSize=0.001) '
    record += "time=0->0.001 status=OK\n"
    deep_kit = {"deep_kit/s.json": "[" * 100_000 + "]" * 100_000, "deep_kit/s_in.csv": "time,torque\n0,1\n1,1\n"}
    return {
        "escaping.fmu": _zip({"modelDescription.xml": SPRING, "../../escaped.txt": "x"}),
        "absolute.fmu": _zip({"modelDescription.xml": SPRING, "/tmp/escaped.txt": "x"}),
        "link.fmu": _zip_entries([("modelDescription.xml", SPRING), (_link_entry(), "/etc/passwd")]),
        # 8 MiB of zeros from 8 kB, as a zip bomb's gigabytes come from a few MB.
        "bomb.fmu": bomb,
        "huge.fmu": _zip_entries(
            [("modelDescription.xml", SPRING)] + [(f"resources/{n}", bytes(2**20)) for n in range(513)]
        ),
        "crowded.fmu": _zip_entries(
            [("modelDescription.xml", SPRING)] + [(f"resources/{n}", "") for n in range(10_000)]
        ),
        # Few entries, but a list of them that zipfile would read whole before counting them.
        "listed.fmu": _zip_entries(
            [("modelDescription.xml", SPRING)] + [(f"resources/{n:04d}" + "x" * 1000, "") for n in range(2_600)]
        ),
        "laughs.fmu": _zip({"modelDescription.xml": LAUGHS + SPRING.split("?>", 1)[1].replace("Spring", "&lol9;", 1)}),
        "external.fmu": _zip(
            {"modelDescription.xml": EXTERNAL + SPRING.split("?>", 1)[1].replace("Spring", "&secret;", 1)}
        ),
        "laughs.ssp": _ssp(LAUGHS + '<ssv:ParameterSet name="&lol9;"/>'),
        "bomb.ssp": _zip_entries([("SystemStructure.ssd", " " * 8 * 2**20)], level=6),
        # The SSP is small; an FMU in it, which a master would unpack, is the bomb.
        "bomb_inside.ssp": _zip_entries([("SystemStructure.ssd", "<a/>"), ("resources/Pendulum.fmu", bomb)]),
        "long_line.log": record + "x" * 2**20 + "\n" + record,
        "nul.log": record + "\0" + record,
        "long_line.csv": "time,torque\n0,1\n1," + "1" * 2**20 + "\n",
        "nul.csv": "time,torque\n0,1\n1,\x002\n",
        "long_cell.csv": "time,torque\n0,1\n1," + "x" * 10_000 + "\n",
        "long_result.csv": "time,theta\n0,0\n0.001," + "0" * 2**20 + "\n",
        "nul_result.csv": "time,theta\n0,0\n0.001,\x000\n",
        **deep_kit,
        "settings/deep.json": "[" * 100_000 + "]" * 100_000,
        "settings/large.json": _settings(note="x" * 2**20),
        "settings/input_elsewhere.json": _settings(input="../../.ssh/id_rsa"),
        "settings/input_absolute.json": _settings(input="/etc/hostname"),
    }


# Input files the cases name, written into {files} before they run.
FILES = {
    "bad_number.csv": "time,torque\n0,1\n1,x\n",
    "epoch.csv": "time,torque\n1700000000,1\n1700000100,2\n",
    "latin1.csv": "time,torque\n0,1\n1,2 # Drehmoment \u00fcber\n".encode("latin-1"),
    "empty.csv": "",
    "header_only.csv": "time,torque\n",
    "no_torque.csv": "time,force\n0,1\n",
    "backwards.csv": "time,torque\n0,1\n2,1\n1,1\n",
    "three_times.csv": "time,torque\n0,1\n1,1\n1,2\n1,3\n",
    "nan.csv": "time,torque\n0,1\n1,nan\n",
    "one_row.csv": "time,torque\n0,5\n",
    "far_end.csv": "time,torque\n0,1\n1e308,3\n",
    "extra_column.csv": "time,torque\n0,1\n1,2,3\n",
    "underscore.csv": "time,torque\n0,1\n1,1_0\n",
    "blank_first.csv": "\ntime,torque\n0,1\n",
    "huge_torque.csv": "time,torque\n0,1e308\n0.01,-1e308\n",
    "short_row.csv": "time,torque\n0,1\n1\n",
    "empty.fmu": _zip({}),
    "no_model_description.fmu": _zip({"documentation/index.html": "<html></html>"}),
    "spring.fmu": _zip({"modelDescription.xml": SPRING}),
    "fmi1.fmu": _zip({"modelDescription.xml": FMI1}),
    "result.csv": "time,theta\n0,0\n0.001,0\n",
    "result_no_time.csv": "t,theta\n0,0\n0.001,0\n",
    "result_backwards.csv": "time,theta\n0,0\n0.002,0\n0.001,0\n",
    "result_t0.csv": "time,theta\n0,0\n",
    # The controller's record alone: the pendulum's instance is not in it.
    "controller_calls.log": '[pendulum-calls] instance="controller" fmi2SetReal(theta=0) time=0->0 status=OK\n'
    '[pendulum-calls] instance="controller" fmi2DoStep(currentCommunicationPoint=0, communicationStepSize=0.001) '
    "time=0->0.001 status=OK\n",
    # A folder with a study's entry that no sweep wrote.
    "not_a_study/study.json": "{}\n",
    # Folders holding a file of a scenario kit, and an output of a demo.
    "old_kit/ReadMe.md": "my notes\n",
    "old_demo/gravity_effect.png": "old\n",
    # A kit whose one scenario's settings were edited by hand, and settings edited field by field.
    "bad_kit/s.json": _settings(stop_time="three"),
    "bad_kit/s_in.csv": "time,torque\n0,1\n1,1\n",
    "settings/stop_nan_text.json": _settings(stop_time="NaN"),
    "settings/stop_nan.json": _settings(stop_time=float("nan")),
    "settings/tolerance_text.json": _settings(tolerance="x"),
    "settings/output_null.json": _settings(output=None),
    "settings/input_null.json": _settings(input=None),
    "settings/ramp_text.json": _settings(ramp="yes"),
    "settings/parameters_list.json": _settings(parameters=[]),
    "settings/stop_before_start.json": _settings(stop_time=-1.0),
    "settings/list.json": "[]\n",
}


@dataclass(frozen=True)
class Case:
    group: str
    argv: tuple[str, ...]
    exit_code: int
    message: str


def _case(group, command, exit_code, message):
    return Case(group, tuple(command.split()), exit_code, message)


CASES = [
    _case("run length", "simulate --torque 1 --stop-time inf", 2, "stop time inf must be a finite number"),
    _case("run length", "simulate --torque 1 --stop-time nan", 2, "stop time nan must be a finite number"),
    _case("run length", "simulate --torque 1 --stop-time -1", 2, "stop time -1.0 must be after start time 0.0"),
    _case("run length", "simulate --torque 1 --step-size 0", 2, "step size 0.0 must be positive"),
    _case(
        "run length",
        "simulate --torque 1 --step-size 1e-8 --stop-time 7200",
        2,
        "0 to 7200 s in steps of 1e-08 s is 720,000,000,000 steps, over the limit of 10,000,000",
    ),
    _case(
        "run length",
        "simulate --torque-file {files}/epoch.csv",
        2,
        "0 to 1.7e+09 s in steps of 0.001 s is 1,700,000,100,000 steps, over the limit",
    ),
    # Counts past the largest double (a span of 1e308 s, a 1e-320 s step): the same refusal.
    _case(
        "run length",
        "simulate --torque 1 --stop-time 1e308",
        2,
        "0 to 1e+308 s in steps of 0.001 s is about 1e+311 steps, over the limit of 10,000,000",
    ),
    _case(
        "run length",
        "simulate --torque 1 --step-size 1e-320 --stop-time 0.01",
        2,
        "is about 1e+318 steps, over the limit of 10,000,000",
    ),
    _case(
        "run length",
        "simulate --torque-file {files}/far_end.csv",
        2,
        "0 to 1e+308 s in steps of 0.001 s is about 1e+311 steps, over the limit",
    ),
    _case(
        "run length",
        "compare --torque 1 --tools fmu,reference --stop-time 1e308 --output-dir {files}/out",
        2,
        "is about 1e+311 steps, over the limit of 10,000,000",
    ),
    _case(
        "run length",
        "compare --torque 20 --tools fmu,reference --stop-time 1e10 --step-size 1e9 --output-dir {files}/out",
        2,
        "the reference would take about 40,594,443,387 Taylor steps from 0 to 1e+10 s (rtol 1e-14), over its limit",
    ),
    _case(
        "sweep",
        "sweep --torque 1 --stop-time 0.01 --output-dir {files}/huge_study --resume",
        2,
        "huge_study/study.json: over 268,435,456 bytes, longer than any such file; choose another output directory",
    ),
    _case(
        "run length",
        "sweep --torque 1 --step-size 1e-320 --output-dir {files}/out",
        2,
        "is about 3e+320 steps, over the limit of 10,000,000",
    ),
    _case(
        "run length",
        "judge {files}/result.csv --torque 1 --start-time=-1e308 --stop-time 0.01",
        2,
        "-1e+308 to 0.01 s in steps of 0.001 s is about 1e+311 steps, over the limit",
    ),
    _case("run length", "simulate --torque 1 --max-steps 0", 2, "argument --max-steps: 0 must be at least 1"),
    _case("torque file", "simulate --torque-file {files}/absent.csv", 2, "absent.csv: cannot read: No such file"),
    _case(
        "torque file",
        "simulate --torque-file {files}/bad_number.csv",
        2,
        "bad_number.csv:3: torque 'x' is not a number",
    ),
    _case(
        "torque file",
        "simulate --torque-file {files}/latin1.csv",
        2,
        "latin1.csv:3: byte 0xfc is not UTF-8; save the file as UTF-8",
    ),
    _case("torque file", "simulate --torque-file {files}/empty.csv", 2, "empty.csv: the file is empty"),
    _case("torque file", "simulate --torque-file {files}/header_only.csv", 2, "header_only.csv: no data rows"),
    _case("torque file", "simulate --torque-file {files}/no_torque.csv", 2, "no_torque.csv:1: missing column 'torque'"),
    _case("torque file", "simulate --torque-file {files}/backwards.csv", 2, "backwards.csv:4: time 1 goes backwards"),
    _case(
        "torque file",
        "simulate --torque-file {files}/three_times.csv",
        2,
        "three_times.csv:5: time 1 appears three times",
    ),
    _case(
        "torque file", "simulate --torque-file {files}/nan.csv", 2, "nan.csv:3: torque is nan; values must be finite"
    ),
    _case(
        "torque file", "simulate --torque-file {files}/short_row.csv", 2, "short_row.csv:3: torque '' is not a number"
    ),
    _case(
        "torque file",
        "simulate --torque-file {files}/extra_column.csv",
        2,
        "extra_column.csv:3: 3 columns, but the header names 2; quote a cell holding a comma",
    ),
    _case(
        "torque file",
        "simulate --torque-file {files}/underscore.csv",
        2,
        "underscore.csv:3: torque '1_0' is not a number",
    ),
    _case(
        "torque file",
        "simulate --torque-file {files}/blank_first.csv",
        2,
        "blank_first.csv:1: the line is blank; the header, e.g. time,torque, must be the first line",
    ),
    _case(
        "torque file",
        "simulate --torque-file {files}/huge_torque.csv --ramp",
        2,
        "huge_torque.csv ramps from 1e+308 to 8e+307 N.m between t = 0 and 0.001 s, a rate past the largest double",
    ),
    _case(
        "torque file",
        "compare --torque-file {files}/huge_torque.csv --tools fmu,reference --output-dir {files}/out",
        2,
        "the reference would take about 1.04e+285 Taylor steps from 0 to 0.01 s (rtol 1e-14), over its limit",
    ),
    _case(
        "torque file",
        "simulate --torque-file {files}/huge_torque_file.csv",
        2,
        "huge_torque_file.csv: over 1,073,741,824 bytes, longer than any such file; give a CSV of time,torque rows",
    ),
    _case(
        "torque file",
        "simulate --torque-file {files}/one_row.csv",
        2,
        "one_row.csv ends at 0 s, not after the start time 0 s; give a stop time",
    ),
    _case("arguments", "simulate --torque abc", 2, "argument --torque: 'abc' is not a number"),
    _case("arguments", "simulate", 2, "one of the arguments --torque --torque-file is required"),
    _case("parameters", "simulate --torque 1 --set mas=2", 2, "unknown parameter 'mas'"),
    _case("parameters", "simulate --torque 1 --set mass=heavy", 2, "'heavy' is not a number"),
    _case("parameters", "simulate --torque 1 --set mass=-1", 2, "mass must be > 0"),
    _case("parameters", "simulate --torque 1 --set damping=inf", 2, "parameter damping = inf must be finite"),
    _case("parameters", "simulate --torque 1 --set mass", 2, "expected name=value, got 'mass'"),
    # The reference's solve_ivp fails where mass*gravity*length overflows.
    _case(
        "compare",
        "compare --torque 1 --tools fmu,reference --set mass=1e308 --stop-time 0.01 --output-dir {files}/out",
        2,
        "the reference cannot integrate the pendulum from t = 0 s with mass = 1e+308, length = 0.5",
    ),
    _case("compare", "compare --torque 1 --tools fmu,matlab --output-dir {files}/out", 2, "unknown tool(s) matlab"),
    _case("compare", "compare --torque 1 --tools fmu,fmu --output-dir {files}/out", 2, "--tools names fmu twice"),
    _case(
        "compare",
        "compare --torque 1 --tools fmu,gymnasium --set damping=2 --output-dir {files}/out",
        2,
        "gymnasium: Pendulum-v1 has no damping, so damping 2.0 N.m.s/rad cannot be represented",
    ),
    _case(
        "compare",
        "compare --torque 1 --tools fmu,envpool --step-size 0.05 --output-dir {files}/out",
        2,
        "envpool: EnvPool's Pendulum-v1 is a fixed 1 kg, 1 m rod under g = 10",
    ),
    _case(
        "compare",
        "compare --torque 1 --tools fmu,envpool --set mass=1 --set inertia=0.08333333333333333 --set gravity=10 "
        "--output-dir {files}/out",
        2,
        "envpool: EnvPool's Pendulum-v1 steps 0.05 s, fixed; this run's steps are 0.001 s",
    ),
    _case(
        "compare",
        "compare --torque 1 --tools fmu,envpool --set mass=1 --set inertia=0.08333333333333333 --set gravity=10 "
        "--step-size 0.05 --output-dir {files}/out",
        2,
        "envpool: EnvPool's Pendulum-v1 cannot be put in a state; it starts where its reset draws (seed 0)",
    ),
    _case(
        "compare",
        "compare --torque 1 --tools fmu --output-dir {files}/out",
        2,
        "compare needs at least two tools, got fmu",
    ),
    _case(
        "compare",
        "compare --torque 1 --tools fmu,reference --tol nan --output-dir {files}/out",
        2,
        "the tolerance nan must be a positive finite number",
    ),
    _case(
        "compare",
        "compare --torque 1 --tools fmu,reference --tol -1 --output-dir {files}/out",
        2,
        "the tolerance -1.0 must be a positive finite number",
    ),
    _case(
        "fmu", "simulate --torque 1 --fmu {files}/absent.fmu", 2, "FMU {files}/absent.fmu: No such file or directory"
    ),
    _case(
        "fmu",
        "simulate --torque 1 --fmu {files}/one_row.csv",
        2,
        "{files}/one_row.csv is not an FMU (an FMU is a zip archive with a modelDescription.xml): check the path",
    ),
    _case(
        "fmu",
        "simulate --torque 1 --fmu {files}/empty.fmu",
        2,
        "{files}/empty.fmu is not an FMU: the zip archive has no modelDescription.xml (it is empty)",
    ),
    _case(
        "fmu",
        "simulate --torque 1 --fmu {files}/no_model_description.fmu",
        2,
        "no_model_description.fmu is not an FMU: the zip archive has no modelDescription.xml",
    ),
    _case(
        "fmu",
        "simulate --torque 1 --fmu {files}/spring.fmu",
        2,
        "spring.fmu is not a pendulum FMU: it has no variable torque, theta, omega, alpha (it is the model 'Spring')",
    ),
    _case(
        "fmu",
        "simulate --torque 1 --fmu {files}/fmi1.fmu",
        2,
        "fmi1.fmu is an FMI 1.0 FMU; this package runs FMI 2.0 and 3.0 FMUs",
    ),
    _case(
        "fmu",
        "compare --torque 1 --tools fmu,reference --fmu {files}/one_row.csv --output-dir {files}/out",
        2,
        "one_row.csv is not an FMU",
    ),
    _case(
        "fmu",
        "compare --torque 1 --tools fmu,other={files}/fmi1.fmu --output-dir {files}/out",
        2,
        "other: {files}/fmi1.fmu is an FMI 1.0 FMU",
    ),
    _case(
        "fmu",
        "sweep --torque 1 --fmu {files}/spring.fmu --output-dir {files}/out",
        2,
        "spring.fmu is not a pendulum FMU",
    ),
    _case("fmu", "sweep --torque 1 --fmu {files}/empty.fmu --output-dir {files}/out", 2, "empty.fmu is not an FMU"),
    _case("fmu", "cross-check --fmu {files}/fmi1.fmu --output-dir {files}/out", 2, "fmi1.fmu is an FMI 1.0 FMU"),
    _case(
        "sweep",
        "sweep --torque 5 --scheduler tcp://127.0.0.1:9 --connect-timeout 1 --output-dir {files}/out",
        2,
        "no dask scheduler answered at tcp://127.0.0.1:9 within 1 s",
    ),
    _case(
        "sweep",
        "sweep --torque 5 --scheduler tls://127.0.0.1:9 --tls-ca-file {files}/ca.pem --tls-cert {files}/client.pem "
        "--output-dir {files}/out",
        2,
        "TLS file {files}/ca.pem (--tls-ca-file, or dask's distributed.comm.tls.ca-file): no such file",
    ),
    _case(
        "sweep",
        "sweep --torque 5 --scheduler tls://127.0.0.1:9 --tls-ca-file {files}/result.csv --tls-cert {files}/result.csv "
        "--output-dir {files}/out",
        2,
        "the TLS files for tls://127.0.0.1:9 cannot be read as a CA certificate, certificate and key",
    ),
    _case(
        "sweep",
        "sweep --torque 5 --scheduler tls://127.0.0.1:9 --tls-cert {files}/result.csv --output-dir {files}/out",
        2,
        "--tls-ca-file and --tls-cert go together",
    ),
    _case(
        "sweep",
        "sweep --torque 5 --tls-ca-file {files}/result.csv --tls-cert {files}/result.csv --output-dir {files}/out",
        2,
        "--tls-ca-file, --tls-cert and --tls-key are for --scheduler tls://...",
    ),
    _case(
        "sweep",
        "sweep --torque 5 --set mass=heavy --output-dir {files}/out",
        2,
        "--set mass=heavy: expected comma-separated numbers",
    ),
    _case(
        "sweep", "sweep --torque 5 --stop-time inf --output-dir {files}/out", 2, "stop time inf must be a finite number"
    ),
    _case(
        "sweep",
        "sweep --torque 5 --run-in process --workers 2 --output-dir {files}/out",
        2,
        "run_in 'process' (--run-in process) runs the study in this process: give it no scheduler",
    ),
    _case(
        "sweep",
        "sweep --torque 1 2 3 4 5 6 7 8 9 10 --set mass=1,2,3,4,5,6,7,8,9,10 "
        "--set length=1,2,3,4,5,6,7,8,9,10 --max-cases 999 --output-dir {files}/out",
        2,
        "1,000 cases is over the limit of 999: give fewer values",
    ),
    _case(
        "output",
        "simulate --torque 1 --stop-time 0.01 --output {files}/bad_number.csv/out.csv",
        2,
        "bad_number.csv is a file, not a folder; choose another output path",
    ),
    # /proc/self: a folder in which nothing can be created, whoever runs (Linux).
    _case(
        "output",
        "simulate --torque 1 --stop-time 0.01 --output /proc/self/out.csv",
        2,
        "cannot write /proc/self/out.csv: no file can be created in /proc/self (No such file or directory)",
    ),
    _case(
        "output",
        "simulate --torque 1 --stop-time 0.01 --plot /proc/self/out.png",
        2,
        "cannot write /proc/self/out.png: no file can be created in /proc/self",
    ),
    _case(
        "output",
        "simulate --torque 1 --stop-time 0.01 --output {files}",
        2,
        "cannot write {files}: it is a folder; give a file name",
    ),
    _case(
        "output",
        "compare --torque 1 --tools fmu,reference --output-dir /proc/self/out",
        2,
        "cannot write /proc/self/out/trajectories.csv: the folder /proc/self/out cannot be created",
    ),
    _case(
        "output",
        "build --output /proc/self/Pendulum.fmu --platforms linux64",
        2,
        "cannot write /proc/self/Pendulum.fmu: no file can be created in /proc/self",
    ),
    _case(
        "output",
        "sweep --torque 1 --output-dir /proc/self/out",
        2,
        "cannot write /proc/self/out: the folder /proc/self/out cannot be created",
    ),
    _case(
        "fmu",
        "simulate --torque 1 --stop-time 0.01 --fmu {files}/other_guid.fmu",
        2,
        "other_guid.fmu: the FMU refused to instantiate: [ERROR] fmi2Instantiate: fmuGUID "
        "{00000000-0000-0000-0000-000000000000} does not match this FMU's",
    ),
    _case(
        "fmu",
        "compare --torque 1 --stop-time 0.01 --tools fmu,x={files}/other_identifier.fmu --output-dir {files}/out",
        2,
        "x: {files}/other_identifier.fmu cannot be loaded here: it has no binaries/linux64/Nope.so",
    ),
    _case(
        "output",
        "sweep --torque 1 --output-dir=",
        2,
        "argument --output-dir: an empty path; give a file or folder name (is a shell variable unset?)",
    ),
    _case("output", "simulate --torque 1 --output=", 2, "argument --output: an empty path"),
    _case(
        "output",
        "simulate --torque 1 --stop-time 0.01 --plot {files}/out.csv",
        2,
        "out.csv: a figure cannot be written as .csv; end its name in .png, .pdf or .svg",
    ),
    _case(
        "output",
        "simulate --torque-file {files}/epoch.csv --output {files}/epoch.csv",
        2,
        "--output {files}/epoch.csv names the same file as --torque-file: writing it would destroy what the "
        "command reads; choose another path",
    ),
    _case(
        "output",
        "simulate --torque 1 --stop-time 0.01 --output {files}/out.png --plot {files}/out.png",
        2,
        "--plot {files}/out.png names the same file as --output: writing it would lose one of the two",
    ),
    _case(
        "output",
        "simulate --torque 1 --stop-time 0.01 --output {files}/" + "a" * 300 + ".csv",
        2,
        "File name too long; choose another output path",
    ),
    _case(
        "judge",
        "judge {files}/result.csv --torque 1 --json {files}/result.csv",
        2,
        "--json {files}/result.csv names the same file as the result: writing it would destroy what the command reads",
    ),
    _case(
        "judge",
        "judge {files}/result_no_time.csv --torque 1",
        2,
        "result_no_time.csv:1: no column 'time' (header is t,theta); name the result's time column",
    ),
    _case(
        "judge",
        "judge {files}/result_backwards.csv --torque 1",
        2,
        "result_backwards.csv:4: time 0.001 goes backwards (previous row: 0.002)",
    ),
    _case(
        "judge",
        "judge {files}/result.csv --torque 1 --map theta=phi",
        2,
        "result.csv:1: no column 'phi', which --map names for theta (header is time,theta)",
    ),
    _case(
        "judge",
        "judge {files}/result.csv --torque 1 --map torque=u",
        2,
        "--map: unknown quantity 'torque'; map any of time, theta, omega, alpha",
    ),
    _case(
        "judge",
        "judge {files}/result.csv --torque 1 --stop-time 0.001 --set mass=1e308",
        2,
        "the reference cannot integrate the pendulum from t = 0 s with mass = 1e+308",
    ),
    _case("judge", "judge {files}/result.csv", 2, "judging a result file needs the run's torque"),
    _case("judge", "judge {files}/absent.csv --torque 1", 2, "absent.csv: cannot read: No such file"),
    _case(
        "judge",
        "judge {files}/result.csv --torque 1 --stop-time 0.0005",
        2,
        "result.csv: time 0.001 is after the run's stop time 0.0005 s; give the run's --stop-time",
    ),
    _case("judge", "judge {files}", 2, "no scenario settings (NAME.json) in this folder"),
    _case(
        "judge",
        "judge --calls {files}/controller_calls.log --ssp {files}/absent.ssp",
        2,
        "no instance of the pendulum stepped with a torque set",
    ),
    _case(
        "judge",
        "judge {files}/result.csv --calls {files}/controller_calls.log --ssp {files}/absent.ssp",
        2,
        "the master's result CSV or the pendulum's call record, one of them",
    ),
    _case("judge", "judge {files} --torque 1", 2, "is a folder, judged as a scenario kit whose NAME.json files"),
    _case(
        "judge",
        "judge {files}/result.csv {files}/absent.csv --torque 1 --stop-time 0.001",
        2,
        "absent.csv: cannot read: No such file",
    ),
    _case(
        "judge", "judge {files}/result.csv {files} --torque 1", 2, "is a folder, judged as a scenario kit on its own"
    ),
    _case(
        "judge",
        "judge {files}/result.csv {files}/result_t0.csv --ssp {files}/absent.ssp",
        2,
        "--ssp judges one result or log at a time; 2 results were given",
    ),
    _case(
        "judge",
        "judge {files}/result.csv {files}/result.csv --torque 1 --stop-time 0.001 --plot {files}/out",
        2,
        "would both be drawn as {files}/out/result.png",
    ),
    _case(
        "scenarios",
        "scenarios --output-dir {files}/bad_number.csv/kit",
        2,
        "bad_number.csv is a file, not a folder; choose another output path",
    ),
    _case(
        "judge",
        "judge {files}/result_t0.csv --torque 1",
        2,
        "result_t0.csv: the result ends at 0 s, before the run's stop time 3 s, so it covers only part of the run",
    ),
    _case(
        "judge",
        "judge {files}/result.csv --torque 1 --start-time=-1 --stop-time 0.001",
        2,
        "result.csv: the result starts at 0 s, not at the run's start time -1 s",
    ),
    _case(
        "judge",
        "judge {files}/bad_kit",
        2,
        'bad_kit/s.json: stop_time is "three"; it must be a finite number (s): correct it, or write the kit again',
    ),
    _case(
        "scenarios",
        "scenarios --output-dir {files}/old_kit",
        2,
        "{files}/old_kit already holds a scenario kit (ReadMe.md): choose another output directory, or add --overwrite",
    ),
    _case(
        "demo",
        "demo --output-dir {files}/old_demo",
        2,
        "{files}/old_demo already holds a demo's outputs (gravity_effect.png): choose another output "
        "directory, or add --overwrite",
    ),
    # A sweep into a folder that holds a study (issue 23, item 1).
    _case(
        "sweep",
        "sweep --torque 5 --output-dir {files}/not_a_study",
        2,
        "holds study.json but no study.json of a sweep: choose another output directory, or add --overwrite",
    ),
    _case(
        "sweep",
        "sweep --torque 5 --resume --overwrite --output-dir {files}/out",
        2,
        "argument --overwrite: not allowed with argument --resume",
    ),
    # Files a user received, crafted to harm whoever opens them (issue 38).
    _case(
        "received file",
        "simulate --torque 1 --fmu {files}/escaping.fmu",
        2,
        "escaping.fmu: the archive's entry '../../escaped.txt' would be unpacked outside its folder; do not open it",
    ),
    _case(
        "received file",
        "simulate --torque 1 --fmu {files}/absolute.fmu",
        2,
        "absolute.fmu: the archive's entry '/tmp/escaped.txt' would be unpacked outside its folder",
    ),
    _case(
        "received file",
        "simulate --torque 1 --fmu {files}/link.fmu",
        2,
        "link.fmu: the archive's entry 'resources/link' is a symbolic link",
    ),
    _case(
        "received file",
        "simulate --torque 1 --fmu {files}/bomb.fmu",
        2,
        "bomb.fmu: the archive's entry 'resources/zeros' expands 1,0",
    ),
    _case(
        "received file",
        "compare --torque 1 --tools fmu,theirs={files}/huge.fmu --output-dir {files}/out",
        2,
        "huge.fmu: the archive unpacks to 513 MiB, over the limit of 512 MiB",
    ),
    _case(
        "received file",
        "sweep --torque 1 --fmu {files}/crowded.fmu --output-dir {files}/out",
        2,
        "crowded.fmu: the archive holds 10,001 entries, over 10,000",
    ),
    _case(
        "received file",
        "simulate --torque 1 --fmu {files}/listed.fmu",
        2,
        "listed.fmu: the archive's list of entries takes 2,",
    ),
    _case(
        "received file",
        "simulate --torque 1 --fmu {files}/laughs.fmu",
        2,
        "laughs.fmu's modelDescription.xml declares a document type (<!DOCTYPE), where XML defines entities",
    ),
    _case(
        "received file",
        "simulate --torque 1 --fmu {files}/external.fmu",
        2,
        "external.fmu's modelDescription.xml declares a document type",
    ),
    _case(
        "received file",
        "judge {files}/result.csv --ssp {files}/laughs.ssp",
        2,
        "laughs.ssp's resources/pendulum.ssv declares a document type",
    ),
    _case(
        "received file",
        "judge {files}/result.csv --ssp {files}/bomb.ssp",
        2,
        "bomb.ssp: the archive's entry 'SystemStructure.ssd' expands",
    ),
    _case(
        "received file",
        "judge {files}/result.csv --ssp {files}/bomb_inside.ssp",
        2,
        "bomb_inside.ssp's resources/Pendulum.fmu: the archive's entry 'resources/zeros' expands",
    ),
    _case(
        "received file",
        "judge --calls {files}/long_line.log --torque 1",
        2,
        "long_line.log:2: the line is longer than 131,072 characters; give the FMU's call record",
    ),
    _case("received file", "judge --calls {files}/nul.log --torque 1", 2, "nul.log:2: a NUL byte, which no text holds"),
    _case(
        "received file",
        "simulate --torque-file {files}/long_line.csv",
        2,
        "long_line.csv:3: the line is longer than 131,072 bytes",
    ),
    _case("received file", "simulate --torque-file {files}/nul.csv", 2, "nul.csv:3: a NUL byte, which no text holds"),
    _case(
        "received file",
        "simulate --torque-file {files}/long_cell.csv",
        2,
        "long_cell.csv:3: torque 'xxxxxxxx",
    ),
    _case(
        "received file",
        "judge {files}/long_result.csv --torque 1",
        2,
        "long_result.csv:3: the line is longer than 131,072 characters",
    ),
    _case("received file", "judge {files}/nul_result.csv --torque 1", 2, "nul_result.csv:3: a NUL byte"),
    _case("received file", "judge {files}/deep_kit", 2, "deep_kit/s.json: not a scenario's settings: nested too deep"),
    _case(
        "received file",
        "verify {files}/escaping.fmu",
        2,
        "escaping.fmu: the archive's entry '../../escaped.txt' would be unpacked outside its folder",
    ),
    _case(
        "received file", "verify {files}/laughs.fmu", 2, "laughs.fmu's modelDescription.xml declares a document type"
    ),
]

# What the calls below have in scope.
API_IMPORTS = """\
import gymnasium
import numpy as np

import pendulum_fmu.gym
from pendulum_fmu import (
    Study,
    compare,
    create_closed_loop_fmu,
    default_fmu,
    judge,
    judge_results,
    linearize,
    read_settings,
    reference,
    reference_schedule,
    run_sweep,
    simulate,
    sweep_grid,
    tls_files,
    write_scenarios,
)"""


@dataclass(frozen=True)
class Call:
    group: str
    code: str
    error: str  # the name of the PendulumFmuError subclass it raises
    message: str


ONE = 'Study([{"torque": 1.0}])'
OUT = 'output_dir="{files}/out"'

CALLS = [
    Call(
        "simulate",
        'simulate(20.0, stop_time=float("inf"))',
        "InvalidInput",
        "stop time inf must be a finite number of seconds",
    ),
    Call(
        "simulate", 'simulate(20.0, stop_time="3")', "InvalidInput", "stop time '3' must be a finite number of seconds"
    ),
    Call("simulate", "simulate(20.0, step_size=0)", "InvalidInput", "step size 0 must be positive"),
    Call(
        "simulate",
        "simulate(20.0, step_size=1e-9, stop_time=100)",
        "InvalidInput",
        "is 100,000,000,000 steps, over the limit of 10,000,000",
    ),
    Call(
        "simulate",
        "simulate(20.0, step_size=1e-320, stop_time=0.01)",
        "InvalidInput",
        "is about 1e+318 steps, over the limit of 10,000,000",
    ),
    Call(
        "simulate",
        "simulate(20.0, max_steps=1.5)",
        "InvalidInput",
        "max steps 1.5 must be a whole number of steps, at least 1",
    ),
    Call(
        "simulate",
        "simulate(None)",
        "InvalidInput",
        "a torque is a number, a callable of time, a per-step array or a CSV path; got NoneType",
    ),
    Call("simulate", 'simulate(float("nan"))', "InvalidInput", "the torque is nan at t = 0.0; it must be finite"),
    Call(
        "simulate",
        'simulate(["a", "b"], stop_time=0.002)',
        "InvalidInput",
        "a torque array needs one value per step, each a number in N.m",
    ),
    Call(
        "simulate",
        "simulate([1.0, 2.0, 3.0], stop_time=1.0)",
        "InvalidInput",
        "the torque array has 3 values but 0 to 1 s in steps of 0.001 s is 1000 steps",
    ),
    Call(
        "simulate",
        'simulate(lambda t: "x", stop_time=0.01)',
        "InvalidInput",
        "the torque callable returned 'x' at t = 0.0",
    ),
    Call("simulate", "simulate(lambda: 1.0)", "InvalidInput", "a torque callable takes the time in s and returns N.m"),
    Call("simulate", 'simulate("{files}/absent.csv")', "TorqueFileError", "absent.csv: cannot read: No such file"),
    Call(
        "simulate", 'simulate("{files}/no_torque.csv")', "TorqueFileError", "no_torque.csv:1: missing column 'torque'"
    ),
    Call("simulate", 'simulate(20.0, parameters={"mas": 2})', "InvalidInput", "unknown parameter 'mas'"),
    Call(
        "simulate",
        'simulate(20.0, parameters={"mass": "heavy"})',
        "InvalidInput",
        "parameter mass = 'heavy' is not a number",
    ),
    Call(
        "simulate",
        'simulate(20.0, parameters={"mass": -1})',
        "InvalidInput",
        "the FMU refuses the parameters: mass must be > 0",
    ),
    Call("simulate", 'simulate(20.0, parameters=[("mass", 2)])', "WrongType", "parameters is a dict {name: value}"),
    Call("simulate", 'simulate(20.0, theta0="a")', "InvalidInput", "theta0 = 'a' must be a finite number of rad"),
    Call(
        "simulate",
        'simulate(20.0, omega0=float("inf"))',
        "InvalidInput",
        "omega0 = inf must be a finite number of rad/s",
    ),
    Call("simulate", "simulate(20.0, tolerance=2.0)", "FmuError", "tolerance 2 must be in (0, 1)"),
    Call(
        "simulate",
        'simulate(20.0, fmu_path="{files}/absent.fmu")',
        "MissingFile",
        "absent.fmu: No such file or directory",
    ),
    Call("reference", "reference(20.0, step_size=0)", "InvalidInput", "step size 0.0 must be positive"),
    Call(
        "reference",
        "reference(20.0, step_size=1e-9, stop_time=100)",
        "InvalidInput",
        "is 100,000,000,000 steps, over the limit of 10,000,000",
    ),
    Call(
        "reference",
        "reference(20.0, stop_time=1e308)",
        "InvalidInput",
        "is about 1e+311 steps, over the limit of 10,000,000",
    ),
    Call(
        "reference",
        "reference(20.0, stop_time=1e10, step_size=1e9)",
        "InvalidInput",
        "Taylor steps from 0 to 1e+10 s (rtol 1e-14), over its limit of 10,000,000: give a shorter stop time",
    ),
    Call(
        "reference", 'reference(20.0, rtol=float("nan"))', "InvalidInput", "rtol nan must be a positive finite number"
    ),
    Call("reference", "reference(20.0, rtol=1e-20)", "InvalidInput", "rtol 1e-20 asks for more than a double holds"),
    Call("reference", "reference(20.0, at=[5.0])", "InvalidInput", "at: 5.0 is no time of the run, 0 to 3 s"),
    Call("reference", 'reference(lambda t: "x", stop_time=0.01)', "InvalidInput", "the torque is 'x' at t = 0.0"),
    Call(
        "reference", 'reference("{files}/no_torque.csv")', "TorqueFileError", "no_torque.csv:1: missing column 'torque'"
    ),
    Call(
        "reference",
        'reference(20.0, theta0=float("nan"))',
        "InvalidInput",
        "theta0 = nan must be a finite number of rad",
    ),
    Call(
        "reference",
        'reference(20.0, stop_time=0.01, parameters={"mass": 1e308})',
        "InvalidInput",
        "the reference cannot integrate the pendulum from t = 0 s with mass = 1e+308",
    ),
    Call("reference", "reference_schedule(None)", "WrongType", "plan is a TorqueSchedule"),
    Call("linearize", 'linearize(theta=float("nan"))', "InvalidInput", "theta = nan must be a finite number of rad"),
    Call("linearize", 'linearize(torque="1")', "InvalidInput", "torque = '1' must be a finite number of N.m"),
    Call(
        "linearize",
        'linearize(parameters={"damping": -1.0})',
        "InvalidInput",
        "the FMU refuses the parameters: damping must be >= 0",
    ),
    Call("compare", f'compare(20.0, "fmu", {OUT})', "ToolSpecError", "compare needs at least two tools, got fmu"),
    Call("compare", f'compare(20.0, ["fmu", "matlab"], {OUT})', "ToolSpecError", "unknown tool(s) matlab"),
    Call("compare", f"compare(20.0, 42, {OUT})", "WrongType", "tools is a comma-separated string or a list of names"),
    Call(
        "compare",
        'compare(20.0, "fmu,reference", output_dir=None)',
        "WrongType",
        "output_dir is a folder's path, not None",
    ),
    Call(
        "compare",
        f'compare(20.0, "fmu,reference", tolerance=-1, {OUT})',
        "InvalidInput",
        "the tolerance -1 must be a positive finite number",
    ),
    Call(
        "compare",
        f'compare(20.0, "fmu,reference", mapping="torque=u", {OUT})',
        "ToolSpecError",
        "--map applies to FMUs given as LABEL=path/to/Their.fmu in --tools, and there is none",
    ),
    Call(
        "compare",
        'compare(20.0, "fmu,reference", stop_time=0.01, output_dir="{files}/bad_number.csv/out")',
        "CannotWrite",
        "bad_number.csv is a file, not a folder; choose another output path",
    ),
    Call("sweep", "sweep_grid([1.0, 1.0])", "InvalidInput", "torque values repeat: [1.0, 1.0]"),
    Call("sweep", 'sweep_grid([1.0], extra={"colour": [1.0]})', "InvalidInput", "cannot sweep 'colour'"),
    Call(
        "sweep", 'sweep_grid([1.0], extra=[("damping", [0.0])])', "WrongType", "extra is a dict {name: [values, ...]}"
    ),
    Call("sweep", "Study([])", "InvalidInput", "no cases to run"),
    Call("sweep", "Study([1.0, 2.0])", "WrongType", "case 0 is 1.0, not a dict"),
    Call("sweep", 'Study([{"torque": 1.0}, {"torque": 1.0}])', "InvalidInput", "case 1 repeats case 0"),
    Call("sweep", 'Study([{"torque": 1.0}], outputs="theta")', "WrongType", "outputs is a list of names"),
    Call(
        "sweep",
        'Study([{"torque": 1.0}], output_interval=0.0015)',
        "InvalidInput",
        "output interval 0.0015 s must be a whole number of steps of 0.001 s",
    ),
    Call("sweep", 'Study([{"torque": 1.0}], format="xlsx")', "InvalidInput", "format 'xlsx': choose parquet or csv"),
    Call(
        "sweep",
        f'run_sweep([{{"torque": 1.0}}], {OUT})',
        "WrongType",
        "run_sweep takes a Study(cases, ...), not a list",
    ),
    Call(
        "sweep",
        f"run_sweep({ONE}, output_dir=None)",
        "WrongType",
        "output_dir is a folder's path or an fsspec URL, not None",
    ),
    Call("sweep", f"run_sweep({ONE}, {OUT}, workers=0)", "InvalidInput", "workers must be a positive integer"),
    Call(
        "sweep",
        f"run_sweep({ONE}, {OUT}, resume=True, overwrite=True)",
        "InvalidInput",
        "and overwrite replaces it: choose one",
    ),
    Call(
        "sweep",
        f'run_sweep({ONE}, {OUT}, scheduler="tcp://127.0.0.1:9", connect_timeout=1)',
        "SchedulerUnreachable",
        "no dask scheduler answered at tcp://127.0.0.1:9 within 1 s",
    ),
    Call(
        "sweep",
        f'run_sweep({ONE}, {OUT}, security=tls_files("{{files}}/result.csv", "{{files}}/result.csv"))',
        "InvalidInput",
        "security is for a scheduler's address",
    ),
    Call(
        "sweep",
        f'run_sweep({ONE}, {OUT}, scheduler="tls://127.0.0.1:9", security="{{files}}/result.csv")',
        "WrongType",
        "security is a distributed.security.Security, e.g. tls_files(...)",
    ),
    Call(
        "sweep",
        f'run_sweep({ONE}, output_dir="{{files}}/bad_number.csv")',
        "CannotWrite",
        "cannot write {files}/bad_number.csv: the folder {files}/bad_number.csv cannot be created",
    ),
    Call("sweep", f'run_sweep({ONE}, output_dir="nosuch://study")', "InvalidInput", "Protocol not known: nosuch"),
    Call(
        "sweep",
        f'run_sweep({ONE}, output_dir="{{files}}/not_a_study")',
        "StudyExists",
        "holds study.json but no study.json of a sweep",
    ),
    Call(
        "scenarios",
        'write_scenarios("{files}/old_kit")',
        "KitExists",
        "{files}/old_kit already holds a scenario kit (ReadMe.md): choose another output directory, or add --overwrite",
    ),
    Call(
        "scenarios",
        'read_settings("{files}/settings/stop_nan_text.json")',
        "InvalidInput",
        'stop_nan_text.json: stop_time is "NaN"; it must be a finite number (s)',
    ),
    Call(
        "scenarios",
        'read_settings("{files}/settings/stop_nan.json")',
        "InvalidInput",
        "stop_nan.json: stop_time is NaN; it must be a finite number (s)",
    ),
    Call(
        "scenarios",
        'read_settings("{files}/settings/stop_before_start.json")',
        "InvalidInput",
        "stop_before_start.json: stop_time -1.0 is not after start_time 0.0",
    ),
    Call(
        "scenarios",
        'read_settings("{files}/settings/tolerance_text.json")',
        "InvalidInput",
        'tolerance_text.json: tolerance is "x"; it must be a positive finite number (rad)',
    ),
    Call(
        "scenarios",
        'read_settings("{files}/settings/output_null.json")',
        "InvalidInput",
        "output_null.json: output is null; it must be a file name (a JSON string)",
    ),
    Call(
        "scenarios",
        'read_settings("{files}/settings/input_null.json")',
        "InvalidInput",
        "input_null.json: input is null; it must be a file name (a JSON string)",
    ),
    Call(
        "scenarios",
        'read_settings("{files}/settings/ramp_text.json")',
        "InvalidInput",
        'ramp_text.json: ramp is "yes"; it must be true or false',
    ),
    Call(
        "scenarios",
        'read_settings("{files}/settings/parameters_list.json")',
        "InvalidInput",
        "parameters_list.json: parameters is []; it must be an object {name: value}",
    ),
    Call(
        "scenarios",
        'read_settings("{files}/settings/list.json")',
        "InvalidInput",
        "list.json: not a scenario's settings: it holds a JSON array, not an object",
    ),
    Call(
        "judge",
        'judge("{files}/result.csv", 1.0, stop_time=0.001, mapping=3)',
        "WrongType",
        "a map is text such as 'time=t,theta=phi*0.0174532925' or a dict such as",
    ),
    Call(
        "judge",
        'judge("{files}/result.csv", 1.0, stop_time=0.001, mapping={"theta": "phi"})',
        "ResultFileError",
        "result.csv:1: no column 'phi'",
    ),
    Call(
        "judge",
        'judge_results(["{files}/result.csv", "{files}/absent.csv"], 1.0, stop_time=0.001)',
        "ResultFileError",
        "absent.csv: cannot read: No such file or directory",
    ),
    Call(
        "judge",
        'judge(simulate(1.0, stop_time=0.01), 1.0, stop_time=0.01, mapping="theta=theta*2")',
        "InvalidInput",
        "a map renames and scales a result file's columns: an array result is judged as it is",
    ),
    Call(
        "simulate",
        "simulate(1.0, stop_time=0.01, fmu_path=0)",
        "WrongType",
        "fmu_path is the FMU file's path (a str or Path), not 0",
    ),
    Call(
        "received file",
        'simulate(20.0, fmu_path="{files}/escaping.fmu")',
        "FmuFileError",
        "escaping.fmu: the archive's entry '../../escaped.txt' would be unpacked outside its folder",
    ),
    Call("received file", 'simulate("{files}/nul.csv")', "TorqueFileError", "nul.csv:3: a NUL byte"),
    Call(
        "received file",
        'judge("{files}/long_result.csv", 1.0, stop_time=0.001)',
        "ResultFileError",
        "long_result.csv:3: the line is longer than 131,072 characters",
    ),
    Call(
        "received file",
        'read_settings("{files}/settings/deep.json")',
        "InvalidInput",
        "deep.json: not a scenario's settings: nested too deep",
    ),
    Call(
        "received file",
        'read_settings("{files}/settings/large.json")',
        "InvalidInput",
        "large.json: over 1,048,576 bytes, longer than any such file",
    ),
    Call(
        "received file",
        'read_settings("{files}/settings/input_elsewhere.json")',
        "InvalidInput",
        'input_elsewhere.json: input is "../../.ssh/id_rsa"; it must be the name of a file in the kit\'s folder',
    ),
    Call(
        "received file",
        'read_settings("{files}/settings/input_absolute.json")',
        "InvalidInput",
        'input_absolute.json: input is "/etc/hostname"; it must be the name of a file in the kit\'s folder',
    ),
    Call(
        "gymnasium environment",
        'gymnasium.make("pendulum_fmu.gym:PendulumFMU-v0", masss=2.0)',
        "InvalidInput",
        "unknown keyword 'masss': the keywords are the FMU's parameters (mass, length, inertia, gravity, damping), "
        "max_torque, dt, tolerance, fmu, render_mode",
    ),
    Call(
        "gymnasium environment",
        'gymnasium.make("pendulum_fmu.gym:PendulumFMU-v0", dt=-0.05)',
        "InvalidInput",
        "dt = -0.05 s must be positive and finite",
    ),
    Call(
        "gymnasium environment",
        'gymnasium.make("pendulum_fmu.gym:PendulumFMU-v0", mass=0.0)',
        "FmuError",
        "initialization failed: [ERROR] fmi2ExitInitializationMode: mass must be > 0",
    ),
    Call(
        "gymnasium environment",
        'gymnasium.make_vec("pendulum_fmu.gym:PendulumFMU-v0", num_envs=0)',
        "InvalidInput",
        "num_envs = 0 must be from 1 to 1,000,000",
    ),
    Call(
        "gymnasium environment",
        'gymnasium.make_vec("pendulum_fmu.gym:PendulumFMU-v0", num_envs=10**9)',
        "InvalidInput",
        "num_envs = 1000000000 must be from 1 to 1,000,000",
    ),
    Call(
        "gymnasium environment",
        "pendulum_fmu.gym.PendulumFmuEnv().step(np.array([1.0]))",
        "InvalidInput",
        "step before reset (or after a step the FMU refused): call reset() first",
    ),
    Call(
        "gymnasium environment",
        '((env := pendulum_fmu.gym.PendulumFmuEnv()), env.reset(seed=0), env.step(np.array([float("nan")])))',
        "InvalidInput",
        "action array([nan]) is not finite: every torque must be a finite number of N.m",
    ),
    Call(
        "gymnasium environment",
        "((env := pendulum_fmu.gym.PendulumFmuEnv()), env.reset(seed=0), env.step(np.array([1.0, 2.0])))",
        "InvalidInput",
        "action of shape (2,): the action space's shape is (1,)",
    ),
    Call(
        "gymnasium environment",
        '((envs := gymnasium.make_vec("pendulum_fmu.gym:PendulumFMU-v0", num_envs=4)), envs.reset(seed=0), '
        "envs.step(np.zeros(4)))",
        "InvalidInput",
        "action of shape (4,): the action space's shape is (4, 1)",
    ),
    Call("other", "default_fmu(fmi_version=4)", "InvalidInput", "no FMI 4 FMU: the FMI versions are 2, 3"),
    Call(
        "other",
        'create_closed_loop_fmu("{files}/loop.fmu", step_size=0)',
        "InvalidInput",
        "step size 0 must be a positive number of seconds",
    ),
]


# The package's FMU with its modelDescription.xml edited by hand after the build.
EDITED_FMUS = {
    "other_guid.fmu": lambda xml: re.sub(
        r'guid="[^"]*"', 'guid="{00000000-0000-0000-0000-000000000000}"', xml, count=1
    ),
    "other_identifier.fmu": lambda xml: xml.replace('modelIdentifier="Pendulum"', 'modelIdentifier="Nope"'),
}


def _edited_fmu(edit) -> bytes:
    from pendulum_fmu import default_fmu

    buffer = io.BytesIO()
    with zipfile.ZipFile(default_fmu()) as original, zipfile.ZipFile(buffer, "w") as copy:
        for item in original.infolist():
            data = original.read(item)
            copy.writestr(item, edit(data.decode()).encode() if item.filename == "modelDescription.xml" else data)
    return buffer.getvalue()


def alpha_not_an_output(xml: str) -> str:
    """The pendulum's model description with alpha a local variable: outputs theta and omega."""
    edited = xml.replace(
        'name="alpha" valueReference="3" causality="output"', 'name="alpha" valueReference="3" causality="local"'
    )
    edited = re.sub(r'\s*<Unknown index="4" [^>]*/>(\s*</Outputs>)', r"\1", edited, count=1)
    assert edited.count('causality="output"') == 2 and "<Outputs>" in edited
    return edited


@dataclass(frozen=True)
class Sparse:
    """A file of this many zero bytes, which takes no room on the disk."""

    size: int


def sparse_files() -> dict[str, Sparse]:
    """Files past the size a file read whole may have (_received_files.py's MAX_*_BYTES)."""
    from pendulum_fmu._received_files import MAX_STUDY_BYTES, MAX_TORQUE_CSV_BYTES

    return {
        "huge_study/study.json": Sparse(MAX_STUDY_BYTES + 1),
        "huge_torque_file.csv": Sparse(MAX_TORQUE_CSV_BYTES + 1),
    }


def write_files(folder: Path) -> None:
    files = {
        **FILES,
        **received_files(),
        **{name: _edited_fmu(edit) for name, edit in EDITED_FMUS.items()},
        **sparse_files(),
    }
    for name, content in files.items():
        path = folder / name
        path.parent.mkdir(exist_ok=True)
        if isinstance(content, Sparse):
            with open(path, "wb") as file:
                file.truncate(content.size)
        else:
            path.write_bytes(content) if isinstance(content, bytes) else path.write_text(content)


@contextlib.contextmanager
def _no_runtime_warnings():
    """Numpy's RuntimeWarnings (overflow, invalid value) raised as errors: printed, each would be
    lines beside the one line, and pytest would record them instead, unseen.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        yield


def run_case(case: Case, folder: Path) -> tuple[int, str]:
    """(exit code, what the command printed on stderr), run in-process."""
    from pendulum_fmu.cli import main

    argv = [part.format(files=folder) for part in case.argv]
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()), _no_runtime_warnings():
        try:
            code = main(argv)
        except SystemExit as exit_:  # argparse's own refusals
            code = exit_.code
    return code, stderr.getvalue().replace(str(folder), "{files}")


def run_call(call: Call, folder: Path) -> BaseException | None:
    """What the call raises, run in-process (None when it raises nothing)."""
    namespace: dict = {}
    exec(API_IMPORTS, namespace)
    code = call.code.replace("{files}", str(folder))
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()), _no_runtime_warnings():
        try:
            eval(code, namespace)
        except Exception as error:
            return error
    return None


def raised(error: BaseException | None, folder: Path) -> tuple[str, str]:
    """The error's type and message as the table shows them."""
    if error is None:
        return "nothing", ""
    return type(error).__name__, str(error).replace(str(folder), "{files}")


def markdown(rows: list[tuple[Case, int, str]], calls: list[tuple[Call, str, str]]) -> str:
    lines = [
        "# What the command line and the Python API answer to bad input",
        "",
        "Generated by `python tests/bad_inputs.py docs/bad_inputs.md` from the cases that "
        "`tests/test_bad_inputs.py` asserts; do not edit by hand. Every answer is one line on "
        "stderr (argparse's own refusals add the usage line before it), never a traceback; "
        "`--debug` shows the traceback instead. Nothing is written when a run is refused.",
        "",
        "| group | command | exit | answer |",
        "|---|---|---|---|",
    ]
    for case, code, printed in rows:
        answer = printed.strip().splitlines()[-1].replace("|", "\\|")
        lines.append(f"| {case.group} | `pendulum-fmu {' '.join(case.argv)}` | {code} | {answer} |")
    lines += [
        "",
        "## The Python API",
        "",
        "Each call runs after",
        "",
        "```python",
        API_IMPORTS,
        "```",
        "",
        "and raises a subclass of `pendulum_fmu.PendulumFmuError` (each also derives "
        "from the built-in exception a caller expects: `ValueError`, `TypeError`, `OSError`, "
        "...) whose message is one line; no numpy, scipy or fmpy error gets through. "
        "Nothing is written when a call is refused.",
        "",
        "| group | call | raises | message |",
        "|---|---|---|---|",
    ]
    for call, error, message in calls:
        message = message.replace("|", "\\|")
        lines.append(f"| {call.group} | `{call.code}` | {error} | {message} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    import tempfile

    out = Path((argv or sys.argv[1:] or ["docs/bad_inputs.md"])[0])
    with tempfile.TemporaryDirectory() as folder:
        write_files(Path(folder))
        rows = [(case, *run_case(case, Path(folder))) for case in CASES]
        calls = [(call, *raised(run_call(call, Path(folder)), Path(folder))) for call in CALLS]
    from pendulum_fmu._atomic_files import replacing

    with replacing(out) as file:
        file.write(markdown(rows, calls))
    print(f"wrote {out}: {len(rows)} command lines, {len(calls)} calls")


if __name__ == "__main__":
    main()
