"""The model object: one FMU file, parsed once, with everything the tools ask of it.

fmu_model() turns what a user gives as an FMU (a path, None for pendulum_fmu.default_fmu(), or a
model already made) into an FmuModel, made once per file version: its model description, its
variables with their value references, units, descriptions and start values, and the folder it is
extracted to. Every tool takes and passes that object instead of resolving the path again, and
this is where every FMU a user names is first opened: a file that is no FMI 2.0 or 3.0 FMU is
refused here with FmuFileError, and one that is not a pendulum wherever the pendulum's variables
are asked for.
"""

from __future__ import annotations

import os
import tempfile
import threading
import zipfile
from functools import cached_property, lru_cache
from pathlib import Path

import fmpy
from fmpy import extract, read_model_description

from .._errors import InvalidInput, MissingFile, WrongType
from .._received_files import open_fmu
from . import WASM_PLATFORM

# The start values a user gives, and the FMU's variables they start.
START_VALUES = {"theta0": "theta", "omega0": "omega"}
# What every tool reads from or writes to a pendulum FMU.
PENDULUM_VARIABLES = ("torque", "theta", "omega", "alpha")
FMI_VERSIONS = ("2.0", "3.0")


class FmuFileError(InvalidInput):
    """The file given as an FMU is none this package can run: not a zip, no modelDescription.xml,
    not FMI 2.0 or 3.0, or not a pendulum; the message names the file and what to do.

    Examples
    --------
    A text file given as an FMU:

    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import FmuFileError, simulate
    >>> not_an_fmu = Path(tempfile.mkdtemp(), "notes.fmu")
    >>> _ = not_an_fmu.write_text("not a zip")
    >>> try:
    ...     simulate(20.0, fmu_path=not_an_fmu)
    ... except FmuFileError as error:
    ...     print(str(error).replace(str(not_an_fmu), "notes.fmu"))
    notes.fmu is not an FMU (an FMU is a zip archive with a modelDescription.xml): check the path
    """


def file_version(path: str | os.PathLike) -> tuple[int, int, int, int]:
    """(device, inode, size, modification time in ns) of a file: a file rebuilt, rewritten or
    replaced has another. MissingFile (with the path) when it is not there.
    """
    try:
        status = os.stat(path)
    except OSError as error:
        raise MissingFile(f"FMU {path}: {error.strerror}") from None
    return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns


def fmu_file(fmu_path: str | os.PathLike | FmuModel | None) -> Path:
    """The FMU file a function is about: fmu_path (a model's own path), or
    pendulum_fmu.default_fmu().
    """
    if isinstance(fmu_path, FmuModel):
        return fmu_path.path
    if fmu_path is None:
        from .. import default_fmu

        return default_fmu()
    # bool and int would pass for a file descriptor, which is no FMU's path.
    if not isinstance(fmu_path, (str, os.PathLike)):
        raise WrongType(f"fmu_path is the FMU file's path (a str or Path), not {fmu_path!r}")
    return Path(fmu_path)


