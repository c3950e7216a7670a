"""The tools compare runs, and the parsing of --tools and --map.

    --tools fmu,reference,opensim,mujoco,drake:default,pybullet,gymnasium,envpool,theirs=path/to/Their.fmu
    --map torque=u,theta=phi*0.0174532925

An item is a tool's name, optionally with a mode (accurate, the default, or default: what the
engine does with its own settings), or LABEL=PATH for any other FMU, run through the --map (see
_mapped_fmu.py). Every tool has the same runner:

    tool.run(plan, parameters=..., theta0=..., omega0=...) -> results array (_results.py)

A tool that can also run a schedule a window at a time, its state carried from one window into
the next (the FMU's binaries, native or WebAssembly), has a windowed runner besides:

    tool.run_windows(windows, parameters=..., theta0=..., omega0=...) -> its rows, window by window

which compare walks in memory bounded by a window, as it does a Co-Simulation FMU through a --map;
the others (the engines, Pendulum-v1, a Model Exchange FMU through a --map) run the whole
schedule at once.

A tool returns the time, the torque and the outputs it computes; Tool.run hands back the outputs
asked for (the FMU's, FmuModel.outputs, unless told otherwise), one it cannot compute as NaN with a
one-line warning (errors.NotComputed), never zeros.

A tool whose Python package is missing is refused when the list names it, with the pip command
that installs it; of the default list, compare runs the tools that are installed and warns
(errors.Skipped) which it left out.
"""

from __future__ import annotations

import importlib
import importlib.util
import re
import warnings
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from .._errors import InvalidInput, Skipped, WrongType
from ..engines import MODES, check_mode
from ..fmu import WASM_PLATFORM, _results as results
from ..fmu._model import FmuModel, fmu_model
from ..fmu._simulate import resolve_parameters, simulate_windows
from ..oracle._reference import reference_schedule
from ..signals._torque_schedule import TorqueSchedule


class ToolSpecError(InvalidInput):
    """A --tools or --map that names no runnable tool; the message says which and what to do."""


@dataclass(frozen=True)
class Tool:
    """A tool as compare runs it: its label in tables and figures, its runner, and the FMU (a
    path, a model or None for the default) whose outputs it is asked for.
    """

    label: str
    runner: Callable[..., np.ndarray]
    fmu: str | Path | FmuModel | None = None
    # The runner of consecutive windows of a schedule, for a tool that carries its state across
    # them; None for a tool that runs a whole schedule only.
    windowed: Callable[..., Iterator[np.ndarray]] | None = None

    def run(
        self,
        plan: TorqueSchedule,
        *,
        parameters: dict | None = None,
        theta0: float = 0.0,
        omega0: float = 0.0,
        outputs: Sequence[str] | None = None,
    ) -> np.ndarray:
        """The tool's result for a schedule, with exactly the outputs asked for.

        Parameters
        ----------
        plan : TorqueSchedule
            The schedule.
        parameters : dict, optional
            The pendulum's parameters (the FMU's defaults for those not given).
        theta0, omega0 : float, optional
            Start angle (rad) and rate (rad/s).
        outputs : sequence of str, optional
            The outputs asked for (default: the FMU's, FmuModel.outputs).

        Returns
        -------
        numpy.ndarray
            A result array (_results.py): time, torque, then outputs in that order.

        Warns
        -----
        NotComputed
            One line naming the outputs the tool cannot compute; their columns are NaN.
        """
        run = self.runner(plan, parameters=parameters, theta0=theta0, omega0=omega0)
        return results.with_outputs(run, self._asked(outputs), self.label)

    def run_windows(
        self,
        windows: Iterable[TorqueSchedule],
        *,
        parameters: dict | None = None,
        theta0: float = 0.0,
        omega0: float = 0.0,
        outputs: Sequence[str] | None = None,
    ) -> Iterator[np.ndarray]:
        """The tool's result for a schedule given as consecutive windows (schedule_windows), a
        window at a time, for a tool whose windowed is set.

        Parameters
        ----------
        windows : iterable of TorqueSchedule
            Consecutive windows of one schedule, sharing their boundary points.
        parameters, theta0, omega0, outputs
            As run() takes them.

        Returns
        -------
        iterator of numpy.ndarray
            Result arrays, one a window, that concatenate to run()'s of the whole schedule, bit
            for bit: a boundary's row is the later window's.

        Raises
        ------
        TypeError
            The tool has no windowed runner.
        """
        if self.windowed is None:
            raise TypeError(f"{self.label} runs a whole schedule only")
        asked = self._asked(outputs)
        for block in self.windowed(windows, parameters=parameters, theta0=theta0, omega0=omega0):
            yield results.with_outputs(block, asked, self.label)

    def _asked(self, outputs: Sequence[str] | None) -> tuple[str, ...]:
        return fmu_model(self.fmu).outputs if outputs is None else tuple(outputs)


