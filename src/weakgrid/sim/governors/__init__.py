"""Turbine-governor models."""

from .hygov import HYGOV
from .ieeeg1 import IEEEG1
from .ieesgo import IEESGO
from .tg2 import TG2
from .tgov1 import TGOV1
from .tgov1n import TGOV1N
from .gast import GAST
from .degov1 import DEGOV1
from .degov import DEGOV
from .pidgov import PIDGOV
from .wpidhy import WPIDHY
from .ggov1 import GGOV1

__all__ = ["TGOV1", "TGOV1N", "HYGOV", "IEEEG1", "IEESGO", "TG2"]
__all__ += ["GAST"]
__all__ += ["DEGOV1", "DEGOV"]
__all__ += ["PIDGOV"]
__all__ += ["WPIDHY"]
__all__ += ["GGOV1"]
