"""`pendulum-fmu export`: the FMU this package runs, written where the user works.

From an installed package the FMU is the one packaged with it; in a checkout it is dist/'s,
rebuilt first when a source is newer (pendulum_fmu.default_fmu). The platforms an FMU holds are
read from the zip's binaries/ folders, so what is printed is what was written.
"""

from __future__ import annotations

import os
import shutil
import zipfile
from dataclasses import dataclass
from pathlib import Path

from .. import FMU_FILES, default_fmu
from .._atomic_files import check_writable, replacing_path
from .._errors import PendulumFmuError
from ._build_record import RECORD_FILE, SIGNATURE_FILE, read_entries, recorded_epoch, write_archive
from ._signing import load_private_key


class FmuExists(PendulumFmuError, FileExistsError):
    """A file is already at the export's output path and the export was not asked to replace it."""


@dataclass(frozen=True)
class ExportedFmu:
    """An FMU written by export_fmu.

    Attributes
    ----------
    path : Path
        Where it was written.
    platforms : tuple of str
        The binaries/ folders it holds (linux64, win64, ... for FMI 2.0; x86_64-linux, ... for
        FMI 3.0), sorted.
    """

    path: Path
    platforms: tuple[str, ...]


def fmu_platforms(fmu: str | os.PathLike) -> tuple[str, ...]:
    """The platforms an FMU has binaries for: the folders of its zip's binaries/ that hold a file.

    Parameters
    ----------
    fmu : str or os.PathLike
        An FMU file.

    Returns
    -------
    tuple of str
        The folder names under binaries/, sorted.

    Examples
    --------
    >>> from pendulum_fmu import default_fmu
    >>> "linux64" in fmu_platforms(default_fmu())  # doctest: +SKIP
    True
    """
    with zipfile.ZipFile(fmu) as archive:
        folders = {
            parts[1]
            for parts in (name.split("/") for name in archive.namelist())
            if len(parts) == 3 and parts[0] == "binaries" and parts[2]
        }
    return tuple(sorted(folders))


def export_fmu(
    output: str | os.PathLike | None = None,
    *,
    fmi_version: int = 2,
    overwrite: bool = False,
    sign: str | os.PathLike | None = None,
) -> ExportedFmu:
    """Write the pendulum's FMU to output, whole or not at all.

    Parameters
    ----------
    output : str or os.PathLike, optional
        Where to write it; None: Pendulum.fmu (Pendulum-fmi3.fmu for FMI 3.0) in the current folder.
    fmi_version : {2, 3}, optional
        The FMI standard of the FMU.
    overwrite : bool, optional
        Replace a file already at output; False refuses it.
    sign : str or os.PathLike, optional
        An Ed25519 private key (PEM): the FMU then carries a signature of its build record
        (extra/org.pendulum-fmu.build/build.json.sig), which `pendulum-fmu verify --public-key`
        checks.

    Returns
    -------
    ExportedFmu
        The path written and the platforms the FMU holds binaries for.

    Raises
    ------
    FmuExists
        A file is at output and overwrite is False.
    InvalidInput
        An FMI version the package does not build.
    CannotWrite
        output cannot be written.
    BuildError
        In a checkout, a stale FMU that cannot be rebuilt here.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from pendulum_fmu import export_fmu
    >>> exported = export_fmu(Path(tempfile.mkdtemp(), "Pendulum.fmu"))
    >>> exported.path.name, exported.platforms
    ('Pendulum.fmu', ('aarch64-linux', 'darwin64', 'linux64', 'win64'))
    """
    source = default_fmu(fmi_version)  # first: it says which FMI versions there are
    output = Path(FMU_FILES[fmi_version] if output is None else output)
    if not overwrite and output.exists():
        raise FmuExists(f"{output} exists: pass --overwrite (overwrite=True) to replace it, or another --output")
    key = load_private_key(sign) if sign is not None else None  # before anything is written
    check_writable(output)
    with replacing_path(output) as partial:
        if key is None:
            shutil.copyfile(source, partial)
        else:
            entries = read_entries(source)
            entries[SIGNATURE_FILE] = key.sign(entries[RECORD_FILE])
            write_archive(partial, entries.items(), recorded_epoch(entries))
    return ExportedFmu(output, fmu_platforms(output))
