"""Census of ANDES's shipped cases: how many import into weakgrid.sim, run, and match ANDES.

Every case input ANDES ships is tried: each ``.xlsx``, ``.json`` and ``.m`` file, each
PSS/E ``.raw`` alone, and each ``.raw`` + ``.dyr`` pair (the ``.dyr`` with the ``.raw`` of its
folder whose name is the longest prefix of its own). For each:

1. ANDES's parser loads it (``andes.load(..., setup=False)``); the case's own timed events are
   switched off and a three-phase fault is added at the bus of the first in-service PQ load,
   1.0-1.05 s;
2. weakgrid imports it (:func:`weakgrid.sim.io.andes.from_andes`) -- or reports why not (all
   unsupported models at once);
3. both simulate ``--tf`` seconds (default 5) at the same fixed step ``--h`` (default 1/120 s);
4. speeds and rotor angles relative to the first machine are compared; a case *matches* when
   they agree within 2e-5 pu and 0.5 deg. A case within 2e-4 pu that does not match is re-run
   in both tools at ``h/2`` and, if the gap shrank, at ``h/4``: if it then matches, the
   difference was step error ("match at h/2", "match at h/4").

Two columns: weakgrid with its standard models (``conventions="standard"``, the default of the
importer) and with ANDES 2.0's documented departures from them (``conventions="andes"``: EXAC1
and ESDC2A without their sensing lag, IEEEX1 with constant regulator limits, EXST1's output
limiter, HYGOV's system-base equations; see
:data:`weakgrid.sim.io.andes.ANDES_CONVENTIONS`). A case none of whose models has such a
departure gets the same result in both (``"andes": {"same": true}``); otherwise weakgrid runs
again with the ANDES conventions against the same ANDES run (with the same step halving).

ANDES 2.0 cannot initialize an ``ESDC1A`` (its regulator keeps limit services it never
evaluates); its runs are patched with :func:`weakgrid.sim.peer.andes_case.fix_andes_esdc1a`
(a no-op without ESDC1A), which points the regulator at its constant limits.

Each case runs in its own subprocess with a time limit (``--timeout``, default 300 s). Results
are written atomically to ``--out`` (default ``benchmarks/andes_case_census.json``) after every
case; a re-run skips the cases already there (``--fresh`` to start over). The summary counts the
outcomes and lists the models still missing, with the number of cases each one blocks.

Run:  PYTHONPATH=src python benchmarks/andes_case_census.py [--tf 5] [--only kundur,ieee39] [--redo]
      [--fresh]   (``--redo``: run the cases selected by ``--only`` again even if already in the file)
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

DW_TOL, DD_TOL = 2e-5, 0.5


def case_inputs():
    """``[(key, path, addfile)]`` of every case input shipped with ANDES."""
    import andes

    root = Path(andes.get_case("kundur/kundur_full.xlsx")).parents[1]
    out = []
    for p in sorted(root.rglob("*")):
        if "__pycache__" in p.parts or not p.is_file():
            continue
        rel = str(p.relative_to(root))
        if p.suffix in (".xlsx", ".json", ".m", ".raw"):
            out.append((rel, str(p), None))
        elif p.suffix == ".dyr":
            raws = [r for r in p.parent.glob("*.raw") if p.stem.startswith(r.stem)]
            raws = raws or list(p.parent.glob("*.raw"))
            if raws:
                raw = max(raws, key=lambda r: len(r.stem))
                out.append((f"{raw.relative_to(root)}+{p.name}", str(raw), str(p)))
    return out


def run_one(path, addfile, tf, h, halve=True):
    """Try one case; returns a dict with ``stage`` (where it stopped) and details."""
    from weakgrid.sim.errors import DataError
    from weakgrid.sim.io.andes import from_andes
    from weakgrid.sim.peer.andes_case import (fix_andes_esdc1a, load_case, machine_names, run_andes_ss,
                                              run_weakgrid_ss)

    r = {"stage": "parse"}
    try:
        ss = load_case(path, addfile, fault="auto")
    except Exception as exc:   # ANDES cannot read it
        return {**r, "error": f"{type(exc).__name__}: {exc}"[:400]}
    if not machine_names(ss):
        return {"stage": "power-flow only", "error": "no dynamic machine models"}
    r["stage"] = "import"
    try:
        system, _ = from_andes(ss)
    except DataError as exc:
        missing = exc.value if exc.field == "models" else None
        return {**r, "error": str(exc)[:400], "missing": missing}
    except Exception as exc:
        return {**r, "error": f"{type(exc).__name__}: {exc}"[:400]}
    r["stage"] = "setup"
    r["notes"] = getattr(system, "import_notes", [])[:5]
    if not system.machine_names:
        return {**r, "error": "no dynamic machine models (power-flow-only case)"}
    try:
        system.setup()
    except Exception as exc:
        # refused with the standard models (e.g. an initial torque beyond WTTQA1's Temax):
        # ANDES's conventions may accept it (ANDES widens that limit)
        return _conventions_only({**r, "error": f"{type(exc).__name__}: {exc}"[:400]},
                                 path, addfile, tf, h, halve)
    r["stage"] = "run"
    try:
        w = run_weakgrid_ss(load_case(path, addfile, fault="auto"), tf, h)
    except Exception as exc:
        return {**r, "error": f"{type(exc).__name__}: {exc}"[:400]}
    if not w["ok"]:
        return {**r, "error": "weakgrid run failed"}
    r["stage"] = "andes"
    try:
        a = run_andes_ss(load_case(path, addfile, fault="auto"), tf, h, configure=fix_andes_esdc1a)
    except Exception as exc:
        return {**r, "error": f"ANDES: {type(exc).__name__}: {exc}"[:400]}
    if not a["ok"]:
        return {**r, "error": a.get("error", "ANDES run failed")}
    andes_runs = {1: a}
    r = {**r, **_compare(path, addfile, tf, h, a, w, andes_runs, "standard", halve),
         "wall_weakgrid": w["wall"], "wall_andes": a["wall"]}
    # the same case with ANDES 2.0's departures from the standard models, where it has any
    system_a, _ = from_andes(load_case(path, addfile, fault="auto"), conventions="andes")
    applied = system_a.conventions_applied
    if not applied:
        r["andes"] = {"same": True}
        return r
    try:
        wa = run_weakgrid_ss(load_case(path, addfile, fault="auto"), tf, h, conventions="andes")
        r["andes"] = {"applied": applied, **_compare(path, addfile, tf, h, a, wa, andes_runs, "andes", halve)}
    except Exception as exc:  # noqa: BLE001  (a census records every failure)
        r["andes"] = {"applied": applied, "stage": "run", "error": f"{type(exc).__name__}: {exc}"[:300]}
    return r


def _conventions_only(r, path, addfile, tf, h, halve):
    """A case refused at setup with the standard models, tried with ANDES's conventions."""
    from weakgrid.sim.io.andes import from_andes
    from weakgrid.sim.peer.andes_case import fix_andes_esdc1a, load_case, run_andes_ss, run_weakgrid_ss

    try:
        system_a, _ = from_andes(load_case(path, addfile, fault="auto"), conventions="andes")
        applied = system_a.conventions_applied
        if not applied:
            return r
        system_a.setup()
        wa = run_weakgrid_ss(load_case(path, addfile, fault="auto"), tf, h, conventions="andes")
        a = run_andes_ss(load_case(path, addfile, fault="auto"), tf, h, configure=fix_andes_esdc1a)
        if not (wa["ok"] and a["ok"]):
            r["andes"] = {"applied": applied, "stage": "run", "error": "a run failed"}
            return r
        r["andes"] = {"applied": applied, **_compare(path, addfile, tf, h, a, wa, {1: a}, "andes", halve)}
    except Exception as exc:  # noqa: BLE001  (a census records every failure)
        r["andes"] = {"stage": "setup", "error": f"{type(exc).__name__}: {exc}"[:300]}
    return r


