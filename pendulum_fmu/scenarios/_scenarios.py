"""A kit for testing a master with this FMU: scenarios with their input, settings and reference.

    pendulum-fmu scenarios --output-dir kit

writes into kit/:
- Pendulum.fmu: the FMU, carrying the kit as FMI-LS-REF related files (below);
- per scenario NAME: NAME_in.csv, the torque (time,torque in fmpy's convention, docs/signals.md);
  NAME.json, the settings (start, stop, communication step, every parameter, the initial state,
  whether the torque ramps, where a run resumes from a saved state); NAME_ref.csv, the independent
  reference (reference.reference) at every communication point: time,torque,theta,omega,alpha;
- ReadMe.md: what a master's vendor does with it.

A master runs each scenario and writes NAME_out.csv beside its input; `pendulum-fmu judge kit`
judges each one (_judge.py).

FMI-LS-REF, the layered standard for related files in an FMU, followed as of its v1.0.0-beta.1
(github.com/modelica/fmi-ls-ref, tag v1.0.0-beta.1, 2026-07-01): the FMU carries
extra/org.fmi-standard.fmi-ls-ref/fmi-ls-manifest.xml, whose Related elements name the
experiments file (role experiment/validation), each scenario's parameter set (role parameter, an
SSV file of SSP 1.0 that also sets the start values of theta and omega), settings (role
configuration) and reference (role result), each labelled scenario:NAME; and
documentation/fmi-ls-ref.txt, as the standard recommends. Where it departs:
- The experiments file's format is now MA-HS-Experiments (application/x-ma-hs-experiments), a
  separate specification this project could not obtain; the file follows the format FMI-LS-REF
  itself defined until it moved out (its appendix A, removed in commit cd7d904, 2026-06-17):
  Experiments/Experiment with startTime, stopTime, stepSize, tolerance and Parameters, Stimuli
  and References sources.
- That format has no place for what the judge needs besides: whether the torque ramps (input
  derivatives) and where a run is stopped and resumed. NAME.json carries them (and everything
  else), and each experiment's description says them in words.
- The standard's own table gives fmi-ls-version as 1.0.0-alpha.1 even in the beta.1 text; the
  manifest says 1.0.0-beta.1, the version followed.
"""

from __future__ import annotations

import json
import os
import shutil
import uuid
from pathlib import Path
from xml.etree import ElementTree

from .. import __version__
from .._atomic_files import check_writable, make_folder, replacing, replacing_path
from .._errors import InvalidInput, PendulumFmuError
from .._stop_signals import signals_deferred
from ..fmu import _results as results
from ..fmu._build_record import read_entries, rewrite_fmu
from ..fmu._model import START_VALUES, FmuModel, fmu_model
from ..fmu._simulate import resolve_parameters
from ..oracle._reference import reference
from ._scenario_list import SCENARIOS, Scenario
from ._scenario_settings import KIT_FMU, RELATIVE_TOLERANCE, scenario_settings

LS_REF_NAME = "org.fmi-standard.fmi-ls-ref"
LS_REF_VERSION = "1.0.0-beta.1"
LS_REF_FOLDER = f"extra/{LS_REF_NAME}/"
LS_REF_DOCUMENTATION = "documentation/fmi-ls-ref.txt"
EXPERIMENTS_FILE = "scenarios.exp"
EXPERIMENTS_TYPE = "application/x-ma-hs-experiments"
SSV_NAMESPACE = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"


def _csv_text(header: tuple[str, ...], rows) -> str:
    return ",".join(header) + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n" for row in rows)


def _ssv(scenario: Scenario, parameters: dict) -> bytes:
    """The parameter set and initial state as an SSV file (SSP 1.0); theta and omega are the
    FMU's own variables, so the set applies as-is.
    """
    ElementTree.register_namespace("ssv", SSV_NAMESPACE)

    def tag(name: str) -> str:
        return f"{{{SSV_NAMESPACE}}}{name}"

    root = ElementTree.Element(tag("ParameterSet"), {"version": "1.0", "name": scenario.name})
    listed = ElementTree.SubElement(root, tag("Parameters"))
    values = {**parameters, START_VALUES["theta0"]: scenario.theta0, START_VALUES["omega0"]: scenario.omega0}
    for name, value in values.items():
        parameter = ElementTree.SubElement(listed, tag("Parameter"), {"name": name})
        ElementTree.SubElement(parameter, tag("Real"), {"value": repr(float(value))})
    return _xml(root)


