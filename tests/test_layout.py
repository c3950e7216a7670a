"""The package's folders: a folder per job, each importing only the folders its docstring names.

Every folder's __init__.py says its job and, in a paragraph that starts "May import:", the
folders below it that it may import; this holds the modules to it, lazy imports included, so
that the folders stay layered as docs/design.md draws them.
"""

import ast
import re
from pathlib import Path

import pytest

import pendulum_fmu

PACKAGE = Path(pendulum_fmu.__file__).parent
# The modules at the top beside the folders: the face, the program, and the basics every folder
# may use, which import no folder.
PROGRAM = {"__init__", "__main__", "_entry"}
BASICS = {"_errors", "_atomic_files", "_received_files", "_stop_signals", "_checkout", "_progress_bar", "_drawn_points"}
FOLDERS = sorted(path.parent.name for path in PACKAGE.glob("*/__init__.py"))


def _imported(path: Path) -> set[str]:
    """The pendulum_fmu modules or packages path imports, by their dotted names, lazily too."""
    package = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if path.name != "__init__.py":
        package = package.rpartition(".")[0]
    else:
        package = package.removesuffix(".__init__")
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
            stem = ".".join(base + ([node.module] if node.module else []))
            names |= {f"{stem}.{alias.name}" for alias in node.names}
    return {name for name in names if name.split(".")[0] == "pendulum_fmu"}


def _where(dotted: str) -> str:
    """The folder of a pendulum_fmu name, the top module it is in, or "pendulum_fmu" for the face."""
    parts = dotted.split(".")
    if len(parts) > 1 and parts[1] in FOLDERS:
        return parts[1] + "/"
    if len(parts) > 1 and (PACKAGE / f"{parts[1]}.py").is_file():
        return parts[1]
    return "pendulum_fmu"


def _may_import(folder: str) -> set[str]:
    """What the first sentence of the "May import:" paragraph of folder's docstring allows."""
    docstring = ast.get_docstring(ast.parse((PACKAGE / folder / "__init__.py").read_text(encoding="utf-8"))) or ""
    found = re.search(r"^May import:(.*?)\.(?:\s|\Z)", docstring, re.MULTILINE | re.DOTALL)
    assert found, f"{folder}/__init__.py: no 'May import:' paragraph in its docstring"
    text = found[1]
    allowed = {f"{name}/" for name in re.findall(r"\b([a-z_]+)/", text)} | {f"{folder}/"}
    if "every folder" in text:
        allowed |= {f"{name}/" for name in FOLDERS}
    if "the basics" in text:
        allowed |= BASICS
    if "the top's own names" in text:
        allowed.add("pendulum_fmu")
    return allowed


def test_the_top_holds_the_program_and_the_basics_and_the_rest_is_in_folders():
    assert {path.stem for path in PACKAGE.glob("*.py")} == PROGRAM | BASICS
    # A folder named as an API name would replace that name once imported (pendulum_fmu.judge).
    assert not set(FOLDERS) & set(pendulum_fmu.__all__)


def test_the_basics_import_no_folder():
    for name in BASICS:
        assert {_where(dotted) for dotted in _imported(PACKAGE / f"{name}.py")} <= BASICS | {"pendulum_fmu"}, name


@pytest.mark.parametrize("folder", FOLDERS)
def test_a_folder_imports_only_what_its_docstring_allows(folder):
    allowed = _may_import(folder)
    wrong = sorted(
        f"{path.relative_to(PACKAGE)} imports {dotted}"
        for path in (PACKAGE / folder).rglob("*.py")
        for dotted in _imported(path)
        if _where(dotted) not in allowed
    )
    assert wrong == []


def test_the_layers_have_an_order():
    """Each folder may import only folders below it: no two allow each other, however indirectly."""
    below = {
        folder: {name.rstrip("/") for name in _may_import(folder) if name.endswith("/")} - {folder}
        for folder in FOLDERS
    }
    order = []
    while below:
        ready = sorted(folder for folder, needs in below.items() if needs <= set(order))
        assert ready, f"the folders {sorted(below)} allow each other in a circle"
        order += ready
        below = {folder: needs for folder, needs in below.items() if folder not in ready}
    assert order[0] == "signals" and order[-1] == "cli"
