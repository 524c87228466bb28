"""WECC generic renewable-plant models (converter interface)."""

from .regca1 import REGCA1

__all__ = ["REGCA1"]
