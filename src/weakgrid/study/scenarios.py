"""The paper's scenarios (Section V), as data.

Case 1: three-phase fault 0.2–0.25 s, the UPQC controller bypassed during the
fault, high and low load; HJI and (29) with the conventional and the reduced
UPQC, LQR, the PQ baseline, PSS alone and no supplementary control.
Case 2: fault at the UPQC bus 3.0–3.2 s and 3.0–3.1 s at high load, 3.0–3.1 s
at low load; HJI against LQR (its initial policy), PSS alone.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

__all__ = ["Scenario", "paper_scenarios", "scenario_by_id"]


@dataclass(frozen=True)
class Scenario:
    """One simulation run.

    Attributes
    ----------
    id : str
    case : str
    load : {"high", "low"}
    upqc : {"conventional", "reduced"}
    controller : str
        See :mod:`weakgrid.study.controllers`.
    t_fault, t_clear : float
        Three-phase fault application and clearance, s (the UPQC controller is
        bypassed in between).
    t_end : float
        Simulated time, s.
    """

    id: str
    case: str
    load: str
    upqc: str
    controller: str
    t_fault: float
    t_clear: float
    t_end: float

    def to_dict(self):
        return asdict(self)


C1, C2 = "case1-weak-grid", "case2-lv-microgrid"


def paper_scenarios(quick: bool = False) -> list[Scenario]:
    """Every run of the report (``quick``: shorter runs and the essential subset)."""
    out = []
    t1 = 3.0 if quick else 6.0
    for load in ("high", "low"):
        ctrls = ["hji", "nonlinear-29", "pq"] if quick else \
            ["hji", "nonlinear-29", "lqr", "pq", "pss-only", "none"]
        for c in ctrls:
            out.append(Scenario(f"c1-{load}-conv-{c}", C1, load, "conventional", c, 0.2, 0.25, t1))
        for c in (["hji"] if quick else ["hji", "nonlinear-29"]):
            out.append(Scenario(f"c1-{load}-red-{c}", C1, load, "reduced", c, 0.2, 0.25, t1))
    t2 = 6.0 if quick else 10.0
    runs2 = [("high", 3.2), ("high", 3.1), ("low", 3.1)]
    if quick:
        runs2 = [("high", 3.1), ("low", 3.1)]
    for load, tc in runs2:
        tag = f"f{int(round((tc - 3.0) * 1000))}"
        for c in (["hji", "lqr"] if quick else ["hji", "lqr", "pss-only"]):
            out.append(Scenario(f"c2-{load}-{tag}-{c}", C2, load, "conventional", c, 3.0, tc, t2))
    return out


def scenario_by_id(sid: str, quick: bool = False) -> Scenario:
    """The scenario of :func:`paper_scenarios` with id ``sid``; a clear error if there is none."""
    for s in paper_scenarios(quick):
        if s.id == sid:
            return s
    from ..game.errors import ParameterError

    raise ParameterError("scenario", sid, "unknown scenario id; see `weakgrid simulate --list`")
