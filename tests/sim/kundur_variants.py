"""Kundur two-area cases (ANDES's ``kundur_full.xlsx``) with the controls swapped for other models.

The case file is copied sheet by sheet with pandas; the exciter/governor rows of
the chosen generators are replaced by rows of another model, and PSS rows added,
so that ANDES and weakgrid read exactly the same data file.
"""

from __future__ import annotations

import andes
import pandas as pd


def kundur_variant(path, exciters=None, governors=None, pss=(), base="kundur/kundur_full.xlsx"):
    """Write a variant of an ANDES stock case to ``path`` and return the path.

    Parameters
    ----------
    exciters, governors : dict, optional
        ``{generator idx: (model, params)}``; the generator's EXDC2 / TGOV1 row is removed and a
        row of ``model`` added (``None`` instead of a tuple: just remove). Extra link fields
        (e.g. ``syn2``) go in ``params``.
    pss : sequence of (model, exciter idx, params)
        Stabilizers to add.
    """
    sheets = dict(pd.read_excel(andes.get_case(base), sheet_name=None))

    def add(model, row):
        df = pd.DataFrame([row])
        sheets[model] = pd.concat([sheets[model], df], ignore_index=True) if model in sheets else df

    for old, mapping in (("EXDC2", exciters), ("TGOV1", governors)):
        for g, spec in (mapping or {}).items():
            sheets[old] = sheets[old][sheets[old]["syn"] != g]
            if spec is not None:
                model, prm = spec
                add(model, {"idx": f"{model}_{g}", "u": 1, "name": f"{model}_{g}", "syn": g, **prm})
        if old in sheets and len(sheets[old]) == 0:
            del sheets[old]
    for model, avr, prm in pss:
        add(model, {"idx": f"{model}_{avr}", "u": 1, "name": f"{model}_{avr}", "avr": avr, **prm})
    with pd.ExcelWriter(path) as w:
        for name, df in sheets.items():
            df.to_excel(w, sheet_name=name, index=False)
    return str(path)