class FmuModel:
    """One FMU file as the tools see it: parsed once, extracted once (on first use).

    Make it with fmu_model(); shared by every tool and thread: do not modify it.

    Attributes
    ----------
    path : Path
        The file, as the user gave it (for messages) .
    version : tuple
        file_version() of the file when it was read.
    description : fmpy.model_description.ModelDescription
        fmpy's model description.
    variables : dict
        {name: fmpy ModelVariable} of every variable.
    fmi_version : int
        2 or 3.

    Examples
    --------
    >>> from pendulum_fmu.fmu._model import fmu_model
    >>> model = fmu_model()          # the default FMU
    >>> model.value_reference("theta") == model.variables["theta"].valueReference
    True
    """

    def __init__(self, path: Path, version: tuple, description, archive_names: frozenset[str]):
        self.path, self.version, self.description = path, version, description
        self.variables = {v.name: v for v in description.modelVariables}
        self.fmi_version = int(description.fmiVersion[0])
        self._archive_names = archive_names
        self._extracting = threading.Lock()  # threads of one dask worker share the model

    @cached_property
    def pendulum_variables(self) -> dict:
        """Variables of a pendulum FMU this machine can run.

        Raises
        ------
        FmuFileError
            Not a pendulum (no torque, theta, omega or alpha), no Co-Simulation interface, or no
            binary for this platform nor a WebAssembly one (binary() says which).
        """
        description, path = self.description, self.path
        missing = [name for name in PENDULUM_VARIABLES if name not in self.variables]
        if missing:
            raise FmuFileError(
                f"{path} is not a pendulum FMU: it has no variable {', '.join(missing)} "
                f"(it is the model {description.modelName!r}); give the pendulum's FMU, "
                "or compare another model with compare --tools LABEL=path --map"
            )
        if description.coSimulation is None:
            raise FmuFileError(
                f"{path} has no Co-Simulation interface, which this package runs: export it for Co-Simulation"
            )
        if self.binary(WASM_PLATFORM, refuse=False) is None:
            self.binary()
        return self.variables

    def binary(self, platform: str | None = None, *, refuse: bool = True) -> str | None:
        """The archive name of the FMU's Co-Simulation binary for a platform.

        Parameters
        ----------
        platform : str, optional
            None: this machine's (fmpy's platform folder); WASM_PLATFORM: the WebAssembly
            component of FMI-LS-WASM (FMI 3.0 only).
        refuse : bool, optional
            Raise when the FMU has no such binary (else return None).

        Returns
        -------
        str or None
            Such as binaries/x86_64-linux/Pendulum.so, or binaries/wasm32-wasip2/Pendulum.wasm.

        Raises
        ------
        FmuFileError
            No such binary in the FMU (when refuse), naming the one it lacks and what to do.
        """
        identifier = self.description.coSimulation.modelIdentifier
        if platform == WASM_PLATFORM:
            name = f"binaries/{WASM_PLATFORM}/{identifier}.wasm"
            advice = "give the FMI 3.0 FMU that carries it (pendulum-fmu export --fmi-version 3)"
            if self.fmi_version != 3:
                name, advice = "", "a WebAssembly binary is FMI 3.0 only: give the FMI 3.0 FMU"
        else:
            folder = fmpy.platform_tuple if self.fmi_version == 3 else fmpy.platform
            name = f"binaries/{folder}/{identifier}{fmpy.sharedLibraryExtension}"
            advice = "build it here with pendulum-fmu build, or give an FMU built for this platform"
            if self.binary(WASM_PLATFORM, refuse=False):
                advice = (
                    f"run its WebAssembly binary instead: --platform {WASM_PLATFORM} "
                    f"(platform={WASM_PLATFORM!r} in Python)"
                )
        if name in self._archive_names:
            return name
        if not refuse:
            return None
        what = "this platform" if platform is None else platform
        raise FmuFileError(f"{self.path} has no binary for {what}{f' ({name})' if name else ''}: {advice}")

    @cached_property
    def default_parameters(self) -> dict[str, float]:
        """{name: start value} of every Real parameter (shared: copy before changing); raises as
        pendulum_variables. String parameters (callRecordFile) are no physical parameter.
        """
        return {
            name: float(v.start)
            for name, v in self.pendulum_variables.items()
            if v.causality == "parameter" and v.type in ("Real", "Float64")
        }

    @cached_property
    def outputs(self) -> tuple[str, ...]:
        """The names of the FMU's output variables, in modelDescription.xml's order: the one place
        that names what a result records besides time and the inputs.
        """
        return tuple(name for name, v in self.variables.items() if v.causality == "output")

    @cached_property
    def recorded(self) -> tuple[str, ...]:
        """What a run records at every communication point, read back from the FMU: its inputs
        (the torque it received), then its outputs, in modelDescription.xml's order.
        """
        return tuple(name for name, v in self.variables.items() if v.causality in ("input", "output"))

    @cached_property
    def value_references(self) -> dict[str, int]:
        """{name: value reference} of every variable of a pendulum FMU, made once per model so a
        run looks each one up in a dict; raises as pendulum_variables.
        """
        return {name: v.valueReference for name, v in self.pendulum_variables.items()}

    def value_reference(self, name: str) -> int:
        """The value reference of a pendulum variable; raises as pendulum_variables, KeyError
        for a name it does not have.
        """
        return self.value_references[name]

    def unit(self, name: str) -> str:
        """The declared unit of a variable, parameter or start value (theta0: theta's), '' where
        none; raises as value_reference.
        """
        return self.pendulum_variables[START_VALUES.get(name, name)].unit or ""

    @cached_property
    def folder(self) -> str:
        """The folder the FMU is extracted to, once per model; removed at exit."""
        with self._extracting:
            if "_unzipped" not in self.__dict__:
                self._unzipped = tempfile.TemporaryDirectory(prefix="pendulum_fmu_")
                extract(str(self.path), unzipdir=self._unzipped.name)
        return self._unzipped.name


@lru_cache(maxsize=32)
def _read(path: str, version: tuple, shown: str) -> FmuModel:
    """The FmuModel of the file at path (resolved) as it is at version; shown is the path as the
    user gave it, for the messages.
    """
    try:
        with open_fmu(path, shown, FmuFileError) as archive:  # before fmpy parses and unpacks it
            names = frozenset(archive.namelist())
    except (zipfile.BadZipFile, OSError):
        raise FmuFileError(
            f"{shown} is not an FMU (an FMU is a zip archive with a modelDescription.xml): check the path"
        ) from None
    if "modelDescription.xml" not in names:
        raise FmuFileError(
            f"{shown} is not an FMU: the zip archive has no modelDescription.xml" + ("" if names else " (it is empty)")
        )
    try:
        description = read_model_description(path)
    except Exception as error:  # lxml's and fmpy's own: the XML is broken or invalid
        # fmpy lists its validation problems one per line: one line here.
        problems = "; ".join(line.strip(" -") for line in str(error).splitlines() if line.strip(" -"))
        raise FmuFileError(f"{shown}: its modelDescription.xml cannot be read: {problems}") from None
    if description.fmiVersion not in FMI_VERSIONS:
        raise FmuFileError(
            f"{shown} is an FMI {description.fmiVersion} FMU; this package runs "
            "FMI 2.0 and 3.0 FMUs: export the model as one of those"
        )
    return FmuModel(Path(shown), version, description, names)


def fmu_model(fmu: str | os.PathLike | FmuModel | None = None) -> FmuModel:
    """The model object of an FMU: made once per file version, the same object after that.

    Parameters
    ----------
    fmu : str, Path, FmuModel or None
        The FMU file, a model (returned as it is), or None for pendulum_fmu.default_fmu().

    Returns
    -------
    FmuModel
        A new one whenever the file was rebuilt or replaced.

    Raises
    ------
    WrongType
        fmu is no path.
    MissingFile
        No file there.
    FmuFileError
        The file is no FMI 2.0 or 3.0 FMU.

    Examples
    --------
    >>> from pendulum_fmu import default_fmu, fmu_model
    >>> model = fmu_model(default_fmu())
    >>> model.fmi_version, model.default_parameters
    (2, {'mass': 40.0, 'length': 0.5, 'inertia': 20.0, 'gravity': 9.81, 'damping': 0.0})
    >>> fmu_model(default_fmu()) is model  # made once per file version
    True
    """
    if isinstance(fmu, FmuModel):
        return fmu
    path = fmu_file(fmu)
    version = file_version(path)
    return _read(str(path.resolve()), version, str(path))
