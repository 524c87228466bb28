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
from .ieeevc import IEEEVC
from .ieeet3 import IEEET3
from .ieeex1 import IEEEX1
from .sexs import SEXS
from .esst4b import ESST4B
from .exac4 import EXAC4
from .ac8b import AC8B
from .scrx import SCRX
from .st6b import ST6B
from .st8c import ST8C
from .esac6a import ESAC6A
from .exac2 import EXAC2
from .expic1 import EXPIC1

__all__ = ["EXDC2", "SEXS", "ESST3A", "EXST1", "IEEEX1", "IEEET1", "EXAC1", "ESDC2A", "IEEEVC",
           "ESST1A", "ESAC1A", "ESDC1A", "IEEET3"]
__all__ += ["ESST4B", "EXAC4", "AC8B"]
__all__ += ["SCRX", "ST6B", "ST8C", "ESAC6A", "EXAC2", "EXPIC1"]
