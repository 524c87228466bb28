"""Synchronous machine models (stator/rotor electrical part + single-mass shaft)."""

from .gencls import GENCLS
from .genroe import GENROE
from .genrou import GENROU
from .gensae import GENSAE
from .gensal import GENSAL

__all__ = ["GENCLS", "GENROE", "GENROU", "GENSAE", "GENSAL"]
