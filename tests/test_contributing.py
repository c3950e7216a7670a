"""CONTRIBUTING.md stays in step with what it describes: its table of markers is pyproject's, each
marker but `slow` implies `slow` (tests/conftest.py), and its set-up commands are the README's,
which tests/test_readme_commands.py runs.
"""

import re
import tomllib
from pathlib import Path

from conftest import SLOW_MARKERS
from test_readme_commands import commands_in

ROOT = Path(__file__).resolve().parent.parent
CONTRIBUTING = (ROOT / "CONTRIBUTING.md").read_text(encoding="utf-8")


def declared_markers() -> set[str]:
    """The markers pyproject.toml declares, by name."""
    settings = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    return {line.split(":", 1)[0] for line in settings["tool"]["pytest"]["ini_options"]["markers"]}


def test_the_markers_table_lists_every_marker_pyproject_declares_and_no_other():
    tabled = set(re.findall(r"^\| `(\w+)` \|", CONTRIBUTING, re.MULTILINE))
    assert tabled == declared_markers()


def test_every_declared_marker_but_slow_implies_slow():
    assert set(SLOW_MARKERS) == declared_markers() - {"slow"}


def test_the_set_up_commands_are_the_readme_s():
    readme = commands_in((ROOT / "README.md").read_text(encoding="utf-8"))
    shown = commands_in(CONTRIBUTING)
    for start in (
        "python3 -m venv .venv && .venv/bin/pip install -e ",
        "sudo apt-get install ",
        ".venv/bin/sphinx-build ",
    ):
        [in_contributing] = [command for command in shown if command.startswith(start)]
        assert in_contributing in readme, f"CONTRIBUTING.md's {in_contributing!r} is not the README's"
