"""What a model's ``psse_params`` knows about the record it converts."""

from __future__ import annotations

from dataclasses import dataclass


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
    """

    bus: int
    id: str
    mbase: float
    sbase: float
    zsorce: complex
    kv: float
    fn: float
    where: str
