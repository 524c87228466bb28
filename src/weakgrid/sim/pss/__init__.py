"""Power system stabilizers."""

from .ieeest import IEEEST
from .pss2a import PSS2A
from .pss2b import PSS2B
from .pss2c import PSS2C
from .st2cut import ST2CUT
from .stab1 import STAB1

__all__ = ["IEEEST", "PSS2A", "PSS2B", "PSS2C", "ST2CUT", "STAB1"]
