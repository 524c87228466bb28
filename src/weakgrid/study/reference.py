"""The study file's reference page and JSON Schema, rendered from :mod:`weakgrid.study.fields`
(the declarations the validator uses).

``weakgrid schema`` writes either (``--markdown`` for the page); the committed
``docs/study-file-reference.md`` and ``weakgrid/data/study.schema.json`` are these renderings,
and a test keeps them up to date.
"""

from __future__ import annotations

import json

from .fields import (EVENT_KINDS, GRID_KINDS, NO_DEFAULT, REQUIRED_TOP, TABLES, TOP, Field,
                     Said, Table, choices_of)

__all__ = ["json_schema", "reference_markdown", "schema_text", "SCHEMA_ID"]

SCHEMA_ID = "https://weakgrid.invalid/study.schema.json"


# ------------------------------------------------------------------------------ JSON Schema
def _field_schema(f: Field) -> dict:
    s = dict(f.schema)
    ch = choices_of(f)
    if ch and not f.more:
        if s.get("type") == "array":
            s["items"] = {**s.get("items", {}), "enum": list(ch)}
        else:
            s["enum"] = list(ch)
    s["description"] = f.doc + (f" [{f.unit}]" if f.unit else "") + (
        f" One of {', '.join(ch)}, or {f.more}." if ch and f.more else "") + (
        f" Default: {f.default}." if isinstance(f.default, Said) else "")
    if f.default is not NO_DEFAULT and not isinstance(f.default, Said):
        s["default"] = f.default
    return s


def _object(t: Table, children: dict) -> dict:
    props = {f.name: _field_schema(f) for f in t.fields}
    for name, sub in children.items():
        props[name] = {**sub, "description": props.get(name, {}).get("description", "")}
    out = {"type": "object", "description": t.doc, "properties": props,
           "additionalProperties": t.extra if t.open else False}
    req = [f.name for f in t.fields if f.required]
    if req:
        out["required"] = req
    return out


def _table_schema(path: str) -> dict:
    """Schema of the table at ``path`` with its sub-tables (an array of tables as an array)."""
    t = TABLES[path]
    children = {}
    for sub in TABLES:
        head, _, name = sub.rpartition(".")
        if head == path:
            children[name] = _table_schema(sub)
    if path == "scenarios":
        children["events"] = {"type": "array", "items": {"oneOf": [
            _object(TABLES[f"events.{k}"], {}) for k in EVENT_KINDS]}}
    if path == "grid":       # grid kinds: the fields of other kinds are refused
        obj = _object(t, children)
        obj["allOf"] = [_grid_kind_rule(k) for k in GRID_KINDS]
    else:
        obj = _object(t, children)
    return {"type": "array", "items": obj} if t.array else obj


def _grid_kind_rule(kind: str) -> dict:
    t = TABLES["grid"]
    other = [f.name for f in t.fields if f.kinds and kind not in f.kinds]
    req = [f.name for f in t.fields if kind in f.required_for]
    then: dict = {}
    if other:
        then["not"] = {"anyOf": [{"required": [k]} for k in other]}
    if req:
        then["required"] = req
    return {"if": {"properties": {"kind": {"const": kind}}, "required": ["kind"]},
            "then": then}


def json_schema() -> dict:
    """The JSON Schema (draft 2020-12) of a study file read as TOML."""
    props = {}
    for name in TOP:
        props[name] = _table_schema(name)
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "$id": SCHEMA_ID,
            "title": "weakgrid study file",
            "description": "A weakgrid study (TOML). Generated from weakgrid.study.fields, the "
                           "declarations the validator uses; the validator also checks cross "
                           "references (buses, run ids, controllers) the schema cannot.",
            "type": "object", "properties": props, "required": list(REQUIRED_TOP),
            "additionalProperties": False}


def schema_text() -> str:
    """:func:`json_schema` as the text of ``study.schema.json``."""
    return json.dumps(json_schema(), indent=1, ensure_ascii=False) + "\n"


# ------------------------------------------------------------------------------ reference page
def _md(x) -> str:
    return str(x).replace("|", "\\|")


