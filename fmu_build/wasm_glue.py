"""Generate the canonical-ABI glue of a WebAssembly component (wit_glue.h/.c) from its WIT world.

There is no wit-bindgen here, so this writes what it would for C, for the types FMI-LS-WASM's
interfaces use: each function a world exports becomes a core export under the name
`wasm-tools component new` expects, which lifts its flat arguments into C values, calls a C
function of the same name (`fmi3_wit_<function>`, declared in wit_glue.h, written by hand in
fmu_src/wasm/fmi3_wit.c), and lowers what it returns; its `cabi_post_` export frees what the result
holds, and the arguments' memory, which the host allocated through cabi_realloc, is freed after
the call. Each imported function gets a C wrapper that flattens its arguments. A resource's
methods of both interfaces call one C function, so Co-Simulation and Model Exchange share the
adapter's code. The C types mirror the canonical ABI's memory layout (natural alignment on wasm32,
as the Component Model lays out records, variants and lists), so results are written as structs.

Input: the world's WIT as `wasm-tools component wit --json <dir>` prints it. It needs nothing but
Python's standard library: CMake runs it at build time
(`python fmu_build/wasm_glue.py <wit.json> <world> <out_dir>`).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

GENERATED_GLUE = ("wit_glue.h", "wit_glue.c")
# The Component Model passes at most this many flat values as parameters (else through memory).
MAX_FLAT_PARAMS = 16
_PRIMITIVES = {
    "bool": ("bool", "int32_t"),
    "u8": ("uint8_t", "int32_t"),
    "s8": ("int8_t", "int32_t"),
    "u16": ("uint16_t", "int32_t"),
    "s16": ("int16_t", "int32_t"),
    "u32": ("uint32_t", "int32_t"),
    "s32": ("int32_t", "int32_t"),
    "u64": ("uint64_t", "int64_t"),
    "s64": ("int64_t", "int64_t"),
    "f32": ("float", "float"),
    "f64": ("double", "double"),
}


class WitGlueError(ValueError):
    """A WIT world the glue cannot be generated for; the message says which function and why."""


def c_name(name: str) -> str:
    """A WIT name (kebab-case) as a C identifier."""
    return name.replace("-", "_").replace(".", "_")


class _Types:
    """The C type of each WIT type of a resolved WIT document, with its typedefs in order."""

    def __init__(self, document: dict):
        self.types = document["types"]
        self.typedefs: list[str] = []
        self.done: dict[str, str] = {}

    def resolve(self, ref):
        """A type reference with its aliases followed: a primitive's name or a type's entry."""
        while isinstance(ref, int):
            kind = self.types[ref]["kind"]
            if isinstance(kind, dict) and "type" in kind:
                ref = kind["type"]
            else:
                return self.types[ref]
        return ref

    def flat_count(self, ref) -> int:
        """How many core values the type flattens to."""
        entry = self.resolve(ref)
        if isinstance(entry, str):
            return 2 if entry == "string" else 1
        kind = entry["kind"]
        if "list" in kind:
            return 2
        if "record" in kind:
            return sum(self.flat_count(field["type"]) for field in kind["record"]["fields"])
        if "tuple" in kind:
            return sum(self.flat_count(part) for part in kind["tuple"]["types"])
        if "option" in kind:
            return 1 + self.flat_count(kind["option"])
        if "result" in kind:
            cases = [kind["result"][case] for case in ("ok", "err") if kind["result"][case] is not None]
            return 1 + max((self.flat_count(case) for case in cases), default=0)
        return 1  # enum, handle

    def c_type(self, ref) -> str:
        """The C type of a WIT type, its typedef (and those of its parts) added once."""
        entry = self.resolve(ref)
        if isinstance(entry, str):
            if entry == "string":
                return self._define("wit_string_t", "typedef struct { uint8_t *ptr; size_t len; } wit_string_t;")
            return _PRIMITIVES[entry][0]
        kind = entry["kind"]
        if "enum" in kind:
            return "uint8_t"
        if "handle" in kind:
            return "int32_t"
        if "record" in kind:
            fields = " ".join(f"{self.c_type(f['type'])} {c_name(f['name'])};" for f in kind["record"]["fields"])
            name = f"wit_{c_name(entry['name'])}_t"
            return self._define(name, f"typedef struct {{ {fields} }} {name};")
        if "list" in kind:
            element = self.c_type(kind["list"])
            name = f"wit_list_{_stem(element)}_t"
            return self._define(name, f"typedef struct {{ {element} *ptr; size_t len; }} {name};")
        if "tuple" in kind:
            parts = [self.c_type(part) for part in kind["tuple"]["types"]]
            name = f"wit_tuple_{'_'.join(map(_stem, parts))}_t"
            fields = " ".join(f"{part} f{index};" for index, part in enumerate(parts))
            return self._define(name, f"typedef struct {{ {fields} }} {name};")
        if "option" in kind:
            value = self.c_type(kind["option"])
            name = f"wit_option_{_stem(value)}_t"
            return self._define(name, f"typedef struct {{ bool is_some; {value} val; }} {name};")
        if "result" in kind:
            if None in (kind["result"]["ok"], kind["result"]["err"]):
                raise WitGlueError("a result without an ok or an err type: the glue has no C type for it")
            ok, err = (self.c_type(kind["result"][case]) for case in ("ok", "err"))
            name = f"wit_result_{_stem(ok)}_{_stem(err)}_t"
            body = f"typedef struct {{ bool is_err; union {{ {ok} ok; {err} err; }} val; }} {name};"
            return self._define(name, body)
        raise WitGlueError(f"WIT type {entry.get('name') or kind}: the glue has no C type for it")

    def _define(self, name: str, typedef: str) -> str:
        if name not in self.done:
            self.done[name] = typedef
            self.typedefs.append(typedef)
        return name

    def free(self, ref, value: str) -> list[str]:
        """C statements that free what the value of a WIT type owns (nothing for plain data)."""
        entry = self.resolve(ref)
        if isinstance(entry, str):
            return [f"if ({value}.len) free({value}.ptr);"] if entry == "string" else []
        kind = entry["kind"]
        if "list" in kind:
            inner = self.free(kind["list"], f"{value}.ptr[i]")
            loop = [f"for (size_t i = 0; i < {value}.len; i++) {{ {' '.join(inner)} }}"] if inner else []
            return [*loop, f"if ({value}.len) free({value}.ptr);"]
        if "option" in kind:
            inner = self.free(kind["option"], f"{value}.val")
            return [f"if ({value}.is_some) {{ {' '.join(inner)} }}"] if inner else []
        if "result" in kind:
            inner = self.free(kind["result"]["ok"], f"{value}.val.ok") if kind["result"]["ok"] is not None else []
            return [f"if (!{value}.is_err) {{ {' '.join(inner)} }}"] if inner else []
        parts = (
            [f["type"] for f in kind["record"]["fields"]]
            if "record" in kind
            else kind.get("tuple", {}).get("types", [])
        )
        if any(self.free(part, "part") for part in parts):
            raise WitGlueError(f"WIT type {entry.get('name') or kind}: the glue frees no records holding memory")
        return []


def _stem(c_type: str) -> str:
    """A C type's name as a part of another type's name: wit_string_t -> string."""
    return c_type.removeprefix("wit_").removesuffix("_t")


def _lift_param(types: _Types, name: str, ref) -> tuple[list[str], str]:
    """The flat core parameters of one WIT parameter and the C expression that lifts them."""
    entry = types.resolve(ref)
    c = c_name(name)
    if isinstance(entry, str) and entry != "string":
        core = _PRIMITIVES[entry][1]
        lifted = f"({c} != 0)" if entry == "bool" else f"({_PRIMITIVES[entry][0]}){c}"
        return [f"{core} {c}"], lifted
    kind = {} if isinstance(entry, str) else entry["kind"]
    if entry == "string" or "list" in kind:
        c_type = types.c_type(ref)
        element = types.c_type(kind["list"]) if "list" in kind else "uint8_t"
        return [f"int32_t {c}_ptr", f"int32_t {c}_len"], f"({c_type}){{({element} *){c}_ptr, (size_t){c}_len}}"
    if "option" in kind and isinstance(types.resolve(kind["option"]), str):
        value = types.resolve(kind["option"])
        core, c_value = _PRIMITIVES[value][1], _PRIMITIVES[value][0]
        lifted = f"({types.c_type(ref)}){{{c}_is_some != 0, ({c_value}){c}_value}}"
        return [f"int32_t {c}_is_some", f"{core} {c}_value"], lifted
    if "enum" in kind:
        return [f"int32_t {c}"], f"(uint8_t){c}"
    if "handle" in kind:
        return [f"int32_t {c}"], f"(WitInstance *)(uintptr_t){c}"
    raise WitGlueError(f"parameter {name}: the glue lifts no parameter of this WIT type")


def _export_name(function: str) -> str:
    """The C adapter's name of an exported function: a method's or static's without its resource."""
    return "fmi3_wit_" + c_name(function.split("]", 1)[-1].split(".")[-1])