def _compare(path, addfile, tf, h, a, w, andes_runs, conventions, halve):
    """Stage and gaps of weakgrid run ``w`` against ANDES run ``a`` (both at step ``h``); a
    near miss is re-run at h/2 and h/4 in both tools (ANDES runs cached in ``andes_runs``)."""
    import numpy as np

    from weakgrid.sim.peer.andes_case import (compare_named, fix_andes_esdc1a, load_case, run_andes_ss,
                                              run_weakgrid_ss)

    dw, dd = compare_named(a, w)
    ok = bool(np.isfinite(dw) and dw < DW_TOL and dd < DD_TOL)
    r = {"stage": "match" if ok else "mismatch", "dw": dw, "dd": dd}
    if not ok and dw < 10 * DW_TOL and halve:
        # is it step error? halve the step in both tools, twice if needed (ANDES converges
        # slowly after events: the kundur_full family matches only at h/4)
        for k in (2, 4):
            try:
                wk = run_weakgrid_ss(load_case(path, addfile, fault="auto"), tf, h / k,
                                     conventions=conventions)
                if k not in andes_runs:
                    andes_runs[k] = run_andes_ss(load_case(path, addfile, fault="auto"), tf, h / k,
                                                  configure=fix_andes_esdc1a)
                dwk, ddk = compare_named(andes_runs[k], wk)
                r.update({f"dw_h{k}": dwk, f"dd_h{k}": ddk})
                if dwk < DW_TOL and ddk < DD_TOL:
                    r["stage"] = f"match at h/{k}"
                    break
                if not dwk < dw:      # not shrinking with the step: not step error
                    break
                dw = dwk
            except Exception as exc:
                r[f"error_h{k}"] = f"{type(exc).__name__}: {exc}"[:300]
                break
    return r


