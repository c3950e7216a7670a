"""The FMU's documentation/index.html, made from its model description."""

from __future__ import annotations

import html


def documentation_html(model_description, fmi_version: int = 2) -> str:
    """documentation/index.html: what the model is and every variable with its unit and meaning."""
    rows = "\n".join(
        "<tr>"
        + "".join(
            f"<td>{html.escape(str(cell))}</td>"
            for cell in (
                v.name,
                v.valueReference,
                v.causality,
                v.variability,
                v.unit or "",
                "" if v.start is None else v.start,
                v.description or "",
            )
        )
        + "</tr>"
        for v in model_description.modelVariables
    )
    interfaces = " and ".join(
        name
        for name, present in (
            ("Model Exchange", model_description.modelExchange),
            ("Co-Simulation", model_description.coSimulation),
        )
        if present
    )
    name = html.escape(model_description.modelName)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{name} FMU</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}
table{{border-collapse:collapse}}td,th{{border:1px solid #999;padding:.2em .5em}}</style></head>
<body>
<h1>{name}</h1>
<p>{html.escape(model_description.description or "")}</p>
<p>FMI {fmi_version}.0 {interfaces}, model identifier <code>{name}</code>.</p>
<h2>Inside a communication step</h2>
<p>Each <code>fmi{fmi_version}DoStep(t, h)</code> integrates exactly [t, t+h] with an error-controlled
Taylor series method of order 6 (Dormand-Prince 5(4) where the model has no series or the
method gives up): internal steps end on t+h and never cross it, and the internal step size
carries over between calls. Inputs are held over the step (zero-order
hold) or, after <code>fmi2SetRealInputDerivatives</code> (orders 1 and 2; higher orders are
ignored), follow their Taylor polynomial from their values at t until the derivatives are set
again. FMI 3.0 has no input derivatives: there inputs are always held. The relative tolerance is
<code>fmi2SetupExperiment</code>'s when defined, else 1e-10; the absolute tolerance equals it.
A step that needs more than 100000 internal steps returns fmi2Discard and leaves the instance
where it was.</p>
<h2>Variables</h2>
<table><tr><th>name</th><th>value reference</th><th>causality</th><th>variability</th>
<th>unit</th><th>start</th><th>description</th></tr>
{rows}
</table>
</body></html>
"""
