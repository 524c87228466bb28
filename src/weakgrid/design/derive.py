"""The design model (10) of a machine behind a UPQC, derived from a set-up simulator system.

``derive_design(system, machine, upqc, T)`` reads the power-flow operating point and the
machine's data and returns (10) in its calibrated form ``(T, a, V̄r, ϕs0)`` with every
intermediate value and where it came from:

* **GTI** with a dc link (Section II, (4)–(9)): ``Es = Vs∠(θr+ϕs)`` is the inverter's internal
  voltage behind its coupling susceptance ``B_gti``; ``B = |Y12|`` of the two-port from ``Es`` to
  ``V' = Vr + Vu`` (:func:`~weakgrid.design.twoport.source_twoport`, Kron reduction of the machine
  side of the UPQC branch); ``a = τ'·Vs·B/C`` with ``τ' = (1+χ)·τ``; ``ϕs0`` is the inverter angle
  w.r.t. the shunt bus r; ``V̄r = |Vr|``.
* **SG** in the classical model (Remark 5): ``E'`` behind ``x'd`` from the terminal voltage and
  current; ``B = 1/(x'd + X_path)`` (lossless: the path's reactances only, resistances reported);
  ``ϕs0 = ∠E' − ∠Vr``; ``a = ωs·E'·B/(2H)``, with ``H`` on the system base (``M = 2H`` of the
  simulator is on the system base) and ``ωs = 2π·f``.

``grid_model="thevenin"`` (:mod:`weakgrid.design.thevenin`, SG only) replaces the stiff
shunt-bus voltage by the grid seen from r: ``V̄r``/``ϕs0`` refer to the Thevenin voltage
``E_th``, ``B`` is the transfer admittance through the path *and* ``Z_th``
(:meth:`TwoPort.through`; its reactance only for the lossless SG), and ``a`` is multiplied by
the two-machine inertia factor ``1 + M1/M2``. A GTI's angle is referred to r by its own
control (its PLL), so the grid behind r does not enter its angle dynamics: for a GTI the
Thevenin form *is* the paper's. Both forms are always derived (``Derivation.forms``) so that
the mode check can print both.

The continuous model (9) linearized at ϕs0 oscillates at ``ω = sqrt(a·V̄r·cos ϕs0)`` (rad/s):
:func:`design_mode` returns it for comparison with the full grid's mode
(:mod:`weakgrid.design.modes`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..game.errors import ParameterError
from ..models.design import UPQCDesignModel, sg_design_model
from ..sim.network import BR_R, BR_X, F_BUS, T_BUS
from .thevenin import GridThevenin, grid_thevenin, two_machine_factor
from .twoport import TwoPort, source_twoport

GRID_MODELS = ("paper", "thevenin")

__all__ = ["GRID_MODELS", "Derivation", "derive_design", "design_mode", "find_machine",
           "mode_states", "upqc_branch_of"]


@dataclass
class Derivation:
    """A derived design model and how it was obtained.

    Attributes
    ----------
    model : weakgrid.models.UPQCDesignModel
    machine : {"gti", "sg"}
    name : str
        Name of the controlled GTI or machine.
    shunt_bus : int
        External number of the UPQC shunt bus r.
    upqc_branch : int
        0-based branch row of the UPQC series branch.
    values : list of dict
        ``{"name", "value", "unit", "source"}`` of every value used, in order of use.
    twoport : TwoPort
    details : dict
        Flat checks (exact two-port power vs design model's, loss angle …).
    grid_model : {"paper", "thevenin"}
        Which form ``model`` is.
    forms : dict
        ``{"paper": UPQCDesignModel, "thevenin": UPQCDesignModel or None}``: both forms (None
        when the grid behind r has no source; ``forms_note`` says why).
    thevenin : GridThevenin or None
    """

    model: UPQCDesignModel
    machine: str
    name: str
    shunt_bus: int
    upqc_branch: int
    values: list = field(default_factory=list)
    twoport: TwoPort | None = None
    details: dict = field(default_factory=dict)
    grid_model: str = "paper"
    forms: dict = field(default_factory=dict)
    forms_note: str = ""
    thevenin: GridThevenin | None = None

    def add(self, name, value, unit, source):
        self.values.append({"name": name, "value": value, "unit": unit, "source": source})
        return value

    def table(self) -> str:
        """The values as aligned text lines."""
        w = max(len(v["name"]) for v in self.values)
        out = []
        for v in self.values:
            x = v["value"]
            xs = f"{x:.6g}" if isinstance(x, float) else str(x)
            out.append(f"  {v['name']:<{w}}  {xs:>12} {v['unit']:<8} {v['source']}")
        return "\n".join(out)

    def to_dict(self):
        return {"model": self.model.to_dict(), "machine": self.machine, "name": self.name,
                "shunt_bus": self.shunt_bus, "upqc_branch": self.upqc_branch,
                "values": [dict(v, value=float(v["value"]) if isinstance(v["value"], (float, int,
                            np.floating)) else str(v["value"])) for v in self.values],
                "details": {k: float(v) for k, v in self.details.items()},
                "grid_model": self.grid_model,
                "forms": {k: (m.to_dict() if m is not None else None)
                          for k, m in self.forms.items()}}


def design_mode(model) -> complex:
    """Eigenvalue (upper) of the continuous design model (9) linearized at ϕs0 [1/s].

    ``d²ϕ̂/dt² = −a·V̄r·cos ϕs0 · ϕ̂``: ``λ = j·sqrt(a·V̄r·cos ϕs0)`` (undamped).
    """
    k = model.a * model.Vr_bar * math.cos(model.phi_s0)
    return complex(0.0, math.sqrt(k)) if k > 0 else complex(math.sqrt(-k), 0.0)


def mode_states(derivation) -> list:
    """The states of the full grid that correspond to the design states (ϕ̂, υ)."""
    n = derivation.name
    return [f"{n}.phi_hat", f"{n}.Vc"] if derivation.machine == "gti" else [f"{n}.delta",
                                                                            f"{n}.omega"]


def find_machine(system, name):
    """``(kind, component, index)`` of the GTI or synchronous machine called ``name``."""
    gti = system.components.get("GTI")
    if gti is not None and name in gti.names:
        return "gti", gti, gti.names.index(name)
    for c in system.components.values():
        if c.kind == "machine" and name in c.names:
            return "sg", c, c.names.index(name)
    names = [n for c in system.components.values() if c.kind == "machine" for n in c.names]
    names += list(gti.names) if gti is not None else []
    raise ParameterError("machine.name", name, f"no GTI or machine of that name; choose one of {names}")


def upqc_branch_of(system, upqc):
    """0-based branch row of the UPQC called ``upqc`` (or a branch row given directly)."""
    if isinstance(upqc, (int, np.integer)):
        return int(upqc)
    up = system.components.get("UPQC")
    if up is None or upqc not in up.names:
        raise ParameterError("upqc.name", upqc, "no UPQC of that name in the system")
    return int(up.links[up.names.index(upqc)]["branch"])


def derive_design(system, machine: str, upqc, T: float, structure: str = "conventional",
                  lossless_sg: bool = True, grid_model: str = "paper",
                  thevenin_sources: str = "auto") -> Derivation:
    """Derive the design model (10) of ``machine`` behind the UPQC ``upqc``.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        Set up (power flow solved, components initialized).
    machine : str
        Name of the controlled GTI (with dc link) or synchronous machine.
    upqc : str or int
        Name of the UPQC instance, or the 0-based row of its series branch.
    T : float
        Sampling period of the digital controller, s (a design choice, not plant data).
    structure : {"conventional", "reduced"}
        UPQC structure (the model is the same, (16)).
    lossless_sg : bool
        SG: B from reactances only (the classical model's lossless path).
    grid_model : {"paper", "thevenin"}
        The paper's stiff shunt-bus voltage, or the grid's Thevenin equivalent at r with the
        two-machine inertia factor (:mod:`weakgrid.design.thevenin`). Both are derived; this
        chooses ``Derivation.model``.
    thevenin_sources : {"auto", "terminal", "transient"}
        How the other machines enter the Thevenin equivalent (:func:`grid_thevenin`).
    """
    if grid_model not in GRID_MODELS:
        raise ParameterError("design.grid_model", grid_model, f"choose one of {GRID_MODELS}")
    if not getattr(system, "is_setup", False):
        raise ParameterError("system", "not set up", "call System.setup() before deriving")
    net = system.network
    k_up = upqc_branch_of(system, upqc)
    r_id = int(net.branch[k_up, F_BUS])
    r = net.index_of(r_id)
    Vr = net.pf.V[r]
    kind, comp, i = find_machine(system, machine)
    if kind == "gti":
        d = _derive_gti(system, comp, i, k_up, r_id, Vr, T, structure)
    else:
        d = _derive_sg(system, comp, i, k_up, r_id, Vr, T, structure, lossless_sg)
    _add_thevenin(d, system, comp, i, Vr, lossless_sg, thevenin_sources)
    if grid_model == "thevenin":
        if d.forms["thevenin"] is None:
            raise ParameterError("design.grid_model", "thevenin", d.forms_note)
        d.model = d.forms["thevenin"]
        d.grid_model = "thevenin"
    return d


def _add_thevenin(d, system, comp, i, Vr, lossless_sg, sources):
    """Derive the Thevenin form beside the paper's (``d.forms``) and record its values."""
    d.forms = {"paper": d.model, "thevenin": None}
    if d.machine == "gti":
        # the GTI's angle is referred to the shunt bus r (its PLL, checked in _derive_gti): the
        # grid behind r does not enter its angle dynamics, the Thevenin form is the paper's
        d.forms["thevenin"] = d.model
        d.forms_note = "GTI referred to r: the Thevenin form is the paper's"
        d.details.update(omega_design_paper=abs(design_mode(d.model)),
                         omega_design_thevenin=abs(design_mode(d.model)))
        return
    try:
        th = grid_thevenin(system, d.upqc_branch, int(comp.bus[i]), sources)
    except ParameterError as exc:
        d.forms_note = exc.fix
        return
    d.thevenin = th
    p = d.model
    lossless = lossless_sg
    z = complex(0.0, th.Z.imag) if lossless else th.Z
    B_th = float(abs(d.twoport.through(z)))
    B = next(v["value"] for v in d.values if v["name"] == "B")
    src_angle = p.phi_s0 + float(np.angle(Vr))                # ∠E'
    base = p.a / B
    k = two_machine_factor(float(comp.p["M"][i]), th.M_behind)  # M = 2H, system base
    a_th = base * B_th * k
    phi_th = float(np.angle(np.exp(1j * (src_angle - np.angle(th.E)))))
    try:
        m = UPQCDesignModel(p.T, a_th, float(abs(th.E)), phi_th, machine=p.machine, upqc=p.upqc,
                            source=dict(p.source, grid_model="thevenin", B=B_th,
                                        Vr_bar=float(abs(th.E)), phi_s0=phi_th,
                                        Z_th=[th.Z.real, th.Z.imag], inertia_factor=k))
    except ParameterError as exc:
        d.forms_note = f"the Thevenin form has no valid operating point: {exc.fix}"
        return
    d.forms["thevenin"] = m
    d.add("R_th", float(th.Z.real), "pu", "grid's Thevenin resistance at r")
    d.add("X_th", float(th.Z.imag), "pu", "grid's Thevenin reactance at r (UPQC branch open, "
          f"loads at their power-flow impedance, sources: {', '.join(th.sources)})")
    d.add("E_th", float(abs(th.E)), "pu", "|Vr + Z_th·I| (I: UPQC branch current r → b1)")
    d.add("B_th", B_th, "pu", "|Y12·y_th/(Y22 + y_th)|: the path and Z_th"
          + (" (reactance only)" if lossless else ""))
    if math.isfinite(th.M_behind):
        d.add("M2", th.M_behind, "s", "Σ M = 2H of the machines behind r (system base)")
    d.add("k_inertia", k, "", "two-machine factor 1 + M1/M2")
    d.add("a_th", a_th, "rad/s²/pu", "a·(B_th/B)·k")
    d.add("phi_th", phi_th, "rad", "∠source − ∠E_th")
    d.details.update(omega_design_paper=abs(design_mode(p)),
                     omega_design_thevenin=abs(design_mode(m)),
                     inertia_factor=k, X_th=th.Z.imag, R_th=th.Z.real, B_th=B_th)


def _buses(net, ids) -> str:
    """Bus numbers with their source names (:meth:`Network.bus_label`)."""
    return "[" + ", ".join(net.bus_label(b) for b in ids) + "]"


def _labels(net, rows) -> str:
    """Branch rows as their source names (:meth:`Network.branch_label`)."""
    return "[" + ", ".join(net.branch_label(k) for k in rows) + "]"


def _derive_gti(system, gti, i, k_up, r_id, Vr, T, structure):
    net = system.network
    p = gti.p
    if int(gti.ref[i]) != net.index_of(r_id):
        raise ParameterError("gti.ref_bus", int(net.bus_ids[gti.ref[i]]),
                             f"the GTI's angle reference must be the UPQC shunt bus {r_id}")
    Vs = float(gti.Vs0[i])
    phi0 = float(gti.phi0[i])
    Bg = float(p["B"][i])
    tp = source_twoport(system, int(gti.bus[i]), -1j * Bg, k_up)
    B = tp.B
    eps = tp.loss_angle
    chi, tau, C = float(p["chi"][i]), float(p["tau"][i]), float(p["C"][i])
    tau_p = (1 + chi) * tau
    a = tau_p * Vs * B / C
    name = gti.names[i]
    model = UPQCDesignModel(T, a, abs(Vr), phi0, machine="gti", upqc=structure,
                            source={"C": C, "tau": tau, "chi": chi, "Vs": Vs, "B": B,
                                    "Vr_bar": float(abs(Vr)), "T": T, "Pin": float(gti.Pin[i]),
                                    "phi_s0": phi0})
    d = Derivation(model, "gti", name, r_id, k_up, twoport=tp)
    src = f"GTI '{name}'"
    d.add("C", C, "pu·s", f"{src} parameter C (dc-link capacitance, system base)")
    d.add("tau", tau, "1/(pu·s)", f"{src} parameter tau (phase-control gain of (5))")
    d.add("chi", chi, "pu", f"{src} parameter chi (inverter losses)")
    d.add("tau'", tau_p, "1/(pu·s)", "(1 + chi)·tau")
    d.add("B_gti", Bg, "pu", f"{src} parameter B (coupling susceptance)")
    d.add("Vs", Vs, "pu", "|Es| = |V + jI/B_gti| at the power-flow operating point")
    d.add("B", B, "pu", f"|Y12| of the two-port Es → V' = Vr + Vu (Kron reduction over buses "
          f"{_buses(net, tp.buses)}, branches {_labels(net, tp.branches)} and the UPQC branch "
          f"{net.branch_label(k_up)})")
    d.add("eps", eps, "rad", "loss angle ∠Y12 − π/2 of that two-port (0 if lossless)")
    d.add("T", T, "s", "study design.T (sampling period)")
    d.add("a", a, "rad/s²/pu", "τ'·Vs·B/C")
    d.add("Vr_bar", float(abs(Vr)), "pu", f"|V| of the UPQC shunt bus {net.bus_label(r_id)} (power flow)")
    d.add("phi_s0", phi0, "rad", f"∠Es − ∠Vr (power flow, GTI '{name}' phi0)")
    Y11 = tp.Y11
    d.details = {"Vs": Vs, "B_eff": B, "loss_angle_eps": eps, "G11": float(Y11.real),
                 "Pac": float(gti.Pac0[i]), "Pin": float(gti.Pin[i]),
                 "Pm": float(gti.Pin[i]) / (1 + chi),
                 "P_twoport": float(Vs**2 * Y11.real + Vs * B * abs(Vr) * np.sin(phi0 - eps)),
                 "P_design": float(Vs * abs(Vr) * B * np.sin(phi0)),
                 "phi_s0_lossless_equivalent": phi0 - eps,
                 "omega_design": float(np.sqrt(a * abs(Vr) * np.cos(phi0))),
                 "omega_twoport": float(np.sqrt(tau_p / C * Vs * B * abs(Vr) * np.cos(phi0 - eps)))}
    return d


def _derive_sg(system, gm, i, k_up, r_id, Vr, T, structure, lossless):
    net = system.network
    name = gm.names[i]
    g = int(gm.gen[i])
    b1 = net.index_of(int(net.bus_ids[gm.bus[i]]))
    V1 = net.pf.V[b1]
    S = complex(net.pf.Pg[g], net.pf.Qg[g])
    I = np.conj(S / V1)
    ra, xd1 = float(gm.p["ra"][i]), float(gm.p["xd1"][i])           # system base
    E = V1 + I * complex(ra, xd1)                                     # E' behind x'd
    Ru, Xu = float(net.branch[k_up, BR_R]), float(net.branch[k_up, BR_X])
    y_src = 1.0 / complex(0.0 if lossless else ra, xd1)
    tp = source_twoport(system, b1, y_src, k_up, lossless=lossless)
    direct = not tp.branches and int(net.branch[k_up, T_BUS]) == int(net.bus_ids[b1])
    # a machine directly on the UPQC branch: B = 1/(x'd + Xu) exactly (the chain's |Y12|)
    B = 1.0 / (xd1 + Xu) if (direct and lossless) else tp.B
    Vr_bar = float(abs(Vr))
    phi_s0 = float(np.angle(E / Vr))
    H = float(gm.p["M"][i]) / 2.0
    f_hz = float(net.f_hz)
    model = sg_design_model(H=H, E_prime=float(abs(E)), B=B, Vr_bar=Vr_bar, T=T,
                            f_nominal=f_hz, delta0=phi_s0)
    model.upqc = structure
    d = Derivation(model, "sg", name, r_id, k_up, twoport=tp)
    src = f"machine '{name}' ({gm.type_name})"
    d.add("H", H, "s", f"{src} M/2 on the system base ({net.Sb:g} MVA)")
    d.add("f", f_hz, "Hz", "network nominal frequency; ωs = 2πf")
    d.add("ra", ra, "pu", f"{src} stator resistance (system base; reported, not in B)")
    d.add("x'd", xd1, "pu", f"{src} transient reactance (system base)")
    d.add("E'", float(abs(E)), "pu", "|V + I·(ra + j·x'd)| at the power-flow operating point")
    d.add("Xu", Xu, "pu", f"UPQC series branch {net.branch_label(k_up)} reactance")
    d.add("Ru", Ru, "pu", f"UPQC series branch {net.branch_label(k_up)} resistance "
          "(reported, not in B)")
    d.add("B", B, "pu", "1/(x'd + Xu)" if direct else
          f"|Y12| of E' → V' (Kron reduction over buses {_buses(net, tp.buses)}, branches "
          f"{_labels(net, tp.branches)}"
          + (", reactances only)" if lossless else ")"))
    d.add("T", T, "s", "study design.T (sampling period)")
    d.add("a", model.a, "rad/s²/pu", "ωs·E'·B/(2H)")
    d.add("Vr_bar", Vr_bar, "pu", f"|V| of the UPQC shunt bus {net.bus_label(r_id)} (power flow)")
    d.add("phi_s0", phi_s0, "rad", "∠E' − ∠Vr (power flow)")
    d.details = {"E_prime": float(abs(E)), "B": B, "H_system_base_s": H,
                 "M_design": 2 * H / (2 * math.pi * f_hz), "x_d1_system": xd1, "Xu_system": Xu,
                 "Ru_system": Ru, "ra_system": ra, "Pe_pu": S.real, "Qe_pu": S.imag,
                 "Pm_design_pu": float(abs(E)) * Vr_bar * B * math.sin(phi_s0),
                 "omega_design": math.sqrt(max(model.a * Vr_bar * math.cos(phi_s0), 0.0))}
    return d
