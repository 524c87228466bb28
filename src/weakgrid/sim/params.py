"""Parameter declarations and validation shared by all component models.

A component model declares its parameters as a tuple of :class:`Param`.
Each parameter carries its unit, its per-unit base conversion and a validity
rule; :func:`validate` applies the rule and raises :class:`~weakgrid.sim.errors.DataError`
naming the element, field, value and fix.

Per-unit conventions (as in PSS/E and ANDES)
--------------------------------------------
Parameters are given on the *device* base (``Sn`` MVA, ``Vn`` kV) and converted
to the system base (``Sb`` MVA, bus base kV) when the system is set up:

* ``base="z"``: impedance, multiplied by ``(Vn**2/Sn) / (Vb**2/Sb)``.
* ``base="power"``: power or inertia, multiplied by ``Sn/Sb``.
* ``base="ipower"``: inverse power (e.g. droop R), multiplied by ``Sb/Sn``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import DataError


@dataclass(frozen=True)
class Param:
    """One numeric parameter of a component model.

    Attributes
    ----------
    name : str
        Standard (PSS/E / ANDES) name.
    default : float or None
        Default value; ``None`` means mandatory.
    unit : str
        Unit, e.g. ``"s"``, ``"pu"``, ``"pu (machine base)"``.
    info : str
        One-line description.
    rule : str
        ``"pos"`` (> 0), ``"nonneg"`` (>= 0), ``"nonzero"``, ``"flag"`` (0 or 1) or ``""`` (any
        finite value).
    base : str
        ``""``, ``"z"``, ``"power"`` or ``"ipower"`` (see module docstring).
    """

    name: str
    default: float | None
    unit: str = "pu"
    info: str = ""
    rule: str = ""
    base: str = ""


_RULE_TEXT = {
    "pos": ("must be > 0", "give a positive value"),
    "nonneg": ("must be >= 0", "give a value >= 0 (0 bypasses the block where allowed)"),
    "nonzero": ("must be non-zero", "give a non-zero value"),
    "flag": ("must be 0 or 1", "give 0 or 1"),
}


def validate(element: str, params: tuple[Param, ...], values: dict) -> dict:
    """Check ``values`` against ``params``; return a complete dict with defaults filled in.

    Parameters
    ----------
    element : str
        Human-readable element name used in error messages, e.g. ``"GENROU 'G1'"``.
    params : tuple of Param
        Declared parameters.
    values : dict
        User-supplied values (unknown keys are rejected).

    Raises
    ------
    DataError
        For an unknown field, a missing mandatory field, a non-finite value or a rule violation.
    """
    known = {p.name: p for p in params}
    for key in values:
        if key not in known:
            raise DataError(element, key, values[key],
                            f"unknown parameter; known parameters are {sorted(known)}")
    out = {}
    for p in params:
        v = values.get(p.name, p.default)
        if v is None:
            raise DataError(element, p.name, None, f"mandatory parameter ({p.info}, {p.unit}); supply it")
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise DataError(element, p.name, v, f"must be a number ({p.info}, {p.unit})") from None
        if not math.isfinite(v):
            raise DataError(element, p.name, v, f"must be finite ({p.info}, {p.unit})")
        if p.rule:
            ok = {"pos": v > 0, "nonneg": v >= 0, "nonzero": v != 0, "flag": v in (0.0, 1.0)}[p.rule]
            if not ok:
                what, fix = _RULE_TEXT[p.rule]
                raise DataError(element, p.name, v, f"{p.info or p.name} [{p.unit}] {what}; {fix}")
        out[p.name] = v
    return out
