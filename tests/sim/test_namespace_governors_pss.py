"""The governors GAST, IEEEG1, IEESGO, PIDGOV, TG2, WPIDHY and the stabilizers PSS2A, PSS2B,
PSS2C, ST2CUT, STAB1 evaluated on another array namespace (issue #21).

As :mod:`test_namespace`: each grid's residual and recorded outputs on ``array_api_strict`` equal
NumPy's bit for bit, at the initial point and at perturbed points far enough out to take the
limits; several instances of a model with different options (limits tight around the initial
point, optional blocks on and off, input modes), on non-contiguous machines (index arrays, not
slices). DEGOV1, DEGOV and GGOV1 read the time and a stored history (their engine dead time,
:class:`~weakgrid.sim.blocks.TransportDelay`): they stay on NumPy."""

from __future__ import annotations

import numpy as np
import pytest
from test_namespace import _check, _no_numpy_on_strict_arrays, _points  # noqa: F401

from weakgrid.sim.system import System

GENROU = dict(Sn=200, M=8.0, D=0.0, ra=0.0, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25,
              xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
SEXS = dict(TATB=0.4, TB=5.0, K=20.0, TE=1.0, EMIN=-50.0, EMAX=50.0)
TGOV1 = dict(R=0.05, VMAX=1.2, VMIN=0.0, T1=0.1, T2=0.5, T3=2.0, Dt=0.0)


def _case(ngen, p):
    """``ngen`` PV buses (``p`` pu each), each on a line to the slack bus 0 and in a ring."""
    n = ngen + 1
    bus = np.array([[k + 1, 3 if k == 0 else 2, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5]
                    for k in range(n)], dtype=float)
    gen = np.array([[k + 2, p * 100, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11
                    for k in range(ngen)] + [[1, 0, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11],
                   dtype=float)
    lines = [(1, k + 2) for k in range(ngen)] + [(k + 2, k + 3) for k in range(ngen - 1)]
    branch = np.array([[a, b, 0.01, 0.3, 0.0, 0, 0, 0, 0, 0, 1, -360, 360] for a, b in lines], dtype=float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}


def _grid(kind, model, instances, at=(0, 2, 3), ngen=4, p=0.8, governor=None):
    """``ngen`` GENROU + SEXS units (PSS/E's shaft on the even ones) against a large classical machine; the
    ``kind`` ("governor" or "pss") ``model`` with the parameters ``instances[k]`` on unit
    ``at[k]`` (a dict may carry ``machine2``); ``governor`` on every unit (stabilizer grids)."""
    s = System(_case(ngen, p))
    for g in range(ngen):
        s.add_machine("GENROU", f"G{g}", gen=g, psse_shaft=float(g % 2 == 0), **GENROU)
        s.add_exciter("SEXS", f"G{g}.avr", f"G{g}", **SEXS)
        if governor is not None:
            s.add_governor(governor[0], f"G{g}.gov", f"G{g}", **governor[1])
    for k, (g, prm) in enumerate(zip(at, instances)):
        prm = dict(prm)
        if kind == "governor":
            s.add_governor(model, f"G{g}.{model}{k}", f"G{g}", machine2=prm.pop("machine2", None), **prm)
        else:
            s.add_pss(model, f"G{g}.{model}{k}", f"G{g}", **prm)
    s.add_machine("GENCLS", "S", gen=ngen, Sn=1000, M=20.0, xd1=0.1)    # the strong grid
    return s.setup()


# the initial torque is 0.8 pu on the system base: 0.4 pu on the 200-MVA machine (turbine) base
PSS2A_PSID = dict(ICS1=1, ICS2=3, M=5, N=1, TW1=1.5, TW2=1.5, T6=0.0, TW3=1.5, TW4=0.0, T7=1.5,
                  KS2=0.1875, KS3=1.0, T8=0.5, T9=0.1, KS1=2.0, T1=0.59451, T2=0.0447, T3=0.59451,
                  T4=0.0447, VSTMAX=0.1, VSTMIN=-0.1)
PSS2B_PSID = dict(PSS2A_PSID, T10=1.0, T11=1.0, VS1MAX=0.00035, VS1MIN=-0.00055, VS2MAX=0.915,
                  VS2MIN=0.895)
PSS2C_PSID = dict(PSS2B_PSID, T12=1.0, T13=1.0, PSSON=0.895, PSSOFF=0.885, Xcomp=1.0, Tcomp=1.0)
GATE = dict(G0=0.1, G1=0.3, P1=0.3, G2=0.7, P2=0.8, P3=1.0)

GOVERNORS = {
    "GAST": [dict(), dict(AT=0.5, KT=2.0, VMAX=0.5, Dt=0.1, Tn=300.0),
             dict(VMIN=0.38, VMAX=0.42, Dt=-0.05, R=0.04)],
    "IEEEG1": [dict(machine2="G1", K1=0.5, K2=0.5, K3=0.0, T7=0.0),
               dict(K=20, PMAX=0.45, PMIN=0.35, T7=0.0, UO=0.05, UC=-0.05),
               dict(T1=0.0, T2=0.0, T4=0.0, T6=0.0, K5=0.3, K7=0.2, Tn=250.0)],
    "IEESGO": [dict(K1=20, K2=0.7, K3=0.4), dict(K1=20, PMAX=0.45, PMIN=0.35, T1=0.0, T3=0.0),
               dict(K1=5, K2=0.5, K3=0.5, T4=0.0, T5=0.0, T6=0.0, Tn=300.0)],
    "TG2": [dict(R=0.05, pmax=2.0), dict(R=0.05, pmax=0.42, pmin=0.38, T1=0.0),
            dict(R=0.1, T1=0.5, T2=5.0, Tn=250.0)],
    "PIDGOV": [dict(Flag=0),
               dict(Flag=1, Kd=0.5, Ta=0.1, Treg=0.2, Dturb=0.1, Gmax=0.45, Gmin=0.35,
                    Velmax=0.05, Velmin=-0.05),
               dict(Flag=0, Ta=0.0, Kd=0.0, Tw=0.0, **GATE)],
    "WPIDHY": [dict(),
               dict(KD=0.5, TA=0.1, TREG=0.2, GATMX=0.45, GATMN=0.35, PMAX=0.45, PMIN=0.35, D=0.1),
               dict(TA=0.0, KD=0.0, TB=0.0, TW=0.0, **GATE)],
}
STABILIZERS = {
    "STAB1": [dict(KT=6.0, T=1.5, T1T3=13.3, T3=0.0447, T2T4=13.3, T4=0.0447, HLIM=0.2),
              dict(KT=6.0, T=1.5, T3=0.0, HLIM=0.01), dict(KT=20.0, T=3.0, T4=0.0)],
    "PSS2A": [PSS2A_PSID, dict(PSS2A_PSID, ICS1=5, ICS2=1, M=2, N=4, T6=0.05, TW4=1.0, T7=0.0),
              dict(PSS2A_PSID, ICS1=3, ICS2=5, M=0, N=0, VSTMAX=0.01, VSTMIN=-0.01)],
    "PSS2B": [PSS2B_PSID, dict(PSS2B_PSID, ICS1=5, M=1, N=8, VS1MAX=2.0, VS1MIN=-2.0, T11=0.0),
              dict(PSS2B_PSID, ICS1=3, ICS2=1, M=0, N=0, VS1MAX=0.5, VS1MIN=0.3, VS2MAX=0.01,
                   VS2MIN=-0.01, T10=0.2, T11=0.05)],
    "PSS2C": [PSS2C_PSID,                                  # PT0 = 0.4 pu < PSSOFF: starts off
              dict(PSS2C_PSID, PSSON=0.2, PSSOFF=0.1, T12=0.3, T13=0.1, M=2, N=2),
              dict(PSS2C_PSID, M=0, N=0, VS1MAX=9, VS1MIN=-9, PSSON=0.6, PSSOFF=0.3),   # holds
              dict(PSS2C_PSID, PSSON=-1.0, T13=0.0)],      # no output logic
    "ST2CUT": [dict(MODE=1, MODE2=3, K1=5, K2=0.2, T3=1.0),
               dict(MODE=4, MODE2=1, T3=0.0, VCU=0.1, VCL=-0.1, LSMAX=0.02, LSMIN=-0.02),
               dict(MODE=3, MODE2=5, T1=0.0, T2=0.0, T6=0.0, VCU=0.0, VCL=0.0)],
}


def build(model):
    """The set-up grid of ``model`` (a key of GOVERNORS or STABILIZERS)."""
    if model in GOVERNORS:
        return _grid("governor", model, GOVERNORS[model])
    inst = STABILIZERS[model]
    return _grid("pss", model, inst, at=(0, 2, 3, 4)[:len(inst)], ngen=max(4, len(inst) + 1),
                 governor=("TGOV1", TGOV1))


MODELS = list(GOVERNORS) + list(STABILIZERS)


@pytest.mark.parametrize("model", MODELS)
def test_the_governors_and_stabilizers_evaluate_on_the_strict_namespace_as_on_numpy(model):
    from weakgrid.sim.namespace import namespace_models

    system = build(model)
    assert namespace_models(system) == []
    assert system.components[model].n == len({**GOVERNORS, **STABILIZERS}[model])
    Z = np.concatenate([_points(system, seed=5), _points(system, seed=6)[1:]])
    _check(system, Z)


def test_the_limits_and_switches_are_taken_at_the_perturbed_points():
    """The points reach the branches: output limits, the PSS2C switch off and on."""
    system = build("PSS2C")
    _, ctx = system.device_residual(0.0, _points(system, seed=5))
    on = ctx.out["PSS2C.on"]
    assert np.any(on == 0.0) and np.any(on == 1.0)
    vss, vs = ctx.out["PSS2C.vss"], ctx.out["PSS2C.vs"]
    assert np.any(np.abs(vss) > 0.1) and np.all(np.abs(vs) <= 0.1)
    system = build("TG2")
    _, ctx = system.device_residual(0.0, _points(system, seed=5))
    pout = ctx.out["TG2.pout"][..., 1]
    assert np.any(pout == 0.84) or np.any(pout == 0.76)


def test_the_diesel_and_ggov1_governors_with_a_dead_time_stay_on_numpy():
    """DEGOV1, DEGOV, GGOV1 (their engine dead time reads the time and a history): refused."""
    from weakgrid.sim.namespace import namespace_models

    system = _grid("governor", "DEGOV1", [dict(TMAX=2.0, TMIN=-1.0)], at=(0,))
    assert namespace_models(system) == ["DEGOV1"]
