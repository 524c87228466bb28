"""PSS/E's own results as the peer: weakgrid and ANDES on PSID's PSS/E benchmark cases.

Not a test (the test is ``tests/psse/test_psid_benchmarks.py``): writes
``benchmarks/psse_benchmarks.json`` and prints a markdown table, one row per compared quantity:

    case | models | quantity | PSS/E swing | weakgrid vs PSS/E (max abs, % of swing) |
    ANDES vs PSS/E | PSID tolerance | status

Cases: every entry of ``tests/data/psid/cases.toml`` (PowerSimulationsDynamics.jl's PSS/E cases,
vendored unedited, BSD-3; one entry per PSID test case and ``.dyr`` variant, with its event,
quantities, tolerance and load conversion). Each tool reads the ``.raw`` + ``.dyr`` exactly as
shipped:

* weakgrid through its native PSS/E reader ``weakgrid.sim.io.psse.from_psse`` (``--route
  andes``: through ANDES's PSS/E parser and ``from_andes`` instead, the route the reader
  replaces; it changes the data, see issue 26);
* ANDES 2.0: ``andes.load(raw, addfile=dyr, setup=False)``, its own time-domain simulation
  (trapezoidal, fixed step, tolerance 1e-8) with the same event (a ``Toggle`` of the line); loads
  as PSID converts them (ANDES's PQ ``p2z``/``p2p``/``p2i`` config).

Both tools step at 1/240 s (an entry may set ``dt``) to the case's own final time. Differences are
taken at PSS/E's samples (5 ms; repeated event time stamps keep the pre-event sample, as PSID
does), the simulators' trajectories interpolated linearly. "max abs" is the largest difference,
in PSID's tolerance unit (rad for rotor angles, pu otherwise); "% of swing" divides it by PSS/E's
``max - min`` of the quantity over the run. Status ``pass``: within PSID's tolerance in PSID's
norm AND within 5 % of the swing (the criterion of the test).

Run:  PYTHONPATH=src python benchmarks/psse_benchmarks.py [--cases id,id] [--tools weakgrid,andes]
      [--route psse|andes] [--docs docs/psse-validation.md]
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import time
import traceback
from pathlib import Path

from weakgrid.fileio import write_text_atomic
from weakgrid.sim.errors import DataError
from weakgrid.sim.peer import psid

HERE = Path(__file__).resolve().parent
BEGIN, END = "<!-- psse-table:begin -->", "<!-- psse-table:end -->"


def _weakgrid(case, route):
    try:
        run = psid.run_weakgrid(case, route=route)
    except ImportError as e:
        return {"status": f"reader not available ({e})"}
    except NotImplementedError as e:
        return {"status": f"reader not complete ({e})"}
    except psid.Unsupported as e:
        return {"status": f"skipped: {e}"}
    except DataError as e:
        if e.field in ("models", "model"):
            return {"status": f"skipped: models weakgrid lacks: {_names(e.value)}", "error": str(e)}
        return {"status": f"refused: {e}", "error": str(e)}
    except Exception as e:   # noqa: BLE001 - a table of outcomes, not a test
        return {"status": f"error: {type(e).__name__}: {e}", "error": traceback.format_exc(limit=3)}
    res = run["res"]
    out = {"wall_s": run["wall"], "ok": bool(res.ok), "t_end": float(res.t[-1]),
           "notes": list(getattr(run["system"], "import_notes", []))}
    if not res.ok:
        out["status"] = f"run stopped at t = {res.t[-1]:.3g} s: {res.failure}"
        return out
    if case["csv"]:
        try:
            out["rows"] = psid.compare_case(case, run)
        except psid.Unsupported as e:
            out["status"] = f"skipped: {e}"
            return out
    out["status"] = "ran"
    return out


def _andes(case):
    try:
        run = psid.run_andes(case)
    except psid.Unsupported as e:
        return {"status": f"n/a: {e}"}
    except Exception as e:   # noqa: BLE001
        return {"status": f"error: {type(e).__name__}: {str(e)[:200]}"}
    out = {"wall_s": run["wall"], "status": "ran", "rows": [], "changes": run["notes"]}
    for cmp in case["compare"]:
        try:
            out["rows"].append(psid.compare_case({**case, "compare": [cmp]}, run)[0])
        except psid.Unsupported as e:
            out["rows"].append({"quantity": psid._label(cmp), "status": f"n/a: {e}"})
    return out


def _names(v):
    if isinstance(v, (list, tuple, set)):
        return ", ".join(str(x) for x in v)
    return str(v)


def _fmt(r, unit=True):
    if r is None or "max_abs" not in r:
        return (r or {}).get("status", "—")
    u = f" {r['unit']}" if unit else ""
    share = "no swing" if not r["swing"] > 0 else f"{100 * r['share_of_swing']:.2f} %"
    return f"{r['max_abs']:.3g}{u} ({share})"


def table(results):
    head = ("| case | models | quantity | PSS/E swing | weakgrid vs PSS/E (max abs, % of swing) | "
            "ANDES vs PSS/E | PSID tolerance | status |\n|---|---|---|---|---|---|---|---|")
    lines = [head]
    for e in results:
        c = e["case"]
        models = ", ".join(c["models"])
        wg, an = e.get("weakgrid", {}), e.get("andes", {})
        if not c["run"]:
            lines.append(f"| {c['id']} | {models} | — | — | — | — | — | not a comparison of the files: {c['note']} |")
            continue
        if not c["csv"]:
            st = "run only (no PSS/E results shipped): " + ("runs to the end" if wg.get("status") == "ran" else wg.get("status", "—"))
            lines.append(f"| {c['id']} | {models} | — | — | — | — | — | {st} |")
            continue
        wrows = {r["quantity"]: r for r in wg.get("rows", [])}
        arows = {r["quantity"]: r for r in an.get("rows", [])}
        for cmp in c["compare"]:
            q = psid._label(cmp)
            w, a = wrows.get(q), arows.get(q)
            swing = (w or a or {}).get("swing")
            sw = f"{swing:.3g} {cmp['tol_unit']}" if swing is not None else "—"
            tol = f"{cmp['tol']:g} {cmp['tol_unit']} ({cmp['norm']}-norm)"
            if w is None:
                st = wg.get("status", "—")
                wtxt = "—"
            else:
                wtxt = _fmt(w)
                if cmp["norm"] != "inf":
                    wtxt += f"; 2-norm {w['psid_norm']:.3g}"
                st = "pass" if w["ok"] else ", ".join(
                    x for x, bad in (("outside PSID's tolerance", not w["within_tol"]),
                                     ("beyond 5 % of the swing", not w["within_swing"]),
                                     ("incomplete", not w["complete"])) if bad)
            atxt = _fmt(a, unit=False) if a is not None else an.get("status", "—")
            if a is not None and "psid_norm" in a and cmp["norm"] != "inf":
                atxt += f"; 2-norm {a['psid_norm']:.3g}"
            if an.get("changes"):
                atxt += " [ANDES's parser: " + ", ".join(an["changes"]) + "]"
            if c.get("results_from", "PSS/E") != "PSS/E":
                st += f" (the CSV is {c['results_from']}'s, not PSS/E's: see cases.toml)"
            lines.append(f"| {c['id']} | {models} | {q} | {sw} | {wtxt} | {atxt} | {tol} | {st} |")
    return "\n".join(lines)


def _jsonable(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items() if k not in ("ss",)}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    return x


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", default="", help="comma-separated case ids (default: all)")
    ap.add_argument("--tools", default="weakgrid,andes")
    ap.add_argument("--route", default="psse", choices=("psse", "andes"),
                    help="weakgrid's reader: native (psse) or ANDES's parser (andes)")
    ap.add_argument("--json", default=str(HERE / "psse_benchmarks.json"))
    ap.add_argument("--docs", default="", help="also write the table into this markdown file (between markers)")
    ap.add_argument("--andes-from", default="", help="reuse the ANDES results of an earlier JSON of this script "
                    "(ANDES's runs do not depend on weakgrid's code)")
    ap.add_argument("--label", default="", help="provenance written above the table (e.g. the merged commits)")
    a = ap.parse_args(argv)
    want = {x for x in a.cases.split(",") if x}
    tools = set(a.tools.split(","))
    results = []
    t_all = time.perf_counter()
    andes_prev = {}
    if a.andes_from:
        andes_prev = {e["case"]["id"]: e["andes"] for e in json.loads(Path(a.andes_from).read_text())["cases"]
                      if "andes" in e}
    for c in psid.load_cases():
        if want and c["id"] not in want:
            continue
        e = {"case": c}
        if c["run"]:
            if "weakgrid" in tools:
                e["weakgrid"] = _weakgrid(c, a.route)
            if c["id"] in andes_prev:
                e["andes"] = andes_prev[c["id"]]
            elif "andes" in tools and c["csv"]:
                e["andes"] = _andes(c)
        results.append(e)
        print(f"{c['id']}: weakgrid {e.get('weakgrid', {}).get('status', '-')}; "
              f"ANDES {e.get('andes', {}).get('status', '-')}", flush=True)
    md = table(results)
    print()
    print(md)
    meta = {"route": a.route, "label": a.label, "andes_from": a.andes_from,
            "python": platform.python_version(), "wall_s": time.perf_counter() - t_all,
            "dt_default": psid.DT, "swing_share": psid.SWING_SHARE}
    try:
        import andes

        meta["andes"] = andes.__version__
    except ImportError:
        pass
    write_text_atomic(a.json, json.dumps(_jsonable({"meta": meta, "cases": results}), indent=1))
    if a.docs:
        p = Path(a.docs)
        s = p.read_text()
        i, j = s.index(BEGIN) + len(BEGIN), s.index(END)
        label = f"\n{a.label}\n" if a.label else ""
        write_text_atomic(p, s[:i] + "\n" + label + "\n" + md + "\n" + s[j:])
    return results


if __name__ == "__main__":
    main()
