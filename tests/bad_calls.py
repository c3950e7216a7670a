"""Every bad call a master can make, as data: run by tests/test_robustness.py, and written as the
table in docs/robustness.md by `python tests/bad_calls.py docs/robustness.md`.

The calls go straight to the FMU's binary through ctypes, so that NULL pointers and calls in the
wrong state reach it exactly as a foreign master would make them (fmpy guards some itself).
"""

from __future__ import annotations

import ctypes
import struct
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

if __name__ == "__main__":  # a script documents the clone it is in, whatever package is installed
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from fmpy.fmi2 import fmi2CallbackFunctions
from fmpy.fmi3 import fmi3LogMessageCallback

from pendulum_fmu.fmu._instance import MessageLog

OK, WARNING, DISCARD, ERROR = 0, 1, 2, 3
STATUS_NAMES = ["fmi2OK", "fmi2Warning", "fmi2Discard", "fmi2Error", "fmi2Fatal", "fmi2Pending"]


def status_name(call: str, status: int) -> str:
    """fmi2Error, fmi3Error, ...: the status in the standard of the call."""
    return call[:4] + STATUS_NAMES[status][4:]


CO_SIMULATION, MODEL_EXCHANGE = 1, 0
TORQUE, THETA, OMEGA, ALPHA, MASS, LENGTH, INERTIA, GRAVITY, DAMPING = range(9)


def reals(*values):
    return (ctypes.c_double * len(values))(*values)


def refs(*references):
    return (ctypes.c_uint * len(references))(*references)


def strings(*values):
    return (ctypes.c_char_p * len(values))(*values)


CALL_RECORD_FILE = 9  # the String parameter callRecordFile's value reference; FMI 3.0 time has the next


class Harness:
    """The FMU's library through ctypes, with a logger that keeps what the FMU says."""

    prefix = "fmi2"
    state_calls: ClassVar[dict[str, str]] = {
        "get": "fmi2GetFMUstate",
        "set": "fmi2SetFMUstate",
        "size": "fmi2SerializedFMUstateSize",
        "serialize": "fmi2SerializeFMUstate",
        "free": "fmi2FreeFMUstate",
        "deserialize": "fmi2DeSerializeFMUstate",
    }

    def __init__(self, library: Path, guid: str):
        self.lib = ctypes.CDLL(str(library))
        self.lib.fmi2Instantiate.restype = ctypes.c_void_p
        self.lib.fmi2Instantiate.argtypes = [
            ctypes.c_char_p,
            ctypes.c_int,
            ctypes.c_char_p,
            ctypes.c_char_p,
            ctypes.c_void_p,
            ctypes.c_int,
            ctypes.c_int,
        ]
        self.guid = guid.encode()
        self.log = MessageLog()
        self.callbacks = self.log.callbacks
        self.live: list[int] = []

    @property
    def messages(self) -> list[str]:
        return self.log.lines

    def __getattr__(self, name):
        return getattr(self.lib, name)

    def instantiate(self, name=b"robust", kind=CO_SIMULATION, guid=None, callbacks="default", resources=b""):
        callbacks = ctypes.byref(self.callbacks) if callbacks == "default" else callbacks
        token = self.guid if guid is None else guid
        component = self.lib.fmi2Instantiate(name, kind, token, resources, callbacks, 0, 0)
        if component:
            self.live.append(component)
        return ctypes.c_void_p(component) if component else None

    def initializing(self):
        """An instance in initialization mode, where start values can be set and read."""
        component = self.instantiate()
        assert self.fmi2EnterInitializationMode(component) == OK
        return component

    def ready(self, kind=CO_SIMULATION, name=b"robust", resources=b"", **parameters):
        """An instance after initialization: step complete (or event mode)."""
        component = self.instantiate(name=name, kind=kind, resources=resources)
        for name, value in parameters.items():
            assert self.fmi2SetReal(component, refs(globals()[name.upper()]), 1, reals(value)) == OK
        assert (
            self.fmi2SetupExperiment(component, 0, ctypes.c_double(0), ctypes.c_double(0), 0, ctypes.c_double(0)) == OK
        )
        assert self.fmi2EnterInitializationMode(component) == OK
        assert self.fmi2ExitInitializationMode(component) == OK
        return component

    def get(self, component, reference) -> float:
        value = reals(0.0)
        assert self.fmi2GetReal(component, refs(reference), 1, value) == OK
        return value[0]

    def set(self, component, reference, value) -> int:
        return self.fmi2SetReal(component, refs(reference), 1, reals(value))

    def step(self, component, time, size):
        return self.fmi2DoStep(component, ctypes.c_double(time), ctypes.c_double(size), 1)

    def last_message(self) -> str:
        return self.messages[-1] if self.messages else ""

    def close(self):
        for component in self.live:
            getattr(self.lib, f"{self.prefix}FreeInstance")(ctypes.c_void_p(component))
        self.live.clear()


class Harness3(Harness):
    """The same for an FMI 3.0 binary: fmi3 entry points, FMI 3.0's logger."""

    prefix = "fmi3"
    state_calls: ClassVar[dict[str, str]] = {
        "get": "fmi3GetFMUState",
        "set": "fmi3SetFMUState",
        "size": "fmi3SerializedFMUStateSize",
        "serialize": "fmi3SerializeFMUState",
        "free": "fmi3FreeFMUState",
        "deserialize": "fmi3DeserializeFMUState",
    }

    def __init__(self, library: Path, token: str):
        self.lib = ctypes.CDLL(str(library))
        for name in ("fmi3InstantiateCoSimulation", "fmi3InstantiateModelExchange"):
            getattr(self.lib, name).restype = ctypes.c_void_p
        self.guid = token.encode()
        self.log = MessageLog(fmi_version=3)
        self.logger = fmi3LogMessageCallback(self.log.log_fmi3)
        self.live = []

    def __getattr__(self, name):
        """The library's function, with Python numbers passed as ctypes would not guess them: an
        int as a 64-bit word (every integer argument, size_t or bool, takes a full register or
        stack slot in the x86-64 and AArch64 calling conventions), a float as a double.
        """
        function = getattr(self.lib, name)

        def call(*arguments):
            return function(
                *(
                    ctypes.c_size_t(a) if isinstance(a, int) else ctypes.c_double(a) if isinstance(a, float) else a
                    for a in arguments
                )
            )

        return call

    def instantiate(self, name=b"robust", kind=CO_SIMULATION, guid=None, logger="default", resources=b""):
        logger = self.logger if logger == "default" else logger
        token = self.guid if guid is None else guid
        if kind == CO_SIMULATION:
            component = self.lib.fmi3InstantiateCoSimulation(
                name, token, resources, False, False, False, False, None, ctypes.c_size_t(0), None, logger, None
            )
        else:
            component = self.lib.fmi3InstantiateModelExchange(name, token, resources, False, False, None, logger)
        if component:
            self.live.append(component)
        return ctypes.c_void_p(component) if component else None

    def initializing(self):
        component = self.instantiate()
        assert (
            self.fmi3EnterInitializationMode(
                component, False, ctypes.c_double(0), ctypes.c_double(0), False, ctypes.c_double(0)
            )
            == OK
        )
        return component

    def ready(self, kind=CO_SIMULATION, name=b"robust", resources=b"", **parameters):
        component = self.instantiate(name=name, kind=kind, resources=resources)
        for name, value in parameters.items():
            assert self.fmi3SetFloat64(component, refs(globals()[name.upper()]), 1, reals(value), 1) == OK
        assert (
            self.fmi3EnterInitializationMode(
                component, False, ctypes.c_double(0), ctypes.c_double(0), False, ctypes.c_double(0)
            )
            == OK
        )
        assert self.fmi3ExitInitializationMode(component) == OK
        return component

    def get(self, component, reference) -> float:
        value = reals(0.0)
        assert self.fmi3GetFloat64(component, refs(reference), 1, value, 1) == OK
        return value[0]

    def set(self, component, reference, value) -> int:
        return self.fmi3SetFloat64(component, refs(reference), 1, reals(value), 1)

    def step(self, component, time, size, last_successful_time=None):
        flags = [ctypes.c_bool() for _ in range(3)]
        last = last_successful_time if last_successful_time is not None else ctypes.c_double()
        return self.fmi3DoStep(
            component, ctypes.c_double(time), ctypes.c_double(size), True, *map(ctypes.byref, flags), ctypes.byref(last)
        )


