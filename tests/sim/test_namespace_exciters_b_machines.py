"""EXAC4, EXPIC1, EXST1, IEEET1, IEEET3, IEEEVC, SCRX, ST6B, ST8C, GENSAL, GENSAE, GENROE and ZIP
on another array namespace (issue #21).

The oracle is NumPy itself (as :mod:`test_namespace`): each model's residual and outputs on
``array_api_strict`` equal NumPy's bit for bit, on grids whose instances differ in their
options, at the initial point and at perturbed points far enough out to take the limits."""

from __future__ import annotations

import numpy as np
import pytest
from sim_cases import two_machine_case
from test_exciters_psse import EXPIC1, SCRX, SCRX_FAST, ST6B, ST8C, ST8C_COMPOUND
from test_namespace import _check, _no_numpy_on_strict_arrays, _points  # noqa: F401

from weakgrid.sim.namespace import namespace_models
from weakgrid.sim.system import System

pytest.importorskip("array_api_strict")

ROU = dict(Sn=100, M=7.0, D=0.0, ra=0.002, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55,
           xd2=0.25, xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
SAL = dict(Td10=5.0, Td20=0.05, Tq20=0.2, M=10.0, D=0.0, xd=1.0, xq=0.75, xd1=0.4, xd2=0.25,
           xq2=0.25, xl=0.1, S10=0.11, S12=0.62, Sn=100.0)
#: the machines' variants: with and without saturation, stator resistance, PSS/E's shaft
MACHINE_VARIANTS = ({}, dict(S10=0.0, S12=0.0), dict(ra=0.003), dict(psse_shaft=0.0, D=1.0))


def _grid(machine="GENROU", exciter=None, variants=(), compensator=None, zip_loads=False):
    """Four generators, two on each of two buses (one a slack), of type ``machine``; generator
    ``k`` gets ``exciter`` with the parameters ``variants[k]`` (and the compensator IEEEVC with
    ``compensator[k]``, a SEXS exciter if none given); ``zip_loads``: ZIP loads on both buses."""
    case = two_machine_case(x_line=0.2, p=0.8)
    g = case["gen"]
    extra = g.copy()
    extra[0, 1] = 40.0
    extra[1, 1] = 0.0
    case["gen"] = np.vstack([g, extra])
    if zip_loads:
        case["bus"][0, 2:4] = [60.0, 25.0]
        case["bus"][1, 2:4] = [30.0, 10.0]
    s = System(case)
    base = SAL if machine in ("GENSAL", "GENSAE") else ROU
    for k in range(4):
        prm = dict(base, **MACHINE_VARIANTS[k])
        prm["M"] += k
        s.add_machine(machine, f"G{k}", gen=k, **prm)
    if compensator is not None:
        for k, c in enumerate(compensator):
            s.add_exciter("SEXS", f"E{k}", machine=f"G{k}", TATB=0.1, TB=10.0, K=100.0, TE=0.1,
                          EMIN=-5.0, EMAX=5.0)
            s.add_compensator("IEEEVC", f"C{k}", machine=f"G{k}", **c)
    for k, v in enumerate(variants):
        s.add_exciter(exciter, f"E{k}", machine=f"G{k}", **v)
    if zip_loads:
        from weakgrid.sim.loads import ZIP

        z = s.add_component(ZIP())
        z.add_zip("Z0", bus=0, P0=0.3, Q0=0.1, kpp=50, kpi=30, kpz=20, kqp=10, kqi=0, kqz=90)
        z.add_zip("Z1", bus=0, P0=0.2, Q0=0.1, kpp=0, kpi=100, kpz=0, kqp=100, kqi=0, kqz=0)
        z.add_zip("Z2", bus=1, P0=0.2, Q0=0.05, kpp=20, kpi=20, kpz=60, kqp=0, kqi=50, kqz=50)
    s.setup()
    return s


def _far(system, seed):
    """The points of :func:`_points` and one further out (states and voltages moved by up to ±5)."""
    Z = _points(system, seed)
    rng = np.random.default_rng(seed + 100)
    return np.concatenate([Z, (system.z0 + rng.uniform(-5, 5, system.z0.shape))[None]])


def _run(system, seed=0):
    assert namespace_models(system) == []
    _check(system, _far(system, seed))


EXCITERS = {
    "EXAC4": ({}, dict(TR=0.0, KC=0.05), dict(TC=0.0, TB=0.0, VIMAX=0.05, VIMIN=-0.05),
              dict(KA=50.0, TA=0.02, VRMAX=6.0, VRMIN=-3.0)),
    "EXPIC1": (EXPIC1, dict(EXPIC1, TE=0.0), dict(EXPIC1, KP=0.0, KI=0.0, KC=0.0),
               dict(EXPIC1, TF2=0.0, KF=0.02, TA4=0.0, SE1=0.0)),
    "EXST1": ({}, dict(VR_limited=0.0), dict(VR_Vt=1.0, KC=0.1), dict(VR_limited=0.0, VR_Vt=1.0,
                                                                     TR=0.0, TC=0.0, TB=0.0)),
    "IEEET1": ({}, dict(TA=0.0), dict(VRMAX=0.0, E1=2.8, SE1=0.05, E2=3.7, SE2=0.3),
               dict(TR=0.0, KF=0.0)),
    "IEEET3": ({}, dict(TA=0.0), dict(VRMAX=0.0, TR=0.0), dict(KI=0.5, VBMAX=3.0)),
    "SCRX": (SCRX, dict(SCRX, CSWITCH=0), dict(SCRX, CSWITCH=0, rc_rfd=1.0), dict(SCRX_FAST, TE=0.0)),
    "ST6B": (ST6B, dict(ST6B, TG=0.0, TR=0.0), dict(ST6B, KDA=0.5, TDA=0.05, OEL=1), dict(ST6B, KIA=0.0)),
    "ST8C": (ST8C, dict(ST8C, SW1=2), ST8C_COMPOUND, dict(ST8C_COMPOUND, TA=0.0, SW1=1)),
}


@pytest.mark.parametrize("model", sorted(EXCITERS))
def test_the_exciters_evaluate_on_the_strict_namespace_as_on_numpy(model):
    system = _grid("GENROU", model, EXCITERS[model])
    _run(system, seed=5)


@pytest.mark.parametrize("machine", ["GENSAL", "GENSAE", "GENROE"])
def test_the_machines_evaluate_on_the_strict_namespace_as_on_numpy(machine):
    """Saturated and not, with and without ra, both shafts; with an exciter on each."""
    system = _grid(machine, "SEXS", [dict(TATB=0.1, TB=10.0, K=100.0, TE=0.1, EMIN=-5.0, EMAX=5.0)] * 4)
    _run(system, seed=6)


def test_the_voltage_compensator_and_zip_loads_evaluate_on_the_strict_namespace_as_on_numpy():
    """IEEEVC on every machine (both bases, signs of xc), ZIP loads with two on one bus."""
    comp = (dict(rc=0.01, xc=0.08), dict(rc=0.0, xc=-0.05, on_Sb=1.0), dict(rc=0.02, xc=0.0),
            dict(rc=0.0, xc=0.1, on_Sb=1.0))
    system = _grid("GENSAL", compensator=comp, zip_loads=True)
    assert not system.components["ZIP"]._uniq
    _run(system, seed=7)
