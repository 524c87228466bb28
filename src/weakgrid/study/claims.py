"""Claims as data: each claim names a rule (``judge``) and the runs it compares by id.

A study's ``[[claims]]`` entry: ``id``, ``case`` (label), ``paper`` (what the paper says),
``rule`` (the verdict rule in words, shown beside the verdict), ``judge`` (one of
:data:`RULES`) and the judge's parameters (run ids, thresholds). A judge receives
``{run id: metrics}`` and returns ``(verdict, measured text)`` or ``(verdict, measured text,
why)`` with verdict ``reproduced`` / ``partly`` / ``tie`` / ``not`` / ``not run``; ``why`` names
what decided it in a few words (a tie and its uncertainty, a failed run and its cause).

Judges that compare two runs take ``step_unc`` (metric → relative step-halving uncertainty,
from the sweeps' half-step check; :func:`weakgrid.study.sweep_maps.metric_uncertainty`) and
apply the one tie rule of :mod:`weakgrid.study.ties`, as the maps do.

**Stability first** (:func:`run_instability`, :func:`stability_gate`; the one definition,
:mod:`weakgrid.study.stability`, which the sweep maps use too): before any judge compares two
runs' costs, ITAE, overshoot or settling, it asks whether each run is stable. A run is *not
stable* when it failed (voltage collapse, loss of synchronism, Newton failure, …: ``failed``
and its ``failure``), or when the stability verdict of its SG speed or dc-link voltage
(``speed_verdict``, ``vdc_verdict``; :func:`weakgrid.study.metrics.stability_verdict`) is
``unstable`` (growing, or running away from its set-point: a dc link ramping away) or
``undamped``. A swing still decaying at the end of a short record (outside its 2 % settling
band) is stable. A metric a run does not record is not evidence either way. Then,
for a pair (the claim's run a, its baseline b):

* a not stable → ``not``, ``why`` naming it ("c1-high-conv-hji not stable: dc link never
  settles within the run"; a failure as "… failed: voltage collapse");
* only b not stable → a win for a without comparing numbers (``reproduced``), saying so;
* both not stable → ``not``, "both runs unstable: no comparison" — a cost or ITAE of two
  diverged runs says nothing about the claim.

Only a pair of two stable runs is compared. Judges whose claim is closeness, not a win
(``itae_close``), count b not stable as ``not`` too; :func:`stability_contrast` (a claim *about*
stability) uses :func:`run_instability` as its definition of stable.
"""

from __future__ import annotations

import fnmatch
import inspect

from .stability import metric, run_instability
from .ties import compare, run_uncertainty, unc_text

__all__ = ["RULES", "STABILITY_NOTE", "judge_all", "judge_claim", "stability_gate"]


def _get(m, rid, key):
    return metric(m.get(rid), key)


def _fmt(v, unit="", nd=3):
    return "n/a" if v is None else f"{v:.{nd}g}{unit}"


def _combine(vs):
    """One verdict of a claim's pairs: all alike → that one; any reproduced or partly →
    partly; else (ties and losses mixed) → not."""
    if not vs:
        return "not run"
    if len(set(vs)) == 1:
        return vs[0]
    if any(v in ("reproduced", "partly") for v in vs):
        return "partly"
    return "not"


#: The rule in words, as every report states it (weakgrid.study.engine.DEFINITIONS).
STABILITY_NOTE = (
    "Stability first (claim table and sweep maps): before comparing two runs' costs, ITAE, "
    "overshoot or settling, each run must be stable: finished (no voltage collapse, loss of "
    "synchronism, Newton failure), SG speed and dc link neither unstable (growing, or running "
    "away from the set-point: ending at its largest deviation, on one side of the set-point "
    "and still moving away) nor undamped (stability verdict), and back: a signal that never "
    "enters its 2 % band and ends beyond half its peak deviation from its set-point is not "
    "stable. A pair where the claim's run "
    "is not stable is 'not' (named); where only the baseline is not stable, a win without "
    "comparing numbers (named); where both are not stable, 'not' — both runs unstable: no "
    "comparison (a map shows such a cell as 'no comparison').")