def run_fmu(
    plan: TorqueSchedule,
    *,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    mode: str = "accurate",
    fmu_path: str | Path | FmuModel | None = None,
    platform: str | None = None,
) -> np.ndarray:
    """The project's FMU (the checkout's, or fmu_path) through fmpy; ramps are passed on.
    platform: its binary, as simulate's (the wasm tool's: WASM_PLATFORM).
    """
    windows = fmu_windows(
        (plan,), parameters=parameters, theta0=theta0, omega0=omega0, mode=mode, fmu_path=fmu_path, platform=platform
    )
    return next(windows)


def fmu_windows(
    windows: Iterable[TorqueSchedule],
    *,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    mode: str = "accurate",
    fmu_path: str | Path | FmuModel | None = None,
    platform: str | None = None,
) -> Iterator[np.ndarray]:
    """run_fmu's result for consecutive windows of one schedule, through one run of the FMU
    (simulate_windows): a window's rows at a time.
    """
    check_mode(mode, "fmu")
    if platform:
        # A set the FMU refuses, in its words as every tool says them, before the binary is looked for.
        resolve_parameters(parameters, fmu_path)
    return simulate_windows(
        windows, parameters=parameters, theta0=theta0, omega0=omega0, fmu_path=fmu_path, platform=platform
    )


# The wasm tool: the FMU's WebAssembly binary through wasmtime, fmu_path's (FMI 3.0) or the
# checkout's FMI 3.0 FMU; the torque held over each step.
run_wasm = partial(run_fmu, platform=WASM_PLATFORM)
wasm_windows = partial(fmu_windows, platform=WASM_PLATFORM)


def run_reference(
    plan: TorqueSchedule,
    *,
    parameters: dict | None = None,
    theta0: float = 0.0,
    omega0: float = 0.0,
    mode: str = "accurate",
    fmu_path: str | Path | FmuModel | None = None,
) -> np.ndarray:
    """The schedule's own torques through the reference (_reference.py); fmu_path's defaults apply."""
    check_mode(mode, "reference")
    return reference_schedule(plan, parameters=parameters, theta0=theta0, omega0=omega0, fmu_path=fmu_path)


@dataclass(frozen=True)
class Kind:
    """A tool that --tools names: where its runner is, the package it needs, its modes."""

    runner: str  # "module:function", imported only when the tool is used
    package: str | None = None  # the module its extra installs
    extra: str | None = None
    modes: tuple[str, ...] = ("accurate",)
    windowed: str | None = None  # "module:function" of its runner of windows, if it has one

    def load(self, runner: str | None = None) -> Callable:
        """The tool's runner (or the one named "module:function"), its module imported now."""
        module, function = (runner or self.runner).split(":")
        return getattr(importlib.import_module(module), function)


