"""Zero-parameter conventions of every model, against ANDES (issue 8, item 5).

PSS/E data use zeros for "absent": VCU = VCL = 0 means no IEEEST output cut-off,
T5 = 0 turns the IEEEST washout into a lag, zero lead-lag/filter time constants pass
the signal, TR = 0 removes a sensing lag, S10 = S12 = 0 means no saturation, ...
Each variant of ANDES's kundur_ieeest case (fault at bus 8, 1.00-1.05 s, IEEEST gain
KS raised to 10 so that the PSS matters) is run in both tools at the same step and must
agree as the other peer cases do (2e-4 pu of speed, 1 deg of relative angle; the
unedited case agrees to 4.4e-5 pu / 0.2 deg at this step).
"""

import pytest

andes = pytest.importorskip("andes")

from weakgrid.sim.peer.andes_runs import compare, run_andes, run_weakgrid  # noqa: E402

pytestmark = [pytest.mark.andes, pytest.mark.slow]

CASE = "kundur/kundur_ieeest.xlsx"
KS10 = [("IEEEST", "KS", 10.0)]
VARIANTS = {
    "IEEEST VCU=VCL=0": [("IEEEST", "VCU", 0.0), ("IEEEST", "VCL", 0.0)] + KS10,
    "IEEEST T5=0": [("IEEEST", "T5", 0.0)] + KS10,
    "IEEEST A1..A6=T1..T4=0": [("IEEEST", p, 0.0) for p in
                               ("A1", "A2", "A3", "A4", "A5", "A6", "T1", "T2", "T3", "T4")] + KS10,
    "EXDC2 TR=TB=TC=KF1=0": [("EXDC2", p, 0.0) for p in ("TR", "TB", "TC", "KF1")],
    "TGOV1 T2=0": [("TGOV1", "T2", 0.0)],
    "GENROU S10=S12=0": [("GENROU", "S10", 0.0), ("GENROU", "S12", 0.0)],
    "GENROU S12=0": [("GENROU", "S10", 0.1), ("GENROU", "S12", 0.0)],
}
KW = dict(fault=(8, 1.0, 1.05), disable_toggles=True)


@pytest.mark.parametrize("name", list(VARIANTS))
def test_zero_parameters_as_andes(name):
    h = 1 / 60
    a = run_andes(CASE, 10.0, h, edit=VARIANTS[name], **KW)
    w = run_weakgrid(CASE, 10.0, h, edit=VARIANTS[name], **KW)
    assert a["ok"] and w["ok"]
    dw, dd = compare(a, w)
    assert dw < 2e-4, f"speed difference {dw:.3g} pu"
    assert dd < 1.0, f"relative angle difference {dd:.3g} deg"
