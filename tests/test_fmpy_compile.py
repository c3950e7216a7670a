"""fmpy compile rebuilds the binary from the FMU's sources/ alone, with the same numbers."""

import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from pendulum_fmu.fmu._simulate import simulate


@pytest.mark.skipif(shutil.which("cmake") is None, reason="fmpy compile needs cmake")
@pytest.mark.parametrize(
    "fixture, binary", [("fmu", "binaries/linux64/Pendulum.so"), ("fmu3", "binaries/x86_64-linux/Pendulum.so")]
)
def test_fmpy_compile_from_sources_alone(request, fixture, binary, tmp_path):
    """FMI 2.0 from <SourceFiles>, FMI 3.0 from sources/buildDescription.xml."""
    fmu = request.getfixturevalue(fixture)
    stripped = tmp_path / "Pendulum.fmu"
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(stripped, "w") as target:
        for item in source.infolist():
            if not item.filename.startswith("binaries/"):
                target.writestr(item, source.read(item))
    subprocess.run(
        [sys.executable, "-m", "fmpy", "compile", str(stripped)], check=True, capture_output=True, cwd=tmp_path
    )
    with zipfile.ZipFile(stripped) as rebuilt:
        assert binary in rebuilt.namelist()
    theirs = simulate(20.0, fmu_path=stripped)
    ours = simulate(20.0, fmu_path=fmu)
    assert np.max(np.abs(theirs["theta"] - ours["theta"])) < 1e-13