def summarize(results):
    for v in results.values():   # older files: power-flow-only cases were stopped at setup
        if v["stage"] == "setup" and str(v.get("error", "")).startswith("no dynamic"):
            v["stage"] = "power-flow only"
    stages = Counter(v["stage"] for v in results.values())
    missing = Counter()
    for v in results.values():
        for m in v.get("missing") or []:
            missing[m] += 1
    return stages, missing


def andes_stage(v):
    """Outcome of a case with the ANDES conventions: its own where the case has a departure,
    the standard outcome where it has none (``"same"``), ``None`` where it was not checked
    (a result from before the conventions existed, compared but not re-run)."""
    a = v.get("andes")
    if a is None:
        return None if "dw" in v else v["stage"]
    return v["stage"] if a.get("same") else a.get("stage")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--tf", type=float, default=5.0)
    ap.add_argument("--h", type=float, default=1 / 120)
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--out", default=str(Path(__file__).with_name("andes_case_census.json")))
    ap.add_argument("--only", default="", help="substring filter(s) on case keys, comma-separated")
    ap.add_argument("--redo", action="store_true", help="run the selected cases again even if in the file")
    ap.add_argument("--fresh", action="store_true")
    ap.add_argument("--one", nargs=2, metavar=("PATH", "ADDFILE"), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        res = run_one(a.one[0], None if a.one[1] == "-" else a.one[1], a.tf, a.h)
        print("CENSUS_RESULT " + json.dumps(res))
        return 0
    from weakgrid.fileio import write_json_atomic

    out = Path(a.out)
    results = {} if a.fresh or not out.exists() else json.loads(out.read_text())["cases"]
    only = [o for o in a.only.split(",") if o] or [""]
    cases = [c for c in case_inputs() if any(o in c[0] for o in only)]
    for n, (key, path, addfile) in enumerate(cases, 1):
        if key in results and not a.redo:
            continue
        t0 = time.perf_counter()
        cmd = [sys.executable, __file__, "--tf", str(a.tf), "--h", repr(a.h), "--one", path, addfile or "-"]
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=a.timeout, env=os.environ)
            line = [ln for ln in p.stdout.splitlines() if ln.startswith("CENSUS_RESULT ")]
            res = json.loads(line[-1][14:]) if line else {"stage": "crash", "error": p.stderr[-400:]}
        except subprocess.TimeoutExpired:
            res = {"stage": "timeout", "error": f"over {a.timeout:g} s"}
        res["seconds"] = round(time.perf_counter() - t0, 1)
        results[key] = res
        extra = f" dw={res['dw']:.2g} dd={res['dd']:.2g}" if "dw" in res else f" {res.get('error', '')[:90]}"
        if "dw" in res.get("andes", {}):
            extra += f"; ANDES conventions: {res['andes']['stage']} dw={res['andes']['dw']:.2g}"
        print(f"[{n}/{len(cases)}] {key}: {res['stage']}{extra}", flush=True)
        write_json_atomic(out, {"tf": a.tf, "h": a.h, "tolerances": [DW_TOL, DD_TOL], "cases": results})
    stages, missing = summarize(results)
    imported = sum(v for k, v in stages.items() if k not in ("parse", "import", "power-flow only"))
    loose = sum(1 for v in results.values() if "dw" in v and v["dw"] < 2e-4 and v["dd"] < 1.0)
    print(f"\n{len(results)} case inputs ({stages.get('power-flow only', 0)} without dynamic data): "
          f"{imported} import, {stages.get('match', 0)} match ANDES "
          f"at h, {stages.get('match at h/2', 0)} more at h/2, {stages.get('match at h/4', 0)} at h/4 "
          f"(dw < {DW_TOL:g} pu, dd < {DD_TOL:g} deg), {loose} within 2e-4 pu and 1 deg; "
          f"stages: {dict(stages)}")
    st_a = Counter(andes_stage(v) for v in results.values())
    print(f"with ANDES's conventions (conventions='andes'): {st_a.get('match', 0)} match at h, "
          f"{st_a.get('match at h/2', 0)} more at h/2, {st_a.get('match at h/4', 0)} at h/4, "
          f"{st_a.get('mismatch', 0)} mismatch; {st_a.get(None, 0)} compared but not checked with them; "
          f"stages: { {k: c for k, c in st_a.items() if k is not None} }")
    for k, v in sorted(results.items()):
        if "dw" in v.get("andes", {}):
            std = f"{v['dw']:.2g} pu / {v['dd']:.2g} deg" if "dw" in v else v.get("error", "")[:60]
            print(f"  {k}: standard {v['stage']} {std}; ANDES conventions "
                  f"{v['andes']['stage']} {v['andes']['dw']:.2g} pu / {v['andes']['dd']:.2g} deg "
                  f"({', '.join(f'{m} x{c}' for m, c in v['andes']['applied'].items())})")
    print("models missing (cases blocked): " + ", ".join(f"{m} ({c})" for m, c in missing.most_common()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