def _xml(root: ElementTree.Element) -> bytes:
    ElementTree.indent(root)
    return ElementTree.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"


def _description(scenario: Scenario) -> str:
    how = "ramped with first-order input derivatives" if scenario.ramp else "held over each step"
    resume = (
        f"; stop at {scenario.resume_time:g} s and resume from the saved FMU state"
        if scenario.resume_time is not None
        else ""
    )
    return f"{scenario.description} Torque {how}{resume}; settings in {scenario.name}.json."


def _experiments() -> bytes:
    root = ElementTree.Element(
        "Experiments",
        {
            "name": "pendulum-fmu scenarios",
            "description": f"Runs that test a master with this FMU (pendulum_fmu {__version__}): judge a "
            "result with pendulum-fmu judge",
        },
    )
    for scenario in SCENARIOS:
        experiment = ElementTree.SubElement(
            root,
            "Experiment",
            {
                "name": scenario.name,
                "description": _description(scenario),
                "startTime": repr(scenario.start_time),
                "stopTime": repr(scenario.stop_time),
                "stepSize": repr(scenario.step_size),
                "tolerance": repr(RELATIVE_TOLERANCE),
            },
        )
        ElementTree.SubElement(experiment, "Parameters", {"source": f"{scenario.name}.ssv"})
        ElementTree.SubElement(experiment, "Stimuli", {"source": f"{scenario.name}_in.csv"})
        ElementTree.SubElement(experiment, "References", {"source": f"{scenario.name}_ref.csv"})
    return _xml(root)


def _manifest() -> bytes:
    namespace = "http://fmi-standard.org/fmi-ls-manifest"
    ElementTree.register_namespace("fmi-ls", namespace)
    root = ElementTree.Element(
        "fmiReferences",
        {
            f"{{{namespace}}}fmi-ls-name": LS_REF_NAME,
            f"{{{namespace}}}fmi-ls-version": LS_REF_VERSION,
            f"{{{namespace}}}fmi-ls-description": "Layered Standard providing information on related files "
            "included in an FMU.",
        },
    )
    ElementTree.SubElement(
        root,
        "Related",
        {
            "type": EXPERIMENTS_TYPE,
            "source": EXPERIMENTS_FILE,
            "role": "experiment/validation",
            "description": "Scenarios that test a master with this FMU, each with its stimuli and reference",
        },
    )
    for scenario in SCENARIOS:
        for suffix, kind, role, what in (
            (".ssv", "application/x-ssp-parameter-set", "parameter", "parameters and initial state"),
            (".json", "application/json", "configuration", "settings"),
            ("_ref.csv", "text/csv", "result", "reference result"),
        ):
            related = ElementTree.SubElement(
                root,
                "Related",
                {
                    "type": kind,
                    "source": f"{scenario.name}{suffix}",
                    "role": role,
                    "description": f"{scenario.name}: {what}",
                },
            )
            ElementTree.SubElement(related, "Label", {"name": f"scenario:{scenario.name}"})
    return _xml(root)


