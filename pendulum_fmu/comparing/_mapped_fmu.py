"""Any FMI 2.0 or 3.0 FMU, Co-Simulation or Model Exchange, as a compare tool (through fmpy).

A map names the FMU's variable for each quantity of the comparison, with an optional unit-free
scale factor from the FMU's value to SI:

    torque=u,theta=phi*0.0174532925,omega=w*0.0174532925,alpha=der(w),mass=m,length=L

reads "torque is the FMU's u; theta in rad is the FMU's phi times 0.0174532925 (phi is in
degrees)". A quantity left out of the map is the FMU's variable of the same name when there is
one. torque and theta are required; omega and alpha are reported as NaN when the FMU has neither.
theta0 and omega0 name the variables that take the start values when they are not theta's and
omega's own (a Modelica model's phi_start, say). A parameter the FMU lacks keeps the FMU's own
value, which is refused when the comparison sets it to anything but the pendulum's default.

Co-Simulation is preferred when the FMU has both. Co-Simulation steps run in a loop here (fmpy's
simulate_fmu would apply, at a torque jump, the value from before it); Model Exchange runs through
fmpy's simulate_fmu with CVode, which stops at every torque jump.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import fmpy
import numpy as np
from fmpy import simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from .._errors import InvalidInput, WrongType
from ..engines import ToolCannotRamp, check_held, check_mode, held_results
from ..fmu._instance import FmuError, MessageLog, fmi2_library, instantiate
from ..fmu._model import START_VALUES, FmuFileError, fmu_model
from ..fmu._parameters import default_parameters
from ..fmu._simulate import resolve_parameters
from ..signals._torque_schedule import TorqueSchedule

REQUIRED = ("torque", "theta")
# accurate: the tolerance the FMU or CVode is asked for; default: what it uses when not asked.
TOLERANCE = {"accurate": 1e-12, "default": None}
_FACTOR = re.compile(r"^(?P<variable>.+?)\*(?P<factor>[-+0-9.eE]+)$")


class MapError(InvalidInput):
    """A --map or an FMU that does not fit it; the message says which and what to do."""


@dataclass(frozen=True)
class Mapped:
    """The FMU's variable for one quantity: SI value = the FMU's value * factor."""

    variable: str
    factor: float = 1.0


def quantities() -> tuple[str, ...]:
    """What a map may name: the torque, the pendulum FMU's outputs, start values and parameters."""
    return ("torque", *fmu_model().outputs, *START_VALUES, *default_parameters())


def parse_map(text: str | None, allowed: tuple[str, ...] | None = None) -> dict[str, Mapped]:
    """{quantity: Mapped} from 'torque=u,theta=phi*0.0174532925,...'; allowed: the quantities
    that may be mapped (default: every quantity of a compared FMU, quantities()).
    """
    allowed = quantities() if allowed is None else allowed
    mapping: dict[str, Mapped] = {}
    for item in filter(None, (part.strip() for part in (text or "").split(","))):
        quantity, equals, target = (part.strip() for part in item.partition("="))
        if not equals or not quantity or not target:
            raise MapError(f"--map item {item!r} is not QUANTITY=VARIABLE[*FACTOR]")
        if quantity not in allowed:
            raise MapError(f"--map: unknown quantity {quantity!r}; map any of {', '.join(allowed)}")
        if quantity in mapping:
            raise MapError(f"--map: {quantity} is mapped twice")
        factor = 1.0
        scaled = _FACTOR.match(target)
        if scaled:
            target, factor = scaled["variable"].strip(), float(scaled["factor"])
            if not (math.isfinite(factor) and factor != 0):
                raise MapError(f"--map: the factor of {quantity} must be finite and nonzero")
        mapping[quantity] = Mapped(target, factor)
    return mapping


def as_map(mapping, allowed: tuple[str, ...] | None = None) -> dict[str, Mapped]:
    """A map given as --map's text, as a dict of such texts ({"theta": "phi*0.0174532925"}), as
    parse_map's result, or None (nothing mapped), as parse_map's result.

    Raises
    ------
    WrongType
        Anything else.
    MapError
        A text parse_map refuses.
    """
    if mapping is None or isinstance(mapping, str):
        return parse_map(mapping, allowed)
    if isinstance(mapping, dict) and all(isinstance(value, Mapped) for value in mapping.values()):
        return dict(mapping)
    if isinstance(mapping, dict) and all(
        isinstance(key, str) and isinstance(value, str) for key, value in mapping.items()
    ):
        return parse_map(",".join(f"{key}={value}" for key, value in mapping.items()), allowed)
    raise WrongType(
        f"a map is text such as 'time=t,theta=phi*0.0174532925' or a dict such as "
        f"{{'theta': 'phi*0.0174532925'}}, not {mapping!r}"
    )


