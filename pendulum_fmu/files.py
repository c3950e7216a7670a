"""Files that appear whole or not at all.

Everything the project writes goes through `replacing`: the content is written to a unique
temporary beside the target (same folder, so the rename is atomic on one file system) and renamed
into place only when the writer finished without an exception. An interrupted or failed write
leaves the old file, or none, and no temporary.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
import uuid
from pathlib import Path


# Every temporary a writer here leaves if it is killed (SIGKILL, a lost worker) matches this, so
# that whoever owns the folder can sweep them up.
TEMPORARY_GLOB = ".*.partial*"


def _read_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


# Read once at import: os.umask can only be read by setting it, which races with other threads.
_UMASK = _read_umask()


class NotWritable(OSError):
    """No file can be written where the user asked; the message names the user's path (never a
    temporary) and what to do."""


def _temporary_beside(path: Path, suffix: str) -> tuple[int, str]:
    """A new file beside path with the permissions a plain open() would give (mkstemp's are 0600,
    which would hide an FMU or a table from the other users of a shared folder)."""
    for folder in (path.parent, *path.parent.parents):
        if folder.exists() and not folder.is_dir():
            raise NotADirectoryError(f"cannot write {path}: {folder} is a file, not a folder; "
                                     "choose another output path")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise NotWritable(f"cannot write {path}: the folder {error.filename} cannot be created "
                          f"({error.strerror}); choose another output path") from None
    try:
        descriptor, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    except OSError as error:
        raise NotWritable(f"cannot write {path}: no file can be created in {path.parent} "
                          f"({error.strerror}); choose another output path") from None
    os.chmod(temporary, 0o666 & ~_UMASK)
    return descriptor, temporary


def check_writable(*paths: str | os.PathLike) -> None:
    """Refuse, before a long run, an output path that `replacing` could not write after it.

    The unique temporary `replacing` would write is created beside each path and removed again,
    with the folders made for it, so the check leaves nothing behind.

    Raises
    ------
    NotWritable
        A path is a folder, or no file can be created beside it.
    NotADirectoryError
        A folder on the way is a file.
    """
    for path in map(Path, paths):
        if path.is_dir():
            raise NotWritable(f"cannot write {path}: it is a folder; give a file name")
        made = [folder for folder in (path.parent, *path.parent.parents) if not folder.exists()]
        try:
            descriptor, temporary = _temporary_beside(path, f".partial{path.suffix}")
            os.close(descriptor)
            os.unlink(temporary)
        finally:
            for folder in made:  # deepest first
                with contextlib.suppress(OSError):
                    folder.rmdir()


@contextlib.contextmanager
def replacing(path: str | os.PathLike, mode: str = "w", **open_arguments):
    """Open a unique temporary beside path for writing; on success rename it to path.

    with replacing("out.csv", newline="") as file: ...
    """
    # The file closes before replacing_path renames it.
    with replacing_path(path) as temporary, open(temporary, mode, **open_arguments) as file:
        yield file


@contextlib.contextmanager
def replacing_path(path: str | os.PathLike):
    """A unique temporary path beside path, for writers that want a file name (savefig, zip);
    renamed to path on success, removed otherwise."""
    path = Path(path)
    descriptor, temporary = _temporary_beside(path, f".partial{path.suffix}")
    os.close(descriptor)
    try:
        yield Path(temporary)
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)
        raise


@contextlib.contextmanager
def replacing_on(filesystem, path: str):
    """replacing(path, "wb") on any fsspec file system, for outputs given as URLs.

    The local file system goes through replacing. Elsewhere the content is written to a unique
    temporary name beside path and moved into place (an object store's upload appears whole;
    the move makes that hold for the other file systems too).
    """
    from fsspec.implementations.local import LocalFileSystem

    if isinstance(filesystem, LocalFileSystem):
        with replacing(path, "wb") as file:
            yield file
        return
    parent, _, name = path.rpartition("/")
    temporary = f"{parent}/.{name}.{uuid.uuid4().hex}.partial"
    with contextlib.ExitStack() as on_failure:
        on_failure.callback(_remove_if_there, filesystem, temporary)
        with filesystem.open(temporary, "wb") as file:
            yield file
        filesystem.mv(temporary, path)
        on_failure.pop_all()  # moved into place: nothing to remove


class InUse(OSError):
    """Another process holds the lock; the message says which folder and what to do."""


@contextlib.contextmanager
def held_lock(path: str | os.PathLike, what: str):
    """Hold an exclusive lock on the file path while the block runs, or raise InUse at once when
    another process holds it. The file is created for the block and removed after it; the
    operating system releases the lock when the process ends, however it ends, so a killed run
    leaves at most a file that locks nothing."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise NotWritable(f"cannot write in {path.parent}: the folder {error.filename} cannot be "
                          f"created ({error.strerror}); choose another output folder") from None
    with open(path, "a+b") as file:
        try:
            _lock(file)
            # A holder that finished removed the file we opened: the lock is on a file no other
            # run can see.
            held = os.path.samestat(os.fstat(file.fileno()), os.stat(path))
        except OSError:
            held = False
        if not held:
            raise InUse(f"{what} is in use by another run (it holds {path}); wait for that run "
                        "to end, or choose another output")
        try:
            yield
        finally:
            with contextlib.suppress(OSError):  # Windows keeps an open file
                os.unlink(path)


if os.name == "nt":
    import msvcrt

    def _lock(file) -> None:
        msvcrt.locking(file.fileno(), msvcrt.LK_NBLCK, 1)
else:
    import fcntl

    def _lock(file) -> None:
        fcntl.flock(file.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)


def _remove_if_there(filesystem, path: str) -> None:
    with contextlib.suppress(FileNotFoundError):
        filesystem.rm(path)
