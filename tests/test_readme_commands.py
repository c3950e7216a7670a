"""Every shell command the READMEs and the docs pages show runs as written, as a newcomer runs it.

What counts as a command: each line of an indented (4-space) code block and of a ```sh, ```bash,
```shell or ```console fenced block (console lines start with "$ "), lines ending in a backslash
joined with the next, and the first code span of every cell in a table column named "command".
Everything else a README shows as code goes in a fenced block with another language (```text,
```python), so an indented block is always something to type.

Each command runs with `bash -c` in a fresh shell (no virtual environment active, no venv on
PATH), in document order, in one temporary copy of the repository per README (the docs pages,
which were the README's sections, share one copy and run in the README's old order), so its
outputs never land in the checkout. The copy leaves out what the commands write when run in the
clone (the section of .gitignore that lists them): the README's main job leaves `demo/`, which
the same README's `demo --output-dir demo` would refuse. The copy's `.venv` is a symlink to this
interpreter's environment: that stands for "after the set-up command", which CI (.ci/run) runs
itself. The few commands that cannot run here are listed in EXCLUDED, each with its reason;
every entry must match a command, so the list stays what the documents need.
"""

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
READMES = ("README.md", "examples/README.md")
# The docs pages with commands, in the order the README held them.
DOCS_PAGES = tuple(
    f"docs/{name}.md"
    for name in (
        "install",
        "fmu",
        "fmi3",
        "wasm",
        "torque_signals",
        "python_api",
        "command_line",
        "comparing",
        "reinforcement_learning",
        "judging",
        "scenario_kit",
        "masters",
        "sweeps",
        "robustness_overview",
        "benchmarks",
        "layout",
    )
)
DOCUMENTS = READMES + DOCS_PAGES
# The heading of the .gitignore section that lists what the documents' commands write.
OUTPUTS_SECTION = "# What the README's commands write when run in a clone"

# The set-up commands: CI runs them; here the .venv symlink stands for them, and what follows
# them on the line runs.
SETUP = re.compile(r'^python3 -m venv \.venv && \.venv/bin/pip install (?:-e )?"[^"]+"(?: && )?')

EXCLUDED = {
    r"^\.venv/bin/pytest$": "the whole test suite, which this test is part of; CI runs it",
    r"^sudo apt-get ": "installs system packages as root; .ci/run installs the same list",
    r"^\.venv/bin/pip install ": "changes the environment this test suite runs in",
    r"^ssh ": "runs on other machines (head, node1, ...)",
    r"^\.venv/bin/python build_wheels\.py$": "builds every OS's wheel, longer than a README command "
    "may take; tests/test_wheels.py runs the same build",
    r"^(helm|kubectl) ": "needs a Kubernetes cluster",
    r"--scheduler tls://(head|localhost):8786": "needs the cluster's dask scheduler started above",
    r"^openssl ": "makes the certificates of a cluster on other machines (tested by hand; "
    "tests/test_sweep_security.py makes its own with cryptography and runs a TLS cluster on them)",
    r"jupyter notebook": "starts a server that runs until stopped; tests/test_notebook.py runs the notebook",
}

# A guard against a command that hangs, not a speed goal (those are the benchmarks', such as
# benchmarks.install): building the wheel took 1.5 min on a quiet 2-core machine and over 3 min
# on a loaded one.
COMMAND_TIMEOUT = 600


def fenced_language(line: str):
    match = re.match(r"^\s*```\s*(\S*)", line)
    return match.group(1).lower() if match else None


