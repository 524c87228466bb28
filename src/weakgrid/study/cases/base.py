"""The interface between a case's data and the rest of the study.

A case module turns its data file (``src/weakgrid/data/cases/<name>.toml`` plus
network data) into a simulator :class:`~weakgrid.sim.system.System` at a load
level, with the UPQC in a given structure, and reports the design model (10)
derived from the operating point (power flow → V̄r, ϕs0, a).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import import_module
from typing import Callable

from ...game.errors import ParameterError

__all__ = ["CaseBuild", "CASES", "build_case", "case_names"]

# case name -> module (relative to weakgrid.study.cases) implementing build()
CASES = {
    "case1-weak-grid": "case1",
    "case2-lv-microgrid": "case2",
}

LOADS = ("high", "low")
UPQC_STRUCTURES = ("conventional", "reduced")
# "upqc": UPQC in service (driven by a digital controller or idle);
# "pq": the conventional baseline — GTI phase by PQ PID loops, no UPQC (case 1 only)
VARIANTS = ("upqc", "pq")


@dataclass
class CaseBuild:
    """A case ready to simulate.

    Attributes
    ----------
    name : str
        Case name, e.g. ``"case1-weak-grid"``.
    system : weakgrid.sim.system.System
        Set up (power flow solved, initialized).
    load, upqc, variant : str
        As requested.
    machine : {"gti", "sg"}
        What the design states describe.
    source : str
        Name of the GTI or SG instance whose design states are measured.
    sg : str
        Name of the synchronous generator (its speed is a reported signal).
    upqc_name : str or None
        Name of the UPQC instance (None for the "pq" variant).
    shunt_bus : int
        UPQC shunt bus id (the angle reference r).
    measure : callable
        Measurement function ``(sim, t, z, ctx) -> [ϕ̂, υ]`` in the design model's units
        (ϕ̂ in rad, υ in rad/s) for :class:`~weakgrid.sim.controllers.DigitalController`.
    design : weakgrid.models.UPQCDesignModel
        The design model (10) derived from the operating point.
    line_power_mw : float
        Active power through the UPQC's line at the operating point (MW), for
        "injected power in % of the line's power".
    fault_bus : int
        Bus of the paper's three-phase fault.
    signals : dict
        Names of the result variables of the figures: ``"sg_speed"`` (pu),
        ``"dc_voltage"`` (pu, GTI cases), ``"vup"``, ``"vuq"``, ``"p_series"`` (pu on Sb) …
    Sb_mva : float
        System base (MVA).
    info : dict
        Derived values with their sources, for the report (T, a, V̄r, ϕs0 beside the
        preset's; load totals; …).
    """

    name: str
    system: object
    load: str
    upqc: str
    variant: str
    machine: str
    source: str
    sg: str
    upqc_name: str | None
    shunt_bus: int
    measure: Callable
    design: object
    line_power_mw: float
    fault_bus: int
    signals: dict = field(default_factory=dict)
    Sb_mva: float = 100.0
    info: dict = field(default_factory=dict)


def case_names() -> list[str]:
    """Names of the registered cases (keys of :data:`CASES`)."""
    return list(CASES)


def build_case(name: str, load: str = "high", upqc: str = "conventional",
               variant: str = "upqc") -> CaseBuild:
    """Build case ``name`` at a load level with a UPQC structure and variant."""
    if name not in CASES:
        raise ParameterError("case", name, f"unknown case; choose one of {case_names()}")
    if load not in LOADS:
        raise ParameterError("load", load, f"choose one of {LOADS}")
    if upqc not in UPQC_STRUCTURES:
        raise ParameterError("upqc", upqc, f"choose one of {UPQC_STRUCTURES}")
    if variant not in VARIANTS:
        raise ParameterError("variant", variant, f"choose one of {VARIANTS}")
    mod = import_module(f".{CASES[name]}", __package__)
    return mod.build(load=load, upqc=upqc, variant=variant)
