"""ClosedLoop.ssp: the pendulum under the PID controller as an SSP 1.0 system for any master.

The archive holds SystemStructure.ssd (both components, the three connections, the
DefaultExperiment), both FMUs under resources/, and one parameter set (.ssv) per component bound
to it. Fixed-step masters need to be told the step in their own annotation: libcosim reads
osp:FixedStepAlgorithm from the DefaultExperiment (without it, and without a step from its
caller, libcosimpy 0.0.6 crashes), OMSimulator its org.openmodelica FixedStepMaster from the
system. read_ssp() reads back what a judge needs: the stop time, the step and the parameter sets.
"""

from __future__ import annotations

import math
import numbers
import os
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree

from .. import default_fmu
from .._atomic_files import replacing
from .._errors import InvalidInput, MissingFile, PendulumFmuError
from .._received_files import check_xml, open_archive, open_fmu
from ..fmu._simulate import resolve_parameters
from ._closed_loop import WIRES, controller_defaults, controller_fmu

NAMESPACES = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
    "oms": "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd",
}
# The component's name in the system, its FMU under resources/, and which way each of its
# connectors points.
COMPONENTS = {
    "pendulum": ("resources/Pendulum.fmu", {"torque": "input", "theta": "output", "omega": "output"}),
    "controller": ("resources/PIDController.fmu", {"theta": "input", "omega": "input", "torque": "output"}),
}
# The setpoint the exported parameter set carries: not the controller's own default (0.5 rad), so
# that a result shows whether a master applied the set.
DEFAULT_SETPOINT = 0.3


class SspExists(PendulumFmuError, FileExistsError):
    """The SSP to write is there already and the user did not ask to replace it."""


class SspFileError(PendulumFmuError, ValueError):
    """A file given as the closed loop's SSP that is not one.

    No zip, no SystemStructure.ssd, no step annotation or no parameter set.
    """


@dataclass(frozen=True)
class SspSettings:
    """What an SSP asks of its master.

    Attributes
    ----------
    stop_time, step_size : float
        The DefaultExperiment's stop time and the fixed step of its annotations, in s.
    controller : dict
        The controller's parameter set (setpoint, kp, ki, kd).
    pendulum : dict
        The pendulum's parameter set.
    call_record : str
        The pendulum's callRecordFile in its set: where it writes the record of every FMI call
        it receives (docs/calls.md); '' when the set has none.
    """

    stop_time: float
    step_size: float
    controller: dict
    pendulum: dict
    call_record: str = ""


def _positive(name: str, value) -> float:
    if not (isinstance(value, numbers.Real) and 0 < float(value) < math.inf):
        raise InvalidInput(f"{name} {value!r} must be a positive number of seconds")
    return float(value)


def _tag(prefix: str, name: str) -> str:
    return f"{{{NAMESPACES[prefix]}}}{name}"


def _element(parent, prefix: str, tag: str, **attributes) -> ElementTree.Element:
    return ElementTree.SubElement(parent, _tag(prefix, tag), {k: str(v) for k, v in attributes.items()})


def parameter_set_xml(name: str, values: dict[str, float], strings: dict[str, str] | None = None) -> bytes:
    """An SSP 1.0 parameter set (.ssv) of real values, and string ones.

    Parameters
    ----------
    name : str
        The set's name.
    values : dict
        Parameter name (relative to the component it is bound to) to value.
    strings : dict, optional
        String parameters, name to value, set before the real ones (the pendulum's
        callRecordFile: a record opens when it is set, so what is set after it is in the record).

    Returns
    -------
    bytes
        The .ssv document, UTF-8.

    Examples
    --------
    >>> parameter_set_xml("controller", {"setpoint": 0.3})[:5]
    b'<?xml'
    """
    root = ElementTree.Element(_tag("ssv", "ParameterSet"), version="1.0", name=name)
    parameters = _element(root, "ssv", "Parameters")
    for parameter, text in (strings or {}).items():
        _element(_element(parameters, "ssv", "Parameter", name=parameter), "ssv", "String", value=text)
    for parameter, value in values.items():
        _element(_element(parameters, "ssv", "Parameter", name=parameter), "ssv", "Real", value=repr(float(value)))
    return ElementTree.tostring(root, encoding="UTF-8", xml_declaration=True)


