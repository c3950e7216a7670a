"""Bounds on what the package reads from a file a user may have received from someone else.

An FMU, an SSP and its parameter sets, a result or torque CSV, a call log, a scenario kit's
NAME.json: each may come from another person's tool, or be crafted to harm whoever opens it. The
readers check such a file here before they hand it on (to fmpy, to an XML parser, to the csv
module or a regular expression), so that a crafted file is refused in one line, naming the file
and what is wrong with it, instead of writing outside the folder it is unpacked to, filling the
disk or the memory, or keeping a core busy for hours:

- a zip archive (open_archive; open_fmu adds the model description's XML): a central directory
  of at most MAX_DIRECTORY_BYTES, checked before zipfile lists it, no entry that would
  be unpacked outside its folder (``..``, an absolute path, a drive letter, a backslash, a
  symbolic link), at most MAX_ENTRIES entries and MAX_UNPACKED_BYTES unpacked, no large entry
  that expands more than MAX_RATIO times (a zip bomb); zipfile stops reading an entry at the size
  the archive declares for it, so the declared sizes bound what is unpacked; an SSP's FMUs are
  checked as FMUs, for the master it is handed to;
- an XML document (check_xml): no document type declaration, the only place XML entities are
  defined (a billion laughs, an external entity that reads a local file or a URL); no FMI or SSP
  file has one;
- a text file read line by line (bounded_lines, check_lines): no line over MAX_LINE_CHARS, and
  no NUL byte, which no text has (the readers' regular expressions take time linear in a line's
  length: benchmarks/hostile_lines.py);
- a file read whole (bounded_read, bounded_text): at most its size below, the one place for them.
"""

from __future__ import annotations

import os
import stat
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, TextIO
from xml.parsers import expat

import numpy as np

# The pendulum's FMU holds 20 entries and an SSP of the closed loop 5; an FMU with its sources
# and documentation, a few hundred. Ten thousand leaves room for any of them and keeps a crafted
# archive of a million empty entries from taking minutes and memory to list and unpack.
MAX_ENTRIES = 10_000
# zipfile lists the whole central directory when it opens an archive, whatever the count of
# entries the archive declares (a crafted one declares few and lists millions: 200,000 took
# 1.9 s and 152 MB). An entry's record is 46 bytes and its name; 256 bytes an entry on average
# is more than any FMU's, and bounds the listing to well under a second.
MAX_DIRECTORY_BYTES = MAX_ENTRIES * 256
_END_OF_DIRECTORY = b"PK\x05\x06"
_ZIP64_LOCATOR = b"PK\x06\x07"
_ZIP64_END_OF_DIRECTORY = b"PK\x06\x06"
# The pendulum's FMU unpacks to 0.5 MB, an SSP holding it and the controller to 0.3 MB; FMUs
# with tables or meshes in resources/ reach tens of MB. 512 MiB leaves room for those and keeps
# an archive from filling the temporary folder it is unpacked to.
MAX_UNPACKED_BYTES = 512 * 2**20
# Deflate shrinks binaries, sources and XML 3 to 20 times; a file of one repeated byte, about
# 1000 times, which is how a zip bomb fits gigabytes into a few MB. Entries below
# RATIO_CHECKED_BYTES are not checked: a small file may be all spaces.
MAX_RATIO = 200
RATIO_CHECKED_BYTES = 2**20
# A result's row with a thousand columns is under 30 kB, a torque CSV's row under 100 bytes, a
# line of the FMU's call record under 2 kB; the csv module refuses a cell over 128 Ki characters
# (csv.field_size_limit()), so a line within this bound holds no cell it refuses.
MAX_LINE_CHARS = 2**17
# A kit's NAME.json is under 1 kB; one of a megabyte is no scenario's, and is not read.
MAX_SETTINGS_BYTES = 2**20
# A sweep's study.json holds its grid's values, about 25 bytes each: 256 MiB is ten million
# values, ten times the default limit of cases (DEFAULT_MAX_CASES) on a single axis.
MAX_STUDY_BYTES = 2**28
# A torque CSV of a row a step for the longest run without --max-steps (DEFAULT_MAX_STEPS, 10
# million) at up to 100 bytes a row.
MAX_TORQUE_CSV_BYTES = 2**30
# How much of an XML document check_xml hands the parser at a time, to stop at its root element.
_XML_CHUNK = 2**16

_SENDER = "do not open it; ask whoever sent it for a file their tool wrote"


def _leaves_folder(name: str) -> bool:
    """Whether unpacking the entry name would write outside the folder it is unpacked to (or
    somewhere that differs between systems: a backslash is a separator on Windows).
    """
    parts = name.split("/")
    return name.startswith("/") or "\\" in name or ":" in name or "\0" in name or ".." in parts