class _Glue:
    """The header's and the source's lines, filled in function by function."""

    def __init__(self, document: dict):
        self.document = document
        self.types = _Types(document)
        self.prototypes: dict[str, str] = {}
        self.declarations: list[str] = []
        self.source: list[str] = []

    def interface_name(self, interface_id: int) -> str:
        """The interface's full name: fmi:fmi3/co-simulation@3.0.0."""
        interface = self.document["interfaces"][interface_id]
        package = self.document["packages"][interface["package"]]["name"]
        namespace, _, version = package.partition("@")
        return f"{namespace}/{interface['name']}" + (f"@{version}" if version else "")

    def prototype(self, name: str, returns: str, params: list[str]) -> None:
        """Declare the adapter function name once; the same name must mean the same signature."""
        text = f"{returns} {name}({', '.join(params) or 'void'});"
        if self.prototypes.setdefault(name, text) != text:
            raise WitGlueError(f"{name}: two exported functions of this name differ:\n{self.prototypes[name]}\n{text}")

    def export_function(self, interface: str, function: dict) -> None:
        """The core export of one function: lift, call the adapter, lower, free; its cabi_post_."""
        export = f"{interface}#{function['name']}"
        adapter = _export_name(function["name"])
        core_params, arguments, frees, c_params, locals_ = [], [], [], [], []
        for param in function["params"]:
            flat, lifted = _lift_param(self.types, param["name"], param["type"])
            core_params += flat
            local = f"arg_{c_name(param['name'])}"
            c_type = "WitInstance *" if "WitInstance" in lifted else self.types.c_type(param["type"])
            c_params.append(f"{c_type} {c_name(param['name'])}")
            locals_.append(f"    {c_type} {local} = {lifted};")
            arguments.append(local)
            frees += self.types.free(param["type"], local)
        if len(core_params) > MAX_FLAT_PARAMS:
            raise WitGlueError(
                f"{export}: {len(core_params)} flat parameters, the glue passes at most {MAX_FLAT_PARAMS}"
            )
        result = function.get("result")
        symbol = f"fmi3_wit_export_{c_name(interface.split('/')[-1].split('@')[0])}_{adapter.removeprefix('fmi3_wit_')}"
        body = [f'__attribute__((export_name("{export}")))']
        if result is None:
            self.prototype(adapter, "void", c_params)
            body += [f"void {symbol}({', '.join(core_params) or 'void'}) {{", *locals_]
            body += [f"    {adapter}({', '.join(arguments)});", *(f"    {f}" for f in frees), "}"]
        elif self.types.flat_count(result) == 1:
            c_result = self.types.c_type(result)
            self.prototype(adapter, c_result, c_params)
            body += [f"int32_t {symbol}({', '.join(core_params) or 'void'}) {{", *locals_]
            body += [f"    const {c_result} result = {adapter}({', '.join(arguments)});"]
            body += [*(f"    {f}" for f in frees), "    return (int32_t)result;", "}"]
        else:
            c_result = self.types.c_type(result)
            self.prototype(adapter, "void", [*c_params, f"{c_result} *ret"])
            body += [f"int32_t {symbol}({', '.join(core_params) or 'void'}) {{", f"    static {c_result} ret;"]
            body += [*locals_, f"    {adapter}({', '.join([*arguments, '&ret'])});"]
            body += [*(f"    {f}" for f in frees), "    return (int32_t)(uintptr_t)&ret;", "}"]
            post = self.types.free(result, "(*value)")
            if post:
                body += [f'__attribute__((export_name("cabi_post_{export}")))']
                body += [
                    f"void {symbol}_post(int32_t ret) {{",
                    f"    {c_result} *value = ({c_result} *)(uintptr_t)ret;",
                ]
                body += [*(f"    {f}" for f in post), "}"]
        self.source += ["", *body]

    def export_resource(self, interface: str, resource: str) -> None:
        """A resource's destructor export and its resource-new import."""
        name = c_name(resource)
        self.prototype(f"fmi3_wit_drop_{name}", "void", ["WitInstance *self"])
        self.declarations += [
            f"/* The handle the host gets for a new {resource} whose representation is rep. */",
            f'__attribute__((import_module("[export]{interface}"), import_name("[resource-new]{resource}")))',
            f"int32_t fmi3_wit_new_{name}(int32_t rep);",
        ]
        self.source += [
            "",
            f'__attribute__((export_name("{interface}#[dtor]{resource}")))',
            f"void fmi3_wit_export_dtor_{name}(int32_t rep) {{ fmi3_wit_drop_{name}((WitInstance *)(uintptr_t)rep); }}",
        ]

    def import_function(self, interface: str, function: dict) -> None:
        """A C wrapper that flattens an imported function's arguments and calls the import."""
        if function.get("result") is not None:
            raise WitGlueError(f"{interface}#{function['name']}: the glue imports no functions with results")
        c_params, core_params, flat_arguments = [], [], []
        for param in function["params"]:
            c, c_type = c_name(param["name"]), self.types.c_type(param["type"])
            c_params.append(f"{c_type} {c}")
            if c_type == "wit_string_t":
                core_params += ["int32_t", "int32_t"]
                flat_arguments += [f"(int32_t)(uintptr_t){c}.ptr", f"(int32_t){c}.len"]
            elif self.types.flat_count(param["type"]) == 1 and not c_type.startswith("wit_"):
                core = "int32_t" if c_type not in ("double", "float", "int64_t", "uint64_t") else c_type
                core_params.append(core.replace("uint64_t", "int64_t"))
                flat_arguments.append(f"({core_params[-1]}){c}")
            else:
                raise WitGlueError(f"{interface}#{function['name']}: the glue lowers no {c_type} argument")
        raw = f"fmi3_wit_import_{c_name(function['name'])}"
        self.declarations += [
            f'__attribute__((import_module("{interface}"), import_name("{function["name"]}")))',
            f"void {raw}({', '.join(core_params) or 'void'});",
            f"static inline void fmi3_wit_{c_name(function['name'])}({', '.join(c_params) or 'void'}) {{",
            f"    {raw}({', '.join(flat_arguments)});",
            "}",
        ]


