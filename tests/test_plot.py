"""_plot.py: what each figure draws and says, read back from the matplotlib figure."""

from pathlib import Path

import numpy as np
import pytest
from matplotlib import rcParams

from pendulum_fmu.cli import main
from pendulum_fmu.figures import _plot as plot
from pendulum_fmu.fmu import _results as results
from pendulum_fmu.oracle._reference import reference


@pytest.fixture
def drawn(monkeypatch):
    """Every figure _plot.py finishes, as (figure, its axes, title), and still written."""
    figures = []
    finish = plot._finish

    def keep(fig, axes, title, path):
        figures.append((fig, list(np.ravel(axes)), title))
        return finish(fig, axes, title, path)

    monkeypatch.setattr(plot, "_finish", keep)
    return figures


def test_band_quantiles_are_numpys_per_value():
    rng = np.random.default_rng(7)
    x, y = rng.integers(0, 9, 2000).astype(float), rng.normal(size=2000)
    levels, values = plot._quantiles(x, y, [0.05, 0.5, 0.75])
    assert levels.tolist() == sorted(set(x.tolist()))
    for i, level in enumerate(levels):
        assert np.allclose([v[i] for v in values], np.quantile(y[x == level], [0.05, 0.5, 0.75]), rtol=0, atol=1e-12)
    many = rng.uniform(0.0, 1.0, 5000)  # more distinct values than levels: pooled into bins
    levels, (median,) = plot._quantiles(many, many, [0.5])
    assert len(levels) == plot.BAND_LEVELS and np.max(np.abs(median - levels)) < 0.5 / plot.BAND_LEVELS


def _legend(ax) -> list[str]:
    return ax.get_legend_handles_labels()[1]


def test_one_case_per_value_draws_the_cases_not_bands(drawn, tmp_path):
    torque = np.array([40.0, 5.0, 20.0, 10.0])
    summaries = {"max |theta| in rad": torque / 100, "final theta in rad": torque / 200}
    plot.plot_case_bands({"torque": torque}, summaries, tmp_path / "one.png", "t", units={"torque": "N.m"})
    _, axes, _ = drawn[0]
    for ax, y in zip(axes, summaries.values(), strict=False):
        assert len(ax.collections) == 0, "no band where each value has one case"
        (line,) = ax.get_lines()
        assert line.get_xdata().tolist() == [5.0, 10.0, 20.0, 40.0]
        assert line.get_ydata().tolist() == sorted(y.tolist())
    assert _legend(axes[0]) == ["one case per value"]
    assert axes[-1].get_xlabel() == "torque in N.m"


def test_several_cases_per_value_draw_the_median_and_two_bands(drawn, tmp_path):
    rng = np.random.default_rng(3)
    gravity = np.repeat([0.0, 9.81], 20)
    y = rng.normal(size=40)
    plot.plot_case_bands(
        {"gravity": gravity}, {"final theta in rad": y}, tmp_path / "bands.png", "t", units={"gravity": "m/s2"}
    )
    (_, (ax,), _) = drawn[0]
    assert len(ax.collections) == 2
    (median,) = ax.get_lines()
    assert np.allclose(median.get_ydata(), [np.median(y[:20]), np.median(y[20:])], rtol=0, atol=1e-15)
    assert _legend(ax) == ["5%-95% of cases", "25%-75% of cases", "median"]
    assert ax.get_xlabel() == "gravity in m/s2"


