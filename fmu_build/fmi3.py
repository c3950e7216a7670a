"""The FMI 3.0 model description and build description, generated from the FMI 2.0
modelDescription.xml (the single source of truth for the variables).

What changes between the standards is only how the same facts are written: `guid` becomes
`instantiationToken`, each `<ScalarVariable><Real/>` a `<Float64>`, the independent variable
`time` is declared (value reference after the model's, as fmu_src/src/fmi3_functions.c expects),
references by index (derivative, dependencies) become references by value reference, and the
capability flags take their FMI 3.0 names. The sources' list moves to sources/buildDescription.xml.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

# FMI version -> the C file of its entry points: a build compiles its own version's and leaves
# out the other's.
ADAPTERS = {2: "fmi2_functions.c", 3: "fmi3_functions.c"}
FMI2_ADAPTER = ADAPTERS[2]
# Capabilities both interfaces declare (FMI 2.0 name -> FMI 3.0 name).
_COMMON_FLAGS = {
    "needsExecutionTool": "needsExecutionTool",
    "canBeInstantiatedOnlyOncePerProcess": "canBeInstantiatedOnlyOncePerProcess",
    "canGetAndSetFMUstate": "canGetAndSetFMUState",
    "canSerializeFMUstate": "canSerializeFMUState",
    "providesDirectionalDerivative": "providesDirectionalDerivatives",
}


def adapter_left_out(fmi_version: int) -> str:
    """The entry-point file of the other standard, which a build for fmi_version leaves out."""
    return ADAPTERS[3 if fmi_version == 2 else 2]


def with_adapter(fmi2_sources, fmi_version: int) -> list[str]:
    """The C files of the build for fmi_version: the FMI 2.0 list (as modelDescription.xml's
    <SourceFiles> gives it) with fmi_version's adapter in place of the FMI 2.0 one.
    """
    return [ADAPTERS[fmi_version] if name == FMI2_ADAPTER else name for name in fmi2_sources]


def source_files(fmi2_root: ET.Element) -> list[str]:
    """The C files of the FMI 3.0 build: the FMI 2.0 list with the adapter swapped."""
    listed = [f.get("name") for f in fmi2_root.find("CoSimulation/SourceFiles").iter("File")]
    return with_adapter(listed, 3)


def _interface(fmi2_root: ET.Element, tag: str) -> dict[str, str] | None:
    element = fmi2_root.find(tag)
    if element is None:
        return None
    attributes = {"modelIdentifier": element.get("modelIdentifier")}
    for fmi2_name, fmi3_name in _COMMON_FLAGS.items():
        if element.get(fmi2_name) is not None:
            attributes[fmi3_name] = element.get(fmi2_name)
    # The adjoint is the transpose of the same analytic Jacobian (fmi3GetAdjointDerivative).
    attributes["providesAdjointDerivatives"] = attributes.get("providesDirectionalDerivatives", "false")
    if tag == "ModelExchange":
        attributes["needsCompletedIntegratorStep"] = str(
            element.get("completedIntegratorStepNotNeeded") != "true"
        ).lower()
    else:
        attributes["canHandleVariableCommunicationStepSize"] = element.get(
            "canHandleVariableCommunicationStepSize", "false"
        )
        attributes["maxOutputDerivativeOrder"] = element.get("maxOutputDerivativeOrder", "0")
        # Event mode, early return and intermediate update have nothing to do in the pendulum.
        attributes["hasEventMode"] = "false"
    return attributes


def _add_variables(root: ET.Element, variables: list, references: dict, time_reference: str, fmi2_xml) -> None:
    """ModelVariables: `time`, then each FMI 2.0 variable as Float64 or String."""
    model_variables = ET.SubElement(root, "ModelVariables")
    ET.SubElement(
        model_variables,
        "Float64",
        {
            "name": "time",
            "valueReference": time_reference,
            "causality": "independent",
            "variability": "continuous",
            "description": "Simulation time",
            "unit": "s",
        },
    )
    for variable in variables:
        attributes = {
            key: variable.get(key)
            for key in ("name", "valueReference", "causality", "variability", "initial", "description")
            if variable.get(key) is not None
        }
        string = variable.find("String")
        if string is not None:
            # FMI 3.0 gives a String's start value as an element.
            start = string.get("start")
            element = ET.SubElement(model_variables, "String", attributes)
            if start is not None:
                ET.SubElement(element, "Start", {"value": start})
            continue
        real = variable.find("Real")
        if real is None:
            raise ValueError(f"{fmi2_xml}: variable {variable.get('name')!r} is neither Real nor String")
        attributes.update(real.attrib)
        if "derivative" in attributes:
            attributes["derivative"] = references[attributes["derivative"]]
        ET.SubElement(model_variables, "Float64", attributes)


def _add_structure(root: ET.Element, fmi2_structure: ET.Element, references: dict) -> None:
    """ModelStructure: FMI 2.0's unknowns by index become FMI 3.0's by value reference."""
    structure = ET.SubElement(root, "ModelStructure")
    for fmi2_tag, fmi3_tag in (
        ("Outputs", "Output"),
        ("Derivatives", "ContinuousStateDerivative"),
        ("InitialUnknowns", "InitialUnknown"),
    ):
        for unknown in fmi2_structure.findall(f"{fmi2_tag}/Unknown"):
            attributes = {"valueReference": references[unknown.get("index")]}
            if unknown.get("dependencies") is not None:
                attributes["dependencies"] = " ".join(
                    references[index] for index in unknown.get("dependencies").split()
                )
            if unknown.get("dependenciesKind") is not None:
                attributes["dependenciesKind"] = unknown.get("dependenciesKind")
            ET.SubElement(structure, fmi3_tag, attributes)


def model_description(fmi2_xml: str | Path) -> str:
    """The FMI 3.0 modelDescription.xml for the FMU that fmi2_xml describes."""
    fmi2 = ET.parse(fmi2_xml).getroot()
    variables = fmi2.find("ModelVariables").findall("ScalarVariable")
    references = {str(index): v.get("valueReference") for index, v in enumerate(variables, start=1)}
    time_reference = str(len(variables))
    if time_reference in references.values():
        raise ValueError(
            f"{fmi2_xml}: value references must be 0..{len(variables) - 1}, one per "
            "variable, so that `time` can take the next one"
        )

    root = ET.Element(
        "fmiModelDescription",
        {
            "fmiVersion": "3.0",
            "modelName": fmi2.get("modelName"),
            "description": fmi2.get("description", ""),
            "instantiationToken": fmi2.get("guid"),
            "generationTool": fmi2.get("generationTool", ""),
            "variableNamingConvention": fmi2.get("variableNamingConvention", "flat"),
        },
    )
    for tag in ("ModelExchange", "CoSimulation"):
        attributes = _interface(fmi2, tag)
        if attributes:
            ET.SubElement(root, tag, attributes)

    units = ET.SubElement(root, "UnitDefinitions")
    ET.SubElement(ET.SubElement(units, "Unit", {"name": "s"}), "BaseUnit", {"s": "1"})
    fmi2_units = fmi2.find("UnitDefinitions")
    units.extend(fmi2_units if fmi2_units is not None else [])
    for tag in ("LogCategories", "DefaultExperiment"):
        element = fmi2.find(tag)
        if element is not None:
            root.append(element)

    _add_variables(root, variables, references, time_reference, fmi2_xml)
    _add_structure(root, fmi2.find("ModelStructure"), references)

    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def build_description(fmi2_xml: str | Path) -> str:
    """sources/buildDescription.xml: what a tool compiles to rebuild the FMU."""
    fmi2 = ET.parse(fmi2_xml).getroot()
    root = ET.Element("fmiBuildDescription", {"fmiVersion": "3.0"})
    configuration = ET.SubElement(
        root, "BuildConfiguration", {"modelIdentifier": fmi2.find("CoSimulation").get("modelIdentifier")}
    )
    file_set = ET.SubElement(configuration, "SourceFileSet", {"language": "C99"})
    for name in source_files(fmi2):
        ET.SubElement(file_set, "SourceFile", {"name": name})
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
