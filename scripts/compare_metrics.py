"""Compare two ``metrics.csv`` of `weakgrid reproduce` / `weakgrid run` (same runs, same numbers).

    python scripts/compare_metrics.py BEFORE/metrics.csv AFTER/metrics.csv [--rtol 1e-9]

Every numeric metric of every run must agree to ``rtol`` (relative, with an absolute floor of
``rtol`` for values near zero); wall times are ignored; text metrics must be equal. Exit status
0 when everything agrees, 1 otherwise (the differences are printed).
"""

from __future__ import annotations

import argparse
import math
import sys

import pandas as pd

IGNORE = {"wall_s"}


def compare(before: str, after: str, rtol: float = 1e-9) -> list[str]:
    a = pd.read_csv(before).set_index("id")
    b = pd.read_csv(after).set_index("id")
    out = []
    if sorted(a.index) != sorted(b.index):
        out.append(f"runs differ: only before {sorted(set(a.index) - set(b.index))}, "
                   f"only after {sorted(set(b.index) - set(a.index))}")
    cols = [c for c in a.columns if c not in IGNORE]
    missing = [c for c in cols if c not in b.columns]
    if missing:
        out.append(f"metrics missing after: {missing}")
    worst = 0.0
    for rid in sorted(set(a.index) & set(b.index)):
        for c in cols:
            if c not in b.columns:
                continue
            x, y = a.at[rid, c], b.at[rid, c]
            if isinstance(x, (int, float)) and isinstance(y, (int, float)) and \
                    not isinstance(x, bool):
                if (isinstance(x, float) and math.isnan(x)) and (isinstance(y, float)
                                                                  and math.isnan(y)):
                    continue
                d = abs(x - y) / max(abs(x), 1.0)
                worst = max(worst, d)
                if not d <= rtol:
                    out.append(f"{rid} {c}: {x!r} vs {y!r} (rel. {d:.3g})")
            elif not (pd.isna(x) and pd.isna(y)) and str(x) != str(y):
                out.append(f"{rid} {c}: {x!r} vs {y!r}")
    print(f"{len(a)} runs, {len(cols)} metrics compared; largest relative difference "
          f"{worst:.3g}")
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("before")
    p.add_argument("after")
    p.add_argument("--rtol", type=float, default=1e-9)
    a = p.parse_args(argv)
    diffs = compare(a.before, a.after, a.rtol)
    for d in diffs:
        print(d)
    print("EQUAL" if not diffs else f"{len(diffs)} DIFFERENCES")
    return 0 if not diffs else 1


if __name__ == "__main__":
    sys.exit(main())
