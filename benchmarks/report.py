"""The tables the benchmarks print: rows of measure, value and target; text or markdown."""

from __future__ import annotations

import os
import platform
import re
import subprocess
from dataclasses import dataclass


@dataclass(frozen=True)
class Row:
    part: str
    measure: str
    value: str
    target: str = ""
    met: bool | None = None  # None: nothing to meet

    @property
    def verdict(self) -> str:
        return "" if self.met is None else ("met" if self.met else "MISSED")


def skipped(part: str, measure: str, why: str) -> Row:
    return Row(part, measure, f"skipped: {why}")


def microseconds(seconds: float) -> str:
    return f"{seconds * 1e6:.3f} µs"


def ratio(value: float) -> str:
    return f"{value:.3f}"


def count(value: float) -> str:
    return f"{value:,.0f}"


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            for line in cpuinfo:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def gcc_version() -> str:
    try:
        first_line = subprocess.run(["gcc", "--version"], capture_output=True, text=True).stdout
    except OSError:
        return "gcc not found"
    match = re.search(r"\d+\.\d+\.\d+", first_line.splitlines()[0] if first_line else "")
    return f"gcc {match.group(0)}" if match else "gcc (unknown version)"


def machine() -> str:
    return (
        f"{cpu_model()}, {os.cpu_count()} cores; Python {platform.python_version()}; "
        f"{gcc_version()}; {platform.system()} {platform.release()}"
    )


@dataclass(frozen=True)
class Table:
    title: str
    header: tuple[str, ...]
    cells: list[tuple[str, ...]]


def main_table(rows: list[Row]) -> Table:
    return Table(
        f"Machine: {machine()}",
        ("part", "measure", "value", "target", ""),
        [(r.part, r.measure, r.value, r.target, r.verdict) for r in rows],
    )


def as_text(table: Table) -> str:
    lines = [table.header, *table.cells]
    widths = [max(len(line[i]) for line in lines) for i in range(len(table.header))]
    rule = "  ".join("-" * w for w in widths)
    body = ["  ".join(cell.ljust(w) for cell, w in zip(line, widths, strict=False)).rstrip() for line in lines]
    return "\n".join([table.title, rule, body[0], rule, *body[1:], rule])


def as_markdown(table: Table) -> str:
    def line(cells):
        return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"

    return "\n".join(
        [
            table.title,
            "",
            line(table.header),
            line(("---",) * len(table.header)),
            *(line(cells) for cells in table.cells),
        ]
    )
