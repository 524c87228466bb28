"""Excitation systems (AVRs)."""

from .exdc2 import EXDC2
from .sexs import SEXS

__all__ = ["EXDC2", "SEXS"]
