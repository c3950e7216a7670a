"""A Sphinx extension: the examples page, made by running examples/*.py during the build.

Each example runs as a user runs it (``python examples/NAME.py --output-dir ...``) with its
figures written under the build's source tree (docs/examples/, which .gitignore lists); the
page shows its docstring, its source, what it printed and every figure it wrote. An example
that fails fails the build, so the page never shows a stale figure.
"""

import ast
import os
import subprocess
import sys
from pathlib import Path

# The examples the page runs, in the order of examples/README.md, with the arguments that keep
# each run short (each writes only into its own --output-dir).
EXAMPLES = {
    "constant_torque": [],
    "gravity_overlay": [],
    "parameter_study": ["--overwrite"],
    "closed_loop_pd": [],
    "swing_up_lqr": [],
    "compare_with_opensim": [],
    "fmpy_command_line": [],
}
TIMEOUT_S = 300


def _page(name: str, source: Path, printed: str, figures: list[Path], folder: Path) -> str:
    summary = ast.get_docstring(ast.parse(source.read_text(encoding="utf-8"))) or ""
    parts = [
        f"## `{name}.py`",
        "",
        " ".join(summary.split()),
        "",
        f"```{{literalinclude}} ../../examples/{name}.py",
        ":language: python",
        "```",
        "",
        f"It printed (`python examples/{name}.py`):",
        "",
        "```text",
        printed.rstrip(),
        "```",
        "",
    ]
    for figure in figures:
        parts += [f"![{figure.stem}]({figure.relative_to(folder).as_posix()})", ""]
    return "\n".join(parts)


def write_examples_page(app) -> None:
    """Run every example and write docs/examples/index.md, the page that shows them."""
    docs = Path(app.srcdir)
    root = docs.parent
    folder = docs / "examples"
    sections = []
    for name, arguments in EXAMPLES.items():
        output_dir = folder / name
        source = root / "examples" / f"{name}.py"
        environment = dict(os.environ, MPLBACKEND="Agg")
        done = subprocess.run(
            [sys.executable, str(source), "--output-dir", str(output_dir), *arguments],
            cwd=root,
            env=environment,
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
        )
        if done.returncode != 0:
            raise RuntimeError(f"examples/{name}.py exited {done.returncode}:\n{done.stderr[-3000:]}")
        printed = done.stdout.replace(str(root) + os.sep, "")
        sections.append(_page(name, source, printed, sorted(output_dir.rglob("*.png")), folder))
    header = (docs / "examples_intro.md").read_text(encoding="utf-8")
    text = header.rstrip() + "\n\n" + "\n".join(sections)
    page = folder / "index.md"
    # Rewritten only when it changed, so that Sphinx rereads it only then.
    if not page.exists() or page.read_text(encoding="utf-8") != text:
        from pendulum_fmu._atomic_files import replacing

        with replacing(page, encoding="utf-8") as file:
            file.write(text)


def setup(app):
    """Register the examples page with Sphinx (the extension's entry point)."""
    app.connect("builder-inited", write_examples_page)
    return {"parallel_read_safe": True, "version": "1"}