def _type_name(f: Field) -> str:
    s = f.schema
    if "const" in s:
        return f"`\"{s['const']}\"`"
    ty = s.get("type")
    names = {"string": "string", "number": "number", "integer": "integer", "boolean":
             "true/false", "object": "table", "array": "list"}
    if isinstance(ty, list):
        return " or ".join(names[t] for t in ty)
    if ty == "array" and "items" in s and "type" in s["items"]:
        return f"list of {names[s['items']['type']]}s"
    return names.get(ty, str(ty))


def _range(f: Field) -> str:
    s, out = f.schema, []
    for k, sym in (("minimum", "≥"), ("exclusiveMinimum", ">"), ("maximum", "≤"),
                   ("exclusiveMaximum", "<")):
        if k in s:
            out.append(f"{sym} {s[k]:g}")
    return ", ".join(out)


def _default(f: Field) -> str:
    if f.required:
        return "**required**"
    if f.required_for:
        return f"**required** ({', '.join(f.required_for)})"
    if f.default is NO_DEFAULT:
        return "—"
    if isinstance(f.default, Said):
        return str(f.default)
    return f"`{json.dumps(f.default, ensure_ascii=False)}`"


def _allowed(f: Field) -> str:
    ch = choices_of(f)
    parts = [", ".join(f"`{c}`" for c in ch) + (f", or {f.more}" if f.more else "")] if ch \
        else []
    if _range(f):
        parts.append(_range(f))
    return "; ".join(parts) or "—"


def _table_md(t: Table) -> list[str]:
    head = f"[[{t.path}]]" if t.array else f"[{t.path}]"
    if t.path.startswith("events."):
        head = f"event `kind = \"{t.path.split('.')[1]}\"` (in `events = [...]`)"
    elif t.path == "scenarios.quick":
        head = "scenarios: quick = {...}"
    else:
        head = f"`{head}`"
    out = [f"## {head}", "", t.doc, ""]
    grid = t.path == "grid"
    cols = ["field", "type", "unit", "default", "allowed values"] + (["grid kinds"] if grid
                                                                       else []) + ["meaning"]
    out += ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for f in t.fields:
        row = [f"`{f.name}`", _type_name(f), f.unit or "—", _default(f), _allowed(f)]
        if grid:
            row.append(", ".join(f.kinds) if f.kinds else "every")
        row.append(f.doc)
        out.append("| " + " | ".join(_md(c) for c in row) + " |")
    if t.open:
        out += ["", "Other keys are accepted here (see above)."]
    if t.example:
        # an inline table (an event) is not a TOML document: shown as the list it goes in
        ex = f"events = [{t.example}]" if t.example.lstrip().startswith("{") else t.example
        out += ["", "Example:", "", "```toml", ex, "```"]
    return out + [""]


def reference_markdown() -> str:
    """The study-file reference page (MyST markdown)."""
    out = ["# Study file reference", "",
           "<!-- generated by `weakgrid schema --markdown -o docs/study-file-reference.md` "
           "from weakgrid.study.fields; do not edit: tests/study/test_study_reference.py "
           "checks it is up to date -->", "",
           "A study is a TOML file of the tables below (the shipped studies, "
           "`weakgrid run --list`, are complete commented examples: "
           "`src/weakgrid/data/studies/*.toml`). Every table and field is listed with its "
           "type, unit, default and allowed values, from the declarations the validator "
           "itself uses (`weakgrid.study.fields`). The validator also checks what a table "
           "cannot say: buses, branches and machines of the grid, run ids, controllers among "
           "`controllers.compare`, a fault's `t_on < t_off ≤ t_end`; each error names the "
           "field, the value and the fix.", "",
           "**JSON Schema.** `weakgrid schema -o study.schema.json` writes the schema "
           "(also shipped as `weakgrid/data/study.schema.json` in the package). Editors "
           "that check TOML against a JSON Schema (e.g. Taplo / Even Better TOML) take it "
           "with a first line `#:schema ./study.schema.json` in the study file.", "",
           "Required tables: " + ", ".join(f"`[{t}]`" for t in REQUIRED_TOP) + ".", ""]
    order = [p for top in TOP for p in TABLES if p == top or p.startswith(top + ".")]
    order = [p for p in order if p != "scenarios.quick"]
    ev_at = order.index("scenarios") + 1
    order[ev_at:ev_at] = ["scenarios.quick"] + [f"events.{k}" for k in EVENT_KINDS]
    for p in order:
        out += _table_md(TABLES[p])
    return "\n".join(out).rstrip() + "\n"