KINDS = {
    "fmu": Kind(
        "pendulum_fmu.comparing._compare_tools:run_fmu", windowed="pendulum_fmu.comparing._compare_tools:fmu_windows"
    ),
    "reference": Kind("pendulum_fmu.comparing._compare_tools:run_reference"),
    "opensim": Kind("pendulum_fmu.engines.opensim:run", "opensim", "opensim", MODES),
    "mujoco": Kind("pendulum_fmu.engines.mujoco:run", "mujoco", "mujoco", MODES),
    "drake": Kind("pendulum_fmu.engines.drake:run", "pydrake", "drake", MODES),
    "pybullet": Kind("pendulum_fmu.engines.pybullet:run", "pybullet", "pybullet", MODES),
    "wasm": Kind(
        "pendulum_fmu.comparing._compare_tools:run_wasm",
        "wasmtime",
        "wasm",
        windowed="pendulum_fmu.comparing._compare_tools:wasm_windows",
    ),
    # Pendulum-v1, the reinforcement-learning pendulum: semi-implicit Euler at the communication
    # step, with its torque and speed clips; one mode, its own.
    "gymnasium": Kind("pendulum_fmu.engines.gymnasium:run", "gymnasium", "gym"),
    "envpool": Kind("pendulum_fmu.engines.envpool:run", "envpool", "envpool"),
}
# The tools compare runs when none are named: of these, the ones installed here.
DEFAULT_TOOLS = ("fmu", "reference", "opensim")
_LABEL = re.compile(r"^[A-Za-z_][A-Za-z0-9_.-]*$")


def _label(name: str, mode: str) -> str:
    """The tool's label in --tools, tables and figures: its name, with the mode unless accurate."""
    return name if mode == "accurate" else f"{name}:{mode}"


@dataclass(frozen=True)
class ToolInfo:
    """One tool compare() runs by name, as list_tools() describes it.

    Attributes
    ----------
    name : str
        The tool's name: fmu, reference, opensim, mujoco, drake, pybullet, wasm, gymnasium or envpool.
    installed : bool
        Whether its Python package can be imported here.
    labels : tuple of str
        What compare's tools (and --tools) take to run it, one per mode, such as "mujoco" (its
        accurate mode) and "mujoco:default"; each is also the run's label in tables and figures.
    install : str or None
        The pip command that installs what it needs; None when it needs nothing beyond this package.
    """

    name: str
    installed: bool
    labels: tuple[str, ...]
    install: str | None


def list_tools() -> list[ToolInfo]:
    """Every tool compare() runs by name: whether it is installed here, and how to install it.

    Parameters
    ----------
    None
        It takes no arguments; an FMU given as LABEL=path/to/Their.fmu is a tool too, not listed.

    Returns
    -------
    list of ToolInfo
        fmu, reference, the engines (opensim, mujoco, drake, pybullet), wasm: the FMU's
        WebAssembly binary, then Gymnasium's and EnvPool's Pendulum-v1 (gymnasium, envpool).

    Raises
    ------
    Nothing
        A tool that is not installed is listed with installed False.

    Examples
    --------
    >>> from pendulum_fmu import list_tools
    >>> [(tool.name, tool.labels) for tool in list_tools()][:3]
    [('fmu', ('fmu',)), ('reference', ('reference',)), ('opensim', ('opensim', 'opensim:default'))]
    >>> mujoco = next(tool for tool in list_tools() if tool.name == "mujoco")
    >>> mujoco.install
    'pip install ".[mujoco]" in a clone of pendulum-fmu (or "WHEEL.whl[mujoco]" for its wheel)'

    The installed engines, as compare's tools:

    >>> tools = [label for tool in list_tools() if tool.installed for label in tool.labels]
    >>> tools[:2]
    ['fmu', 'reference']
    """
    return [
        ToolInfo(
            name,
            installed(name),
            tuple(_label(name, mode) for mode in kind.modes),
            None if kind.package is None else install_hint(name),
        )
        for name, kind in KINDS.items()
    ]


def installed(name: str) -> bool:
    """Whether the tool's Python package can be imported here."""
    package = KINDS[name].package
    return package is None or importlib.util.find_spec(package) is not None


def install_hint(name: str) -> str:
    """The pip command that installs what the tool needs: its extra of this package, which is
    installed from a clone or a wheel (it is on no package registry).
    """
    extra = KINDS[name].extra
    return f'pip install ".[{extra}]" in a clone of pendulum-fmu (or "WHEEL.whl[{extra}]" for its wheel)'


