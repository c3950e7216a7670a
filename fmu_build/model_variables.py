"""Generate a model's C variables (model_variables.h/.c) from its FMI 2.0 modelDescription.xml.

The XML is the single source of truth for the value references, names, causalities and start
values the C code uses. This file needs nothing but Python's standard library, so that CMake runs
it at build time (CMakeLists.txt: `python fmu_build/model_variables.py <xml> <out_dir>`) with no
package installed; fmu_build imports the same function for the FMU's sources/.
"""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from pathlib import Path

GENERATED_SOURCES = ("model_variables.h", "model_variables.c")
# FMI 2.0's default of `initial` where a variable leaves it out, by variability and causality
# (the standard's section 2.2.7); the combinations missing here have none.
DEFAULT_INITIAL = {
    ("constant", "output"): "exact",
    ("constant", "local"): "exact",
    ("fixed", "parameter"): "exact",
    ("fixed", "calculatedParameter"): "calculated",
    ("fixed", "local"): "calculated",
    ("tunable", "parameter"): "exact",
    ("tunable", "calculatedParameter"): "calculated",
    ("tunable", "local"): "calculated",
    ("discrete", "input"): "exact",
    ("discrete", "output"): "calculated",
    ("discrete", "local"): "calculated",
    ("continuous", "input"): "exact",
    ("continuous", "output"): "calculated",
    ("continuous", "local"): "calculated",
}


class ModelDescriptionError(ValueError):
    """A model description the C code cannot be generated from; the message says why."""


def generate_variables(xml: str | Path, out_dir: str | Path) -> list[Path]:
    """Write model_variables.h and model_variables.c from an FMI 2.0 model description.

    The header holds the GUID, the value references' enum and the inputs; the source the table of
    variables.

    Parameters
    ----------
    xml : str or Path
        The model's FMI 2.0 modelDescription.xml.
    out_dir : str or Path
        The folder to write the two files into (made if missing).

    Returns
    -------
    list of Path
        model_variables.h and model_variables.c.

    Raises
    ------
    ModelDescriptionError
        A variable that is neither Real nor a String parameter, or a Real whose value reference
        is not its index: the C code indexes one array of Reals by value reference.

    Examples
    --------
    >>> generate_variables("modelDescription.xml", "build/generated")  # doctest: +SKIP
    [PosixPath('build/generated/model_variables.h'), PosixPath('build/generated/model_variables.c')]
    """
    root = ET.parse(xml).getroot()
    variables, strings = [], []
    for element in root.iter("ScalarVariable"):
        index = len(variables)
        if element.find("String") is not None and element.get("causality") == "parameter":
            # A String parameter the C code keeps by itself (instance.c: callRecordFile).
            strings.append(f"#define VR_{element.get('name').upper()} {int(element.get('valueReference'))}")
            continue
        real = element.find("Real")
        if real is None or int(element.get("valueReference")) != index:
            raise ModelDescriptionError(
                f"{xml}: variable {element.get('name')!r} must be Real with valueReference {index}, "
                "or a String parameter: the C code indexes one array of Reals by value reference"
            )
        causality = element.get("causality", "local")
        variability = element.get("variability", "continuous")
        variables.append(
            {
                "name": element.get("name"),
                "reference": index,
                "causality": causality,
                "variability": variability,
                "start": real.get("start"),
                "initial": element.get("initial", DEFAULT_INITIAL.get((variability, causality))),
            }
        )
    enum = ",\n".join(f"    VR_{v['name'].upper()} = {v['reference']}" for v in variables)
    inputs = ", ".join(f"VR_{v['name'].upper()}" for v in variables if v["causality"] == "input")
    header = f"""/* Generated from modelDescription.xml by fmu_build/model_variables.py: edit the XML, not this. */
#ifndef MODEL_VARIABLES_H
#define MODEL_VARIABLES_H

#include "variable.h"

#define MODEL_GUID "{root.get("guid")}"
#define N_VARIABLES {len(variables)}
/* Every variable's value reference, String parameters included, is below this. */
#define N_VALUE_REFERENCES {len(variables) + len(strings)}
/* The inputs' value references: a step updates these, without a pass over every variable. */
#define N_INPUTS {sum(v["causality"] == "input" for v in variables)}
#define INPUT_REFERENCES {{{inputs}}}

typedef enum {{
{enum}
}} ValueReference;
/* String parameters, outside the Reals' array. */
{chr(10).join(strings)}

extern const VariableInfo model_variables[N_VARIABLES];

#endif
"""
    rows = ",\n".join(
        f'    {{"{v["name"]}", CAUSALITY_{_enum_name(v["causality"])}, VARIABILITY_{v["variability"].upper()}, '
        f"INITIAL_{(v['initial'] or 'none').upper()}, {float(v['start'] or 0.0)!r}}}"
        for v in variables
    )
    table = f"""/* Generated from modelDescription.xml by fmu_build/model_variables.py: edit the XML, not this. */
#include "model_variables.h"

const VariableInfo model_variables[N_VARIABLES] = {{
{rows}
}};
"""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = [out_dir / name for name in GENERATED_SOURCES]
    for path, text in zip(paths, (header, table), strict=True):
        # Written only when changed, so that CMake recompiles only what a change of the XML touches.
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)
    return paths


def _enum_name(causality: str) -> str:
    return "CALCULATED_PARAMETER" if causality == "calculatedParameter" else causality.upper()


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(f"usage: {sys.argv[0]} MODEL_DESCRIPTION_XML OUT_DIR")
    try:
        generate_variables(sys.argv[1], sys.argv[2])
    except (OSError, ET.ParseError, ModelDescriptionError) as error:
        sys.exit(f"{sys.argv[0]}: {error}")
