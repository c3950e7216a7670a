"""pendulum-fmu export: the package's FMU (here the checkout's), written whole where the user works."""

import warnings
import zipfile

import pytest

from fmu_build import WASM, available_platforms
from fmu_build.wasm_component import MANIFEST_ENTRY
from pendulum_fmu import default_fmu
from pendulum_fmu.cli import main
from pendulum_fmu.fmu._export import FmuExists, export_fmu

# Each FMI 2.0 platform's binary, and its folders in an FMI 3.0 FMU (the standards' own names).
LIBRARY = {
    "linux64": "Pendulum.so",
    "win64": "Pendulum.dll",
    "aarch64-linux": "Pendulum.so",
    "darwin64": "Pendulum.dylib",
}
FMI3_FOLDERS = {
    "linux64": ("x86_64-linux",),
    "win64": ("x86_64-windows",),
    "aarch64-linux": ("aarch64-linux",),
    "darwin64": ("x86_64-darwin", "aarch64-darwin"),
}


@pytest.fixture(scope="module")
def built_platforms():
    """The FMI 2.0 platforms this machine's tools build (a default build skips the others)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return available_platforms()


def test_export_writes_the_fmu_into_the_current_folder_and_names_its_platforms(
    tmp_path, monkeypatch, capsys, built_platforms
):
    monkeypatch.chdir(tmp_path)
    assert main(["export"]) == 0
    written = tmp_path / "Pendulum.fmu"
    assert written.read_bytes() == default_fmu().read_bytes()
    with zipfile.ZipFile(written) as fmu:
        assert {f"binaries/{platform}/{LIBRARY[platform]}" for platform in built_platforms} <= set(fmu.namelist())
    assert capsys.readouterr().out == f"wrote Pendulum.fmu (binaries for {', '.join(sorted(built_platforms))})\n"
    assert list(tmp_path.iterdir()) == [written]  # no temporary left beside it


def test_export_refuses_to_replace_a_file_unless_asked(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "Pendulum.fmu").write_bytes(b"a colleague's FMU")
    assert main(["export"]) == 2
    assert capsys.readouterr().err == (
        "pendulum-fmu export: error: Pendulum.fmu exists: pass --overwrite "
        "(overwrite=True) to replace it, or another --output\n"
    )
    assert (tmp_path / "Pendulum.fmu").read_bytes() == b"a colleague's FMU"
    with pytest.raises(FmuExists):
        export_fmu()
    assert main(["export", "--overwrite"]) == 0
    assert (tmp_path / "Pendulum.fmu").read_bytes() == default_fmu().read_bytes()


def test_export_of_the_fmi3_fmu_lists_its_platform_folders(tmp_path, monkeypatch, built_platforms):
    monkeypatch.chdir(tmp_path)
    exported = export_fmu(fmi_version=3)
    assert exported.path.name == "Pendulum-fmi3.fmu" and exported.path.read_bytes() == default_fmu(3).read_bytes()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        wasm = (WASM,) if WASM in available_platforms(3) else ()  # the WebAssembly component: zig, wasm-tools
    assert exported.platforms == tuple(
        sorted([*(folder for platform in built_platforms for folder in FMI3_FOLDERS[platform]), *wasm])
    )
    with zipfile.ZipFile(exported.path) as fmu:
        assert b'fmiVersion="3.0"' in fmu.read("modelDescription.xml")
        assert (MANIFEST_ENTRY in fmu.namelist()) == bool(wasm)
    other = export_fmu(tmp_path / "sub" / "P.fmu", fmi_version=3)
    assert other.path == tmp_path / "sub" / "P.fmu" and other.platforms == exported.platforms
