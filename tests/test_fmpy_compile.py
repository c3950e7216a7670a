"""fmpy compile rebuilds the binary from the FMU's sources/ alone, with the same numbers."""

import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from pendulum_fmu.simulate import simulate


@pytest.mark.skipif(shutil.which("cmake") is None, reason="fmpy compile needs cmake")
def test_fmpy_compile_from_sources_alone(fmu, tmp_path):
    stripped = tmp_path / "Pendulum.fmu"
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(stripped, "w") as target:
        for item in source.infolist():
            if not item.filename.startswith("binaries/"):
                target.writestr(item, source.read(item))
    subprocess.run([sys.executable, "-m", "fmpy", "compile", str(stripped)], check=True,
                   capture_output=True, cwd=tmp_path)
    with zipfile.ZipFile(stripped) as rebuilt:
        assert "binaries/linux64/Pendulum.so" in rebuilt.namelist()
    theirs = simulate(20.0, fmu_path=stripped)
    ours = simulate(20.0, fmu_path=fmu)
    assert np.max(np.abs(theirs["theta"] - ours["theta"])) < 1e-13
