"""The docs site builds by the command the README names, without a warning (-W).

It holds what its pages promise: the API reference from the docstrings, every command of the
parser, the examples' figures, every docs page.
"""

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

pytest.importorskip("sphinx", reason="the [docs] extra (in [test]) builds the docs site")
pytestmark = pytest.mark.docs


def readme_build_command() -> list[str]:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    commands = [line.strip() for line in readme.splitlines() if line.strip().startswith(".venv/bin/sphinx-build ")]
    assert len(commands) == 1, f"the README names one docs build command, not {commands}"
    return shlex.split(commands[0])


def _built_site(output: Path) -> Path:
    argv = readme_build_command()
    assert "-W" in argv and argv[-2:] == ["docs", "docs/_build/html"]
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", *argv[1:-1], str(output)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert done.returncode == 0, f"the docs build failed (warnings are errors):\n{done.stderr[-4000:]}"
    return output


@pytest.fixture(scope="session")
def site(build_once):
    """The site built by the README's command, into a temporary folder (its last argument), once
    per session.
    """
    return build_once("site", _built_site)


def test_every_docs_page_is_in_the_site(site):
    pages = {path.stem for path in (ROOT / "docs").glob("*.md")} - {"examples_intro"}
    missing = sorted(page for page in pages if not (site / f"{page}.html").is_file())
    assert not missing, f"docs pages not built (add them to a toctree in docs/index.md): {missing}"


@pytest.mark.parametrize("name", ["simulate", "reference", "compare", "judge", "run_sweep", "default_fmu"])
def test_the_api_reference_shows_each_function_s_numpydoc_sections(site, name):
    """Each name at the top of the package has its page, with its numpydoc sections.

    The page documents the function itself, not the module of the same name.
    """
    html = (site / "generated" / f"pendulum_fmu.{name}.html").read_text(encoding="utf-8")
    assert f'id="pendulum_fmu.{name}"' in html, f"{name}: documented as something else than the function"
    for section in ("Parameters", "Returns", "Examples"):
        assert re.search(rf">{section}<", html), f"{name}: no {section} section on its page"


def test_the_command_line_reference_has_every_command_and_option(site):
    from pendulum_fmu.cli import build_parser

    html = (site / "cli_reference.html").read_text(encoding="utf-8")
    parser = build_parser()
    commands = next(action for action in parser._actions if action.dest == "command").choices
    for name, command in commands.items():
        assert re.search(rf"<h3[^>]*>{re.escape(name)}<", html), f"the command {name} is missing"
        for action in command._actions:
            for option in action.option_strings:
                assert option in html, f"{name} {option} is missing"


def test_the_examples_page_shows_every_figure_the_examples_wrote(site):
    html = (site / "examples" / "index.html").read_text(encoding="utf-8")
    images = re.findall(r'<img [^>]*src="([^"]+\.png)"', html)
    assert len(images) >= 6, images
    assert all((site / "examples" / image).is_file() for image in images)
    for name in (
        "constant_torque",
        "gravity_overlay",
        "parameter_study",
        "closed_loop_pd",
        "swing_up_lqr",
        "compare_with_opensim",
        "fmpy_command_line",
    ):
        assert f"{name}.py" in html
