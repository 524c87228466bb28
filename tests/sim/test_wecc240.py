"""The reduced 240-bus WECC case, PSS/E raw + dyr exactly as shipped (tests/data/wecc240).

Read with the native PSS/E reader (:func:`weakgrid.sim.io.psse.from_psse`) and faulted: a
three-phase fault at CORONADO 500 kV (bus 1101, where PSID's tutorial on this case trips a
line) for 3 cycles. Oracles: the initial point is an equilibrium (every derivative 0 at t = 0),
and the grid rides through a cleared fault (no failure, speeds back near nominal). The case
holds its operating point since the units sharing a bus (39 of its 55 generator buses) keep
their own solved QG of the .raw, as PSS/E initializes them: with an equal share of each bus's Q
a SEXS needed a field voltage above its EMAX and setup refused the case.

No ANDES result beside it: ANDES 2.0 reads the same two files (109 GENROU, 109 SEXS, 47 GAST,
37 TGOV1, 25 HYGOV, 10 IEEEST, 37 REGCA1 + REECB1 + REPCA1) and solves the power flow, but its
initialization fails (checked 2026-12-01, re-checked 2026-12-02): the PI integrator of every
REECB1 (``PIQ_xi``, 37 of 37) starts with a residual of 0.018, its limiter's input at 0 below ``VMIN`` = 0.9.
"""

import hashlib
import re
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

DATA = Path(__file__).parents[1] / "data" / "wecc240"
RAW = DATA / "240busWECC_2018_PSS32_fixed_shunts.raw"
DYR = DATA / "240busWECC_2018_PSS.dyr"
#: git blob ids upstream (tests/data/wecc240/SOURCE.md)
BLOBS = {RAW: "13b1034ea193b423f25882b5c6725e87dc305fec", DYR: "8a75e8cfead80a1b7e869585bb3cd316b99debdd"}
FAULT_BUS, T_ON, T_OFF = 1101, 1.0, 1.05


def dyr_models():
    """Model names of the .dyr records, counted (``IBUS 'MODEL' ID`` heads)."""
    heads = re.findall(r"^\s*\d+\s*,?\s*'([A-Za-z0-9_]+)'", DYR.read_text(), flags=re.M)
    return Counter(h.upper() for h in heads)


def test_vendored_files_are_as_shipped():
    for path, blob in BLOBS.items():
        data = path.read_bytes()
        assert hashlib.sha1(b"blob %d\0" % len(data) + data).hexdigest() == blob, path.name


def test_every_model_of_the_dyr_has_a_registry_class():
    from weakgrid.sim.system import _registry

    models = dyr_models()
    assert sum(models.values()) == 448
    missing = sorted(set(models) - set(_registry()))
    assert not missing, f"weakgrid lacks {missing}"


def test_units_sharing_a_bus_start_within_their_limits():
    """39 of the case's 55 generator buses hold several units. Each starts from its own solved QG
    of the .raw (PSS/E's split): every exciter then starts inside its limits. With an equal share
    of the bus's Q the SEXS of unit (3135, 'NG') would need 3.206 pu > EMAX = 3.0 (setup refused
    it, naming EMAX)."""
    from weakgrid.sim.io import psse

    system, _ = psse.from_psse(RAW, DYR)
    system.setup()
    sexs = system.components["SEXS"]
    k = sexs.names.index("SEXS_3135_NG")
    vf0 = system.sig_defaults["vf0"][system.machine_number(sexs.links[k]["machine"])]
    assert sexs.p["EMIN"][k] < vf0 < sexs.p["EMAX"][k]          # 1.37 pu
    row = system.psse_gen_row[(3135, "NG")]
    assert system.network.pf.Qg[row] * system.Sb == pytest.approx(system.network.gen[row, 2], abs=0.5)
    # an equal share of each bus's Q: that SEXS needs 3.206 pu, above its EMAX
    from weakgrid.sim.errors import DataError

    equal, _ = psse.from_psse(RAW, DYR)
    equal.network.gen_split = "equal"
    with pytest.raises(DataError, match="SEXS_3135_NG") as e:
        equal.setup()
    assert e.value.field == "EMAX"


@pytest.mark.slow
def test_wecc240_imports_and_rides_through_a_three_phase_fault():
    from weakgrid.sim.io import psse
    from weakgrid.sim.events import Fault
    from weakgrid.sim.integrate import Simulator
    from weakgrid.sim.system import _registry

    reg = _registry()
    models = dyr_models()
    lacking = sorted(m for m in models if getattr(reg.get(m), "psse_record", None) is None)
    assert not lacking, f"models of the case without a PSS/E record layout: {lacking}"
    system, events = psse.from_psse(RAW, DYR)      # every one of the 448 records is read
    assert events == []
    system.setup()
    F, _ = system.residual(0.0, system.z0)
    k = int(np.argmax(np.abs(F)))
    assert abs(F[k]) < 1e-6, f"not an equilibrium at t = 0: {system.var_name(k)} = {F[k]:.3g}"
    names = system.machine_names
    res = Simulator(system, dt=1 / 120, record=[f"{n}.omega" for n in names]).run(
        10.0, events=[Fault(FAULT_BUS, T_ON, T_OFF)])
    assert res.ok
    w = np.column_stack([res[f"{n}.omega"] for n in names])
    assert np.abs(w - 1.0).max() > 1e-4                       # the fault is felt
    assert np.abs(w[-1] - 1.0).max() < 5e-3                   # and ridden through
