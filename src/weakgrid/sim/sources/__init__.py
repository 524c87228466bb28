"""Ideal sources: static generators without a dynamic model (ANDES ``Slack``/``PV`` in TDS)."""

from .ideal import InfiniteBus, PVSource

__all__ = ["InfiniteBus", "PVSource"]