@dataclass(frozen=True)
class Case:
    group: str
    bad_input: str
    call: str
    expected_status: int
    expected_message: str
    run: Callable[[Harness], int]  # makes the bad call, returns its status; asserts what must hold after


def _unchanged_after(harness, component, reference, bad_value):
    before = harness.get(component, reference)
    status = harness.set(component, reference, bad_value)
    assert harness.get(component, reference) == before, "a refused value must leave the old one"
    return status


def _batch_with_one_nan(h):
    component = h.initializing()
    status = h.fmi2SetReal(component, refs(MASS, DAMPING), 2, reals(3.0, NAN))
    assert h.get(component, MASS) == 40.0, "no part of a refused batch is set"
    return status


def _exit_with(**values):
    def run(h):
        component = h.instantiate()
        references = [globals()[name.upper()] for name in values]
        assert h.fmi2SetReal(component, refs(*references), len(values), reals(*values.values())) == OK
        h.fmi2EnterInitializationMode(component)
        status = h.fmi2ExitInitializationMode(component)
        # The instance stays in initialization mode: the master can correct the value.
        assert h.fmi2SetReal(component, refs(MASS, LENGTH, INERTIA, DAMPING), 4, reals(40, 0.5, 20, 0)) == OK
        assert h.fmi2ExitInitializationMode(component) == OK
        return status

    return run


def _step_then(check):
    def run(h):
        component = h.ready()
        assert h.step(component, 0.0, 0.01) == OK
        return check(h, component)

    return run


def _discarded_huge_step(h):
    component = h.ready()
    # A swinging pendulum: at rest without torque the solution is constant and any step is exact.
    assert h.fmi2SetReal(component, refs(TORQUE), 1, reals(20.0)) == OK
    assert h.step(component, 0.0, 0.5) == OK
    theta = h.get(component, THETA)
    status = h.step(component, 0.5, 1e9)
    last = reals(0.0)
    assert h.fmi2GetRealStatus(component, 2, last) == OK and last[0] == 0.5  # fmi2LastSuccessfulTime
    assert h.get(component, THETA) == theta, "a discarded step must leave the instance where it was"
    return status


def _serialized(h):
    component, call = h.ready(), {name: getattr(h, function) for name, function in h.state_calls.items()}
    h.step(component, 0.0, 0.1)
    state, size = ctypes.c_void_p(), ctypes.c_size_t()
    assert call["get"](component, ctypes.byref(state)) == OK
    assert call["size"](component, state, ctypes.byref(size)) == OK
    blob = (ctypes.c_char * size.value)()
    assert call["serialize"](component, state, blob, size) == OK
    call["free"](component, ctypes.byref(state))
    return component, bytearray(blob.raw)


def _deserialize(mangle):
    def run(h):
        component, blob = _serialized(h)
        blob = mangle(blob)
        buffer = (ctypes.c_char * max(len(blob), 1)).from_buffer_copy(bytes(blob) or b"\0")
        state = ctypes.c_void_p()
        status = getattr(h, h.state_calls["deserialize"])(component, buffer, len(blob), ctypes.byref(state))
        assert not state, "a refused blob must not yield a state"
        return status

    return run


def _flip(index):
    def mangle(blob):
        blob[index] ^= 0x40
        return blob

    return mangle