def test_figures_lie_where_tight_layout_puts_them_inside_the_page_at_120_dpi(drawn, tmp_path):
    # _finish lays out in one measuring pass, on the renderer the file is drawn with: the axes
    # must land where matplotlib's own fig.tight_layout() puts them, everything drawn must lie
    # inside the page, and the PNG must have 120 dots per inch.
    rng = np.random.default_rng(11)
    torque, gravity = np.repeat(np.linspace(0.0, 40.0, 8), 30), np.tile(np.linspace(0.0, 20.0, 30), 8)
    summaries = {
        "max |theta| in rad": 1e-5 * torque * rng.uniform(0.5, 1.5, 240),
        "final theta in rad": 1e4 * rng.normal(size=240),
    }
    plot.plot_case_bands({"torque": torque, "gravity": gravity}, summaries, tmp_path / "bands.png", "bands")
    base = _run(np.linspace(0.0, 1.0, 50))
    plot.plot_comparison({"reference": base, "fmu": _run(base["theta"] + 1e-9)}, tmp_path / "compared.png", "compared")
    for (fig, axes, _), name in zip(drawn, ("bands.png", "compared.png"), strict=True):
        inked = fig.get_tightbbox(fig.canvas.get_renderer())  # inches
        assert 0 <= inked.x0 and inked.x1 <= fig.get_figwidth() and 0 <= inked.y0 and inked.y1 <= fig.get_figheight()
        laid_out = [ax.get_position().bounds for ax in axes]
        fig.subplots_adjust(**{name: rcParams[f"figure.subplot.{name}"] for name in fig.subplotpars.__dict__})
        fig.tight_layout()  # from where _finish started: tight_layout moves a figure laid out already
        assert np.allclose([ax.get_position().bounds for ax in axes], laid_out, rtol=0, atol=1e-12)
        header = (tmp_path / name).read_bytes()[16:24]  # the PNG's IHDR: width, height
        width, height = int.from_bytes(header[:4], "big"), int.from_bytes(header[4:], "big")
        assert (width, height) == (round(120 * fig.get_figwidth()), round(120 * fig.get_figheight()))
    # A column's panels share its x values: only the bottom one writes them.
    _, (top_left, _, bottom_left, _), _ = drawn[0]
    assert not any(label.get_visible() for label in top_left.get_xticklabels())
    assert {"0", "40"} <= {label.get_text() for label in bottom_left.get_xticklabels() if label.get_visible()}


def _run(theta, omega=None):
    run = results.empty(len(theta))
    run["time"] = np.arange(len(theta)) * 1e-3
    run["theta"], run["omega"] = theta, theta if omega is None else omega
    return run


def test_exact_zeros_are_left_out_of_the_log_axis_and_counted(drawn, tmp_path):
    base = _run(np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6]))
    difference = np.array([0.0, 1e-12, 0.0, 0.0, 3e-12, 2e-12])
    plot.plot_comparison({"reference": base, "fmu": _run(base["theta"] + difference)}, tmp_path / "c.png", "t")
    _, axes, _ = drawn[0]
    theta_difference = axes[1]  # row 0, right
    assert theta_difference.get_yscale() == "log"
    line, alone = theta_difference.get_lines()
    drawn_values = line.get_ydata()
    assert np.array_equal(np.isnan(drawn_values), difference == 0)
    assert np.allclose(drawn_values[difference != 0], difference[difference != 0], rtol=1e-3, atol=0)
    assert alone.get_xdata().tolist() == [1e-3]  # between two identical points: a marker, no line
    assert _legend(theta_difference)[0] == "fmu - reference (3 of 6 points identical, not drawn)"


def test_a_difference_zero_everywhere_is_written_not_drawn(drawn, tmp_path):
    base = _run(np.linspace(0.0, 1.0, 5))
    plot.plot_comparison({"reference": base, "copy": base.copy()}, tmp_path / "same.png", "t")
    _, axes, _ = drawn[0]
    for ax in (axes[1], axes[3]):
        assert len(ax.get_lines()) == 0
        assert [text.get_text() for text in ax.texts] == ["copy - reference: identical at every point"]


def test_titles_name_the_torque_and_the_parameters_with_their_units(tmp_path):
    assert plot.case_title(20.0) == "Torque-driven pendulum: torque 20 N.m, gravity 9.81 m/s2"
    assert plot.case_title(tmp_path / "steps.csv", {"gravity": 0.0, "damping": 2.0}, theta0=0.1) == (
        "Torque-driven pendulum: torque from steps.csv, gravity 0 m/s2, damping 2 N.m.s/rad, theta0 0.1 rad"
    )
    assert plot.case_title(lambda t: t).startswith("Torque-driven pendulum: a torque signal, gravity 9.81 m/s2")


def test_simulate_plot_says_torque_and_gravity_and_draws_the_run(drawn, tmp_path):
    assert (
        main(
            [
                "simulate",
                "--torque",
                "20",
                "--set",
                "gravity=0",
                "--stop-time",
                "1",
                "--plot",
                str(tmp_path / "run.png"),
            ]
        )
        == 0
    )
    _, axes, title = drawn[0]
    assert title == "Torque-driven pendulum: torque 20 N.m, gravity 0 m/s2"
    (theta,) = axes[0].get_lines()
    expected = reference(20.0, stop_time=1.0, parameters={"gravity": 0.0})["theta"]
    assert np.max(np.abs(theta.get_ydata() - expected)) < 1e-10