def installed_defaults() -> list[str]:
    """The default tools that are installed here; warns (errors.Skipped) in one line which are not
    and how to install them.

    Returns
    -------
    list of str
        Of DEFAULT_TOOLS, those whose Python package can be imported, in order.

    Examples
    --------
    >>> installed_defaults()[:2]
    ['fmu', 'reference']
    """
    missing = [name for name in DEFAULT_TOOLS if not installed(name)]
    if missing:
        warnings.warn(
            "skipped "
            + "; ".join(f"{name} ({KINDS[name].package} is not installed: {install_hint(name)})" for name in missing),
            Skipped,
            stacklevel=3,
        )
    return [name for name in DEFAULT_TOOLS if name not in missing]


def _mapped_fmu(label: str, path: str, mapping: str | dict | None, fmu: str | Path | FmuModel | None) -> Tool:
    from ._mapped_fmu import MappedFmu

    if not _LABEL.match(label) or label.split(":")[0] in KINDS:
        raise ToolSpecError(
            f"--tools {label}={path}: the label must be a name (letters, digits, _ . -) other than {', '.join(KINDS)}"
        )
    try:
        mapped = MappedFmu(path, mapping, label=label)
    except ValueError as error:
        raise ToolSpecError(str(error)) from None
    # Model Exchange runs through fmpy's simulate_fmu, which integrates a whole schedule at once.
    windowed = mapped.run_windows if mapped.interface == "CoSimulation" else None
    return Tool(label, mapped.run, fmu, windowed)


def _named(item: str, fmu_path: str | Path | FmuModel | None) -> Tool:
    name, _, mode = item.partition(":")
    kind = KINDS[name]
    mode = mode or "accurate"
    if mode not in kind.modes:
        raise ToolSpecError(
            f"--tools {item}: {name} has mode{'s' if len(kind.modes) > 1 else ''} {', '.join(kind.modes)}, not {mode!r}"
        )
    if not installed(name):
        raise ToolSpecError(f"--tools {name}: {kind.package} is not installed; install it with: {install_hint(name)}")
    # Every runner takes the FMU whose defaults (and, for fmu, whose binary) apply.
    runner = partial(kind.load(), mode=mode, fmu_path=fmu_path)
    windowed = None if kind.windowed is None else partial(kind.load(kind.windowed), mode=mode, fmu_path=fmu_path)
    return Tool(_label(name, mode), runner, fmu_path, windowed)


def parse_tools(
    spec: str | Sequence[str], *, mapping: str | dict | None = None, fmu_path: str | Path | FmuModel | None = None
) -> list[Tool]:
    """The tools of a --tools list (a comma-separated string or its items), in order.

    mapping is the --map for the tools given as LABEL=PATH (its text, or a dict as
    mapped_fmu.as_map takes it); fmu_path the FMU that "fmu" runs.
    """
    if isinstance(spec, str):
        spec = spec.split(",")
    if not (isinstance(spec, Sequence) and all(isinstance(item, str) for item in spec)):
        raise WrongType(f"tools is a comma-separated string or a list of names, e.g. 'fmu,reference'; got {spec!r}")
    items = [item.strip() for item in spec]
    items = [item for item in items if item]
    if not items:
        raise ToolSpecError("--tools is empty: name at least one of " + ", ".join(KINDS))
    unknown = [item for item in items if "=" not in item and item.partition(":")[0] not in KINDS]
    if unknown:
        raise ToolSpecError(
            f"unknown tool(s) {', '.join(unknown)}: choose from {', '.join(KINDS)}, or LABEL=path/to/Their.fmu"
        )
    if mapping and not any("=" in item for item in items):
        raise ToolSpecError("--map applies to FMUs given as LABEL=path/to/Their.fmu in --tools, and there is none")
    tools: list[Tool] = []
    for item in items:
        label, equals, path = (part.strip() for part in item.partition("="))
        tool = _mapped_fmu(label, path, mapping, fmu_path) if equals else _named(item, fmu_path)
        if any(tool.label == other.label for other in tools):
            raise ToolSpecError(f"--tools names {tool.label} twice")
        tools.append(tool)
    return tools