def _fnv1a(data: bytes) -> int:
    """FNV-1a, 64 bits, as its authors define it: the serialized state's checksum."""
    hash_value = 0xCBF29CE484222325
    for byte in data:
        hash_value = ((hash_value ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return hash_value


def _resealed(offset, replacement):
    """A blob with bytes at offset replaced and its checksum made anew: what a master forging a
    state would send, which the checksum cannot catch.
    """

    def mangle(blob):
        blob[offset : offset + len(replacement)] = replacement
        blob[-8:] = _fnv1a(bytes(blob[:-8])).to_bytes(8, "little")
        return blob

    return mangle


def _step_past_the_largest_time(h):
    component, call = h.ready(), {name: getattr(h, function) for name, function in h.state_calls.items()}
    assert h.step(component, 0.0, 1e308) == OK  # at rest without torque: exact for any step
    # The state after it is one the FMU reads back (its internal step hint stays finite).
    state, size = ctypes.c_void_p(), ctypes.c_size_t()
    assert (
        call["get"](component, ctypes.byref(state)) == OK and call["size"](component, state, ctypes.byref(size)) == OK
    )
    blob = (ctypes.c_char * size.value)()
    assert call["serialize"](component, state, blob, size) == OK
    restored = ctypes.c_void_p()
    assert call["deserialize"](component, blob, size, ctypes.byref(restored)) == OK, h.last_message()
    status = h.step(component, 1e308, 1e308)
    assert h.step(component, 2.0, 1.0) == ERROR, "time stays at 1e308: no other point is accepted"
    assert h.step(component, 1e308, 1.0) == OK
    return status


def _derivatives_past_the_largest_number(h):
    component = h.ready()
    assert (
        h.fmi2SetRealInputDerivatives(component, refs(TORQUE, TORQUE), 2, (ctypes.c_int * 2)(1, 2), reals(1e308, 1e308))
        == OK
    )
    status = h.step(component, 0.0, 10.0)
    # Refused before anything moved: the same instance steps on once the derivatives are sane.
    assert (
        h.fmi2SetRealInputDerivatives(component, refs(TORQUE, TORQUE), 2, (ctypes.c_int * 2)(1, 2), reals(0.0, 0.0))
        == OK
    )
    assert h.set(component, TORQUE, 20.0) == OK and h.step(component, 0.0, 1.0) == OK
    assert 0 < h.get(component, THETA) < 1
    return status


def _states_never_freed(h):
    component = h.ready()
    states = [ctypes.c_void_p() for _ in range(MAX_FMU_STATES)]
    for state in states:
        assert h.fmi2GetFMUstate(component, ctypes.byref(state)) == OK
    extra = ctypes.c_void_p()
    status = h.fmi2GetFMUstate(component, ctypes.byref(extra))
    assert not extra, "no state is handed out past the limit"
    assert h.fmi2FreeFMUstate(component, ctypes.byref(states.pop())) == OK
    assert h.fmi2GetFMUstate(component, ctypes.byref(extra)) == OK, "freeing one makes room for one"
    return status


FOREIGN = "is not a state this instance handed out"


def _steps_on_after(bad_call):
    """The bad call on an instance 0.5 s into a swing under 20 N.m; the instance must then step
    to the theta of an instance that never saw the call, and its own state must still restore.
    """

    def run(h):
        call = {name: getattr(h, function) for name, function in h.state_calls.items()}
        component, untouched = h.ready(), h.ready()
        for instance in (component, untouched):
            assert h.set(instance, TORQUE, 20.0) == OK and h.step(instance, 0.0, 0.5) == OK
        theta_half, state = h.get(component, THETA), ctypes.c_void_p()
        assert call["get"](component, ctypes.byref(state)) == OK
        status = bad_call(h, call, component, state)
        for instance in (component, untouched):
            assert h.step(instance, 0.5, 0.5) == OK
        assert h.get(component, THETA) == h.get(untouched, THETA) != theta_half, "the instance goes on"
        assert call["set"](component, state) == OK and h.get(component, THETA) == theta_half
        assert call["free"](component, ctypes.byref(state)) == OK and not state
        return status

    return run


def _not_a_state():
    return (ctypes.c_double * 64)()


def _another_instances_state(h, call):
    state = ctypes.c_void_p()
    assert call["get"](h.ready(), ctypes.byref(state)) == OK
    return state


def _freed_state(h, call, component):
    """A copy of a state's address, taken before the state was freed."""
    state = ctypes.c_void_p()
    assert call["get"](component, ctypes.byref(state)) == OK
    stale = ctypes.c_void_p(state.value)
    assert call["free"](component, ctypes.byref(state)) == OK
    return stale


def _overwrite_foreign(h, call, component, state):
    buffer = _not_a_state()
    pointer = ctypes.c_void_p(ctypes.addressof(buffer))
    status = call["get"](component, ctypes.byref(pointer))
    assert pointer.value == ctypes.addressof(buffer), "a refused pointer is left as it was"
    return status


FOREIGN_STATE_CASES = [
    # (bad input, call, expected status, expected message, bad call)
    (
        "the state where the address of its variable belongs (fmusim 0.0.39)",
        "free",
        ERROR,
        "is a state itself",
        lambda h, call, c, state: call["free"](c, state),
    ),
    ("memory that is no FMU state", "set", ERROR, FOREIGN, lambda h, call, c, state: call["set"](c, _not_a_state())),
    (
        "a state of another instance",
        "set",
        ERROR,
        FOREIGN,
        lambda h, call, c, state: call["set"](c, _another_instances_state(h, call)),
    ),
    (
        "a state freed already",
        "set",
        ERROR,
        FOREIGN,
        lambda h, call, c, state: call["set"](c, _freed_state(h, call, c)),
    ),
    (
        "a state freed twice",
        "free",
        ERROR,
        FOREIGN,
        lambda h, call, c, state: call["free"](c, ctypes.byref(_freed_state(h, call, c))),
    ),
    ("memory that is no FMU state, to be overwritten", "get", ERROR, FOREIGN, _overwrite_foreign),
    (
        "memory that is no FMU state, serialized",
        "serialize",
        ERROR,
        FOREIGN,
        lambda h, call, c, state: call["serialize"](c, _not_a_state(), (ctypes.c_char * 1024)(), ctypes.c_size_t(1024)),
    ),
    (
        "a NULL state freed (allowed: nothing happens)",
        "free",
        OK,
        "",
        lambda h, call, c, state: call["free"](c, ctypes.byref(ctypes.c_void_p())),
    ),
]


def _foreign_state_cases(harness_type):
    return [
        Case(
            "FMU state pointers", bad_input, harness_type.state_calls[call], status, message, _steps_on_after(bad_call)
        )
        for bad_input, call, status, message, bad_call in FOREIGN_STATE_CASES
    ]


def _illegal(call, *arguments, state="instantiated"):
    def run(h):
        component = h.instantiate() if state == "instantiated" else h.ready()
        if state == "terminated":
            assert h.fmi2Terminate(component) == OK
        return getattr(h, call)(component, *(a() if callable(a) else a for a in arguments))

    return run


def _terminated_model_exchange_then(call, *arguments):
    def run(h):
        component = h.ready(kind=MODEL_EXCHANGE)
        assert getattr(h, f"{h.prefix}Terminate")(component) == OK
        return getattr(h, call)(component, *(a() if callable(a) else a for a in arguments))

    return run


def _no_instance(check):
    def run(h):
        return 0 if check(h) else 3

    return run


NAN, INF = float("nan"), float("inf")
MEGABYTE = 2**20


def _huge_token(h):
    """A GUID (instantiation token) of a megabyte is refused in one message the FMU's buffer bounds."""
    refused = h.instantiate(guid=b"{" + b"g" * MEGABYTE) is None
    assert len(h.last_message()) < 1024, "the message is cut to the FMU's buffer"
    return refused


def _huge_name_and_resources(h, read):
    """An instance named by a megabyte, whose resources are at a megabyte's path broken by line ends:
    it keeps the name's first 127 bytes, reads no resource, steps and is read (read is the getter).
    """
    component = h.ready(name=b"n" * MEGABYTE, resources=b"file:///" + b"r\n" * (MEGABYTE // 2))
    assert h.step(component, 0.0, 1e-3) == OK
    return read(component)


MAX_FMU_STATES = 10000  # fmu_src/include/instance.h: the FMU states one instance holds at most


def _ready_then(call, *arguments, kind=CO_SIMULATION):
    return lambda h: getattr(h, call)(h.ready(kind=kind), *(a() if callable(a) else a for a in arguments))


def _instantiated_then(call, *arguments):
    return lambda h: getattr(h, call)(h.instantiate(), *(a() if callable(a) else a for a in arguments))


CASES = [
    # Non-finite values
    Case(
        "non-finite values",
        "torque = NaN after initialization",
        "fmi2SetReal",
        ERROR,
        "torque = nan refused",
        lambda h: _unchanged_after(h, h.ready(), TORQUE, NAN),
    ),
    Case(
        "non-finite values",
        "torque = +inf",
        "fmi2SetReal",
        ERROR,
        "torque = inf refused",
        lambda h: _unchanged_after(h, h.ready(), TORQUE, INF),
    ),
    Case(
        "non-finite values",
        "start angle theta = -inf",
        "fmi2SetReal",
        ERROR,
        "theta = -inf refused",
        lambda h: _unchanged_after(h, h.initializing(), THETA, -INF),
    ),
    Case(
        "non-finite values",
        "start rate omega = NaN",
        "fmi2SetReal",
        ERROR,
        "omega = nan refused",
        lambda h: _unchanged_after(h, h.initializing(), OMEGA, NAN),
    ),
    Case(
        "non-finite values",
        "mass = +inf",
        "fmi2SetReal",
        ERROR,
        "mass = inf refused",
        lambda h: _unchanged_after(h, h.initializing(), MASS, INF),
    ),
    Case(
        "non-finite values",
        "gravity = NaN",
        "fmi2SetReal",
        ERROR,
        "gravity = nan refused",
        lambda h: _unchanged_after(h, h.initializing(), GRAVITY, NAN),
    ),
    Case(
        "non-finite values",
        "a batch with one NaN: nothing of it is set",
        "fmi2SetReal",
        ERROR,
        "damping = nan refused",
        lambda h: _batch_with_one_nan(h),
    ),
    Case(
        "non-finite values",
        "torque input derivative = inf",
        "fmi2SetRealInputDerivatives",
        ERROR,
        "derivative of torque = inf refused",
        lambda h: h.fmi2SetRealInputDerivatives(h.ready(), refs(TORQUE), 1, (ctypes.c_int * 1)(1), reals(INF)),
    ),
    # Physical nonsense, refused when initialization ends
    Case(
        "physical nonsense", "mass = 0", "fmi2ExitInitializationMode", ERROR, "mass must be > 0", _exit_with(mass=0.0)
    ),
    Case(
        "physical nonsense", "mass = -1", "fmi2ExitInitializationMode", ERROR, "mass must be > 0", _exit_with(mass=-1.0)
    ),
    Case(
        "physical nonsense",
        "length = -0.1",
        "fmi2ExitInitializationMode",
        ERROR,
        "length must be >= 0",
        _exit_with(length=-0.1),
    ),
    Case(
        "physical nonsense",
        "inertia = -1",
        "fmi2ExitInitializationMode",
        ERROR,
        "inertia must be >= 0",
        _exit_with(inertia=-1.0),
    ),
    Case(
        "physical nonsense",
        "damping = -0.5",
        "fmi2ExitInitializationMode",
        ERROR,
        "damping must be >= 0",
        _exit_with(damping=-0.5),
    ),
    Case(
        "physical nonsense",
        "length = 0 and inertia = 0: no inertia about the pivot",
        "fmi2ExitInitializationMode",
        ERROR,
        "the inertia about the pivot",
        _exit_with(length=0.0, inertia=0.0),
    ),
    # The state machine
    Case(
        "state machine",
        "fmi2DoStep before initialization",
        "fmi2DoStep",
        ERROR,
        "not allowed in state 'instantiated'",
        lambda h: h.step(h.instantiate(), 0.0, 0.001),
    ),
    Case(
        "state machine",
        "fmi2DoStep in initialization mode",
        "fmi2DoStep",
        ERROR,
        "not allowed in state 'initialization mode'",
        lambda h: (lambda c: (h.fmi2EnterInitializationMode(c), h.step(c, 0.0, 0.001))[-1])(h.instantiate()),
    ),
    Case(
        "state machine",
        "fmi2DoStep after fmi2Terminate",
        "fmi2DoStep",
        ERROR,
        "not allowed in state 'terminated'",
        lambda h: (lambda c: (h.fmi2Terminate(c), h.step(c, 0.0, 0.001))[-1])(h.ready()),
    ),
    Case(
        "state machine",
        "fixed parameter mass set after initialization",
        "fmi2SetReal",
        ERROR,
        "a fixed parameter cannot change after initialization",
        lambda h: _unchanged_after(h, h.ready(), MASS, 1.0),
    ),
    Case(
        "state machine",
        "start value theta set after initialization",
        "fmi2SetReal",
        ERROR,
        "can be set only before initialization ends",
        lambda h: _unchanged_after(h, h.ready(), THETA, 1.0),
    ),
    Case(
        "state machine",
        "output alpha set",
        "fmi2SetReal",
        ERROR,
        "it is calculated by the FMU",
        lambda h: h.fmi2SetReal(h.ready(), refs(ALPHA), 1, reals(1.0)),
    ),
    Case(
        "state machine",
        "unknown value reference 99 set",
        "fmi2SetReal",
        ERROR,
        "vr 99 is not a value reference",
        lambda h: h.fmi2SetReal(h.ready(), refs(99), 1, reals(1.0)),
    ),
    Case(
        "state machine",
        "unknown value reference 4000000000 read",
        "fmi2GetReal",
        ERROR,
        "is not a value reference",
        lambda h: h.fmi2GetReal(h.ready(), refs(4000000000), 1, reals(0.0)),
    ),
    Case(
        "state machine",
        "fmi2GetReal before initialization",
        "fmi2GetReal",
        ERROR,
        "not allowed in state 'instantiated'",
        _illegal("fmi2GetReal", refs(THETA), 1, lambda: reals(0.0)),
    ),
    Case(
        "state machine",
        "fmi2ExitInitializationMode twice",
        "fmi2ExitInitializationMode",
        ERROR,
        "not allowed in state 'step complete'",
        _illegal("fmi2ExitInitializationMode", state="ready"),
    ),
    Case(
        "state machine",
        "fmi2SetupExperiment after initialization",
        "fmi2SetupExperiment",
        ERROR,
        "not allowed in state",
        _illegal(
            "fmi2SetupExperiment", 0, ctypes.c_double(0), ctypes.c_double(0), 0, ctypes.c_double(0), state="ready"
        ),
    ),
    Case(
        "state machine",
        "model-exchange call on a co-simulation instance",
        "fmi2SetContinuousStates",
        ERROR,
        "a model-exchange function, and this instance is for co-simulation",
        _illegal("fmi2SetContinuousStates", lambda: reals(0.0, 0.0), 2, state="ready"),
    ),
    Case(
        "state machine",
        "model-exchange call on a co-simulation instance in initialization mode (a state both share)",
        "fmi2GetContinuousStates",
        ERROR,
        "a model-exchange function, and this instance is for co-simulation",
        lambda h: h.fmi2GetContinuousStates(h.initializing(), reals(0.0, 0.0), 2),
    ),
    Case(
        "state machine",
        "fmi2DoStep on a model-exchange instance",
        "fmi2DoStep",
        ERROR,
        "a co-simulation function, and this instance is for model exchange",
        lambda h: h.step(h.ready(kind=MODEL_EXCHANGE), 0.0, 0.001),
    ),
    Case(
        "state machine",
        "co-simulation call on a terminated model-exchange instance (a state both share)",
        "fmi2GetRealStatus",
        ERROR,
        "a co-simulation function, and this instance is for model exchange",
        _terminated_model_exchange_then("fmi2GetRealStatus", 2, lambda: reals(0.0)),
    ),
    Case(
        "state machine",
        "fmi2CancelStep (steps are never asynchronous)",
        "fmi2CancelStep",
        ERROR,
        "illegal call sequence",
        _illegal("fmi2CancelStep", state="ready"),
    ),
    Case(
        "state machine",
        "output derivative of order 3",
        "fmi2GetRealOutputDerivatives",
        ERROR,
        "no derivative of order 3",
        lambda h: h.fmi2GetRealOutputDerivatives(h.ready(), refs(THETA), 1, (ctypes.c_int * 1)(3), reals(0.0)),
    ),
    Case(
        "state machine",
        "input derivative on an output",
        "fmi2SetRealInputDerivatives",
        ERROR,
        "theta is not an input",
        lambda h: h.fmi2SetRealInputDerivatives(h.ready(), refs(THETA), 1, (ctypes.c_int * 1)(1), reals(1.0)),
    ),
    Case(
        "state machine",
        "directional derivative of alpha by mass",
        "fmi2GetDirectionalDerivative",
        ERROR,
        "no partial derivative of vr 3 with respect to vr 4",
        lambda h: h.fmi2GetDirectionalDerivative(h.ready(), refs(ALPHA), 1, refs(MASS), 1, reals(1.0), reals(0.0)),
    ),
    Case(
        "state machine",
        "unknown log category",
        "fmi2SetDebugLogging",
        ERROR,
        "unknown log category logNonsense",
        lambda h: h.fmi2SetDebugLogging(h.ready(), 1, 1, (ctypes.c_char_p * 1)(b"logNonsense")),
    ),
    # fmi2DoStep arguments
    Case(
        "fmi2DoStep",
        "step size 0",
        "fmi2DoStep",
        ERROR,
        "must be positive and finite",
        lambda h: h.step(h.ready(), 0.0, 0.0),
    ),
    Case(
        "fmi2DoStep",
        "step size -0.001",
        "fmi2DoStep",
        ERROR,
        "must be positive and finite",
        lambda h: h.step(h.ready(), 0.0, -1e-3),
    ),
    Case(
        "fmi2DoStep",
        "step size NaN",
        "fmi2DoStep",
        ERROR,
        "must be positive and finite",
        lambda h: h.step(h.ready(), 0.0, NAN),
    ),
    Case(
        "fmi2DoStep",
        "currentCommunicationPoint 0.5 where the instance stands at 0.01",
        "fmi2DoStep",
        ERROR,
        "is not where the instance stands",
        _step_then(lambda h, c: h.step(c, 0.5, 0.001)),
    ),
    Case(
        "fmi2DoStep",
        "a step of 1e9 s: more than the 100000 internal steps allowed",
        "fmi2DoStep",
        DISCARD,
        "step budget exhausted",
        _discarded_huge_step,
    ),
    Case(
        "fmi2DoStep",
        "a step of 1e308 s at rest, then one that ends past the largest double",
        "fmi2DoStep",
        ERROR,
        "ends past the largest time a double holds",
        _step_past_the_largest_time,
    ),
    Case(
        "fmi2DoStep",
        "input derivatives of 1e308 (orders 1 and 2) over a 10 s step",
        "fmi2DoStep",
        ERROR,
        "the input derivatives take torque past the largest number a double holds",
        _derivatives_past_the_largest_number,
    ),
    Case(
        "FMU states",
        "a master that never frees its states",
        "fmi2GetFMUstate",
        ERROR,
        f"holds {MAX_FMU_STATES} FMU states, the most it keeps",
        _states_never_freed,
    ),
    # NULL pointers and counts
    Case(
        "NULL and counts",
        "vr = NULL with nvr = 1",
        "fmi2GetReal",
        ERROR,
        "argument vr must not be NULL",
        lambda h: h.fmi2GetReal(h.ready(), None, 1, reals(0.0)),
    ),
    Case(
        "NULL and counts",
        "value = NULL with nvr = 1",
        "fmi2SetReal",
        ERROR,
        "argument value must not be NULL",
        lambda h: h.fmi2SetReal(h.ready(), refs(TORQUE), 1, None),
    ),
    Case(
        "NULL and counts",
        "NULL instance",
        "fmi2DoStep",
        ERROR,
        "",
        lambda h: h.fmi2DoStep(None, ctypes.c_double(0), ctypes.c_double(0.001), 1),
    ),
    Case(
        "NULL and counts",
        "nx = 3 for 2 continuous states",
        "fmi2GetContinuousStates",
        ERROR,
        "nx = 3, but the model has 2",
        lambda h: h.fmi2GetContinuousStates(h.ready(kind=MODEL_EXCHANGE), reals(0, 0, 0), 3),
    ),
    Case(
        "NULL and counts",
        "NULL event info",
        "fmi2NewDiscreteStates",
        ERROR,
        "argument fmi2eventInfo must not be NULL",
        lambda h: h.fmi2NewDiscreteStates(h.ready(kind=MODEL_EXCHANGE), None),
    ),
    Case(
        "NULL and counts",
        "NULL FMU state pointer",
        "fmi2GetFMUstate",
        ERROR,
        "argument FMUstate must not be NULL",
        lambda h: h.fmi2GetFMUstate(h.ready(), None),
    ),
    Case(
        "NULL and counts",
        "NULL FMU state",
        "fmi2SetFMUstate",
        ERROR,
        "argument FMUstate must not be NULL",
        lambda h: h.fmi2SetFMUstate(h.ready(), None),
    ),
    # fmi2Instantiate
    Case(
        "fmi2Instantiate",
        "a GUID from another FMU",
        "fmi2Instantiate",
        ERROR,
        "does not match this FMU's",
        _no_instance(lambda h: h.instantiate(guid=b"{00000000-0000-0000-0000-000000000000}") is None),
    ),
    Case(
        "fmi2Instantiate",
        "NULL GUID",
        "fmi2Instantiate",
        ERROR,
        "fmuGUID NULL does not match",
        _no_instance(lambda h: h.lib.fmi2Instantiate(b"x", 1, None, b"", ctypes.byref(h.callbacks), 0, 0) is None),
    ),
    Case(
        "fmi2Instantiate",
        "empty instance name",
        "fmi2Instantiate",
        ERROR,
        "instanceName must be a non-empty string",
        _no_instance(lambda h: h.instantiate(name=b"") is None),
    ),
    Case(
        "fmi2Instantiate",
        "a GUID of a megabyte",
        "fmi2Instantiate",
        ERROR,
        "fmuGUID {ggg",
        _no_instance(_huge_token),
    ),
    Case(
        "fmi2Instantiate",
        "an instance name and a resource location of a megabyte, the location with line ends",
        "fmi2GetReal",
        OK,
        "",
        lambda h: _huge_name_and_resources(h, lambda c: h.fmi2GetReal(c, refs(THETA), 1, reals(0.0))),
    ),
    Case(
        "fmi2Instantiate",
        "fmuType 7",
        "fmi2Instantiate",
        ERROR,
        "fmuType 7 is neither",
        _no_instance(lambda h: h.instantiate(kind=7) is None),
    ),
    Case(
        "fmi2Instantiate",
        "NULL callbacks struct",
        "fmi2Instantiate",
        ERROR,
        "",
        _no_instance(lambda h: h.instantiate(callbacks=None) is None),
    ),
    Case(
        "fmi2Instantiate",
        "callbacks struct without a logger",
        "fmi2Instantiate",
        ERROR,
        "",
        _no_instance(lambda h: h.instantiate(callbacks=ctypes.byref(fmi2CallbackFunctions())) is None),
    ),
    # Serialized FMU states
    Case(
        "FMU state blobs",
        "garbage bytes",
        "fmi2DeSerializeFMUstate",
        ERROR,
        "bad magic",
        _deserialize(lambda blob: bytearray(b"\xde\xad\xbe\xef" * (len(blob) // 4))),
    ),
    Case(
        "FMU state blobs",
        "an empty blob",
        "fmi2DeSerializeFMUstate",
        ERROR,
        "bad magic",
        _deserialize(lambda blob: bytearray()),
    ),
    Case(
        "FMU state blobs",
        "truncated by one byte",
        "fmi2DeSerializeFMUstate",
        ERROR,
        "truncated, or from another build",
        _deserialize(lambda blob: blob[:-1]),
    ),
    Case(
        "FMU state blobs",
        "truncated to the header",
        "fmi2DeSerializeFMUstate",
        ERROR,
        "truncated, or from another build",
        _deserialize(lambda blob: blob[:12]),
    ),
    Case(
        "FMU state blobs",
        "another format version",
        "fmi2DeSerializeFMUstate",
        ERROR,
        "state format version",
        _deserialize(_flip(5)),
    ),
    Case(
        "FMU state blobs",
        "one payload bit flipped",
        "fmi2DeSerializeFMUstate",
        ERROR,
        "checksum mismatch",
        _deserialize(_flip(40)),
    ),
    Case(
        "FMU state blobs",
        "a state of another FMU (payload size differs)",
        "fmi2DeSerializeFMUstate",
        ERROR,
        "truncated, or from another build",
        _deserialize(lambda blob: blob[:8] + (len(blob) - 28).to_bytes(4, "little") + blob[12:-8]),
    ),
    Case(
        "FMU state blobs",
        "mass = -1 written into a state after initialization, checksum made anew",
        "fmi2DeSerializeFMUstate",
        ERROR,
        "implausible state: parameters no initialization would accept",
        _deserialize(_resealed(84, struct.pack("<d", -1.0))),
    ),
    Case(
        "FMU state blobs",
        "a machine state of 2^32 + 4, checksum made anew",
        "fmi2DeSerializeFMUstate",
        ERROR,
        "implausible state: unknown machine state",
        _deserialize(_resealed(12, struct.pack("<q", (1 << 32) | 4))),
    ),
    Case(
        "record file",
        "callRecordFile = NULL",
        "fmi2SetString",
        ERROR,
        "callRecordFile is NULL",
        _instantiated_then("fmi2SetString", refs(CALL_RECORD_FILE), 1, lambda: strings(None)),
    ),
    Case(
        "record file",
        "callRecordFile of 1024 bytes",
        "fmi2SetString",
        ERROR,
        "callRecordFile is 1024 bytes long: at most 1023",
        _instantiated_then("fmi2SetString", refs(CALL_RECORD_FILE), 1, lambda: strings(b"x" * 1024)),
    ),
    Case(
        "record file",
        "a String set at vr 0 (torque, a Real)",
        "fmi2SetString",
        ERROR,
        "vr 0: no String variable has this value reference",
        _instantiated_then("fmi2SetString", refs(TORQUE), 1, lambda: strings(b"record.log")),
    ),
    Case(
        "record file",
        "callRecordFile set after initialization",
        "fmi2SetString",
        ERROR,
        "callRecordFile is a fixed parameter",
        _ready_then("fmi2SetString", refs(CALL_RECORD_FILE), 1, lambda: strings(b"record.log")),
    ),
    Case(
        "record file",
        "callRecordFile in a folder that does not exist",
        "fmi2SetString",
        WARNING,
        "cannot be opened for appending",
        _instantiated_then("fmi2SetString", refs(CALL_RECORD_FILE), 1, lambda: strings(b"/no/such/folder/record.log")),
    ),
    Case(
        "record file",
        "callRecordFile a symbolic link (/proc/self/exe, a link on every Linux)",
        "fmi2SetString",
        WARNING,
        "is a symbolic link: the FMU writes no record file",
        _instantiated_then("fmi2SetString", refs(CALL_RECORD_FILE), 1, lambda: strings(b"/proc/self/exe")),
    ),
    *_foreign_state_cases(Harness),
]


def _exit_with_fmi3(**values):
    def run(h):
        component = h.initializing()
        references = [globals()[name.upper()] for name in values]
        assert h.fmi3SetFloat64(component, refs(*references), len(values), reals(*values.values()), len(values)) == OK
        status = h.fmi3ExitInitializationMode(component)
        assert h.fmi3SetFloat64(component, refs(MASS), 1, reals(40.0), 1) == OK
        assert h.fmi3ExitInitializationMode(component) == OK
        return status

    return run


def _discarded_huge_step_fmi3(h):
    component = h.ready()
    assert h.fmi3SetFloat64(component, refs(TORQUE), 1, reals(20.0), 1) == OK
    assert h.step(component, 0.0, 0.5) == OK
    theta, last = h.get(component, THETA), ctypes.c_double()
    status = h.step(component, 0.5, 1e9, last)
    assert last.value == 0.5, "fmi3DoStep reports lastSuccessfulTime"
    assert h.get(component, THETA) == theta, "a discarded step must leave the instance where it was"
    assert h.step(component, 0.5, 1e-3) == ERROR, "step discarded: no more steps without a rollback"
    return status


def _flags(n):
    return [ctypes.byref(ctypes.c_bool()) for _ in range(n)]


def _scheduled_execution(h):
    component = h.lib.fmi3InstantiateScheduledExecution(
        b"x", h.guid, b"", False, False, None, h.logger, None, None, None
    )
    return 0 if not component else 3


CASES_FMI3 = [
    Case(
        "non-finite values",
        "torque = NaN after initialization",
        "fmi3SetFloat64",
        ERROR,
        "torque = nan refused",
        lambda h: _unchanged_after(h, h.ready(), TORQUE, NAN),
    ),
    Case(
        "non-finite values",
        "start angle theta = -inf",
        "fmi3SetFloat64",
        ERROR,
        "theta = -inf refused",
        lambda h: _unchanged_after(h, h.initializing(), THETA, -INF),
    ),
    Case(
        "non-finite values",
        "time set (the independent variable)",
        "fmi3SetFloat64",
        ERROR,
        "cannot set time",
        lambda h: h.fmi3SetFloat64(h.ready(), refs(CALL_RECORD_FILE + 1), 1, reals(1.0), 1),
    ),
    Case(
        "physical nonsense",
        "mass = 0",
        "fmi3ExitInitializationMode",
        ERROR,
        "mass must be > 0",
        _exit_with_fmi3(mass=0.0),
    ),
    Case(
        "state machine",
        "fmi3DoStep before initialization",
        "fmi3DoStep",
        ERROR,
        "not allowed in state 'instantiated'",
        lambda h: h.step(h.instantiate(), 0.0, 0.001),
    ),
    Case(
        "state machine",
        "fmi3DoStep after fmi3Terminate",
        "fmi3DoStep",
        ERROR,
        "not allowed in state 'terminated'",
        lambda h: (lambda c: (h.fmi3Terminate(c), h.step(c, 0.0, 0.001))[-1])(h.ready()),
    ),
    Case(
        "state machine",
        "fmi3DoStep on a model-exchange instance",
        "fmi3DoStep",
        ERROR,
        "a co-simulation function, and this instance is for model exchange",
        lambda h: h.step(h.ready(kind=MODEL_EXCHANGE), 0.0, 0.001),
    ),
    Case(
        "state machine",
        "model-exchange call on a co-simulation instance",
        "fmi3SetContinuousStates",
        ERROR,
        "a model-exchange function, and this instance is for co-simulation",
        _ready_then("fmi3SetContinuousStates", lambda: reals(0.0, 0.0), 2),
    ),
    Case(
        "state machine",
        "co-simulation call on a terminated model-exchange instance (a state both share)",
        "fmi3GetOutputDerivatives",
        ERROR,
        "a co-simulation function, and this instance is for model exchange",
        _terminated_model_exchange_then(
            "fmi3GetOutputDerivatives", refs(THETA), 1, (ctypes.c_int * 1)(1), lambda: reals(0.0), 1
        ),
    ),
    Case(
        "state machine",
        "fmi3EnterEventMode on a co-simulation instance (no event mode)",
        "fmi3EnterEventMode",
        ERROR,
        "not allowed in state 'step complete'",
        _ready_then("fmi3EnterEventMode"),
    ),
    Case(
        "state machine",
        "fixed parameter mass set after initialization",
        "fmi3SetFloat64",
        ERROR,
        "a fixed parameter cannot change after initialization",
        lambda h: _unchanged_after(h, h.ready(), MASS, 1.0),
    ),
    Case(
        "state machine",
        "output derivative of order 3",
        "fmi3GetOutputDerivatives",
        ERROR,
        "no derivative of order 3",
        _ready_then("fmi3GetOutputDerivatives", refs(THETA), 1, (ctypes.c_int * 1)(3), lambda: reals(0.0), 1),
    ),
    Case(
        "state machine",
        "directional derivative of alpha by mass",
        "fmi3GetDirectionalDerivative",
        ERROR,
        "no partial derivative of vr 3 with respect to vr 4",
        _ready_then(
            "fmi3GetDirectionalDerivative", refs(ALPHA), 1, refs(MASS), 1, lambda: reals(1.0), 1, lambda: reals(0.0), 1
        ),
    ),
    Case(
        "state machine",
        "an Int32 variable read",
        "fmi3GetInt32",
        ERROR,
        "this FMU has no variables of this type",
        _ready_then("fmi3GetInt32", refs(0), 1, lambda: (ctypes.c_int32 * 1)(), 1),
    ),
    Case(
        "record file",
        "callRecordFile = NULL",
        "fmi3SetString",
        ERROR,
        "callRecordFile is NULL",
        _instantiated_then("fmi3SetString", refs(CALL_RECORD_FILE), 1, lambda: strings(None), 1),
    ),
    Case(
        "record file",
        "callRecordFile of 1024 bytes",
        "fmi3SetString",
        ERROR,
        "callRecordFile is 1024 bytes long: at most 1023",
        _instantiated_then("fmi3SetString", refs(CALL_RECORD_FILE), 1, lambda: strings(b"x" * 1024), 1),
    ),
    Case(
        "record file",
        "callRecordFile a symbolic link (/proc/self/exe, a link on every Linux)",
        "fmi3SetString",
        WARNING,
        "is a symbolic link: the FMU writes no record file",
        _instantiated_then("fmi3SetString", refs(CALL_RECORD_FILE), 1, lambda: strings(b"/proc/self/exe"), 1),
    ),
    Case(
        "counts",
        "nValues = 2 for one value reference",
        "fmi3SetFloat64",
        ERROR,
        "nValues = 2, expected 1",
        _ready_then("fmi3SetFloat64", refs(TORQUE), 1, lambda: reals(1.0, 2.0), 2),
    ),
    Case(
        "counts",
        "adjoint with nSensitivity = nUnknowns instead of nKnowns",
        "fmi3GetAdjointDerivative",
        ERROR,
        "nSensitivity = 1, expected 3",
        _ready_then(
            "fmi3GetAdjointDerivative",
            refs(ALPHA),
            1,
            refs(TORQUE, THETA, OMEGA),
            3,
            lambda: reals(1.0),
            1,
            lambda: reals(0.0),
            1,
        ),
    ),
    Case(
        "not supported",
        "configuration mode",
        "fmi3EnterConfigurationMode",
        ERROR,
        "not supported: the model has no structural parameters",
        _ready_then("fmi3EnterConfigurationMode"),
    ),
    Case(
        "not supported",
        "a clock read",
        "fmi3GetClock",
        ERROR,
        "not supported: the model has no clocks",
        _ready_then("fmi3GetClock", refs(0), 1, lambda: (ctypes.c_bool * 1)()),
    ),
    Case(
        "not supported",
        "an interval set",
        "fmi3SetIntervalDecimal",
        ERROR,
        "not supported: the model has no clocks",
        _ready_then("fmi3SetIntervalDecimal", refs(0), 1, lambda: reals(1.0)),
    ),
    Case(
        "not supported",
        "fmi3EnterStepMode (co-simulation has no event mode)",
        "fmi3EnterStepMode",
        ERROR,
        "not supported: co-simulation has no event mode",
        _ready_then("fmi3EnterStepMode"),
    ),
    Case(
        "not supported",
        "per-element dependencies",
        "fmi3GetNumberOfVariableDependencies",
        ERROR,
        "providesPerElementDependencies is false",
        _ready_then("fmi3GetNumberOfVariableDependencies", ALPHA, lambda: ctypes.byref(ctypes.c_size_t())),
    ),
    Case(
        "not supported",
        "a model partition activated",
        "fmi3ActivateModelPartition",
        ERROR,
        "not supported: the model has no clocks to schedule",
        _ready_then("fmi3ActivateModelPartition", 0, ctypes.c_double(0)),
    ),
    Case(
        "not supported",
        "scheduled execution",
        "fmi3InstantiateScheduledExecution",
        ERROR,
        "not supported: the model has no clocks",
        _scheduled_execution,
    ),
    Case(
        "fmi3DoStep",
        "step size 0",
        "fmi3DoStep",
        ERROR,
        "must be positive and finite",
        lambda h: h.step(h.ready(), 0.0, 0.0),
    ),
    Case(
        "fmi3DoStep",
        "currentCommunicationPoint 0.5 where the instance stands at 0",
        "fmi3DoStep",
        ERROR,
        "is not where the instance stands",
        lambda h: h.step(h.ready(), 0.5, 0.001),
    ),
    Case(
        "fmi3DoStep",
        "a step of 1e9 s: more than the 100000 internal steps allowed",
        "fmi3DoStep",
        DISCARD,
        "step budget exhausted",
        _discarded_huge_step_fmi3,
    ),
    Case(
        "NULL and counts",
        "NULL instance",
        "fmi3DoStep",
        ERROR,
        "",
        lambda h: h.fmi3DoStep(
            None, ctypes.c_double(0), ctypes.c_double(0.001), True, *_flags(3), ctypes.byref(ctypes.c_double())
        ),
    ),
    Case(
        "NULL and counts",
        "valueReferences = NULL with nValueReferences = 1",
        "fmi3GetFloat64",
        ERROR,
        "argument valueReferences must not be NULL",
        _ready_then("fmi3GetFloat64", None, 1, lambda: reals(0.0), 1),
    ),
    Case(
        "NULL and counts",
        "lastSuccessfulTime = NULL",
        "fmi3DoStep",
        ERROR,
        "argument lastSuccessfulTime must not be NULL",
        lambda h: h.fmi3DoStep(h.ready(), ctypes.c_double(0), ctypes.c_double(0.001), True, *_flags(3), None),
    ),
    Case(
        "NULL and counts",
        "NULL flags",
        "fmi3UpdateDiscreteStates",
        ERROR,
        "argument discreteStatesNeedUpdate must not be NULL",
        _ready_then(
            "fmi3UpdateDiscreteStates", None, *_flags(4), lambda: ctypes.byref(ctypes.c_double()), kind=MODEL_EXCHANGE
        ),
    ),
    Case(
        "NULL and counts",
        "NULL FMU state pointer",
        "fmi3GetFMUState",
        ERROR,
        "argument FMUstate must not be NULL",
        _ready_then("fmi3GetFMUState", None),
    ),
    Case(
        "fmi3Instantiate",
        "a token from another FMU",
        "fmi3InstantiateCoSimulation",
        ERROR,
        "instantiationToken {00000000-0000-0000-0000-000000000000} does not match",
        _no_instance(lambda h: h.instantiate(guid=b"{00000000-0000-0000-0000-000000000000}") is None),
    ),
    Case(
        "fmi3Instantiate",
        "empty instance name",
        "fmi3InstantiateModelExchange",
        ERROR,
        "instanceName must be a non-empty string",
        _no_instance(lambda h: h.instantiate(name=b"", kind=MODEL_EXCHANGE) is None),
    ),
    Case(
        "fmi3Instantiate",
        "an instantiation token of a megabyte",
        "fmi3InstantiateCoSimulation",
        ERROR,
        "instantiationToken {ggg",
        _no_instance(_huge_token),
    ),
    Case(
        "fmi3Instantiate",
        "an instance name and a resource path of a megabyte, the path with line ends",
        "fmi3GetFloat64",
        OK,
        "",
        lambda h: _huge_name_and_resources(h, lambda c: h.fmi3GetFloat64(c, refs(THETA), 1, reals(0.0), 1)),
    ),
    Case(
        "fmi3Instantiate",
        "no logger",
        "fmi3InstantiateCoSimulation",
        ERROR,
        "",
        _no_instance(lambda h: h.instantiate(logger=None) is None),
    ),
    Case(
        "FMU state blobs",
        "garbage bytes",
        "fmi3DeserializeFMUState",
        ERROR,
        "bad magic",
        _deserialize(lambda blob: bytearray(b"\xde\xad\xbe\xef" * (len(blob) // 4))),
    ),
    Case(
        "FMU state blobs",
        "truncated by one byte",
        "fmi3DeserializeFMUState",
        ERROR,
        "truncated, or from another build",
        _deserialize(lambda blob: blob[:-1]),
    ),
    Case(
        "FMU state blobs",
        "one payload bit flipped",
        "fmi3DeserializeFMUState",
        ERROR,
        "checksum mismatch",
        _deserialize(_flip(40)),
    ),
    *_foreign_state_cases(Harness3),
]


def run_case(harness: Harness, case: Case) -> tuple[int, str]:
    """(status, what the FMU logged for the call)."""
    harness.messages.clear()
    status = case.run(harness)
    message = next((m for m in reversed(harness.messages) if case.expected_message in m), harness.last_message())
    harness.close()
    return status, message


def _table(rows: list[tuple[Case, int, str]]) -> list[str]:
    lines = [
        "| group | bad input | call | answer | message logged through the master's logger |",
        "|---|---|---|---|---|",
    ]
    for case, status, message in rows:
        shown = (
            message.replace("|", "\\|")
            if message
            else "(no instance, so nothing to log to)"
            if "Instantiate" in case.call or case.call.endswith("DoStep")
            else ""
        )
        answer = "NULL" if "Instantiate" in case.call else status_name(case.call, status)
        lines.append(f"| {case.group} | {case.bad_input} | `{case.call}` | {answer} | {shown} |")
    return lines


def markdown(rows: list[tuple[Case, int, str]], rows_fmi3: list[tuple[Case, int, str]]) -> str:
    lines = [
        "# What the FMU answers to bad calls",
        "",
        "Generated by `python tests/bad_calls.py docs/robustness.md` from the cases that "
        "`tests/test_robustness.py` asserts; do not edit by hand. Each call goes to the binary through "
        "ctypes. After every refused call the instance keeps its last good state and can go on.",
        "",
        "## FMI 2.0 (`Pendulum.fmu`)",
        "",
        *_table(rows),
        "",
        "## FMI 3.0 (`Pendulum-fmi3.fmu`)",
        "",
        "The same core answers through the FMI 3.0 entry points; what FMI 3.0 adds that the pendulum "
        "has no use for answers `fmi3Error` with the reason.",
        "",
        *_table(rows_fmi3),
    ]
    return "\n".join(lines) + "\n"


def main(argv=None):
    """Build both FMUs, run every case, write the markdown tables."""
    import tempfile
    import zipfile

    from fmpy import read_model_description

    from fmu_build import build_fmu

    out = Path((argv or sys.argv[1:] or ["docs/robustness.md"])[0])
    with tempfile.TemporaryDirectory() as tmp:
        tables = []
        for version, harness_type, folder, cases in (
            (2, Harness, "linux64", CASES),
            (3, Harness3, "x86_64-linux", CASES_FMI3),
        ):
            fmu = build_fmu(Path(tmp) / f"Pendulum{version}.fmu", fmi_version=version)
            zipfile.ZipFile(fmu).extractall(Path(tmp) / str(version))
            harness = harness_type(
                Path(tmp) / str(version) / f"binaries/{folder}/Pendulum.so", read_model_description(str(fmu)).guid
            )
            tables.append([(case, *run_case(harness, case)) for case in cases])
    from pendulum_fmu._atomic_files import replacing

    with replacing(out) as file:
        file.write(markdown(*tables))
    print(f"wrote {out}: {sum(map(len, tables))} cases")


if __name__ == "__main__":
    main()
