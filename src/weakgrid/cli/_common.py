"""Helpers shared by the subcommands (problem selection, records)."""

from __future__ import annotations

from pathlib import Path

from .. import __version__
from ..models import load_preset, load_problem, preset_names


def add_problem_arguments(p):
    """``--preset NAME`` or ``--config FILE`` (one of them required)."""
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--preset", choices=preset_names(), help="a shipped preset")
    src.add_argument("--config", type=Path, help="a problem file (TOML), see the README")


def problem_of(args):
    """The :class:`~weakgrid.models.TrainingProblem` selected by the arguments."""
    return load_preset(args.preset) if args.preset else load_problem(args.config)


def provenance(problem, command: str, **parameters) -> dict:
    """What a result file records about how it was made."""
    return {"command": command, "weakgrid_version": __version__, "problem": problem.name,
            "source": problem.source, "parameters": parameters}


