"""Case 1 of the paper: a wind farm's GTI behind a UPQC in a weak grid (Fig. 6).

Data: ``src/weakgrid/data/cases/case1-weak-grid.toml`` (network, loads at two levels,
GTI, UPQC, SG with exciter/governor/PSS, fault). :func:`build` turns it into a set-up
:class:`~weakgrid.sim.system.System` and derives the design model (10) from the
power-flow operating point.

Which susceptance B the design model uses
-----------------------------------------
In the simulator the GTI internal voltage ``Es = Vs∠(θr+ϕs)`` drives its current through
its coupling susceptance ``B_gti`` into its bus; the feeder (π model) leads to bus 2; the
UPQC branch adds ``Vu`` at the shunt-bus end of the series-transformer leakage ``Zu``, so
the branch current is ``(Vr + Vu − V2)/Zu``. The path from ``Es`` to the node
``V' = Vr + Vu`` (the paper's ``V1∠θ1 = (Vr+Vuq) + jVup``) is therefore the chain
``1/B_gti → feeder → Zu`` with no other load. Kron-reducing it to a two-port
``I_s = Y11·Es + Y12·V'`` gives exactly::

    P_ac = Vs²·Re(Y11) + Vs·|Y12|·[(Vr+Vuq)·sin(ϕs − ε) − Vup·cos(ϕs − ε)],   ε = ∠Y12 − π/2

and the dc link ``C·Vc·dVc/dt = Pin − (1+χ)·P_ac`` with ``υ = τ(Vc² − Vc0²)/2`` gives
``dυ/dt = (τ'/C)(Pm − P_ac)``: the design model (9) with ``B = |Y12|`` (the transfer
susceptance of the whole chain GTI filter + feeder + series-transformer leakage), up to the
small loss angle ε (zero for a lossless path). ``ϕs0`` is the GTI angle w.r.t. the shunt bus
from the power flow (the simulator's ``phi0``), ``V̄r = |Vr|`` and ``Vs`` the GTI's ``Vs0``.
"""

from __future__ import annotations

import tomllib
from importlib import resources

import numpy as np

from ...game.errors import ParameterError
from ...models.design import UPQCDesignModel
from ...sim.controllers import gti_design_states
from ...sim.gti import GTI
from ...sim.system import System
from ...sim.upqc import UPQC
from .base import CaseBuild

NAME = "case1-weak-grid"


def load_data() -> dict:
    """The case's data file as a dict."""
    path = resources.files("weakgrid") / "data" / "cases" / f"{NAME}.toml"
    with resources.as_file(path) as p, open(p, "rb") as fh:
        return tomllib.load(fh)


def _preset() -> dict:
    path = resources.files("weakgrid") / "data" / "presets" / "case1-paper.toml"
    with resources.as_file(path) as p, open(p, "rb") as fh:
        return tomllib.load(fh)["model"]


def matpower_case(data: dict, load: str) -> dict:
    """MATPOWER case dict of the network at load level ``load`` (gen 0: GTI, gen 1: SG)."""
    Sb = float(data["case"]["Sb_mva"])
    loads = data["loads"][load]
    bus = []
    for b in data["bus"]:
        pd, qd = loads.get(str(b["id"]), [0.0, 0.0])
        vm = 1.0
        bus.append([b["id"], b["type"], pd, qd, 0, 0, 1, vm, 0, b["base_kv"], 1, 1.5, 0.5])
    # gen 0: the GTI (a PV bus holds its PCC voltage; on a PQ bus it injects P_mw + j·Q_mvar)
    g, s = data["gti"], data["sg"]
    gen = [
        [g["bus"], g["P_mw"], g.get("Q_mvar", 0.0), 9999, -9999, g.get("V_set", 1.0), g["Mbase"], 1,
         9999, -9999] + [0] * 11,
        [s["bus"], 0, 0, 9999, -9999, s["V_set"], s["Mbase"], 1, 9999, -9999] + [0] * 11,
    ]
    branch = [[br["from"], br["to"], br["r"], br["x"], br["b"], 0, 0, 0, 0, 0, 1, -360, 360]
              for br in data["branch"]]
    return {"baseMVA": Sb, "bus": np.array(bus, float), "gen": np.array(gen, float),
            "branch": np.array(branch, float)}


def _branch_index(data, role):
    for k, br in enumerate(data["branch"]):
        if br["role"] == role:
            return k
    raise ParameterError("branch.role", role, f"no branch with role '{role}' in {NAME}.toml")


