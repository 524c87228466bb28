"""Arguments shared by the study subcommands (a study file or a shipped study's name, and
``--set DOTTED.FIELD=VALUE`` overrides of its fields)."""

from __future__ import annotations

import argparse

SET_HELP = ("override a field of the study after reading it and before validation: a dotted "
            "path (a list element by its id, e.g. scenarios.<id>.t_end) = a TOML value "
            "(0.3, true, [1, 2], \"text\"; a bare word is taken as a string); repeatable")


def add_study_argument(p, nargs=None, case=False):
    """The positional STUDY (``case``: STUDY|CASE, a plain case file accepted too) and
    ``--set``."""
    if case:
        p.add_argument("study", metavar="STUDY|CASE", nargs=nargs,
                       help="a study file (.toml) or a shipped study's name (see `weakgrid run "
                            "--list`); or a case file (.raw, .m, .mat, .json, .xlsx)")
    else:
        p.add_argument("study", nargs=nargs, help="a study file (TOML) or the name of a shipped "
                                                  "study (see `weakgrid run --list`)")
    add_set_argument(p)


def add_set_argument(p):
    """``--set DOTTED.FIELD=VALUE`` (repeatable) on a command that takes a study."""
    p.add_argument("--set", dest="overrides", metavar="DOTTED.FIELD=VALUE", action="append",
                   type=field_value, default=None, help=SET_HELP)


def field_value(text) -> tuple[str, object]:
    """``(path, value)`` of ``DOTTED.FIELD=VALUE``; the value is read as TOML (a bare word
    that is not TOML is taken as a string: ``load=high``)."""
    import tomllib

    path, sep, raw = str(text).partition("=")
    path, raw = path.strip(), raw.strip()
    if not sep or not path or any(p == "" for p in path.split(".")) or not raw:
        raise argparse.ArgumentTypeError(
            f"{text!r} is not DOTTED.FIELD=VALUE: give e.g. upqc.rating=0.3 or "
            "scenarios.c1-high-conv.t_end=4")
    try:
        return path, tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError as exc:
        if raw[0] in "[{\"'+-.0123456789" or raw in ("inf", "nan"):
            raise argparse.ArgumentTypeError(
                f"{text!r}: the value {raw!r} is not valid TOML ({exc}); quote a string "
                "(name=\"text\"), write lists as [1, 2]") from None
        return path, raw


def add_operating_point(p):
    p.add_argument("--load", default=None, help="load level (default: the study's design.load "
                                                "or its first level)")
    p.add_argument("--upqc", default=None, choices=("conventional", "reduced"),
                   help="UPQC structure (default: the study's upqc.structure)")


def study_of(args, name=None):
    """The study named by ``args.study`` (or ``name``) with ``args.overrides`` applied, and
    ``args.engine`` (``--engine``) as ``simulation.engine`` when it differs from the study's
    (an unchanged engine leaves the study's data, and so its cached runs' keys, as they are)."""
    from ..study.runner import sim_engine
    from ..study.studyfile import load_study

    src = args.study if name is None else name
    overrides = list(getattr(args, "overrides", None) or ())
    st = load_study(src, overrides)
    engine = getattr(args, "engine", None)
    if engine is not None and engine != sim_engine(st):
        st = load_study(src, overrides + [("simulation.engine", engine)])
    return st


def add_engine_argument(p):
    """``--engine``: the simulator of a study's runs (``[simulation] engine``)."""
    from ..sim.emt import ENGINES

    p.add_argument("--engine", choices=ENGINES, default=None,
                   help="the simulator of every run: weakgrid's phasor engine, or the same grid "
                        "in DPsim's electromagnetic transients (dpsim-emt) or dynamic phasors "
                        "(dpsim-dp), the extra weakgrid[emt] (default: the study's [simulation] "
                        "engine, else phasor; for a case file: phasor); a model or event DPsim "
                        "lacks is refused by name before any run; DPsim steps at 1e-4 s (a "
                        "case: unless --dt; a study: its step divided into parts of at most "
                        "1e-4 s) (documentation: Engines)")