def _readme(steps: dict[str, int]) -> str:
    rows = "\n".join(
        f"| `{s.name}` | {s.description} | {steps[s.name]:,} | {'ramp' if s.ramp else 'held'} |" for s in SCENARIOS
    )
    return f"""# Scenarios for a master running the pendulum FMU (pendulum_fmu {__version__})

Each scenario is a run of `{KIT_FMU}` (FMI 2.0, Co-Simulation or Model Exchange) under a torque
signal. Run it in your master, write what it gives, and let `pendulum-fmu judge` say whether your
master handed the FMU the signal that was meant and, when not, what it did.

| scenario | what it tests | steps | torque |
|---|---|---|---|
{rows}

For each scenario NAME:

1. Read `NAME.json`: `start_time`, `stop_time` and `step_size` (s, the communication step),
   `parameters` (set them before initialization, or apply `NAME.ssv` from the FMU's
   `{LS_REF_FOLDER}`), `theta0` and `omega0` (the start values of `theta` and `omega`),
   `relative_tolerance` for `fmi2SetupExperiment`, `ramp`, and `resume_time`.
2. Feed `torque` from `NAME_in.csv`: columns time (s), torque (N.m), linear between rows, a jump
   where a time repeats (the step that starts at the jump holds the value after it), held before
   the first row and after the last. Communication points are start + k * step_size (a product,
   not a running sum); a time in the file within a billionth of a step of one is that point.
   With `"ramp": false` each step holds the value just after its start. With `"ramp": true` each
   step ramps: set the value at its start with `fmi2SetReal` and the slope with
   `fmi2SetRealInputDerivatives` (order 1) before `fmi2DoStep`.
3. With a `resume_time`, stop there, keep the FMU state (`fmi2GetFMUstate`, and
   `fmi2SerializeFMUstate` to store it), free the instance, restore the state into a new one
   (`fmi2DeSerializeFMUstate`, `fmi2SetFMUstate`) and go on, setting the torque again.
4. Write `NAME_out.csv` beside `NAME_in.csv`: a header `time,theta` (omega and alpha may follow),
   a row per communication point from the start, every number with 17 significant digits. Other
   names or units: tell the judge with `--map time=t,theta=phi*0.0174532925`.

Then, in this folder:

    pendulum-fmu judge .

prints one line per scenario: pass or fail (max |theta - reference| against `tolerance`, 1e-9 rad),
and for a failure the mistake that explains it (input one step late or early, interpolated where
it holds, held where it ramps, time grid drift, state not restored, integration error), with its
residual. `pendulum-fmu judge NAME_out.csv` with the scenario's options (`--torque-file
NAME_in.csv --step-size ... --set ...`) gives the full table, `--plot` a figure, `--json` the
numbers. `NAME_ref.csv` holds the reference itself: time (s), torque (N.m), theta (rad), omega
(rad/s), alpha (rad/s2) at every communication point, from the reference (its Taylor series, 1e-14 a step).

With each `NAME_out.csv`, send the FMU's call record of that run as `NAME_calls.log`: the FMU
writes one `[pendulum-calls]` line per call it receives (category `logCalls`) when the master
turns logging on, and `pendulum-fmu judge --calls NAME_calls.log` with the scenario's options
names what the master did differently, step by step. How to get it:

- fmpy: `fmpy simulate ... --debug-logging > NAME_calls.log` (API: `simulate_fmu(...,
  debug_logging=True)`, stdout); `--fmi-logging` adds fmpy's own call log, which the judge also
  reads.
- fmusim: `--logging-on --log-file NAME_calls.log`, or `--log-fmi-calls --fmi-log-file
  NAME_calls.log` (fmusim's own call log).
- libcosim: `log_output_level(CosimLogLevel.TRACE)`; send its whole output.
- OMSimulator: a release build drops the FMU's messages of status OK, so set the FMU's String
  parameter `callRecordFile` to a path (`oms_setString(".../callRecordFile", "NAME_calls.log")`
  before initialization). The FMU appends its record to that file itself.
- Simulink (FMIKit), Dymola: set the FMU's parameter `callRecordFile` to `NAME_calls.log`, or
  turn on the FMU's debug logging and send the log they write.
- Any master: `callRecordFile` works whatever the master does with the FMU's messages.

`{KIT_FMU}` carries the same files under `{LS_REF_FOLDER}` as related files of the FMI layered
standard FMI-LS-REF {LS_REF_VERSION}: `fmi-ls-manifest.xml`, the experiments file
`{EXPERIMENTS_FILE}`, and per scenario its parameter set, settings, input and reference.
"""


def _write(path: Path, text: str) -> None:
    with replacing(path, newline="") as file:
        file.write(text)


class KitExists(PendulumFmuError, FileExistsError):
    """The output folder holds files of a scenario kit that writing the kit would replace without
    being asked to; the message names them and --overwrite.
    """


def kit_files() -> tuple[str, ...]:
    """The names of the files `pendulum-fmu scenarios` writes into its folder (results a master
    writes there, NAME_out.csv, are none of them).

    Returns
    -------
    tuple of str
        The FMU, ReadMe.md, and per scenario NAME_in.csv, NAME_ref.csv and NAME.json.
    """
    return (
        KIT_FMU,
        "ReadMe.md",
        *(f"{s.name}{suffix}" for s in SCENARIOS for suffix in ("_in.csv", "_ref.csv", ".json")),
    )


def _check_replaceable(folder: Path, overwrite: bool) -> None:
    held = [name for name in kit_files() if (folder / name).exists()]
    if held and not overwrite:
        shown = ", ".join(held[:3]) + (f" and {len(held) - 3} more" if len(held) > 3 else "")
        raise KitExists(
            f"{folder} already holds a scenario kit ({shown}): choose another output "
            "directory, or add --overwrite to write the kit again in its place (the "
            "results NAME_out.csv beside it are kept)"
        )


