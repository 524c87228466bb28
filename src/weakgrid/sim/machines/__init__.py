"""Synchronous machine models (stator/rotor electrical part + single-mass shaft)."""

from .gencls import GENCLS
from .genrou import GENROU

__all__ = ["GENCLS", "GENROU"]
