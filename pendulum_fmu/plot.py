"""Figures in the style of the OpenSim tutorial: theta and omega over time, tools overlaid."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: works on machines without a display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .files import replacing_path  # noqa: E402

THETA_LABEL = r"Position $\theta$ in rad"
OMEGA_LABEL = r"Velocity $\omega$ in rad/s"
TIME_LABEL = r"Time $t$ in s"


def _finish(fig, axes, title: str, path: str | Path) -> Path:
    for ax in np.ravel(axes):
        ax.grid(True, alpha=0.4)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="upper left", fontsize=9, frameon=True)
    fig.suptitle(title, fontsize=13)
    fig.tight_layout()
    path = Path(path)
    try:
        with replacing_path(path) as partial:
            fig.savefig(partial, dpi=120, format=path.suffix.lstrip(".") or "png")
    finally:
        plt.close(fig)
    return path


def plot_overlay(runs: dict[str, np.ndarray], path: str | Path, title: str) -> Path:
    """theta and omega of each run, overlaid (dashed after the first, so coincident lines show)."""
    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    for i, (label, run) in enumerate(runs.items()):
        style = dict(linewidth=2 if i == 0 else 1.5, linestyle="-" if i == 0 else "--")
        axes[0].plot(run["time"], run["theta"], label=label, **style)
        axes[1].plot(run["time"], run["omega"], label=label, **style)
    axes[0].set_ylabel(THETA_LABEL)
    axes[1].set_ylabel(OMEGA_LABEL)
    axes[1].set_xlabel(TIME_LABEL)
    return _finish(fig, axes, title, path)


def plot_comparison(runs: dict[str, np.ndarray], path: str | Path, title: str) -> Path:
    """Left: theta and omega of every tool overlaid. Right: |difference| of each tool against
    the first one, on a log scale, where agreement to 1e-10 is visible."""
    fig, axes = plt.subplots(2, 2, figsize=(14, 6), sharex=True)
    labels = list(runs)
    base = runs[labels[0]]
    for i, label in enumerate(labels):
        run = runs[label]
        style = dict(linewidth=2 if i == 0 else 1.5, linestyle="-" if i == 0 else "--")
        axes[0, 0].plot(run["time"], run["theta"], label=label, **style)
        axes[1, 0].plot(run["time"], run["omega"], label=label, **style)
        if i:
            # Exact zeros cannot be drawn on a log axis; the floor sits far below any tolerance.
            for row, name in enumerate(("theta", "omega")):
                difference = np.maximum(np.abs(run[name] - base[name]), 1e-18)
                axes[row, 1].semilogy(run["time"], difference, label=f"{label} - {labels[0]}")
    axes[0, 0].set_ylabel(THETA_LABEL)
    axes[1, 0].set_ylabel(OMEGA_LABEL)
    axes[0, 1].set_ylabel(r"$|\Delta\theta|$ in rad")
    axes[1, 1].set_ylabel(r"$|\Delta\omega|$ in rad/s")
    for ax in axes[1]:
        ax.set_xlabel(TIME_LABEL)
    return _finish(fig, axes, title, path)


def plot_cases(runs: dict[str, np.ndarray], path: str | Path, title: str) -> Path:
    """theta and omega of many cases, coloured along a colormap; labelled when few enough."""
    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    colors = plt.cm.viridis(np.linspace(0, 0.9, max(len(runs), 1)))
    labelled = len(runs) <= 12
    for color, (label, run) in zip(colors, runs.items()):
        axes[0].plot(run["time"], run["theta"], color=color, linewidth=1.5,
                     label=label if labelled else None)
        axes[1].plot(run["time"], run["omega"], color=color, linewidth=1.5)
    axes[0].set_ylabel(THETA_LABEL)
    axes[1].set_ylabel(OMEGA_LABEL)
    axes[1].set_xlabel(TIME_LABEL)
    return _finish(fig, axes, title, path)
