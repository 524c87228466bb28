"""Excitation systems (AVRs)."""

from .esac1a import ESAC1A
from .esdc1a import ESDC1A
from .esdc2a import ESDC2A
from .esst1a import ESST1A
from .esst3a import ESST3A
from .exac1 import EXAC1
from .exdc2 import EXDC2
from .exst1 import EXST1
from .ieeet1 import IEEET1
from .ieeet3 import IEEET3
from .ieeex1 import IEEEX1
from .sexs import SEXS

__all__ = ["EXDC2", "SEXS", "ESST3A", "EXST1", "IEEEX1", "IEEET1", "EXAC1", "ESDC2A",
           "ESST1A", "ESAC1A", "ESDC1A", "IEEET3"]
