"""WECC generic renewable-plant models (converter interface)."""

from .esd1 import ESD1
from .pvd1 import PVD1
from .reeca1 import REECA1
from .reecb1 import REECB1
from .regca1 import REGCA1
from .repca1 import REPCA1
from .wtara1 import WTARA1
from .wtdta1 import WTDTA1
from .wtpta1 import WTPTA1
from .wttqa1 import WTTQA1

__all__ = ["ESD1", "PVD1", "REECA1", "REECB1", "REGCA1", "REPCA1",
           "WTARA1", "WTDTA1", "WTPTA1", "WTTQA1"]