def _directory_bytes(file: IO[bytes]) -> int:
    """The size of the central directory that the archive's end record declares (0 where the
    file has no end record: zipfile then refuses it as no archive).
    """
    file.seek(0, 2)
    size = file.tell()
    start = max(0, size - 22 - 65_535)  # the end record is 22 bytes and a comment of at most 65,535
    file.seek(start)
    tail = file.read()
    at = tail.rfind(_END_OF_DIRECTORY)
    if at < 0 or at + 22 > len(tail):
        return 0
    declared = int.from_bytes(tail[at + 12 : at + 16], "little")
    if declared == 0xFFFFFFFF and tail[at - 20 : at - 16] == _ZIP64_LOCATOR:
        file.seek(int.from_bytes(tail[at - 12 : at - 4], "little"))
        record = file.read(56)
        if record[:4] == _ZIP64_END_OF_DIRECTORY:
            declared = int.from_bytes(record[40:48], "little")
    return declared


def open_archive(source: str | Path | IO[bytes], shown: str, error: type[Exception]) -> zipfile.ZipFile:
    """Open a received zip archive for reading, refusing one whose listing would take minutes and
    memory or whose unpacking would leave its folder or fill the disk.

    Parameters
    ----------
    source : str, Path or binary file
        The archive's path, or the archive open for reading (seekable).
    shown : str
        Its path as the user gave it, for the message.
    error : type
        The PendulumFmuError subclass to raise (FmuFileError, SspFileError, ...).

    Returns
    -------
    zipfile.ZipFile
        The archive, open; close it (a ``with`` block).

    Raises
    ------
    error
        One line naming the archive, the entry and the bound: a central directory over
        MAX_DIRECTORY_BYTES, an entry that leaves the folder or is a symbolic link, more than
        MAX_ENTRIES entries, more than MAX_UNPACKED_BYTES unpacked, or an entry over
        RATIO_CHECKED_BYTES that expands more than MAX_RATIO times.
    zipfile.BadZipFile, OSError
        Not a zip archive, or not readable.

    Examples
    --------
    >>> import io, zipfile
    >>> buffer = io.BytesIO()
    >>> with zipfile.ZipFile(buffer, "w") as made:
    ...     made.writestr("../../.bashrc", "echo hello")
    >>> try:
    ...     open_archive(buffer, "Sent.fmu", ValueError)
    ... except ValueError as refused:
    ...     print(refused)
    Sent.fmu: the archive's entry '../../.bashrc' would be unpacked outside its folder; do not open it; ...
    """
    if isinstance(source, (str, Path)):
        with open(source, "rb") as file:
            directory = _directory_bytes(file)
    else:
        directory = _directory_bytes(source)
    if directory > MAX_DIRECTORY_BYTES:
        raise error(
            f"{shown}: the archive's list of entries takes {directory:,} bytes, over {MAX_DIRECTORY_BYTES:,}; {_SENDER}"
        )
    archive = zipfile.ZipFile(source)
    try:
        _check_entries(archive, shown, error)
    except BaseException:
        archive.close()
        raise
    return archive


def _check_entries(archive: zipfile.ZipFile, shown: str, error: type[Exception]) -> None:
    entries = archive.infolist()
    if len(entries) > MAX_ENTRIES:
        raise error(f"{shown}: the archive holds {len(entries):,} entries, over {MAX_ENTRIES:,}; {_SENDER}")
    unpacked = 0
    for entry in entries:
        name, size = entry.filename, entry.file_size
        problem = None
        if _leaves_folder(name):
            problem = "would be unpacked outside its folder"
        elif entry.create_system == 3 and stat.S_ISLNK(entry.external_attr >> 16):  # 3: made on Unix
            problem = "is a symbolic link"
        elif size > RATIO_CHECKED_BYTES and size > MAX_RATIO * entry.compress_size:
            problem = f"expands {size // max(1, entry.compress_size):,} times, to {size:,} bytes, as no real file does"
        if problem:
            raise error(f"{shown}: the archive's entry {name!r} {problem}; {_SENDER}")
        unpacked += size
    if unpacked > MAX_UNPACKED_BYTES:
        raise error(
            f"{shown}: the archive unpacks to {unpacked / 2**20:,.0f} MiB, over the limit of "
            f"{MAX_UNPACKED_BYTES // 2**20} MiB; {_SENDER}"
        )


