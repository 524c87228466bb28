"""Power system stabilizers."""

from .ieeest import IEEEST
from .st2cut import ST2CUT

__all__ = ["IEEEST", "ST2CUT"]