_HEADER_START = """/* Generated by fmu_build/wasm_glue.py from the component's WIT world: do not edit. The canonical
   ABI's glue (wit_glue.c) calls the fmi3_wit_* functions declared here, which the adapter defines. */
#ifndef WIT_GLUE_H
#define WIT_GLUE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The representation of every resource: the adapter's own instance. */
typedef struct WitInstance WitInstance;
"""

_SOURCE_START = """/* Generated by fmu_build/wasm_glue.py from the component's WIT world: do not edit. */
#include <stdlib.h>

#include "wit_glue.h"

/* How the host allocates the arguments it passes in the module's memory (the Component Model's
   cabi_realloc): out of memory traps, as the canonical ABI has no way to report it. */
__attribute__((export_name("cabi_realloc")))
void *cabi_realloc(void *ptr, size_t old_size, size_t align, size_t new_size) {
    (void)old_size;
    if (new_size == 0) return (void *)align;
    void *memory = realloc(ptr, new_size);
    if (!memory) abort();
    return memory;
}"""


def generate_glue(wit_json: str | Path, world: str, out_dir: str | Path) -> list[Path]:
    """Write wit_glue.h and wit_glue.c for a world of a resolved WIT document.

    Parameters
    ----------
    wit_json : str or Path
        The document as `wasm-tools component wit --json <dir>` prints it.
    world : str
        The world's name in it (the component's: its imports and exports).
    out_dir : str or Path
        The folder to write the two files into (made if missing).

    Returns
    -------
    list of Path
        wit_glue.h and wit_glue.c.

    Raises
    ------
    WitGlueError
        When the world is missing, or a function uses a type the glue does not handle.
    """
    document = json.loads(Path(wit_json).read_text(encoding="utf-8"))
    worlds = {entry["name"]: entry for entry in document["worlds"]}
    if world not in worlds:
        raise WitGlueError(f"{wit_json}: no world {world!r} (it has {', '.join(worlds)})")
    glue = _Glue(document)
    for item in worlds[world]["imports"].values():
        interface_id = item.get("interface", {}).get("id")
        if interface_id is None:
            continue  # a type the world uses, imported with its interface
        for function in document["interfaces"][interface_id]["functions"].values():
            glue.import_function(glue.interface_name(interface_id), function)
    for item in worlds[world]["exports"].values():
        interface_id = item["interface"]["id"]
        name = glue.interface_name(interface_id)
        for function in document["interfaces"][interface_id]["functions"].values():
            glue.export_function(name, function)
        for type_name, type_id in document["interfaces"][interface_id]["types"].items():
            if document["types"][type_id]["kind"] == "resource":
                glue.export_resource(name, type_name)
    header = [_HEADER_START, *glue.types.typedefs, "", *glue.declarations, "", *glue.prototypes.values()]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = [out / GENERATED_GLUE[0], out / GENERATED_GLUE[1]]
    written[0].write_text("\n".join([*header, "", "#endif", ""]), encoding="utf-8")
    written[1].write_text("\n".join([_SOURCE_START, *glue.source, ""]), encoding="utf-8")
    return written


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit("usage: wasm_glue.py <wit.json> <world> <out_dir>")
    try:
        generate_glue(sys.argv[1], sys.argv[2], sys.argv[3])
    except (OSError, ValueError, KeyError) as error:
        sys.exit(f"wasm_glue.py: {error}")