def transfer_twoport(system, data):
    """Two-port ``[Y11, Y12]`` from the GTI internal voltage to ``V' = Vr + Vu`` (pu).

    Nodes: Es, the GTI bus, the buses of the feeder chain up to the UPQC's bus 1, and V'.
    The UPQC branch impedance connects bus 1 to V'; interior nodes are Kron-reduced.
    Interior buses must carry no load (checked).
    """
    net = system.network
    g = data["gti"]
    Bg = float(g["B"])
    k_up = _branch_index(data, "upqc")
    k_fd = _branch_index(data, "feeder")
    f, t, Yff, Yft, Ytf, Ytt = net.branch_admittances()
    gbus = net.index_of(g["bus"])
    b1 = t[k_up]
    for b in {gbus, int(b1)}:
        if net.bus[b, 2] != 0 or net.bus[b, 3] != 0 or net.bus[b, 4] != 0 or net.bus[b, 5] != 0:
            raise ParameterError("loads", int(net.bus_ids[b]), "the GTI–UPQC path must carry no load")
    # node order: 0 Es, 1 GTI bus, 2 bus 1, 3 V'
    Y = np.zeros((4, 4), complex)
    yg = -1j * Bg
    Y[0, 0] += yg; Y[1, 1] += yg; Y[0, 1] -= yg; Y[1, 0] -= yg
    if {int(f[k_fd]), int(t[k_fd])} != {gbus, int(b1)}:
        raise ParameterError("branch.feeder", (int(f[k_fd]), int(t[k_fd])),
                             "the feeder must join the GTI bus and the UPQC's bus 1")
    loc = {gbus: 1, int(b1): 2}
    i, j = loc[int(f[k_fd])], loc[int(t[k_fd])]
    Y[i, i] += Yff[k_fd]; Y[i, j] += Yft[k_fd]; Y[j, i] += Ytf[k_fd]; Y[j, j] += Ytt[k_fd]
    yu = 1.0 / complex(net.branch[k_up, 2], net.branch[k_up, 3])
    Y[2, 2] += yu; Y[3, 3] += yu; Y[2, 3] -= yu; Y[3, 2] -= yu
    ext, inn = [0, 3], [1, 2]
    Yr = Y[np.ix_(ext, ext)] - Y[np.ix_(ext, inn)] @ np.linalg.solve(Y[np.ix_(inn, inn)], Y[np.ix_(inn, ext)])
    return Yr[0, 0], Yr[0, 1]


def derive_design(system, data, upqc="conventional"):
    """Design model (10) from the operating point of ``system`` and the GTI data.

    Returns ``(model, details)``.
    """
    net = system.network
    gti = system.components["GTI"]
    g = data["gti"]
    k_up = _branch_index(data, "upqc")
    r = net.index_of(int(net.branch[k_up, 0]))      # the UPQC shunt bus (from-bus of its branch)
    Vr = net.pf.V[r]
    Vs = float(gti.Vs0[0])
    phi0 = float(gti.phi0[0])
    Y11, Y12 = transfer_twoport(system, data)
    B = float(abs(Y12))
    eps = float(np.angle(Y12) - np.pi / 2)
    chi, tau, C = float(g["chi"]), float(g["tau"]), float(g["C"])
    tau_p = (1 + chi) * tau
    a = tau_p * Vs * B / C
    T = float(data["design"]["T"])
    model = UPQCDesignModel(T, a, abs(Vr), phi0, machine="gti", upqc=upqc,
                            source={"case": NAME, "C": C, "tau": tau, "chi": chi, "Vs": Vs, "B": B,
                                    "Vr_bar": float(abs(Vr)), "T": T, "Pin": float(gti.Pin[0]),
                                    "phi_s0": phi0})
    Pac = float(gti.Pac0[0])
    det = {"Vs": Vs, "B_eff": B, "loss_angle_eps": eps, "G11": float(Y11.real), "Pac": Pac,
           "Pin": float(gti.Pin[0]), "Pm": float(gti.Pin[0]) / (1 + chi),
           # the exact two-port power at the operating point vs the design model's Vs·V̄r·B·sin ϕs0
           "P_twoport": float(Vs**2 * Y11.real + Vs * B * abs(Vr) * np.sin(phi0 - eps)),
           "P_design": float(Vs * abs(Vr) * B * np.sin(phi0)),
           # the lossless design model with this angle would match the two-port exactly
           "phi_s0_lossless_equivalent": phi0 - eps,
           "omega_design": float(np.sqrt(a * abs(Vr) * np.cos(phi0))),
           "omega_twoport": float(np.sqrt(tau_p / C * Vs * B * abs(Vr) * np.cos(phi0 - eps)))}
    return model, det


