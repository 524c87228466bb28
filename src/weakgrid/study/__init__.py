"""weakgrid.study — the paper's case studies: grids, controllers, scenarios, metrics, reports.

Layer: imports :mod:`weakgrid.sim` and :mod:`weakgrid.models` (and through them
:mod:`weakgrid.game`); imported only by :mod:`weakgrid.cli`.
"""