def stability_gate(m, ia, ib, baseline_unstable="reproduced"):
    """The verdict of a pair decided by stability alone, or None when both runs are stable.

    ``ia`` is the claim's run, ``ib`` its baseline (ids in ``m``, ``{run id: metrics}``).
    Returns ``(verdict, why)``: ``("not", "<ia> <reason>")`` when ia is not stable
    (:func:`run_instability`); ``(baseline_unstable, "<ib> <reason>; <ia> stable: a win
    without comparing")`` when only ib is not (pass ``"not"`` for a claim of closeness);
    ``("not", "both runs unstable: no comparison (…)")`` when neither is. None: compare them.
    """
    wa, wb = run_instability(m.get(ia)), run_instability(m.get(ib))
    if wa and wb:
        return "not", f"both runs unstable: no comparison ({ia} {wa}; {ib} {wb})"
    if wa:
        return "not", f"{ia} {wa}"
    if wb:
        tail = ("a win without comparing" if baseline_unstable == "reproduced"
                else "not the same performance")
        return baseline_unstable, f"{ib} {wb}; {ia} stable: {tail}"
    return None


def _cmp(m, ia, ib, key, step_unc):
    """The tie rule (:func:`weakgrid.study.ties.compare`) on ``key`` of runs ia and ib:
    ``("a" | "b" | "tie" | "n/a", text)``."""
    a, b = _get(m, ia, key), _get(m, ib, key)
    if a is None or b is None:
        return "n/a", ""
    step = (step_unc or {}).get(key)
    who, tol = compare(a, b, run_uncertainty(m.get(ia), key, step),
                       run_uncertainty(m.get(ib), key, step))
    return who, unc_text(a, b, tol)


_COST_NAMES = {"control_cost": "applied control cost Σu'Ru·T",
               "control_cost_demanded": "demanded control cost Σu'Ru·T",
               "running_cost_18": "running cost of (18) Σx'Qx+u'Ru (Fig. 10)"}


def cost_less(m, pairs, reduction=0.2, settling_tol=0.25, settling="vdc_settling_s",
              metric="control_cost", step_unc=None):
    """Run a needs ≥ ``reduction`` less ``metric`` (a cost) than run b, same settling ±tol.

    A difference within the measured uncertainty (:mod:`weakgrid.study.ties`) is a tie; a
    smaller cost beyond it is ``partly``. Costs are compared only between two stable runs
    (:func:`stability_gate`): a not stable is ``not``, only b not stable ``reproduced``, both
    ``not`` ("both runs unstable: no comparison").
    """
    out, verdicts, why = [], [], []
    name = _COST_NAMES.get(metric, metric)
    for label, ia, ib in pairs:
        if ia not in m or ib not in m:
            continue
        loss = stability_gate(m, ia, ib)
        if loss:
            out.append(f"{label}: {loss[1]}")
            verdicts.append(loss[0])
            why.append(f"{label}: {loss[1]}")
            continue
        a, b = _get(m, ia, metric), _get(m, ib, metric)
        sa, sb = _get(m, ia, settling), _get(m, ib, settling)
        if a is None or b is None or b == 0:
            continue
        red = 1 - a / b
        who, utext = _cmp(m, ia, ib, metric, step_unc)
        same = sa is not None and sb is not None and abs(sa - sb) <= settling_tol * max(sb, 1e-9)
        extra = ""
        if metric == "control_cost":
            da, db = _get(m, ia, "control_cost_demanded"), _get(m, ib, "control_cost_demanded")
            extra = f"; demanded before the rating limit: {_fmt(da)} vs {_fmt(db)}"
        out.append(f"{label}: {ia} {name} {_fmt(a)} vs {ib} {_fmt(b)} "
                   f"({red * 100:+.1f} % less; {utext}){extra}; settling "
                   f"{_fmt(sa, ' s')} vs {_fmt(sb, ' s')}")
        if who == "tie":
            verdicts.append("tie")
            why.append(f"{label}: tie, {utext}")
        else:
            verdicts.append("reproduced" if red >= reduction and same else "partly"
                            if who == "a" else "not")
    return _combine(verdicts), "; ".join(out), "; ".join(why)


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
    """ITAE of the named metrics of two runs within ``close`` (partly: ``partly``).

    Only two stable runs are compared (:func:`stability_gate`); either not stable is ``not``
    (one stable and one not do not perform "the same"; two unstable runs: no comparison).
    """
    out, vs, why = [], [], []
    for label, ia, ib in pairs:
        if ia not in m or ib not in m:
            continue
        gate = stability_gate(m, ia, ib, baseline_unstable="not")
        if gate:
            out.append(f"{label}: {gate[1]}")
            vs.append(gate[0])
            why.append(f"{label}: {gate[1]}")
            continue
        vals = [(_get(m, ia, k), _get(m, ib, k)) for k in metrics]
        if any(None in v for v in vals):
            continue
        rel = [abs(b - a) / max(a, 1e-12) for a, b in vals]
        out.append(f"{label}: " + ", ".join(f"{k} differs by {r * 100:.1f} %"
                                            for k, r in zip(metrics, rel)))
        vs.append("reproduced" if max(rel) <= close else "partly" if max(rel) <= partly
                  else "not")
    return _combine(vs), "; ".join(out), "; ".join(why)