def open_fmu(source: str | Path | IO[bytes], shown: str, error: type[Exception]) -> zipfile.ZipFile:
    """open_archive on an FMU, then check_xml on its modelDescription.xml where it has one: what
    fmpy, or a master an SSP is handed to, trusts when it parses and unpacks the FMU.

    Parameters
    ----------
    source, shown, error
        As open_archive.

    Returns
    -------
    zipfile.ZipFile
        The FMU, open; close it (a ``with`` block).

    Raises
    ------
    error
        As open_archive and check_xml.
    """
    archive = open_archive(source, shown, error)
    try:
        if "modelDescription.xml" in archive.namelist():
            check_xml(archive.read("modelDescription.xml"), f"{shown}'s modelDescription.xml", error)
    except BaseException:
        archive.close()
        raise
    return archive


def check_xml(data: bytes, shown: str, error: type[Exception]) -> None:
    """Refuse an XML document that declares a document type, where entities are defined.

    The document is parsed (by expat, in whatever encoding it declares) up to its root element, a
    chunk at a time; one that is no XML at all passes, for the reader's own parser to name its
    fault.

    Parameters
    ----------
    data : bytes
        The document.
    shown : str
        Where it is, for the message: the file, or ``archive.fmu's modelDescription.xml``.
    error : type
        The PendulumFmuError subclass to raise.

    Raises
    ------
    error
        The document has a ``<!DOCTYPE``.

    Examples
    --------
    >>> check_xml(b'<?xml version="1.0"?><a/>', "a.xml", ValueError)
    >>> try:
    ...     check_xml(b'<!DOCTYPE a [<!ENTITY x SYSTEM "file:///etc/passwd">]><a>&x;</a>', "a.xml", ValueError)
    ... except ValueError as refused:
    ...     print(refused)
    a.xml declares a document type (<!DOCTYPE), where XML defines entities, and no FMI or SSP file has one; ...
    """

    def refuse(*_) -> None:  # raised through the parser, before any entity is declared
        raise error(
            f"{shown} declares a document type (<!DOCTYPE), where XML defines entities, and no FMI "
            f"or SSP file has one; {_SENDER}"
        )

    root = []
    parser = expat.ParserCreate()
    parser.StartDoctypeDeclHandler = refuse
    parser.StartElementHandler = lambda *_: root.append(True)
    try:
        for start in range(0, len(data), _XML_CHUNK):
            parser.Parse(data[start : start + _XML_CHUNK], False)
            if root:  # no declaration can follow the root element
                return
    except expat.ExpatError:
        return


def _line_fault(line: str, bound: int) -> str | None:
    if len(line) > bound:
        return f"the line is longer than {bound:,} characters"
    if "\0" in line:
        return "a NUL byte, which no text holds"
    return None


def bounded_lines(
    file: TextIO, shown: str, error: type[Exception], advice: str, bound: int = MAX_LINE_CHARS
) -> Iterator[str]:
    r"""The lines of a text file, each read no further than bound characters.

    Parameters
    ----------
    file : TextIO
        The file, open for reading.
    shown : str
        Its path, for the message.
    error : type
        The PendulumFmuError subclass to raise.
    advice : str
        What to do, ending the message: e.g. ``give the CSV the tool wrote``.
    bound : int, optional
        The longest line taken, without its line end.

    Yields
    ------
    str
        Each line, with its line end.

    Raises
    ------
    error
        ``FILE:LINE: the line is longer than ... characters`` or ``FILE:LINE: a NUL byte ...``.

    Examples
    --------
    >>> import io
    >>> try:
    ...     list(bounded_lines(io.StringIO("a\n" + "b" * 9), "log.txt", ValueError, "cut it", bound=8))
    ... except ValueError as refused:
    ...     print(refused)
    log.txt:2: the line is longer than 8 characters; cut it
    """
    for number, line in enumerate(iter(lambda: file.readline(bound + 2), ""), start=1):
        fault = _line_fault(line.rstrip("\r\n"), bound)
        if fault:
            raise error(f"{shown}:{number}: {fault}; {advice}")
        yield line


