"""The API at the top of the package: its names, what importing it loads, what simulate loads.

The checks of what is loaded run in a fresh interpreter, whose sys.modules holds only what it did.
"""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import pendulum_fmu

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("matplotlib", "dask", "distributed", "scipy", "fmpy", "numpy", "pyarrow")


def _loaded_after(code: str) -> dict:
    """Run code in a fresh interpreter from the repository's root.

    Returns what it printed, the top-level packages, the pendulum_fmu modules and all the
    modules it loaded.
    """
    script = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    done = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, check=True)
    *printed, loaded = done.stdout.splitlines()
    modules = json.loads(loaded)
    return {
        "top": sorted({name.split(".")[0] for name in modules}),
        "ours": [name for name in modules if name.startswith("pendulum_fmu")],
        "modules": modules,
        "printed": printed,
    }


def test_import_pendulum_fmu_loads_no_numerics_nor_plotting():
    loaded = _loaded_after("import pendulum_fmu")
    assert not set(HEAVY) & set(loaded["top"])
    assert loaded["ours"] == ["pendulum_fmu"]


def test_importing_the_sweep_looks_no_fmu_up():
    """No import-time lookup: a study takes its own FMU's outputs when it is made."""
    # Every FMU the package reads is parsed by _model._read, and the default one is found by
    # pendulum_fmu.default_fmu: both refuse, so a lookup at import fails the import.
    loaded = _loaded_after(
        "import pendulum_fmu, pendulum_fmu.fmu._model as model\n"
        "def refuse(*args, **kwargs):\n"
        "    raise AssertionError('an FMU was looked up')\n"
        "pendulum_fmu.default_fmu = model._read = refuse\n"
        "import pendulum_fmu.sweep\n"
        "try:\n"
        "    pendulum_fmu.sweep.OUTPUTS\n"
        "except AssertionError as error:\n"
        "    print(error)"
    )
    assert {"pendulum_fmu.sweep.study", "pendulum_fmu.sweep.worker"} <= set(loaded["ours"])
    # The refusals were in force: the default FMU's outputs, asked for, were looked up then.
    assert loaded["printed"] == ["an FMU was looked up"]


def test_the_command_lines_simulate_loads_neither_the_sweep_nor_matplotlib():
    loaded = _loaded_after("from pendulum_fmu.cli import main\nmain(['simulate', '--torque', '20'])")
    assert "matplotlib" not in loaded["top"] and "dask" not in loaded["top"]
    assert not [name for name in loaded["ours"] if name.startswith("pendulum_fmu.sweep")]
    assert "pendulum_fmu.figures._plot" not in loaded["ours"]
    # It still simulated: the final angle it printed against the reference.
    theta = float(loaded["printed"][0].split("theta = ")[1].split(" rad")[0])
    assert theta == pytest.approx(pendulum_fmu.reference(20.0)["theta"][-1], abs=1e-9)


def test_the_command_lines_judge_loads_matplotlib_only_to_draw(tmp_path):
    torque = tmp_path / "torque.csv"
    torque.write_text("time,torque\n0,20\n0.5,20\n0.5,-20\n1,-20\n")
    result = pendulum_fmu.simulate(str(torque))
    rows = zip(result["time"].tolist(), result["theta"].tolist(), strict=True)
    (tmp_path / "out.csv").write_text("time,theta\n" + "".join(f"{t!r},{theta!r}\n" for t, theta in rows))
    # The FMU named, as the README's quick start names the one fmpy ran.
    fmu = str(pendulum_fmu.default_fmu())
    judged = f"main(['judge', {str(tmp_path / 'out.csv')!r}, '--torque-file', {str(torque)!r}, '--fmu', {fmu!r}])"
    loaded = _loaded_after(f"from pendulum_fmu.cli import main\nprint({judged})")
    assert "matplotlib" not in loaded["top"] and "dask" not in loaded["top"]
    assert "pendulum_fmu.figures._plot" not in loaded["ours"]
    # Nor what a judgement of a short signal has no use for, each a part of its start-up (issue
    # 42): scipy (the reference integrates on its own, the band is computed in numpy), pyarrow
    # (the signal is read in Python), psutil (only a large run asks for the free memory), the
    # checkout's build of the FMU (the parser reads only its paths and platforms; the FMU named,
    # the default one is not looked up, nor checked for staleness).
    assert not {"scipy", "pyarrow", "psutil"} & set(loaded["top"])
    assert not {"fmu_build.fmu_file", "fmu_build.binaries", "fmu_build.sources"} & set(loaded["modules"])
    # It still judged: the FMU's run agrees with the reference, exit 0.
    assert loaded["printed"][-1] == "0", loaded["printed"]
    assert loaded["printed"][0].startswith(f"{tmp_path / 'out.csv'}: pass: agrees (residual ")


