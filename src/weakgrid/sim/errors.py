"""Exception classes of :mod:`weakgrid.sim`.

Every error raised for bad input names the element, the field, the offending
value and a suggested fix, so that a user can correct the data without reading
the simulator's source.
"""

from __future__ import annotations

from ..game.errors import WeakgridError


class SimError(WeakgridError):
    """Base class of all errors raised by :mod:`weakgrid.sim` (picklable, see
    :class:`weakgrid.game.errors.WeakgridError`)."""


class DataError(SimError, ValueError):
    """Invalid or inconsistent input data.

    Parameters
    ----------
    element : str
        The element concerned, e.g. ``"GENROU 'G1'"`` or ``"bus 7"``.
    field : str
        The parameter or field name, e.g. ``"Td10"``.
    value : object
        The offending value.
    fix : str
        What to do about it.
    """

    def __init__(self, element: str, field: str, value, fix: str):
        self.element = element
        self.field = field
        self.value = value
        self.fix = fix
        super().__init__(f"{element}: field '{field}' = {value!r} is invalid. Fix: {fix}")


class PowerFlowError(SimError):
    """The initializing power flow did not converge or does not satisfy the network equations."""


class SimulationError(SimError):
    """A time-domain simulation could not continue.

    Attributes
    ----------
    t : float
        Simulation time [s] at which the failure was detected.
    cause : str
        One of ``"newton"`` (Newton iteration failed even at the minimum step),
        ``"divergence"`` (non-finite or runaway state), ``"loss of synchronism"``
        (rotor angles swung apart from the initial point beyond the limit), ``"voltage collapse"`` (the network's
        operating point ends at a fold: after a jump of the controllers' outputs, or as the
        states move on; the attribute ``fold`` then holds the last network solution before
        it) or ``"controller"`` (a digital controller returned invalid output).
    """

    def __init__(self, t: float, cause: str, detail: str = ""):
        self.t = float(t)
        self.cause = cause
        self.detail = detail
        super().__init__(f"simulation stopped at t = {self.t:.6g} s: {cause}" + (f" ({detail})" if detail else ""))


class DataWarning(UserWarning):
    """Data that is accepted but unusual enough to be said (e.g. a negative series reactance)."""