def check_lines(
    raw: bytes, shown: str, error: type[Exception], advice: str, bound: int = MAX_LINE_CHARS, first_line: int = 1
) -> None:
    """bounded_lines' checks on a file already read whole (in C, for a file of millions of lines),
    or on a block of a file's whole lines whose first is line first_line.

    Raises
    ------
    error
        As bounded_lines, a line's length counted in bytes.
    """
    data = np.frombuffer(raw, np.uint8)
    ends = np.flatnonzero(data == ord("\n"))
    lengths = np.diff(ends, prepend=-1, append=len(raw)) - 1
    lengths[:-1] -= (ends > 0) & (data[ends - 1] == ord("\r"))  # a line end may be \r\n
    long_lines = np.flatnonzero(lengths > bound)
    faults = []
    if len(long_lines):
        faults.append((int(long_lines[0]) + first_line, f"the line is longer than {bound:,} bytes"))
    nul = raw.find(b"\0")
    if nul >= 0:
        faults.append((raw.count(b"\n", 0, nul) + first_line, "a NUL byte, which no text holds"))
    if faults:
        number, fault = min(faults)
        raise error(f"{shown}:{number}: {fault}; {advice}")


def shortened(text: str, most: int = 80) -> str:
    """Text from a received file as a message quotes it: its first `most` characters, and how long
    it is where it is longer, so that a message stays a line one reads.

    Examples
    --------
    >>> shortened("x" * 100, most=5)
    'xxxxx... (100 characters)'
    """
    return text if len(text) <= most else f"{text[:most]}... ({len(text):,} characters)"


def bounded_read(file: IO[bytes], shown: str, limit: int, error: type[Exception], advice: str) -> bytes:
    """The bytes of a file read whole, read no further than limit bytes.

    Parameters
    ----------
    file : binary file
        The file, open for reading (a local file's or an fsspec file system's).
    shown : str
        Its path, for the message.
    limit : int
        The most bytes taken: one of the MAX_*_BYTES above.
    error : type
        The PendulumFmuError subclass to raise.
    advice : str
        What to do, ending the message.

    Raises
    ------
    error
        ``FILE: over LIMIT bytes, longer than any such file; ADVICE``.

    Examples
    --------
    >>> import io
    >>> try:
    ...     bounded_read(io.BytesIO(b"x" * 9), "study.json", 8, ValueError, "write it again")
    ... except ValueError as refused:
    ...     print(refused)
    study.json: over 8 bytes, longer than any such file; write it again
    """
    try:  # refused by its size where the file has one, before anything is read
        check_size(file, shown, limit, error, advice)
    except OSError:  # a pipe: read as far as the limit to see
        pass
    raw = file.read(limit + 1)
    if len(raw) > limit:
        raise error(f"{shown}: over {limit:,} bytes, longer than any such file; {advice}")
    return raw


def check_size(file: IO[bytes], shown: str, limit: int, error: type[Exception], advice: str) -> None:
    """Refuse a file over limit bytes by its size (bounded_read's words), before anything is read;
    the file is left at its start.

    Raises
    ------
    error
        The file is longer than limit bytes.
    OSError
        A file with no size to seek to (a pipe).
    """
    if file.seek(0, 2) > limit:
        raise error(f"{shown}: over {limit:,} bytes, longer than any such file; {advice}")
    file.seek(0)


def bounded_text(path: Path, limit: int, error: type[Exception], advice: str, encoding: str = "utf-8") -> str:
    """The text of a small file, read no further than limit bytes (bounded_read).

    Raises
    ------
    error
        The file is longer than limit bytes.
    OSError, UnicodeDecodeError
        As reading it does.
    """
    with open(path, "rb") as file:
        return bounded_read(file, str(path), limit, error, advice).decode(encoding)


class ReadAgain:
    """A file read a block of whole lines at a time from any offset, again and again (a torque CSV
    of millions of rows, never held whole), each block from the file first seen at the path: a
    file written again or another moved there since is refused (error, naming the path), never
    read as a mix of two files.
    """

    def __init__(self, path: Path, error: type[Exception], advice: str):
        self.path, self._error, self._advice = path, error, advice
        self._identity = self._identity_of(os.stat(path))
        self.size = self._identity[2]

    @staticmethod
    def _identity_of(status: os.stat_result) -> tuple[int, int, int, int]:
        return status.st_dev, status.st_ino, status.st_size, status.st_mtime_ns

    def block(self, offset: int, size: int) -> bytes:
        """The whole lines from offset, about size bytes of them (b"" at the end of the file): up
        to the last newline or carriage return (one of a pair cut off starts the next block with a
        blank line), more where no line ends within size.
        """
        with open(self.path, "rb") as file:
            if self._identity_of(os.fstat(file.fileno())) != self._identity:
                raise self._error(
                    f"{self.path}: the file changed while it was read (a master still writing it, or "
                    f"another file moved there); {self._advice}"
                )
            file.seek(offset)
            raw = b""
            while True:
                read = file.read(size)
                raw += read
                cut = max(raw.rfind(b"\n"), raw.rfind(b"\r")) + 1
                if len(read) < size:
                    return raw
                if cut:
                    return raw[:cut]