class MappedFmu:
    """An FMU and its map, checked once; run() has the runner signature of every tool."""

    def __init__(
        self,
        path: str | Path,
        mapping: dict[str, Mapped] | str | None = None,
        *,
        interface: str | None = None,
        label: str = "other",
    ):
        self.path, self.label = Path(path), label
        if not self.path.is_file():
            raise MapError(f"{label}: no FMU at {self.path}")
        try:
            self.model = fmu_model(self.path)
        except FmuFileError as error:  # not a zip, no model description, not FMI 2.0 or 3.0
            raise MapError(f"{label}: {error}") from None
        self.description = self.model.description
        available = [
            name
            for name, present in (
                ("CoSimulation", self.description.coSimulation),
                ("ModelExchange", self.description.modelExchange),
            )
            if present
        ]
        self.interface = interface or available[0]
        if self.interface not in available:
            raise MapError(f"{label}: {self.path} has no {self.interface} interface (it has {', '.join(available)})")
        self.variables = self.model.variables  # shared, read only
        self.mapping = self._complete(as_map(mapping))

    def _complete(self, given: dict[str, Mapped]) -> dict[str, Mapped]:
        """The map with every quantity the FMU has by name, and every named variable checked."""
        mapping = {}
        for quantity in quantities():
            mapped = given.get(quantity)
            if mapped is None and quantity in START_VALUES:
                mapped = given.get(START_VALUES[quantity])
            if mapped is None and quantity in self.variables:
                mapped = Mapped(quantity)
            if mapped is None:
                if quantity in REQUIRED:
                    raise MapError(
                        f"{self.label}: {self.path.name} has no variable {quantity!r}: "
                        f"name it with --map {quantity}=VARIABLE"
                    )
                continue
            if mapped.variable not in self.variables:
                raise MapError(
                    f"{self.label}: {self.path.name} has no variable {mapped.variable!r} (mapped to {quantity})"
                )
            mapping[quantity] = mapped
        return mapping

    def _start_values(self, parameters: dict | None, theta0: float, omega0: float) -> dict[str, float]:
        """{FMU variable: value in the FMU's units} for the parameters and start values."""
        values = {**resolve_parameters(parameters), "theta0": theta0, "omega0": omega0}
        defaults = default_parameters()
        start = {}
        for quantity, value in values.items():
            mapped = self.mapping.get(quantity)
            if mapped is None:
                if value != defaults.get(quantity, 0.0):
                    raise MapError(
                        f"{self.label}: {self.path.name} has no variable for {quantity} = "
                        f"{value:g}: map it with --map {quantity}=VARIABLE"
                    )
                continue
            start[mapped.variable] = value / mapped.factor
        return start

    def run(
        self,
        plan: TorqueSchedule,
        *,
        parameters: dict | None = None,
        theta0: float = 0.0,
        omega0: float = 0.0,
        mode: str = "accurate",
    ) -> np.ndarray:
        """The FMU's result for a held schedule, mapped to the pendulum's quantities (see Tool.run)."""
        check_held(plan, self.label)
        if self.interface == "CoSimulation":
            return next(self.run_windows((plan,), parameters=parameters, theta0=theta0, omega0=omega0, mode=mode))
        check_mode(mode, self.label)
        start = self._start_values(parameters, theta0, omega0)
        return self._mapped(plan, self._model_exchange(plan, start, TOLERANCE[mode]))

    def run_windows(
        self,
        windows: Iterable[TorqueSchedule],
        *,
        parameters: dict | None = None,
        theta0: float = 0.0,
        omega0: float = 0.0,
        mode: str = "accurate",
    ) -> Iterator[np.ndarray]:
        """A Co-Simulation FMU's result for consecutive windows of one held schedule, through one
        instance stepped on from window to window: run()'s rows of the whole schedule, a window at
        a time, a boundary's row the later window's (see Tool.run_windows).
        """
        check_mode(mode, self.label)
        start = self._start_values(parameters, theta0, omega0)
        for plan, raw in self._co_simulation(windows, start, TOLERANCE[mode]):
            yield self._mapped(plan, raw)

    def _mapped(self, plan: TorqueSchedule, raw: dict[str, np.ndarray]) -> np.ndarray:
        """The FMU's outputs (their first rows of the schedule's points) in the pendulum's units."""
        out = held_results(plan)[: len(raw["theta"])]  # theta is always mapped
        for name, values in raw.items():  # an output the map does not name stays NaN
            out[name] = values * self.mapping[name].factor
        return out

    def _output_variables(self) -> dict[str, str]:
        """{pendulum output: the FMU's variable} of the outputs the map names."""
        return {name: self.mapping[name].variable for name in fmu_model().outputs if name in self.mapping}

    def _co_simulation(self, windows, start, tolerance):
        """Hold each step's torque, read the outputs at each communication point: for each window
        of the schedule, the window and its outputs, less the boundary's row that the next window
        reads (after setting its torque, as one run of the whole schedule reads it).
        """
        fmi3 = self.description.fmiVersion == "3.0"
        folder = self.model.folder
        identifier = self.description.coSimulation.modelIdentifier
        arguments = dict(
            guid=self.description.guid, unzipDirectory=folder, modelIdentifier=identifier, instanceName=self.label
        )
        windows = iter(windows)
        plan = next(windows)
        check_held(plan, self.label)
        try:
            slave = (
                FMU3Slave(**arguments) if fmi3 else FMU2Slave(**arguments, libraryPath=fmi2_library(folder, identifier))
            )
        except Exception:  # fmpy's own: no binary of that name for this platform
            folder = fmpy.platform_tuple if fmi3 else fmpy.platform
            raise FmuFileError(
                f"{self.label}: {self.path} cannot be loaded here: it has no "
                f"binaries/{folder}/{identifier}{fmpy.sharedLibraryExtension} (its "
                "modelIdentifier's binary for this platform)"
            ) from None
        messages = MessageLog(3 if fmi3 else 2)
        outputs = self._output_variables()
        vr = {name: self.variables[name].valueReference for name in (*start, *outputs.values())}
        torque = self.mapping["torque"]
        torque_vr = [self.variables[torque.variable].valueReference]
        output_vrs = [vr[variable] for variable in outputs.values()]
        set_values = slave.setFloat64 if fmi3 else slave.setReal
        get_values = slave.getFloat64 if fmi3 else slave.getReal
        t0 = float(plan.time[0])
        instantiate(slave, messages, f"{self.label}: {self.path}")
        try:
            if not fmi3:
                call = "fmi2SetupExperiment"
                slave.setupExperiment(tolerance=tolerance, startTime=t0)
            call = "setting the parameters and start values"
            set_values([vr[name] for name in start], list(start.values()))
            set_values(torque_vr, [plan.torque[0] / torque.factor])
            call = "initialization"
            if fmi3:
                slave.enterInitializationMode(tolerance=tolerance, startTime=t0)
            else:
                slave.enterInitializationMode()
            slave.exitInitializationMode()
            while plan is not None:
                recorded = np.full((len(plan.time), len(outputs)), np.nan)
                for k, (t, h, u) in enumerate(
                    zip(plan.time.tolist(), plan.step_size.tolist(), plan.torque.tolist(), strict=False)
                ):
                    call = f"the step from t = {t:.17g}"
                    set_values(torque_vr, [u / torque.factor])
                    recorded[k] = get_values(output_vrs)
                    slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
                window, plan = plan, next(windows, None)
                if plan is None:
                    recorded[-1] = get_values(output_vrs)
                    slave.terminate()
                else:
                    check_held(plan, self.label)
                    recorded = recorded[:-1]
                yield window, {name: recorded[:, i] for i, name in enumerate(outputs)}
        except ToolCannotRamp:
            raise
        except Exception as error:
            raise FmuError(f"{self.label}: {call} failed: {error}") from None
        finally:
            slave.freeInstance()

    def _model_exchange(self, plan, start, tolerance):
        """Fmpy's CVode on the FMU's derivatives, with the torque as a table that jumps where the
        schedule's torque changes (fmpy stops the integrator at each such time).
        """
        torque = self.mapping["torque"]
        change = np.flatnonzero(np.diff(plan.torque)) + 1
        # Rows in fmpy's convention: a time given twice is a jump from the first value to the second.
        times = np.concatenate([plan.time[:1], np.repeat(plan.time[change], 2), plan.time[-1:]])
        jumps = np.column_stack([plan.torque[change - 1], plan.torque[change]]).ravel()
        values = np.concatenate([plan.torque[:1], jumps, plan.torque[-1:]])
        signal = np.zeros(len(times), dtype=[("time", "f8"), (torque.variable, "f8")])
        signal["time"], signal[torque.variable] = times, values / torque.factor
        outputs = self._output_variables()
        try:
            raw = simulate_fmu(
                self.model.folder,
                model_description=self.description,
                fmi_type="ModelExchange",
                solver="CVode",
                relative_tolerance=tolerance,
                start_time=float(plan.time[0]),
                stop_time=float(plan.time[-1]),
                output_interval=float(plan.step_size.min()),
                input=signal,
                output=list(outputs.values()),
                start_values=start,
            )
        except Exception as error:
            raise FmuError(f"{self.label}: Model Exchange simulation failed: {error}") from None
        # At a jump fmpy records the time twice; the row after the event is the one whose outputs
        # see the new torque.
        rows = np.searchsorted(raw["time"], plan.time + 1e-9 * plan.step_size.min(), side="right") - 1
        if np.any(np.abs(raw["time"][rows] - plan.time) > 1e-9 * plan.step_size.min()):
            raise FmuError(f"{self.label}: fmpy did not report every communication point")
        return {name: raw[variable][rows] for name, variable in outputs.items()}
