"""What a model's ``psse_params`` knows about the record it converts."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable


@dataclass(frozen=True)
class PsseContext:
    """The generator a ``.dyr`` record belongs to, and where the record was read.

    Attributes
    ----------
    bus : int
        PSS/E bus number (``IBUS``).
    id : str
        Machine identifier (``ID``).
    mbase : float
        Machine base ``MBASE`` [MVA] of the generator record.
    sbase : float
        System base ``SBASE`` [MVA].
    zsorce : complex
        ``ZSORCE = ZR + j ZX`` [pu on ``MBASE``] of the generator record.
    kv : float
        Base voltage of the machine's bus [kV].
    fn : float
        Nominal frequency ``BASFRQ`` [Hz].
    where : str
        ``"file.dyr line 12, GENROU at bus 102 id '1'"``, for error messages.
    gen_row : int or None
        0-based gen-table row of the generator (IBUS, ID) (for a device's ``psse_link``).
    names : dict
        ``{model: weakgrid name}`` of the records already built at that generator (a converter's
        controls link to its REGCA1, a plant controller to its electrical control).
    branch_row : callable or None
        ``branch_row(from_bus, to_bus, ckt) -> 0-based branch row`` (a monitored branch).
    """

    bus: int
    id: str
    mbase: float
    sbase: float
    zsorce: complex
    kv: float
    fn: float
    where: str
    gen_row: int | None = None
    names: dict = field(default_factory=dict)
    branch_row: Callable | None = None
