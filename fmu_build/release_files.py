"""The package's release files, the sdist and the wheel, the same bytes from one commit in any
folder, at any time, by any user (setup.py, build_wheels.py).

- The sdist's tar.gz is written here: setuptools' own takes each file's time and owner from the
  checkout, the gzip header's time from the clock and its file name from the archive, and has no
  option to fix them (its --owner and --group fix only the owner).
- The wheel's files get fixed permissions before bdist_wheel or `wheel pack` zips them: both
  take an entry's permissions from its file, which the checkout's umask decides. They date the
  entries themselves, by $SOURCE_DATE_EPOCH, which setup.py and build_wheels.py set.

What stays is the bytes zlib's deflate writes, the same for one zlib version and level; a Python
built on zlib-ng (Fedora 40 and later) compresses to other bytes.
"""

from __future__ import annotations

import gzip
import os
import stat
import tarfile
from pathlib import Path

from pendulum_fmu._atomic_files import replacing_path


def normalized_mode(mode: int) -> int:
    """rwxr-xr-x for what its owner may run, else rw-r--r--: a file's permissions without the
    umask of the checkout that made it.
    """
    return 0o755 if mode & stat.S_IXUSR else 0o644


def normalize_modes(folder: str | os.PathLike) -> None:
    """Give every file under folder its normalized_mode."""
    for path in Path(folder).rglob("*"):
        if path.is_file() and not path.is_symlink():
            path.chmod(normalized_mode(path.stat().st_mode))


def _normalized(info: tarfile.TarInfo, epoch: int) -> tarfile.TarInfo:
    info.mtime = epoch
    info.uid = info.gid = 0
    info.uname = info.gname = ""
    info.mode = 0o755 if info.isdir() else normalized_mode(info.mode)
    return info


def write_tarball(archive: str | os.PathLike, folder: str | os.PathLike, epoch: int) -> None:
    """Write folder, under its own name, into archive as a gzipped tar whose bytes depend only on
    the names and contents of its files and whether each may be run.

    Parameters
    ----------
    archive : str or os.PathLike
        The .tar.gz to write (through a temporary beside it, renamed into place; its folder
        made when missing).
    folder : str or os.PathLike
        The tree to archive; its entries are named from folder's last component on.
    epoch : int
        Seconds since 1970 (UTC): the time of every entry and of the gzip header.

    Notes
    -----
    Entries go in sorted order of their names, each owned by uid and gid 0 with no owner names,
    with the permissions of normalized_mode (folders rwxr-xr-x); the gzip header carries no
    file name.
    """
    folder = Path(folder)
    members = sorted(folder.rglob("*"), key=lambda path: path.relative_to(folder).as_posix())
    Path(archive).parent.mkdir(parents=True, exist_ok=True)
    with (
        replacing_path(Path(archive)) as partial,
        open(partial, "wb") as raw,
        gzip.GzipFile(filename="", mode="wb", fileobj=raw, mtime=epoch) as compressed,
        tarfile.open(fileobj=compressed, mode="w", format=tarfile.PAX_FORMAT) as tar,
    ):
        for path in [folder, *members]:
            name = Path(folder.name, path.relative_to(folder)).as_posix()
            info = _normalized(tar.gettarinfo(path, arcname=name), epoch)
            if info.isreg():
                with open(path, "rb") as data:
                    tar.addfile(info, data)
            else:
                tar.addfile(info)