def build(load: str = "high", upqc: str = "conventional", variant: str = "upqc",
          data: dict | None = None) -> CaseBuild:
    """Build case 1 at load level ``load`` ("high"/"low") with the UPQC in structure ``upqc``.

    ``variant="upqc"``: GTI in energy mode (4)–(5) and the UPQC in service (idle until a
    controller drives it). ``variant="pq"``: the GTI's phase by the PQ PID loops (paper's
    gains, the simulator's defaults) and no UPQC (its series transformer stays as a plain
    branch, so both variants share one network). ``data`` replaces the data file's
    contents (for studies of the data's sensitivity; default: the file).
    """
    data = load_data() if data is None else data
    if load not in data["loads"]:
        raise ParameterError("load", load, f"choose one of {sorted(data['loads'])}")
    if upqc not in ("conventional", "reduced"):
        raise ParameterError("upqc", upqc, "choose 'conventional' or 'reduced'")
    if variant not in ("upqc", "pq"):
        raise ParameterError("variant", variant, "choose 'upqc' or 'pq'")
    case = matpower_case(data, load)
    s = System(case)
    s.network.f_hz = float(data["case"]["f_hz"])
    sg = data["sg"]
    parts = {}
    for part in ("machine", "exciter", "governor", "pss"):
        d = dict(sg[part])
        model = d.pop("model")
        parts[part] = (model, d)
    s.add_generator(sg["name"], gen=1, **parts)
    g = data["gti"]
    gti = s.add_component(GTI())
    k_up = _branch_index(data, "upqc")
    r_id = int(data["branch"][k_up]["from"])
    mode = "energy" if variant == "upqc" else "pq"
    gti.add_gti(g["name"], gen=0, ref_bus=r_id, mode=mode, C=g["C"], Vc0=g["Vc0"], chi=g["chi"],
                B=g["B"], ks_max=g["ks_max"], tau=g["tau"])
    upqc_name = None
    if variant == "upqc":
        u = data["upqc"]
        up = s.add_component(UPQC())
        up.add_upqc(u["name"], branch=k_up, structure=upqc,
                    gti=g["name"] if upqc == "reduced" else None, Vmax=u["Vmax"])
        upqc_name = u["name"]
    s.setup()

    design, det = derive_design(s, data, upqc)
    net = s.network
    r = net.index_of(r_id)
    b1 = net.index_of(int(data["branch"][k_up]["to"]))
    Sb = float(data["case"]["Sb_mva"])
    # power through the UPQC line, r -> bus 1 (negative: the wind farm exports towards r)
    yu = 1.0 / complex(net.branch[k_up, 2], net.branch[k_up, 3])
    I = yu * (net.pf.V[r] - net.pf.V[b1])
    p_line = abs(float((net.pf.V[r] * np.conj(I)).real)) * Sb

    pre = _preset()
    ld = data["loads"][load]
    info = {
        "derived": {"T": design.T, "a": design.a, "Vr_bar": design.Vr_bar, "phi_s0": design.phi_s0},
        "preset": {k: float(pre[k]) for k in ("T", "a", "Vr_bar", "phi_s0")},
        "relative_to_preset": {k: (getattr(design, k) - float(pre[k])) / float(pre[k])
                               for k in ("T", "a", "Vr_bar", "phi_s0")},
        "design_details": det,
        "load_MW": float(sum(v[0] for v in ld.values())),
        "load_Mvar": float(sum(v[1] for v in ld.values())),
        "gti_P_MW": float(g["P_mw"]),
        "sg_P_MW": float(net.pf.Pg[1] * Sb),
        "sg_Q_Mvar": float(net.pf.Qg[1] * Sb),
        "gti_Q_Mvar": float(net.pf.Qg[0] * Sb),
        "bus_voltages": {int(b): float(abs(v)) for b, v in zip(net.bus_ids, net.pf.V)},
        "upqc_Vmax": float(data["upqc"]["Vmax"]) if variant == "upqc" else None,
        "fault": dict(data["fault"]),
        "sources": "data/cases/case1-weak-grid.toml (values chosen; paper Tables I-II missing)",
    }
    rel = info["relative_to_preset"]
    info["notes"] = [
        f"derived design model at {load} load: a {rel['a']:+.2%}, V̄r {rel['Vr_bar']:+.2%}, "
        f"ϕs0 {rel['phi_s0']:+.2%} from the case1-paper preset (the data were solved for the "
        "preset at high load; the low load moves the operating point)",
        "B of (9) is |Y12| of the GTI coupling + feeder + series-transformer two-port; the "
        "in-phase series voltage (Vuq) acts at about 0.6 of the design model's gain because "
        "the weak shunt bus absorbs part of it (w reacts to u2), tests/study/test_case1.py",
        "fault: bus 3 (the UPQC shunt bus), xf = 0.1 pu (≈ 250 MVA short-circuit level): with "
        "the UPQC idle it keeps the GTI states inside the training region Ω; stiffer faults "
        "drive υ outside Ω, and faults that nearly island the GTI have no network solution "
        "with the simulator's ideal PLL",
    ]
    f = data["fault"]
    gname, upname = g["name"], upqc_name
    signals = {"sg_speed": f"{sg['name']}.omega", "dc_voltage": f"{gname}.Vc",
               "phi_hat": f"{gname}.phi_hat", "upsilon": f"{gname}.upsilon",
               "vr": f"bus{r_id}.v"}
    if upname:
        signals.update(vup=f"{upname}.Vup", vuq=f"{upname}.Vuq", p_series=f"{upname}.P_series",
                       vu=f"{upname}.Vu")
    return CaseBuild(name=NAME, system=s, load=load, upqc=upqc, variant=variant, machine="gti",
                     source=gname, sg=sg["name"], upqc_name=upqc_name, shunt_bus=r_id,
                     measure=gti_design_states(gname), design=design, line_power_mw=p_line,
                     fault_bus=int(f["bus"]), signals=signals, Sb_mva=Sb, info=info)


def fault_spec(data=None) -> dict:
    """The paper's fault of this case (bus, t_on, t_off, rf, xf) from the data file."""
    data = data or load_data()
    return dict(data["fault"])
