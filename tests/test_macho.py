"""fmu_build/macho.py's universal Mach-O, judged by LLVM's tools, which share no code with it.

llvm-lipo-14 cuts and makes universal binaries, llvm-objdump-14 reads them.
"""

import shutil
import struct
import subprocess
import zipfile

import pytest

from fmu_build.macho import MachOError, merge_universal

LLVM_TOOLS = ("llvm-lipo-14", "llvm-objdump-14")
pytestmark = pytest.mark.skipif(
    not all(map(shutil.which, LLVM_TOOLS)), reason="needs llvm-lipo-14 and llvm-objdump-14 (apt-get install llvm-14)"
)
ARCHITECTURES = ("x86_64", "arm64")


def _llvm(tool, *arguments):
    return subprocess.run([f"llvm-{tool}-14", *map(str, arguments)], capture_output=True, text=True, check=True).stdout


@pytest.fixture(scope="module")
def thin_slices(fmu, tmp_path_factory):
    """The two thin slices of the FMU's darwin64 binary, cut out by llvm-lipo."""
    work = tmp_path_factory.mktemp("macho")
    with zipfile.ZipFile(fmu) as archive:
        if "binaries/darwin64/Pendulum.dylib" not in archive.namelist():
            pytest.skip("this build has no darwin64 binary (needs zig: pip install ziglang)")
        universal = work / "universal.dylib"
        universal.write_bytes(archive.read("binaries/darwin64/Pendulum.dylib"))
    slices = {}
    for architecture in ARCHITECTURES:
        slices[architecture] = work / f"{architecture}.dylib"
        _llvm("lipo", universal, "-thin", architecture, "-output", slices[architecture])
    return slices


def test_merged_binary_is_llvm_lipos_byte_for_byte(thin_slices, tmp_path):
    ours = merge_universal([thin_slices["arm64"], thin_slices["x86_64"]], tmp_path / "ours.dylib")
    theirs = tmp_path / "theirs.dylib"
    _llvm("lipo", "-create", *thin_slices.values(), "-output", theirs)
    assert ours.read_bytes() == theirs.read_bytes()


def test_llvm_objdump_reads_each_slice_of_the_merged_binary(thin_slices, tmp_path):
    ours = merge_universal(list(thin_slices.values()), tmp_path / "ours.dylib")
    headers = _llvm("objdump", "--macho", "--universal-headers", ours)
    assert "fat_magic FAT_MAGIC" in headers and "nfat_arch 2" in headers
    assert "offset 4096" in headers and "align 2^12 (4096)" in headers  # x86_64 on Intel's page
    assert "align 2^14 (16384)" in headers  # arm64 on Apple Silicon's page
    for architecture, thin in thin_slices.items():
        cut = tmp_path / f"cut_{architecture}.dylib"
        _llvm("lipo", ours, "-thin", architecture, "-output", cut)
        assert cut.read_bytes() == thin.read_bytes()
        symbols = _llvm("objdump", "--macho", f"--arch={architecture}", "--exports-trie", ours)
        assert "_fmi2DoStep" in symbols and "_fmi2Instantiate" in symbols


def test_refuses_what_is_not_a_thin_mach_o(thin_slices, tmp_path):
    elf = tmp_path / "not.so"
    elf.write_bytes(b"\x7fELF" + bytes(60))
    with pytest.raises(MachOError, match=r"not\.so is not a thin 64-bit Mach-O"):
        merge_universal([thin_slices["x86_64"], elf], tmp_path / "out.dylib")
    fat = merge_universal(list(thin_slices.values()), tmp_path / "fat.dylib")
    assert struct.unpack(">II", fat.read_bytes()[:8]) == (0xCAFEBABE, 2)
    with pytest.raises(MachOError, match="is not a thin"):
        merge_universal([fat, thin_slices["arm64"]], tmp_path / "out.dylib")
    with pytest.raises(MachOError, match="two slices of one CPU type"):
        merge_universal([thin_slices["arm64"], thin_slices["arm64"]], tmp_path / "out.dylib")
