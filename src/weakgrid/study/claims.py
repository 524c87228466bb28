"""Claims as data: each claim names a rule (``judge``) and the runs it compares by id.

A study's ``[[claims]]`` entry: ``id``, ``case`` (label), ``paper`` (what the paper says),
``rule`` (the verdict rule in words, shown beside the verdict), ``judge`` (one of
:data:`RULES`) and the judge's parameters (run ids, thresholds). A judge receives
``{run id: metrics}`` and returns ``(verdict, measured text)`` with verdict ``reproduced`` /
``partly`` / ``not`` / ``not run``.
"""

from __future__ import annotations

import fnmatch
import math

__all__ = ["RULES", "judge_all", "judge_claim"]


def _get(m, rid, key):
    r = m.get(rid)
    if r is None:
        return None
    v = r.get(key)
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else v


def _fmt(v, unit="", nd=3):
    return "n/a" if v is None else f"{v:.{nd}g}{unit}"


def _combine(vs):
    if not vs:
        return "not run"
    if all(v == "reproduced" for v in vs):
        return "reproduced"
    if all(v == "not" for v in vs):
        return "not"
    return "partly"


def cost_less(m, pairs, reduction=0.2, settling_tol=0.25, settling="vdc_settling_s"):
    """Run a needs ≥ ``reduction`` less applied control cost than run b, same settling ±tol."""
    out, verdicts = [], []
    for label, ia, ib in pairs:
        a, b = _get(m, ia, "control_cost"), _get(m, ib, "control_cost")
        da, db = _get(m, ia, "control_cost_demanded"), _get(m, ib, "control_cost_demanded")
        ra, rb = _get(m, ia, "running_cost_18"), _get(m, ib, "running_cost_18")
        sa, sb = _get(m, ia, settling), _get(m, ib, settling)
        if a is None or b is None or b == 0:
            continue
        red = 1 - a / b
        same = sa is not None and sb is not None and abs(sa - sb) <= settling_tol * max(sb, 1e-9)
        out.append(f"{label}: {ia} control cost {_fmt(a)} vs {ib} {_fmt(b)} "
                   f"({red * 100:+.0f} % less; demanded before the rating limit: {_fmt(da)} "
                   f"vs {_fmt(db)}); running cost of (18) {_fmt(ra)} vs {_fmt(rb)}; settling "
                   f"{_fmt(sa, ' s')} vs {_fmt(sb, ' s')}")
        verdicts.append("reproduced" if red >= reduction and same else "partly" if red > 0
                        else "not")
    return _combine(verdicts), "; ".join(out)


def power_share(m, runs, lo, hi, paper_pct):
    """Peak series power in % of the line power within [lo, hi] (partly: within ×4 of paper)."""
    out, vs = [], []
    for rid in runs:
        pk = _get(m, rid, "p_series_peak_mw")
        pct = _get(m, rid, "p_series_peak_pct_line")
        if pk is None or pct is None:
            continue
        unit = (f"{pk:.3g} MW" if pk >= 0.1 else f"{pk * 1e3:.3g} kW")
        out.append(f"{rid}: peak {unit} = {pct:.2g} % of the line power")
        vs.append("reproduced" if lo <= pct <= hi else
                  "partly" if paper_pct / 4 <= pct <= paper_pct * 4 else "not")
    return _combine(vs), "; ".join(out)


def itae_close(m, pairs, close=0.1, partly=0.3, metrics=("speed_itae", "vdc_itae")):
    """ITAE of the named metrics of two runs within ``close`` (partly: ``partly``)."""
    out, vs = [], []
    for label, ia, ib in pairs:
        vals = [(_get(m, ia, k), _get(m, ib, k)) for k in metrics]
        if any(None in v for v in vals):
            continue
        rel = [abs(b - a) / max(a, 1e-12) for a, b in vals]
        out.append(f"{label}: " + ", ".join(f"{k} differs by {r * 100:.1f} %"
                                            for k, r in zip(metrics, rel)))
        vs.append("reproduced" if max(rel) <= close else "partly" if max(rel) <= partly
                  else "not")
    return _combine(vs), "; ".join(out)


