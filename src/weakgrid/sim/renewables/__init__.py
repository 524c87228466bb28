"""WECC generic renewable-plant models (converter interface)."""

from .pvd1 import PVD1
from .regca1 import REGCA1

__all__ = ["PVD1", "REGCA1"]