def system_structure_xml(stop_time: float, step_size: float) -> bytes:
    """SystemStructure.ssd of the closed loop.

    Components, connections, DefaultExperiment and the fixed-step annotations of libcosim and
    OMSimulator.

    Parameters
    ----------
    stop_time, step_size : float
        The experiment's stop time and the fixed communication step, in s.

    Returns
    -------
    bytes
        The .ssd document, UTF-8.

    Examples
    --------
    >>> b"FixedStepAlgorithm" in system_structure_xml(3.0, 1e-3)
    True
    """
    for prefix, uri in NAMESPACES.items():
        ElementTree.register_namespace(prefix, uri)
    root = ElementTree.Element(_tag("ssd", "SystemStructureDescription"), version="1.0", name="ClosedLoop")
    system = _element(
        root, "ssd", "System", name="ClosedLoop", description="The pendulum under the PID controller, fixed step"
    )
    elements = _element(system, "ssd", "Elements")
    for name, (source, connectors) in COMPONENTS.items():
        component = _element(
            elements, "ssd", "Component", name=name, source=source, type="application/x-fmu-sharedlibrary"
        )
        listed = _element(component, "ssd", "Connectors")
        for connector, kind in connectors.items():
            _element(_element(listed, "ssd", "Connector", name=connector, kind=kind), "ssc", "Real")
        bindings = _element(component, "ssd", "ParameterBindings")
        _element(
            bindings, "ssd", "ParameterBinding", source=f"resources/{name}.ssv", type="application/x-ssp-parameter-set"
        )
    connections = _element(system, "ssd", "Connections")
    for start, output, end, into in WIRES:
        _element(
            connections,
            "ssd",
            "Connection",
            startElement=start,
            startConnector=output,
            endElement=end,
            endConnector=into,
        )
    oms = _element(_element(system, "ssd", "Annotations"), "ssc", "Annotation", type="org.openmodelica")
    information = _element(_element(oms, "oms", "Annotations"), "oms", "SimulationInformation")
    _element(
        information,
        "oms",
        "FixedStepMaster",
        description="oms-ma",
        stepSize=repr(step_size),
        absoluteTolerance="1e-12",
        relativeTolerance="1e-12",
    )
    experiment = _element(root, "ssd", "DefaultExperiment", startTime="0.0", stopTime=repr(stop_time))
    osp = _element(_element(experiment, "ssd", "Annotations"), "ssc", "Annotation", type="com.opensimulationplatform")
    _element(_element(osp, "osp", "Algorithm"), "osp", "FixedStepAlgorithm", baseStepSize=repr(step_size))
    return ElementTree.tostring(root, encoding="UTF-8", xml_declaration=True)


