"""Arguments shared by the study subcommands (a study file or a shipped study's name)."""

from __future__ import annotations


def add_study_argument(p):
    p.add_argument("study", help="a study file (TOML) or the name of a shipped study "
                                 "(see `weakgrid run --list`)")


def add_operating_point(p):
    p.add_argument("--load", default=None, help="load level (default: the study's design.load "
                                                "or its first level)")
    p.add_argument("--upqc", default=None, choices=("conventional", "reduced"),
                   help="UPQC structure (default: the study's upqc.structure)")


def study_of(args):
    from ..study.studyfile import load_study

    return load_study(args.study)