def _pair_verdict(results):
    """A pair's verdict from its comparisons (each "a" won, "b" won, "tie"; "n/a" skipped)."""
    rs = [r for r in results if r != "n/a"]
    if not rs:
        return None
    if all(r == "a" for r in rs):
        return "reproduced"
    if all(r == "tie" for r in rs):
        return "tie"
    return "partly" if "a" in rs else "not"


def beats_baselines(m, groups, step_unc=None):
    """Lower ITAE of speed and dc-link voltage than each baseline (or the baseline failed).

    ``groups``: ``[[label, run, baseline label, baseline run], …]``. Differences within the
    measured uncertainty are ties (:mod:`weakgrid.study.ties`). Only two stable runs are
    compared (:func:`stability_gate`): ours not stable is ``not``, only the baseline not
    stable a win, both ``not``.
    """
    out, vs, why = [], [], []
    for label, hid, base, bid in groups:
        if hid not in m or bid not in m:
            continue
        loss = stability_gate(m, hid, bid)
        if loss:
            out.append(f"{label} vs {base}: {loss[1]}")
            vs.append(loss[0])
            why.append(f"{label} vs {base}: {loss[1]}")
            continue
        h, hv = _get(m, hid, "speed_itae"), _get(m, hid, "vdc_itae")
        b, bv = _get(m, bid, "speed_itae"), _get(m, bid, "vdc_itae")
        if h is None or b is None:
            continue
        cs, ts = _cmp(m, hid, bid, "speed_itae", step_unc)
        cv, tv = _cmp(m, hid, bid, "vdc_itae", step_unc)
        out.append(f"{label} vs {base}: ITAE speed {_fmt(h)} vs {_fmt(b)} ({ts}), dc-link "
                   f"{_fmt(hv)} vs {_fmt(bv)}" + (f" ({tv})" if tv else ""))
        v = _pair_verdict([cs, cv])
        vs.append(v)
        if "tie" in (cs, cv):
            why.append(f"{label} vs {base}: tie on " + " and ".join(
                k for k, c in (("speed", cs), ("dc link", cv)) if c == "tie"))
    return _combine(vs), "; ".join(out), "; ".join(why)


