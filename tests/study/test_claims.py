"""The verdict rules of the paper's claims (data in the shipped studies), on synthetic metrics
(every branch can fail)."""

from types import SimpleNamespace

from weakgrid.study.claims import judge_all, judge_claim
from weakgrid.study.reproduce import paper_studies


def claims():
    return [c for st in paper_studies() for c in st.data["claims"]]


def by_id():
    return {c["id"]: SimpleNamespace(judge=lambda m, c=c: (judge_claim(c, m)["verdict"],))
            for c in claims()}


def test_nothing_run_gives_not_run():
    cs = claims()
    assert len(cs) == 10     # 8 claims of the paper + 2 extra rows (per-load redesign)
    assert all(c["verdict"] == "not run" for c in judge_all(cs, {}))


def test_cost_claim():
    judge = by_id()["C1-cost"].judge
    m = {"c1-high-conv-hji": {"control_cost": 0.7, "vdc_settling_s": 1.0},
         "c1-high-conv-nonlinear-29": {"control_cost": 1.0, "vdc_settling_s": 1.1}}
    assert judge(m)[0] == "reproduced"
    m["c1-high-conv-hji"]["vdc_settling_s"] = 3.0
    assert judge(m)[0] == "partly"
    m["c1-high-conv-hji"]["control_cost"] = 1.5
    assert judge(m)[0] == "not"


def test_low_load_claim_needs_the_contrast():
    judge = by_id()["C2-low-load"].judge
    run = lambda v, failed=False: {"speed_verdict": v, "failed": failed}  # noqa: E731
    m = {"c2-low-f100-hji": run("stable"), "c2-low-f100-lqr": run("unstable", True),
         "c2-low-f100-pss-only": run("undamped")}
    assert judge(m)[0] == "reproduced"
    m["c2-low-f100-pss-only"] = run("stable")
    assert judge(m)[0] == "partly"
    m["c2-low-f100-lqr"] = run("stable")
    assert judge(m)[0] == "not"


def test_power_share_claim():
    judge = by_id()["C1-power"].judge
    m = {"c1-high-conv-hji": {"p_series_peak_mw": 1.2, "p_series_peak_pct_line": 5.0}}
    assert judge(m)[0] == "reproduced"
    m["c1-high-conv-hji"]["p_series_peak_pct_line"] = 15.0
    assert judge(m)[0] == "partly"
    m["c1-high-conv-hji"]["p_series_peak_pct_line"] = 40.0
    assert judge(m)[0] == "not"
