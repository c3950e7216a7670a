"""Files that appear whole or not at all.

Everything the project writes goes through `replacing`: the content is written to a unique
temporary beside the target (same folder, so the rename is atomic on one file system) and renamed
into place only when the writer finished without an exception. An interrupted or failed write
leaves the old file, or none, and no temporary. A target that is a symbolic link replaces the file
the link leads to, and keeps the link; a target that is no regular file (a device such as
/dev/null, a named pipe) has nothing to replace and is written into as it is.

replacing_on does the same on an fsspec file system, or on LocalFolders: this machine's, in the
calls a sweep's store makes of fsspec's, without importing fsspec.
"""

from __future__ import annotations

import contextlib
import errno
import fnmatch
import os
import shutil
import stat
import sys
import tempfile
import uuid
from pathlib import Path

from ._errors import CannotWrite

# Every temporary a writer here leaves if it is killed (SIGKILL, a lost worker) matches this, so
# that whoever owns the folder can sweep them up.
TEMPORARY_GLOB = ".*.partial*"
# A write that fails with one of these found no room where it writes.
_FULL = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


def _read_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


# Read once at import: os.umask can only be read by setting it, which races with other threads.
_UMASK = _read_umask()


# Of the target's name, the temporary carries this much: enough to tell whose it is, and short
# enough that a target whose name the file system just allows still gets a temporary.
_NAME_IN_TEMPORARY = 64


def _streamed(path: Path) -> bool:
    """Whether path is an existing file that is no regular file or folder (a device, a named
    pipe, a socket): renaming over it would destroy it, so it is written into as it is.
    """
    try:
        mode = path.stat().st_mode  # through a link, to what it leads to
    except OSError:
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


def _refuse_link(path: Path) -> None:
    """CannotWrite when path is a symbolic link that does not lead to a stream: an output is
    never written through a link, which anyone who can write the folder may have planted where
    the output is named (a run would replace the user's ~/.bashrc, or, as root, /etc/passwd).
    """
    if path.is_symlink():
        raise CannotWrite(
            f"cannot write {path}: it is a symbolic link (to {os.readlink(path)}), which outputs "
            "are never written through; name the file itself, or remove the link"
        )


def _longest_name(folder: Path) -> int:
    """The longest file name folder's file system allows, in bytes (255 where the platform cannot
    say, as on Windows, whose file systems allow 255 characters).
    """
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (AttributeError, OSError, ValueError):
        return 255


def _temporary_beside(path: Path, suffix: str, make_folders: bool = True) -> tuple[int, str]:
    """A new file beside path with the permissions of the file it replaces, or those a plain
    open() would give (mkstemp's are 0600, which would hide an FMU or a table from the other users
    of a shared folder). make_folders=False: FileNotFoundError where path's folder is not there.
    """
    try:
        descriptor, temporary = _new_file_beside(path, suffix)
    except OSError as error:
        if isinstance(error, FileNotFoundError) and not make_folders:
            raise
        # Only now the folders on the way, which cost a few system calls each: a sweep's worker
        # writes two files per chunk into a folder that exists.
        for folder in (path.parent, *path.parent.parents):
            if folder.exists() and not folder.is_dir():
                raise CannotWrite(
                    f"cannot write {path}: {folder} is a file, not a folder; choose another output path"
                ) from None
        make_folder(path.parent, path)
        try:
            descriptor, temporary = _new_file_beside(path, suffix)
        except OSError as error:
            raise CannotWrite(
                f"cannot write {path}: no file can be created in {path.parent} "
                f"({error.strerror}); choose another output path"
            ) from None
    try:
        permissions = stat.S_IMODE(path.stat().st_mode)
    except OSError:
        permissions = 0o666 & ~_UMASK
    os.chmod(temporary, permissions)
    return descriptor, temporary


def _new_file_beside(path: Path, suffix: str) -> tuple[int, str]:
    return tempfile.mkstemp(
        prefix=f".{path.name[:_NAME_IN_TEMPORARY]}.", suffix=suffix[:_NAME_IN_TEMPORARY], dir=path.parent
    )


def make_folder(folder: Path, target, choice: str = "output path") -> None:
    """Create folder and its parents for writing target; CannotWrite naming target if not.

    Parameters
    ----------
    folder : Path
        The folder to create (nothing happens when it exists).
    target : str or Path
        What the user asked to write, named in the message.
    choice : str, optional
        What the message asks the user to choose instead.

    Raises
    ------
    CannotWrite
        A folder on the way cannot be created.
    """
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise CannotWrite(
            f"cannot write {target}: the folder {error.filename} cannot be created "
            f"({error.strerror}); choose another {choice}"
        ) from None


def _cannot_write(path: Path, error: OSError) -> CannotWrite:
    return CannotWrite(f"cannot write {path}: {error.strerror or error}; choose another output path")


def check_writable(*paths: str | os.PathLike) -> None:
    """Refuse, before a long run, an output path that `replacing` could not write after it.

    The unique temporary `replacing` would write is created beside each path and removed again,
    with the folders made for it, so the check leaves nothing behind.

    Parameters
    ----------
    *paths : str or os.PathLike
        The files the run will write.

    Raises
    ------
    CannotWrite
        A path is a folder, a folder on the way is a file, or no file can be created beside it.
    """
    for path in map(Path, paths):
        try:
            _check_writable(path)
        except CannotWrite:
            raise
        except OSError as error:  # a name too long, a loop of links: the path itself is wrong
            raise _cannot_write(path, error) from None


