"""What an FMU of this project records about how it was made, and its archive written the same way
every time.

The build (fmu_build/) writes ``extra/org.pendulum-fmu.build/build.json`` into every FMU, FMI 2.0
and 3.0 alike: the package version and the commit the FMU was built from, the time every entry
carries (the commit's, or ``SOURCE_DATE_EPOCH``), each binary's toolchain and the commands that
made it from the FMU's own ``sources/``, and the SHA-256 of every other entry. ``export --sign``
adds ``build.json.sig``, an Ed25519 signature of build.json's bytes. _verify.py checks them.

The archive's entries carry that one time, fixed permissions and the order given, so the same
sources give the same bytes whatever the build's folder, clock or machine.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
import zipfile
from collections.abc import Iterable

RECORD_FOLDER = "extra/org.pendulum-fmu.build/"
RECORD_FILE = RECORD_FOLDER + "build.json"
SIGNATURE_FILE = RECORD_FOLDER + "build.json.sig"
RECORD_FORMAT = "pendulum-fmu build record 1"
# Where a recorded link command takes the objects compiled from sources/, in the recorded order.
OBJECTS = "<objects>"
# The oldest time a zip entry can carry (1980-01-01 UTC): entries of a build without a commit.
ZIP_EPOCH = 315532800


def sha256(data: bytes) -> str:
    """The SHA-256 of data, in hex."""
    return hashlib.sha256(data).hexdigest()


def record_bytes(record: dict) -> bytes:
    """build.json's bytes: keys sorted, one indent, a final newline, so equal records are equal bytes."""
    return (json.dumps(record, indent=1, sort_keys=True) + "\n").encode()


def with_record(entries: dict[str, bytes], record: dict) -> dict[str, bytes]:
    """The entries and build.json, which gives record the SHA-256 of each entry (and no signature:
    a signature is of one record's bytes, and this is a new record).
    """
    entries = {name: data for name, data in entries.items() if name not in (RECORD_FILE, SIGNATURE_FILE)}
    record = {**record, "entries": {name: sha256(data) for name, data in entries.items()}}
    return {**entries, RECORD_FILE: record_bytes(record)}


def write_archive(file, entries: Iterable[tuple[str, bytes]], epoch: int) -> None:
    """Zip entries into file (a path or an open binary file) in the order given, each entry dated
    epoch (seconds since 1970, UTC; no earlier than 1980) with the permissions rw-r--r--.
    """
    date_time = time.gmtime(max(epoch, ZIP_EPOCH))[:6]
    with zipfile.ZipFile(file, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in entries:
            entry = zipfile.ZipInfo(name, date_time)
            entry.compress_type = zipfile.ZIP_DEFLATED
            entry.create_system = 3  # Unix, whichever system builds: its permissions below
            entry.external_attr = 0o100644 << 16
            archive.writestr(entry, data)


def read_entries(fmu: str | os.PathLike) -> dict[str, bytes]:
    """Every entry of an FMU by name, in the archive's order (_received_files bounds what it holds)."""
    with zipfile.ZipFile(fmu) as archive:
        return {item.filename: archive.read(item) for item in archive.infolist() if not item.is_dir()}


def recorded_epoch(entries: dict[str, bytes]) -> int:
    """The time an FMU's record gives its entries, or the zip epoch when it has no record."""
    if RECORD_FILE not in entries:
        return ZIP_EPOCH
    return int(json.loads(entries[RECORD_FILE]).get("source_date_epoch", ZIP_EPOCH))


def rewrite_fmu(out_file: str | os.PathLike, entries: dict[str, bytes], record_changes: dict) -> None:
    """Write an FMU's entries, changed, into out_file as its record says its entries are
    written: the record updated by record_changes and made anew over the entries (any signature
    dropped, as it was of the old record).
    """
    record = json.loads(entries[RECORD_FILE]) if RECORD_FILE in entries else {"format": RECORD_FORMAT}
    write_archive(out_file, with_record(entries, {**record, **record_changes}).items(), recorded_epoch(entries))