def beats_baselines(m, groups):
    """Lower ITAE of speed and dc-link voltage than each baseline (or the baseline failed).

    ``groups``: ``[[label, run, baseline label, baseline run], …]``.
    """
    out, vs = [], []
    for label, hid, base, bid in groups:
        h, hv = _get(m, hid, "speed_itae"), _get(m, hid, "vdc_itae")
        b, bv = _get(m, bid, "speed_itae"), _get(m, bid, "vdc_itae")
        failed = (m.get(bid) or {}).get("failed")
        if h is None or (b is None and not failed):
            continue
        if failed:
            out.append(f"{label}: {base} run failed (lost stability), {hid} did not")
            vs.append("reproduced")
            continue
        better = h < b and (hv is None or bv is None or hv < bv)
        out.append(f"{label} vs {base}: ITAE speed {_fmt(h)} vs {_fmt(b)}, dc-link "
                   f"{_fmt(hv)} vs {_fmt(bv)}")
        vs.append("reproduced" if better else "partly" if h < b or
                  (hv is not None and bv is not None and hv < bv) else "not")
    return _combine(vs), "; ".join(out)


def less_overshoot_settling(m, pairs, overshoot="speed_backswing_pu",
                            settling="speed_settling_s"):
    """Run a has a smaller overshoot (backswing) and settling time than run b."""
    out, vs = [], []
    for label, h, l_ in pairs:
        oh, ol = _get(m, h, overshoot), _get(m, l_, overshoot)
        sh, sl = _get(m, h, settling), _get(m, l_, settling)
        if oh is None or ol is None:
            continue
        out.append(f"{label}: speed overshoot (backswing) {_fmt(oh)} vs {_fmt(ol)} pu, "
                   f"settling {_fmt(sh, ' s')} vs {_fmt(sl, ' s')}")
        wins = [oh < ol, sh is not None and (sl is None or sh < sl)]
        vs.append("reproduced" if all(wins) else "partly" if any(wins) else "not")
    return _combine(vs), "; ".join(out)


def max_below(m, runs, below, partly, metric="vu_peak_pu"):
    """The largest ``metric`` over the runs matching the patterns is below ``below``."""
    rids = sorted(k for k in m if any(fnmatch.fnmatchcase(k, p) for p in runs))
    vals = [(k, _get(m, k, metric)) for k in rids]
    vals = [(k, v) for k, v in vals if v is not None]
    if not vals:
        return "not run", ""
    worst = max(v for _, v in vals)
    text = ", ".join(f"{k}: {v:.3g} pu" for k, v in vals)
    return ("reproduced" if worst < below else "partly" if worst < partly else "not"), text


def stability_contrast(m, winner, others):
    """``winner = [label, run]`` stable while each of ``others`` is unstable or undamped.

    partly: the winner stable and one of the others not stable. A missing other run counts
    as not stable (it was not run).
    """
    runs = [tuple(o) for o in others] + [tuple(winner)]
    v = {lbl: (m.get(rid) or {}) for lbl, rid in runs}
    if not any(v.values()):
        return "not run", ""
    verdict = {lbl: ("unstable" if r.get("failed") else r.get("speed_verdict", "n/a"))
               for lbl, r in v.items() if r}
    text = ", ".join(f"{c}: {s}" for c, s in verdict.items())
    ok_w = verdict.get(winner[0]) == "stable"
    ok_o = [verdict.get(lbl) in ("unstable", "undamped", None) for lbl, _ in others]
    if ok_w and all(ok_o):
        return "reproduced", text
    return ("partly" if ok_w and any(ok_o) else "not"), text


RULES = {"cost_less": cost_less, "power_share": power_share, "itae_close": itae_close,
         "beats_baselines": beats_baselines, "less_overshoot_settling": less_overshoot_settling,
         "max_below": max_below, "stability_contrast": stability_contrast}

_META = ("id", "case", "paper", "rule", "judge")


def judge_claim(claim: dict, metrics_by_id: dict) -> dict:
    """The verdict of one claim (a dict of a study file) on ``{run id: metrics}``.

    Returns ``id``, ``case``, ``paper`` (the claim), ``rule``, ``verdict`` and ``measured``.
    """
    params = {k: v for k, v in claim.items() if k not in _META}
    verdict, measured = RULES[claim["judge"]](metrics_by_id, **params)
    return {"id": claim["id"], "case": claim.get("case", ""), "paper": claim["paper"],
            "rule": claim["rule"], "verdict": verdict, "measured": measured}


def judge_all(claims: list, metrics_by_id: dict) -> list[dict]:
    """Verdicts of ``claims`` (dicts from study files) on ``{run id: metrics}``."""
    return [judge_claim(c, metrics_by_id) for c in claims]
