"""Turbine-governor models."""

from .hygov import HYGOV
from .tgov1 import TGOV1

__all__ = ["TGOV1", "HYGOV"]