def _check_writable(path: Path) -> None:
    if path.is_dir():
        raise CannotWrite(f"cannot write {path}: it is a folder; give a file name")
    if _streamed(path):
        if not os.access(path, os.W_OK):
            raise CannotWrite(f"cannot write {path}: permission denied; choose another output path")
        return
    _refuse_link(path)
    made = [folder for folder in (path.parent, *path.parent.parents) if not folder.exists()]
    try:
        descriptor, temporary = _temporary_beside(path, f".partial{path.suffix}")
        os.close(descriptor)
        os.unlink(temporary)
        # The name itself, which the temporary's shorter one did not try.
        longest = _longest_name(path.parent)
        if len(os.fsencode(path.name)) > longest:
            raise CannotWrite(
                f"cannot write {path}: its name is longer than the {longest} bytes "
                "this file system allows; choose a shorter name"
            )
    finally:
        for folder in made:  # deepest first
            with contextlib.suppress(OSError):
                folder.rmdir()


@contextlib.contextmanager
def replacing(path: str | os.PathLike, mode: str = "w", make_folders: bool = True, **open_arguments):
    """Open a unique temporary beside path for writing; on success rename it to path.

    with replacing("out.csv", newline="") as file: ...
    make_folders=False: FileNotFoundError where path's folder is not there, rather than make it.
    """
    # The file closes before replacing_path renames it.
    with replacing_path(path, make_folders) as temporary, open(temporary, mode, **open_arguments) as file:
        yield file


@contextlib.contextmanager
def replacing_path(path: str | os.PathLike, make_folders: bool = True):
    """A unique temporary path beside path, for writers that want a file name (savefig, zip);
    renamed to path on success, removed otherwise. make_folders: as replacing.
    """
    path = Path(path)
    if _streamed(path):
        yield path
        return
    _refuse_link(path)
    descriptor, temporary = _temporary_beside(path, f".partial{path.suffix}", make_folders)
    os.close(descriptor)
    try:
        try:
            yield Path(temporary)
            os.replace(temporary, path)
        except OSError as error:
            # Only a failure to write this file is the place's doing (a folder where the file
            # goes, no permission, no room); any other is the writer's, and goes on as it is.
            about_this = error.filename is not None and os.fspath(error.filename) == temporary
            if not (about_this or error.errno in _FULL):
                raise
            raise _cannot_write(path, error) from None
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)
        raise


class LocalFolders:
    """The machine's own file system in the calls a sweep's store makes of fsspec's LocalFileSystem
    (open, exists, makedirs, glob, mv, rm), made as it makes them, on os and shutil: a local
    output folder then costs no import of fsspec (~20 ms, a twentieth of a small study's time).
    """

    def open(self, path: str, mode: str = "rb"):
        return open(path, mode)

    def exists(self, path: str) -> bool:
        return os.path.exists(path)  # as fsspec's: a link to nothing is not there

    def makedirs(self, path: str, exist_ok: bool = False) -> None:
        os.makedirs(path, exist_ok=exist_ok)

    def glob(self, pattern: str) -> list[str]:
        """The paths in the pattern's folder whose names match its last part, the one with
        wildcards in a store's patterns; as fsspec's, * matches a leading dot too.
        """
        folder, _, names = pattern.rpartition("/")
        try:
            entries = os.listdir(folder)
        except (FileNotFoundError, NotADirectoryError):
            return []
        return [f"{folder}/{name}" for name in sorted(entries) if fnmatch.fnmatchcase(name, names)]

    def mv(self, source: str, target: str, recursive: bool = True) -> None:
        shutil.move(source, target)  # a folder with all it holds, as fsspec's

    def rm(self, path: str, recursive: bool = False) -> None:
        if os.path.isdir(path) and not os.path.islink(path):
            if not recursive:
                raise ValueError(f"{path} is a folder: remove it with recursive=True")
            shutil.rmtree(path)
        else:
            os.remove(path)


def is_local(filesystem) -> bool:
    """Whether an fsspec file system, or LocalFolders, is this machine's."""
    # fsspec's own class is looked for only where fsspec was imported: nothing else made one.
    local = sys.modules.get("fsspec.implementations.local")
    return isinstance(filesystem, LocalFolders) or (local is not None and isinstance(filesystem, local.LocalFileSystem))


@contextlib.contextmanager
def replacing_on(filesystem, path: str, make_folders: bool = True):
    """replacing(path, "wb") on any fsspec file system (or LocalFolders), for outputs given as URLs.
    make_folders: as replacing, on the local file system (elsewhere no folder is made).

    The local file system goes through replacing. Elsewhere the content is written to a unique
    temporary name beside path and moved into place (an object store's upload appears whole;
    the move makes that hold for the other file systems too).
    """
    if is_local(filesystem):
        with replacing(path, "wb", make_folders) as file:
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


def _remove_if_there(filesystem, path: str) -> None:
    with contextlib.suppress(FileNotFoundError):
        filesystem.rm(path)
