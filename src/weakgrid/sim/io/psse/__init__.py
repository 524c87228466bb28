"""Native PSS/E reader: ``.raw`` (versions 29-35) and ``.dyr`` files into a weakgrid System.

Public: :func:`from_psse`. Parts: :mod:`.tokens` (free-format fields), :mod:`.raw` (power-flow
records), :mod:`.dyr` (dynamic records), :mod:`.network` (records -> MATPOWER case),
:mod:`.build` (models, conventions, events).
"""

from .build import from_psse
from .context import PsseContext
from .dyr import read_dyr
from .raw import read_raw

__all__ = ["from_psse", "PsseContext", "read_dyr", "read_raw"]