def test_a_sweep_of_one_case_per_torque_draws_the_cases_with_units(drawn, tmp_path):
    from pendulum_fmu.sweep import Study, run_sweep, sweep_grid

    run_sweep(
        Study(sweep_grid([5.0, 10.0, 20.0, 40.0], [0.0]), stop_time=0.1, outputs=[]),
        output_dir=tmp_path,
        workers=1,
        progress=False,
    )
    _, axes, _ = drawn[-1]
    for ax in axes:
        assert len(ax.collections) == 0
    assert axes[-1].get_xlabel() == "torque in N.m"
    # Gravity 0: theta(t) = tau t^2 / (2 I) with I = inertia + mass length^2 = 30 kg.m2.
    (final,) = axes[-1].get_lines()
    assert np.allclose(final.get_ydata(), np.array([5.0, 10.0, 20.0, 40.0]) * 0.1**2 / 60, rtol=1e-9, atol=0)


@pytest.mark.filterwarnings("error")  # numpy's overflow warnings would be extra lines on stderr
def test_values_too_large_to_draw_are_left_out_and_said(drawn, tmp_path):
    base = _run(np.linspace(0.0, 1.0, 5))
    far = base.copy()
    far["theta"] = 1e308
    plot.plot_comparison({"reference": base, "far": far}, tmp_path / "far.png", "t")
    _, axes, _ = drawn[0]
    theta, theta_difference, omega, _omega_difference = axes
    assert _legend(theta) == ["reference"]
    assert [text.get_text() for text in theta.texts] == ["far reaches 1e+308: too large to draw"]
    assert all(abs(limit) <= 1.1 for limit in theta.get_ylim())  # scaled to what is drawn: 0 to 1
    assert len(theta_difference.get_lines()) == 0
    assert [text.get_text() for text in theta_difference.texts] == ["far - reference reaches 1e+308: too large to draw"]
    assert _legend(omega) == ["reference", "far"]
    assert (tmp_path / "far.png").stat().st_size > 0


@pytest.mark.filterwarnings("error")
def test_a_run_started_past_drawable_angles_is_written_with_a_note(drawn, tmp_path, capsys):
    assert (
        main(
            [
                "simulate",
                "--torque",
                "1",
                "--stop-time",
                "0.05",
                "--theta0",
                "1e308",
                "--plot",
                str(tmp_path / "run.png"),
            ]
        )
        == 0
    )
    _, axes, _ = drawn[0]
    assert [text.get_text() for text in axes[0].texts] == ["FMU reaches 1e+308: too large to draw"]
    assert len(axes[1].get_lines()) == 1  # omega stays small: drawn
    assert (tmp_path / "run.png").is_file() and capsys.readouterr().err == ""


@pytest.mark.filterwarnings("error")
def test_a_sweep_started_past_drawable_angles_still_writes_its_figure(drawn, tmp_path):
    from pendulum_fmu.sweep import Study, run_sweep, sweep_grid

    done = run_sweep(
        Study(sweep_grid([1.0], extra={"theta0": [1e308]}), stop_time=0.01, format="csv"),
        output_dir=tmp_path,
        workers=1,
        progress=False,
    )
    _, axes, _ = drawn[-1]
    assert [text.get_text() for text in axes[0].texts] == [
        "torque = 1 N.m, gravity = 9.81 m/s2, theta0 = 1e+308 rad reaches 1e+308: too large to draw"
    ]
    assert Path(done.figure).is_file()


def test_drawing_a_figure_leaves_matplotlibs_backend_and_pyplot_alone(tmp_path):
    # A notebook's inline backend (or any the user chose) must survive plot_overlay: before,
    # importing _plot switched every process to Agg and its figures went through pyplot.
    import subprocess
    import sys

    script = (
        "import matplotlib; matplotlib.use('svg')\n"
        "import matplotlib.pyplot as plt\n"
        "from pendulum_fmu import plot_overlay, reference\n"
        f"path = plot_overlay({{'reference': reference(20.0, stop_time=0.1)}}, {str(tmp_path / 'o.png')!r}, 't')\n"
        "print(matplotlib.get_backend(), len(plt.get_fignums()), path.stat().st_size > 10000)\n"
    )
    printed = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert printed.split() == ["svg", "0", "True"]
