"""Every public function and class has a docstring; every CLI option has a help text.

Walks every public module of the package (``weakgrid.*`` without a ``_``-prefixed
component): the names in its ``__all__`` or, without one, the public functions and
classes defined in it; and every argument of every ``weakgrid`` subcommand parser.
The API and CLI reference pages of the documentation are generated from these texts.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import pkgutil

import pytest

import weakgrid
from weakgrid.cli.main import build_parser


def public_modules() -> list[str]:
    """Names of the importable public modules of :mod:`weakgrid`."""
    names = ["weakgrid"]
    for info in pkgutil.walk_packages(weakgrid.__path__, "weakgrid."):
        if not any(part.startswith("_") for part in info.name.split(".")[1:]):
            names.append(info.name)
    return sorted(names)


def public_objects(modname: str):
    """``(qualified name, object)`` of the public functions/classes defined in a module."""
    mod = importlib.import_module(modname)
    names = getattr(mod, "__all__", None)
    if names is None:
        names = [n for n in vars(mod) if not n.startswith("_")]
    for name in names:
        obj = getattr(mod, name)
        if (inspect.isfunction(obj) or inspect.isclass(obj)) and obj.__module__ == modname:
            yield f"{modname}.{name}", obj


def parser_arguments(parser: argparse.ArgumentParser, path: str):
    """``(command path, argument, help)`` of every argument, subcommands included."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:          # the subcommands' one-line help
                yield path, choice.dest, choice.help
            for name, sub in action.choices.items():
                yield from parser_arguments(sub, f"{path} {name}")
        else:
            yield path, "/".join(action.option_strings) or action.dest, action.help


MODULES = public_modules()


def test_walk_finds_the_package():
    """The walk is not vacuous: it reaches every layer and many objects."""
    for layer in ("weakgrid.game", "weakgrid.models", "weakgrid.sim.system", "weakgrid.study",
                  "weakgrid.cli.main"):
        assert layer in MODULES
    assert sum(1 for m in MODULES for _ in public_objects(m)) > 150


@pytest.mark.parametrize("modname", MODULES)
def test_module_has_docstring(modname):
    assert inspect.getdoc(importlib.import_module(modname)), f"module {modname} has no docstring"


@pytest.mark.parametrize("modname", MODULES)
def test_public_objects_have_docstrings(modname):
    missing = [q for q, obj in public_objects(modname) if not inspect.getdoc(obj)]
    assert not missing, f"public objects without a docstring: {', '.join(missing)}"


def test_cli_options_have_help():
    missing = [f"{path}: {arg}" for path, arg, text in parser_arguments(build_parser(), "weakgrid")
               if not text or text == argparse.SUPPRESS]
    assert not missing, "CLI arguments without help: " + "; ".join(missing)


def test_cli_walk_reaches_every_subcommand():
    seen = {path for path, _, _ in parser_arguments(build_parser(), "weakgrid")}
    for cmd in ("train", "gamma", "verify", "export", "simulate", "reproduce"):
        assert f"weakgrid {cmd}" in seen
