"""The paper's detailed grids, built for the simulator from data files.

Each case module exposes ``build(load, upqc, variant) -> CaseBuild`` and is
registered in :data:`CASES`.
"""

from .base import CASES, CaseBuild, build_case, case_names

__all__ = ["CASES", "CaseBuild", "build_case", "case_names"]