def export_ssp(
    out_file: str | os.PathLike = "ClosedLoop.ssp",
    *,
    controller: dict | None = None,
    parameters: dict | None = None,
    stop_time: float = 3.0,
    step_size: float = 1e-3,
    call_record: str | os.PathLike | None = None,
    overwrite: bool = False,
) -> Path:
    """Write ClosedLoop.ssp: the pendulum and the PID controller FMUs wired into one system.

    Parameters
    ----------
    out_file : str or PathLike, optional
        The .ssp to write.
    controller : dict, optional
        setpoint, kp, ki, kd over the controller's defaults and a setpoint of DEFAULT_SETPOINT;
        the controller's parameter set.
    parameters : dict, optional
        The pendulum's parameters over its defaults; the pendulum's parameter set.
    stop_time, step_size : float, optional
        The DefaultExperiment's stop time and the fixed communication step, in s.
    call_record : str or PathLike, optional
        The pendulum's callRecordFile in its parameter set: the file the pendulum appends the
        record of every FMI call to, in any master that applies the set (a relative path is
        the master's working folder's). `pendulum-fmu judge --calls FILE --ssp` reads it.
    overwrite : bool, optional
        Replace an existing out_file.

    Returns
    -------
    Path
        out_file.

    Raises
    ------
    SspExists
        out_file is there and overwrite is False.
    InvalidInput
        A stop time or step that is not a positive number, a step longer than the experiment,
        a controller parameter the controller does not have, or pendulum parameters it refuses.
    CannotWrite
        out_file cannot be written.
    MissingFile
        An installed package without its packaged FMUs.
    BuildError
        A checkout whose FMUs are stale and cannot be rebuilt here.

    Examples
    --------
    The times are checked before anything is built:

    >>> from pendulum_fmu import InvalidInput, export_ssp
    >>> try:
    ...     export_ssp("ClosedLoop.ssp", step_size=5.0)
    ... except InvalidInput as error:
    ...     print(error)
    step size 5.0 s is longer than the stop time 3.0 s

    The export itself builds both FMUs for every platform (about half a minute), too long for a
    doctest; tests/test_ssp.py runs it:

    >>> import tempfile, zipfile
    >>> from pathlib import Path
    >>> ssp = export_ssp(Path(tempfile.mkdtemp(), "ClosedLoop.ssp"), controller={"setpoint": 0.4})  # doctest: +SKIP
    >>> for name in sorted(zipfile.ZipFile(ssp).namelist()):  # doctest: +SKIP
    ...     print(name)
    SystemStructure.ssd
    resources/PIDController.fmu
    resources/Pendulum.fmu
    resources/controller.ssv
    resources/pendulum.ssv
    """
    out_file = Path(out_file)
    stop_time, step_size = _positive("stop time", stop_time), _positive("step size", step_size)
    if step_size > stop_time:
        raise InvalidInput(f"step size {step_size} s is longer than the stop time {stop_time} s")
    gains = {**controller_defaults(), "setpoint": DEFAULT_SETPOINT}
    unknown = sorted(set(controller or {}) - set(gains))
    if unknown:
        raise InvalidInput(f"the controller has no parameter {', '.join(unknown)}; it has {', '.join(gains)}")
    for name, value in (controller or {}).items():
        try:
            gains[name] = float(value)
        except (TypeError, ValueError):
            raise InvalidInput(f"controller {name}={value!r} is not a number") from None
    pendulum = resolve_parameters(parameters)
    if out_file.exists() and not overwrite:
        raise SspExists(f"{out_file} exists: pass --overwrite to replace it, or name another file")
    fmus = {"pendulum": default_fmu(), "controller": controller_fmu()}
    with replacing(out_file, "wb") as file, zipfile.ZipFile(file, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("SystemStructure.ssd", system_structure_xml(stop_time, step_size))
        for name, (source, _) in COMPONENTS.items():
            archive.write(fmus[name], source)
        archive.writestr("resources/controller.ssv", parameter_set_xml("controller", gains))
        record = {} if call_record is None else {"callRecordFile": os.fspath(call_record)}
        archive.writestr("resources/pendulum.ssv", parameter_set_xml("pendulum", pendulum, record))
    return out_file


def rebind_ssp(
    ssp: str | os.PathLike,
    out_file: str | os.PathLike,
    *,
    call_record: str | os.PathLike | None = None,
    controller: dict[str, float] | None = None,
) -> Path:
    """A copy of the closed loop's SSP with the pendulum's callRecordFile or the controller's set replaced.

    Parameters
    ----------
    ssp : str or PathLike
        An SSP export_ssp wrote.
    out_file : str or PathLike
        The copy to write (replaced when it exists).
    call_record : str or PathLike, optional
        The pendulum's callRecordFile in the copy's pendulum set (as export_ssp's call_record).
    controller : dict, optional
        The copy's whole controller set, in place of the SSP's (a parameter left out is one the
        controller takes its own default for).

    Returns
    -------
    Path
        out_file.

    Raises
    ------
    MissingFile, SspFileError
        As read_ssp.
    CannotWrite
        out_file cannot be written.

    Examples
    --------
    >>> rebind_ssp("ClosedLoop.ssp", "Recorded.ssp", call_record="calls.log")  # doctest: +SKIP
    PosixPath('Recorded.ssp')
    """
    settings = read_ssp(ssp)
    replaced = {}
    if call_record is not None:
        record = {"callRecordFile": os.fspath(call_record)}
        replaced["resources/pendulum.ssv"] = parameter_set_xml("pendulum", settings.pendulum, record)
    if controller is not None:
        replaced["resources/controller.ssv"] = parameter_set_xml("controller", controller)
    with (
        zipfile.ZipFile(ssp) as source,
        replacing(out_file, "wb") as file,
        zipfile.ZipFile(file, "w", zipfile.ZIP_DEFLATED) as copy,
    ):
        for name in source.namelist():
            copy.writestr(name, replaced.get(name) or source.read(name))
    return Path(out_file)


def _attribute(element: ElementTree.Element, path: str, attribute: str) -> str:
    """The attribute of the element at path under element; a KeyError naming both when either is missing."""
    found = element if path == "." else element.find(path, NAMESPACES)
    value = None if found is None else found.get(attribute)
    if value is None:
        raise KeyError(f"no {path}/@{attribute}")
    return value


def _parsed(archive: zipfile.ZipFile, name: str) -> ElementTree.Element:
    """The XML document the SSP holds as name, refused (SspFileError) where it declares entities."""
    data = archive.read(name)
    check_xml(data, f"{archive.filename}'s {name}", SspFileError)
    return ElementTree.fromstring(data)


def _parameter_set(archive: zipfile.ZipFile, name: str, kind: str = "Real") -> dict:
    """{name: value} of the set's parameters of one kind: Real (as float) or String."""
    root = _parsed(archive, name)
    values = {
        _attribute(p, ".", "name"): _attribute(p, f"ssv:{kind}", "value")
        for p in root.iterfind("ssv:Parameters/ssv:Parameter", NAMESPACES)
        if p.find(f"ssv:{kind}", NAMESPACES) is not None
    }
    return {name: float(value) for name, value in values.items()} if kind == "Real" else values


def read_ssp(path: str | os.PathLike) -> SspSettings:
    """What the closed loop's SSP asks: stop time, fixed step and each component's parameter set.

    Parameters
    ----------
    path : str or PathLike
        An SSP export_ssp wrote (or one laid out like it).

    Returns
    -------
    SspSettings

    Raises
    ------
    MissingFile
        No file at path.
    SspFileError
        path is no zip, or lacks SystemStructure.ssd, the step annotation or a parameter set.

    Examples
    --------
    >>> read_ssp("ClosedLoop.ssp").stop_time  # doctest: +SKIP
    3.0
    """
    path = Path(path)
    if not path.is_file():
        raise MissingFile(f"no SSP at {path}: write one with `pendulum-fmu export-ssp {path}`")
    try:
        with open_archive(path, str(path), SspFileError) as archive:  # before any entry is read
            for name in archive.namelist():  # the FMUs a master will unpack
                if name.endswith(".fmu"):
                    open_fmu(archive.open(name), f"{path}'s {name}", SspFileError).close()
            ssd = _parsed(archive, "SystemStructure.ssd")
            bindings = {
                _attribute(c, ".", "name"): _attribute(c, "ssd:ParameterBindings/ssd:ParameterBinding", "source")
                for c in ssd.iterfind("ssd:System/ssd:Elements/ssd:Component", NAMESPACES)
            }
            sets = {name: _parameter_set(archive, source) for name, source in bindings.items()}
            return SspSettings(
                stop_time=float(_attribute(ssd, "ssd:DefaultExperiment", "stopTime")),
                step_size=float(_attribute(ssd, ".//osp:FixedStepAlgorithm", "baseStepSize")),
                controller=sets["controller"],
                pendulum=sets["pendulum"],
                call_record=_parameter_set(archive, bindings["pendulum"], "String").get("callRecordFile", ""),
            )
    except SspFileError:  # a ValueError too, but its message is whole
        raise
    except (zipfile.BadZipFile, KeyError, ValueError, ElementTree.ParseError) as error:
        raise SspFileError(
            f"{path} is not the closed loop's SSP ({type(error).__name__}: {error}): "
            f"write one with `pendulum-fmu export-ssp`"
        ) from None
