"""Voltage-dependent load models."""

from .zip import ZIP

__all__ = ["ZIP"]
