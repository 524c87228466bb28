"""MATPOWER case files (``.m`` version 2, or ``.mat``) → the MATPOWER case dict.

Parsing is done by ``matpowercaseframes`` (``.m``) and ``scipy.io.loadmat``
(``.mat``); bus numbers stay MATPOWER's (as written in the file), which is what
:class:`~weakgrid.sim.network.Network` takes, and an ``mpc.bus_name`` becomes the case's
``bus_names`` (bus number -> name). Generators have no ids in MATPOWER: weakgrid names them by
bus number and their place at the bus (:func:`weakgrid.sim.templates.machine_id`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import DataError

__all__ = ["load_matpower"]


def load_matpower(path, variable: str = "mpc") -> dict:
    """Read a MATPOWER case file.

    Parameters
    ----------
    path : str or Path
        A ``.m`` (MATPOWER case format version 2) or ``.mat`` file.
    variable : str
        Name of the case struct in a ``.mat`` file.

    Returns
    -------
    dict with ``baseMVA``, ``bus``, ``gen``, ``branch`` (numpy arrays, MATPOWER columns) and,
    when the file has ``mpc.bus_name``, ``bus_names``.
    """
    path = Path(path)
    if not path.exists():
        raise DataError("MATPOWER case", "path", str(path), "the file does not exist")
    if path.suffix == ".m":
        from matpowercaseframes import CaseFrames

        try:
            cf = CaseFrames(str(path))
        except Exception as exc:  # the parser's own errors are not informative types
            raise DataError("MATPOWER case", "path", str(path),
                            f"could not be parsed as a MATPOWER version-2 case ({exc})") from None
        case = {"baseMVA": float(cf.baseMVA)}
        for key in ("bus", "gen", "branch"):
            if not hasattr(cf, key):
                raise DataError("MATPOWER case", key, "missing", f"the file has no mpc.{key}")
            case[key] = np.asarray(getattr(cf, key).values, dtype=float)
        names = getattr(cf, "bus_name", None)      # optional mpc.bus_name, in bus order
        if names is not None and len(names) == len(case["bus"]):
            case["bus_names"] = {int(b): str(n).strip()
                                 for b, n in zip(case["bus"][:, 0], np.ravel(np.asarray(names)))
                                 if str(n).strip()}
        return case
    if path.suffix == ".mat":
        from scipy.io import loadmat

        m = loadmat(str(path), squeeze_me=True, struct_as_record=False)
        if variable not in m:
            raise DataError("MATPOWER case", "variable", variable,
                            f"not in the file; it holds {sorted(k for k in m if not k.startswith('__'))}")
        s = m[variable]
        return {"baseMVA": float(s.baseMVA), "bus": np.atleast_2d(s.bus).astype(float),
                "gen": np.atleast_2d(s.gen).astype(float),
                "branch": np.atleast_2d(s.branch).astype(float)}
    raise DataError("MATPOWER case", "path", str(path), "use a .m or .mat file")
