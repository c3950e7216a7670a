"""One universal (fat) Mach-O binary from thin ones, with the standard library only.

fmpy loads binaries/darwin64 on Intel and Apple Silicon Macs alike, so FMI 2.0's darwin64 binary
holds both slices. llvm-lipo merges them but is not on PyPI; the fat format is small enough to
write here, so that a source build needs no more than zig (PyPI ziglang) for the macOS binaries.
Format (<mach-o/fat.h>, all big-endian): a header {FAT_MAGIC 0xcafebabe, nfat_arch}, then per
slice a fat_arch {cputype, cpusubtype, offset, size, align (a power of 2)}, then each slice
whole at its offset.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

FAT_MAGIC = 0xCAFEBABE
# A 64-bit thin Mach-O's magic, read little-endian (arm64 and x86_64 are little-endian).
MH_MAGIC_64 = 0xFEEDFACF
CPU_TYPE_ARM64 = 0x0100000C
# Each slice starts on a page boundary of its CPU: 2**14 (16 KiB) on Apple Silicon, 2**12 on
# Intel, as llvm-lipo places them.
PAGE_ALIGNMENT = {CPU_TYPE_ARM64: 14}
DEFAULT_ALIGNMENT = 12


class MachOError(ValueError):
    """A file that is not a thin 64-bit Mach-O, or slices that cannot share one universal binary."""


def _slice_header(data: bytes, name: str) -> tuple[int, int]:
    """(cputype, cpusubtype) of a thin 64-bit little-endian Mach-O."""
    if len(data) < 12 or struct.unpack_from("<I", data)[0] != MH_MAGIC_64:
        raise MachOError(f"{name} is not a thin 64-bit Mach-O binary")
    return struct.unpack_from("<ii", data, 4)


def merge_universal(slices: list[str | os.PathLike], out_file: str | os.PathLike) -> Path:
    """Write a universal Mach-O holding each thin slice, as `lipo -create` does.

    Parameters
    ----------
    slices : list of str or os.PathLike
        Thin 64-bit Mach-O binaries (x86_64 and arm64 for darwin64), one per CPU type.
    out_file : str or os.PathLike
        The universal binary to write (written as given; the caller renames it into place).

    Returns
    -------
    Path
        out_file.

    Raises
    ------
    MachOError
        A slice that is not a thin 64-bit Mach-O, or two slices of one CPU type.

    Examples
    --------
    >>> merge_universal(["x86_64/Pendulum.dylib", "arm64/Pendulum.dylib"], "Pendulum.dylib")  # doctest: +SKIP
    PosixPath('Pendulum.dylib')
    """
    contents = [(Path(path).read_bytes(), str(path)) for path in slices]
    headers = [(_slice_header(data, name), data) for data, name in contents]
    headers.sort(key=lambda item: item[0][0])  # by CPU type, as lipo orders them
    cpu_types = [cputype for (cputype, _), _ in headers]
    if len(set(cpu_types)) != len(cpu_types):
        raise MachOError(f"two slices of one CPU type among {', '.join(name for _, name in contents)}")
    offset = 8 + 20 * len(headers)
    table, body = [struct.pack(">II", FAT_MAGIC, len(headers))], []
    for (cputype, cpusubtype), data in headers:
        alignment = PAGE_ALIGNMENT.get(cputype, DEFAULT_ALIGNMENT)
        offset = -(-offset // (1 << alignment)) * (1 << alignment)
        table.append(struct.pack(">iiIII", cputype, cpusubtype, offset, len(data), alignment))
        body.append((offset, data))
        offset += len(data)
    out_file = Path(out_file)
    with open(out_file, "wb") as out:
        out.write(b"".join(table))
        for start, data in body:
            out.write(b"\0" * (start - out.tell()))
            out.write(data)
    return out_file