def commands_in(text: str) -> list[str]:
    """The shell commands in a Markdown text, in order (see the module's docstring)."""
    found, fence, table_column = [], None, None
    indented, previous_blank = False, True
    for line in text.splitlines():
        language = fenced_language(line)
        if fence is not None:
            if language == "":
                fence = None
            elif fence in ("sh", "bash", "shell"):
                found.append(line.strip())
            elif fence == "console" and line.lstrip().startswith("$ "):
                found.append(line.lstrip()[2:].strip())
        elif language is not None:
            fence = language
        elif line.startswith("    ") and (indented or previous_blank):
            found.append(line.strip())
        elif line.startswith("|"):
            cells = [cell.strip() for cell in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
            if table_column is None and "command" in cells:
                table_column = cells.index("command")
            elif table_column is not None and table_column < len(cells):
                span = re.search(r"`([^`]+)`", cells[table_column])
                if span:
                    found.append(span.group(1))
        indented = fence is None and language is None and line.startswith("    ") and (indented or previous_blank)
        if not line.startswith("|"):
            table_column = None
        previous_blank = not line.strip()
    return join_continuations([command for command in found if command and not command.startswith("#")])


def join_continuations(lines: list[str]) -> list[str]:
    commands, pending = [], ""
    for line in lines:
        if line.endswith("\\"):
            pending += line[:-1].rstrip() + " "
        else:
            commands.append(re.sub(r"\s+", " ", pending + line.strip()) if pending else line)
            pending = ""
    assert not pending, f"a command ends in a backslash: {pending}"
    return commands


def to_run(command: str):
    """(the command to run, None) or (None, why it is not run here)."""
    command = SETUP.sub("", command)
    for pattern, reason in EXCLUDED.items():
        if re.search(pattern, command):
            return None, reason
    return command, None


def copy_key(document: str) -> str:
    """The copy of the repository a document's commands run in: the docs pages share one."""
    return "docs" if document in DOCS_PAGES else document


def readme_commands():
    for readme in DOCUMENTS:
        for index, command in enumerate(commands_in((ROOT / readme).read_text(encoding="utf-8"))):
            yield pytest.param(readme, command, id=f"{readme}:{index}:{command[:60]}")


COMMANDS = list(readme_commands())


def test_extraction_reads_every_kind_of_block():
    text = "\n".join(
        [
            "Prose with `inline code` that is not a command.",
            "",
            "    first --flag \\",
            "        --continued",
            "    second",
            "",
            "```python",
            "print('not a command')",
            "```",
            "```text",
            "    not a command either",
            "```",
            "```console",
            "$ third",
            "output line",
            "```",
            "```sh",
            "fourth",
            "```",
            "| example | command |",
            "|---|---|",
            "| a | `fifth arg` (after `x`) |",
            "| b | none |",
            "",
            "Text.",
            "",
            "    sixth",
        ]
    )
    assert commands_in(text) == ["first --flag --continued", "second", "third", "fourth", "fifth arg", "sixth"]


def test_every_exclusion_matches_a_command():
    commands = [SETUP.sub("", param.values[1]) for param in COMMANDS]
    unused = [pattern for pattern in EXCLUDED if not any(re.search(pattern, c) for c in commands)]
    assert not unused, f"exclusions that match no README command (remove them): {unused}"


def command_outputs(gitignore: str) -> set[str]:
    """The top-level names .gitignore's OUTPUTS_SECTION lists (`/demo/` -> `demo`)."""
    lines = gitignore.splitlines()
    section = lines[lines.index(OUTPUTS_SECTION) + 1 :]
    listed = section[: next((n for n, line in enumerate(section) if not line.startswith("/")), len(section))]
    return {line.strip("/").split("/")[0] for line in listed}


def copy_of_the_clone(root: Path, target: Path) -> Path:
    """The clone at root copied to target as its commands meet it fresh.

    The copy holds neither the build's outputs nor what the documents' commands wrote into the
    clone; its `.venv` stands for the set-up (this interpreter's environment), its
    `web/node_modules` for `npm ci --prefix web` (the clone's).
    """
    left_out = command_outputs((root / ".gitignore").read_text(encoding="utf-8"))

    def ignored(folder, names):
        at_top = Path(folder) == root
        return shutil.ignore_patterns(
            ".venv", ".git", "dist", "build", "out", "__pycache__", "*.egg-info", ".pytest_cache", "node_modules"
        )(folder, names) | {name for name in names if at_top and name in left_out}

    shutil.copytree(root, target, symlinks=True, ignore=ignored)
    (target / ".venv").symlink_to(sys.prefix, target_is_directory=True)
    # jco for the docs build's wasm page: the clone's install stands for `npm ci --prefix web`.
    if (root / "web" / "node_modules").is_dir():
        (target / "web" / "node_modules").symlink_to(root / "web" / "node_modules", target_is_directory=True)
    return target


@pytest.fixture(scope="module")
def copies(tmp_path_factory):
    """One copy of the repository per README (one for all the docs pages), made on first use."""
    made = {}

    def copy_for(document):
        key = copy_key(document)
        if key not in made:
            made[key] = copy_of_the_clone(ROOT, tmp_path_factory.mktemp("readme") / "pendulum-fmu")
        return made[key]

    return copy_for


def test_the_copy_leaves_out_what_the_main_job_wrote(tmp_path):
    clone = tmp_path / "clone"
    (clone / "demo").mkdir(parents=True)
    (clone / "demo" / "gravity_effect.png").write_bytes(b"from the main job")
    (clone / "docs" / "demo").mkdir(parents=True)  # a folder of that name deeper down is a source
    (clone / "Pendulum.fmu").write_bytes(b"from the quick start")
    (clone / "README.md").write_text("# a README\n", encoding="utf-8")
    gitignore = (ROOT / ".gitignore").read_text(encoding="utf-8")
    (clone / ".gitignore").write_text(gitignore, encoding="utf-8")
    copy = copy_of_the_clone(clone, tmp_path / "copy")
    assert sorted(path.name for path in copy.iterdir()) == [".gitignore", ".venv", "README.md", "docs"]
    assert (copy / "docs" / "demo").is_dir()
    assert {"demo", "Pendulum.fmu", "torque.csv", "study"} <= command_outputs(gitignore)


def fresh_shell_environment():
    """The caller's environment less any trace of a virtual environment, as a new terminal has."""
    venv_bin = {str(Path(sys.prefix) / "bin"), os.environ.get("VIRTUAL_ENV", "") + "/bin"}
    environment = {
        name: value for name, value in os.environ.items() if name not in ("VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME")
    }
    environment["PATH"] = os.pathsep.join(
        part for part in environment.get("PATH", "").split(os.pathsep) if part not in venv_bin
    )
    return environment


@pytest.mark.readme
@pytest.mark.parametrize(("readme", "command"), COMMANDS)
def test_readme_command_runs_as_written(readme, command, copies):
    command, reason = to_run(command)
    if command is None:
        pytest.skip(f"not run here: {reason}")
    started = time.monotonic()
    result = subprocess.run(
        ["bash", "-c", command],
        cwd=copies(readme),
        env=fresh_shell_environment(),
        capture_output=True,
        text=True,
        timeout=COMMAND_TIMEOUT,
    )
    elapsed = time.monotonic() - started
    assert result.returncode == 0, (
        f"{readme}: `{command}` exited {result.returncode} after {elapsed:.0f} s\n"
        f"--- stdout (end)\n{result.stdout[-3000:]}\n--- stderr (end)\n{result.stderr[-3000:]}"
    )


def test_ci_runs_the_readme_test_command_after_the_readme_system_packages():
    readme = commands_in((ROOT / "README.md").read_text(encoding="utf-8"))
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    test_command = [command for command in readme if command.endswith("&& .venv/bin/pytest")]
    assert len(test_command) == 1 and test_command[0] in ci.splitlines(), (
        f"the README's test command {test_command} is not a line of .ci/run"
    )
    readme_packages = [command.split()[3:] for command in readme if command.startswith("sudo apt-get install ")]
    ci_packages = re.search(r"apt-get install -y -qq ([^>]+)>", ci.replace("\\\n", " ")).group(1).split()
    assert len(readme_packages) == 1 and sorted(readme_packages[0]) == sorted(ci_packages)