def less_overshoot_settling(m, pairs, overshoot="speed_backswing_pu",
                            settling="speed_settling_s", step_unc=None):
    """Run a has a smaller overshoot (backswing) and settling time than run b.

    Each comparison goes through the tie rule (:mod:`weakgrid.study.ties`): a difference
    within the measured uncertainty (step halving + the metric's sensitivity to its own
    definition, e.g. the settling band) is a tie. Only two stable runs are compared
    (:func:`stability_gate`): a not stable (failed, unstable or undamped) is
    ``not``, only b not stable a win (``reproduced``), both ``not``.
    """
    out, vs, why = [], [], []
    for label, h, l_ in pairs:
        if h not in m or l_ not in m:
            continue
        loss = stability_gate(m, h, l_)
        if loss:
            out.append(f"{label}: {loss[1]}")
            vs.append(loss[0])
            why.append(f"{label}: {loss[1]}")
            continue
        oh, ol = _get(m, h, overshoot), _get(m, l_, overshoot)
        sh, sl = _get(m, h, settling), _get(m, l_, settling)
        if oh is None or ol is None:
            continue
        co, to = _cmp(m, h, l_, overshoot, step_unc)
        cs, ts = _cmp(m, h, l_, settling, step_unc)
        if cs == "n/a" and (sh is None) != (sl is None):  # one still decaying at the end
            cs = "a" if sh is not None else "b"          # (stable, not settled): the other wins
        out.append(f"{label}: speed overshoot (backswing) {_fmt(oh)} vs {_fmt(ol)} pu ({to}), "
                   f"settling {_fmt(sh, ' s')} vs {_fmt(sl, ' s')}" + (f" ({ts})" if ts else ""))
        vs.append(_pair_verdict([co, cs]))
        if "tie" in (co, cs):
            why.append(f"{label}: tie on " + " and ".join(
                k for k, c in (("overshoot", co), ("settling", cs)) if c == "tie"))
    return _combine(vs), "; ".join(out), "; ".join(why)


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
    as not stable (it was not run). Stable is :func:`run_instability`'s (the comparing
    judges' definition): finished, no signal unstable or undamped, every recorded signal
    settling within the run.
    """
    runs = [tuple(o) for o in others] + [tuple(winner)]
    v = {lbl: (m.get(rid) or {}) for lbl, rid in runs}
    if not any(v.values()):
        return "not run", ""
    verdict = {lbl: (run_instability(r) or "stable") for lbl, r in v.items() if r}
    text = ", ".join(f"{c}: {s}" for c, s in verdict.items())
    ok_w = verdict.get(winner[0]) == "stable"
    ok_o = [verdict.get(lbl, "") != "stable" for lbl, _ in others]
    if ok_w and all(ok_o):
        return "reproduced", text
    return ("partly" if ok_w and any(ok_o) else "not"), text


RULES = {"cost_less": cost_less, "power_share": power_share, "itae_close": itae_close,
         "beats_baselines": beats_baselines, "less_overshoot_settling": less_overshoot_settling,
         "max_below": max_below, "stability_contrast": stability_contrast}

_META = ("id", "case", "paper", "rule", "judge")


def judge_claim(claim: dict, metrics_by_id: dict, step_unc: dict | None = None) -> dict:
    """The verdict of one claim (a dict of a study file) on ``{run id: metrics}``.

    ``step_unc``: metric → relative step-halving uncertainty (None: not measured).
    Returns ``id``, ``case``, ``paper`` (the claim), ``rule``, ``verdict``, ``measured`` and
    ``why`` (what decided the verdict: a tie and its uncertainty, a failed run; may be "").
    """
    params = {k: v for k, v in claim.items() if k not in _META}
    fn = RULES[claim["judge"]]
    if "step_unc" in inspect.signature(fn).parameters:
        params["step_unc"] = step_unc
    verdict, measured, why = (*fn(metrics_by_id, **params), "")[:3]
    return {"id": claim["id"], "case": claim.get("case", ""), "paper": claim["paper"],
            "rule": claim["rule"], "verdict": verdict, "measured": measured, "why": why}


def judge_all(claims: list, metrics_by_id: dict, step_unc: dict | None = None) -> list[dict]:
    """Verdicts of ``claims`` (dicts from study files) on ``{run id: metrics}``."""
    return [judge_claim(c, metrics_by_id, step_unc) for c in claims]
