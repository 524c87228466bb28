"""Power system stabilizers."""

from .ieeest import IEEEST

__all__ = ["IEEEST"]
