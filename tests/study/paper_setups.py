"""The paper's two grids, built from their shipped study files, for the physics tests.

``build_case(name, load, upqc, variant)`` returns the engine's :class:`Setup` with an ``info``
dict of derived values (the derivation's details, the settings preset, bus ids, totals) and
``fault_bus`` (the bus of the study's first fault).
"""

import numpy as np

from weakgrid.models import load_preset
from weakgrid.study.build import build_setup
from weakgrid.study.studyfile import load_study


def study_data(name):
    return load_study(name).data


def build_case(name, load="high", upqc="conventional", variant="upqc"):
    st = load_study(name)
    s = build_setup(st, load, upqc, variant)
    net = s.system.network
    der = s.derivation
    d = s.design
    pre = load_preset(st.data["design"]["settings"]).system
    fault = next(e for sc in st.data["scenarios"] for e in sc["events"] if e["kind"] == "fault")
    s.fault_bus = s.bus(fault["bus"])
    s.sg = st.data["report"].get("speed_of") or st.data["machine"]["name"]
    m = s.system.machine_number(s.sg)
    comp = next(c for c in s.system.components.values() if c.kind == "machine"
                and s.sg in c.names)
    g = int(comp.gen[comp.names.index(s.sg)])
    s.info = dict(der.details)
    s.info.update(
        derived={"T": d.T, "a": d.a, "Vr_bar": d.Vr_bar, "phi_s0": d.phi_s0},
        preset={k: float(getattr(pre, k)) for k in ("T", "a", "Vr_bar", "phi_s0")},
        design_details=der.details, bus_ids=s.bus_id, fault=dict(fault, bus=s.fault_bus),
        sg_p_mw=float(net.pf.Pg[g] * net.Sb), machine_number=m,
        load_p_mw=float(np.sum(net.bus[:, 2])), load_q_mvar=float(np.sum(net.bus[:, 3])))
    if "Pe_pu" in der.details:
        s.info["Pe_sg_pu"] = der.details["Pe_pu"]
    s.info["preset_case2_paper"] = s.info["preset"]
    return s


def classical_case1():
    """``(data, source)`` of case 1's study with its generator made classical (GENCLS, no
    exciter, governor or PSS: the models every DPsim engine has), for the DPsim study tests."""
    import copy

    src = load_study("case1-weak-grid")
    d = copy.deepcopy(src.data)
    g = d["dynamics"]["generator"][0]
    for k in ("exciter", "governor", "pss"):
        g.pop(k)
    g["machine"] = {"model": "GENCLS", "Sn": 80.0, "M": 6.0, "D": 0.0, "ra": 0.0, "xd1": 0.3}
    return d, src.source