def write_scenarios(
    output_dir: str | Path, fmu_path: str | Path | FmuModel | None = None, overwrite: bool = False
) -> list[Path]:
    """Write the scenario kit (see the module's docstring).

    The kit is written into a hidden folder inside output_dir and moved into place once whole, so
    a run that fails or is stopped leaves the folder as it was.

    Parameters
    ----------
    output_dir : str or Path
        The kit's folder; results a user put there (NAME_out.csv) are left alone.
    fmu_path : str, Path or FmuModel, optional
        The FMI 2.0 FMU to carry and whose parameters apply, or its model (default:
        pendulum_fmu.default_fmu()).
    overwrite : bool, optional
        Replace the files of a kit the folder already holds (kit_files()); without it such a
        folder is refused. Other files in it are kept either way.

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    InvalidInput
        An FMU that is not FMI 2.0 (the ramp scenario needs input derivatives).
    KitExists
        A folder that holds a kit's files, without overwrite.
    CannotWrite
        A folder that cannot be written.

    Examples
    --------
    >>> import tempfile
    >>> from pendulum_fmu import write_scenarios
    >>> written = write_scenarios(tempfile.mkdtemp())
    >>> sorted(path.name for path in written if path.name.startswith("ramp"))
    ['ramp.json', 'ramp_in.csv', 'ramp_ref.csv']
    """
    model = fmu_model(fmu_path)
    version = model.description.fmiVersion
    if version != "2.0":
        raise InvalidInput(
            f"{model.path} is FMI {version}: the kit is for the FMI 2.0 FMU (its ramp scenario needs input derivatives)"
        )
    folder = Path(output_dir)
    _check_replaceable(folder, overwrite)
    # Refused now, not after the references are computed.
    check_writable(folder / KIT_FMU)
    make_folder(folder, folder, "output directory")
    staging = folder / f".scenarios.{uuid.uuid4().hex}.partial"
    try:
        names = _write_kit(staging, model)
        with signals_deferred():
            for name in names:
                os.replace(staging / name, folder / name)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return [folder / name for name in names]


def _write_kit(folder: Path, model: FmuModel) -> list[str]:
    """Write the kit into folder; returns the names written, the FMU first."""
    written, carried, steps = [], {}, {}
    for scenario in SCENARIOS:
        name = scenario.name
        parameters = resolve_parameters(scenario.parameters, model)
        signal = folder / f"{name}_in.csv"
        files = {signal.name: _csv_text(("time", "torque"), scenario.rows)}
        _write(signal, files[signal.name])
        # The reference reads the input file itself, as a master does.
        solution = reference(
            signal,
            start_time=scenario.start_time,
            stop_time=scenario.stop_time,
            step_size=scenario.step_size,
            ramp=scenario.ramp,
            parameters=parameters,
            theta0=scenario.theta0,
            omega0=scenario.omega0,
            fmu_path=model,
        )
        steps[name] = len(solution) - 1
        # The reference's own fields, in the kit's FMU's units.
        fields = results.fields(solution)
        files[f"{name}_ref.csv"] = _csv_text(fields, (tuple(row) for row in solution.tolist()))
        settings = scenario_settings(scenario, parameters, results.units(fields, model))
        files[f"{name}.json"] = json.dumps(settings, indent=2) + "\n"
        for file_name, text in files.items():
            if file_name != signal.name:
                _write(folder / file_name, text)
            written.append(file_name)
            carried[LS_REF_FOLDER + file_name] = text.encode()
        carried[f"{LS_REF_FOLDER}{name}.ssv"] = _ssv(scenario, parameters)
    readme = _readme(steps)
    carried.update(
        {
            f"{LS_REF_FOLDER}fmi-ls-manifest.xml": _manifest(),
            LS_REF_FOLDER + EXPERIMENTS_FILE: _experiments(),
            LS_REF_DOCUMENTATION: readme.encode(),
        }
    )
    _write(folder / "ReadMe.md", readme)
    written.append("ReadMe.md")
    # A kit FMU given as the source: its old kit files give way to the new ones.
    entries = {
        name: data
        for name, data in read_entries(model.path).items()
        if not (name.startswith(LS_REF_FOLDER) or name == LS_REF_DOCUMENTATION)
    }
    with replacing_path(folder / KIT_FMU) as partial:
        # The record names the kit's files too, so that `verify` finds them its own.
        rewrite_fmu(partial, {**entries, **carried}, {"kit": f"pendulum_fmu {__version__} scenarios"})
    return [KIT_FMU, *written]