def test_the_command_lines_small_study_loads_neither_dask_fsspec_nor_the_dataset_reader(tmp_path):
    fmu = str(pendulum_fmu.default_fmu())
    command = ["sweep", "--torque", "5", "20", "--stop-time", "0.5", "--no-figure", "--fmu", fmu]
    command += ["--output-dir", str(tmp_path / "study")]
    loaded = _loaded_after(f"from pendulum_fmu.cli import main\nprint(main({command!r}))")
    # Run in the process, its cases read back part by part, its local folder without fsspec;
    # its start-up (issue 42) builds no FMU and reads no dataset.
    assert not {"dask", "distributed", "matplotlib", "fsspec"} & set(loaded["top"])
    assert not {"pyarrow.dataset", "fmu_build.fmu_file", "fmu_build.binaries"} & set(loaded["modules"])
    assert loaded["printed"][-1] == "0"
    # It still ran: its cases table holds the FMU's final angles, against the scipy reference.
    import pyarrow.parquet as pq

    cases = pq.read_table(tmp_path / "study" / "cases").to_pydict()
    assert cases["status"] == ["ok", "ok"]
    oracle = [pendulum_fmu.reference(torque, stop_time=0.5)["theta"][-1] for torque in (5.0, 20.0)]
    assert cases["final_theta"] == pytest.approx(oracle, abs=1e-9)


def test_the_names_at_the_top_are_the_api():
    from pendulum_fmu import Study, compare, default_fmu, judge, reference, run_sweep, simulate
    from pendulum_fmu.sweep.run import run_sweep as sweep_runner

    assert run_sweep is sweep_runner and Study.__name__ == "Study" and callable(default_fmu)
    assert callable(compare) and callable(judge)
    # The FMU through fmpy against the independent reference, both by their top names.
    run, oracle = simulate(20.0, stop_time=1.0), reference(20.0, stop_time=1.0)
    assert np.max(np.abs(run["theta"] - oracle["theta"])) < 1e-9
    assert set(pendulum_fmu.__all__) <= set(dir(pendulum_fmu))


def test_a_name_that_is_also_a_module_stays_the_function_once_the_module_is_imported():
    loaded = _loaded_after(
        "import pendulum_fmu.fmu._simulate, pendulum_fmu.judging._judge\n"
        "import pendulum_fmu\n"
        "print(type(pendulum_fmu.simulate).__name__, type(pendulum_fmu.judge).__name__)"
    )
    assert loaded["printed"] == ["function function"]


def test_a_name_the_api_has_not_is_an_attribute_error():
    with pytest.raises(AttributeError, match="has no attribute 'simulat'"):
        _ = pendulum_fmu.simulat


@pytest.mark.parametrize("name", [name for name in pendulum_fmu.__all__ if callable(getattr(pendulum_fmu, name))])
def test_every_api_docstring_has_numpydoc_sections_and_its_examples_give_what_they_show(name):
    import doctest
    import inspect

    thing = getattr(pendulum_fmu, name)
    text = inspect.getdoc(thing)
    wanted = ("Examples",) + (("Parameters", "Returns", "Raises") if inspect.isfunction(thing) else ())
    assert all(f"{section}\n{'-' * len(section)}" in text for section in wanted), name
    # Only the docstring's own examples (not its methods'), as doctest runs them.
    tests = doctest.DocTestFinder(recurse=False).find(thing, name, globs={})
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for test in tests:
        runner.run(test)
    assert runner.failures == 0 and runner.tries > 0, name


def _autosummary_blocks(page: str, module: str = "pendulum_fmu") -> list[list[str]]:
    """The names of each autosummary block of a docs page under `.. currentmodule:: module`, in order."""
    blocks = re.findall(
        r"^\.\. currentmodule:: (\S+)\n\n\.\. autosummary::\n(?:   :.*\n)*\n((?:   \S+\n)+)", page, re.MULTILINE
    )
    return [names.split() for current, names in blocks if current == module]


def _lazy_groups() -> list[list[str]]:
    """The names of _LAZY in pendulum_fmu/__init__.py, one list per group its comments start."""
    source = (ROOT / "pendulum_fmu" / "__init__.py").read_text(encoding="utf-8")
    body = source.split("_LAZY = {\n", 1)[1].split("\n}\n", 1)[0]
    groups: list[list[str]] = []
    for line in body.splitlines():
        if line.strip().startswith("#"):
            groups.append([])
        else:
            groups[-1].append(re.match(r'\s*"(\w+)":', line)[1])
    return groups


def test_the_api_reference_lists_every_public_name_once_grouped_as_the_package_groups_them():
    blocks = _autosummary_blocks((ROOT / "docs" / "api_reference.md").read_text(encoding="utf-8"))
    listed = [name for block in blocks for name in block]
    assert sorted(listed) == sorted(pendulum_fmu.__all__), "docs/api_reference.md and pendulum_fmu.__all__ differ"
    # The groups of __init__'s _LAZY, each one block of the page, in the same order; before them
    # the names __init__ defines itself.
    groups = _lazy_groups()
    assert sum(map(len, groups)) == len(pendulum_fmu._LAZY) and len(groups) > 1
    assert [sorted(block) for block in blocks[1:]] == [sorted(group) for group in groups]
    assert sorted(blocks[0]) == sorted(set(pendulum_fmu.__all__) - set(pendulum_fmu._LAZY))


def test_the_api_reference_lists_the_gymnasium_environments_names():
    import pendulum_fmu.gym

    page = (ROOT / "docs" / "api_reference.md").read_text(encoding="utf-8")
    assert _autosummary_blocks(page, "pendulum_fmu.gym") == [sorted(pendulum_fmu.gym.__all__)]
