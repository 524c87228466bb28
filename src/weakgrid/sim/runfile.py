"""The run file: one Parquet file with every recorded signal by name, units in metadata.

Layout (``format = "weakgrid-run"``, ``format_version = 1``)
------------------------------------------------------------
One Parquet table, one row per recorded instant:

* ``t`` — time [s];
* ``pre_event`` — ``True`` on the first of the two rows the simulator records at a
  breakpoint (fault on/off, line trip, load step, controller sample): the value
  *before* the event; the next row (same ``t``) is the value after it;
* one ``float64`` column per signal, named as the simulator names it,
  ``<device>.<signal>`` (``G1.omega``, ``bus7.v``, ``UPQC1.P_series``), values in
  per unit (see :mod:`weakgrid.sim.results` for the bases);
* the controller's samples, when given, in columns ``sample.<key>`` (``sample.t``
  the sample times [s]; a 2-D quantity ``sample.<key>[j]``, ``j`` its column). The
  samples are fewer than the instants: they fill the first rows and are null below;
  conversely, if a run has more samples than instants the instant columns are null
  on the extra rows (``t`` null). :func:`read_run` and :func:`read_samples` undo the
  padding.

Metadata
--------
* per field (Parquet field metadata, bytes): ``unit`` (the per-unit label, e.g.
  ``"pu (Sb)"``), ``kind`` (``power``, ``apparent`` (power, SI MVA), ``voltage``, ``speed``, ``angle``,
  ``current``, ``energy``, ``pu``, ``time``), ``si_unit`` (``"MW"``), ``si_factor``
  (SI value = pu value × factor) and ``base`` (the per-unit base in words:
  ``"Sb = 100 MVA"``, ``"bus base 230 kV"``, ``"f = 60 Hz"``);
* per file (schema metadata key ``weakgrid.run``, JSON): ``format``,
  ``format_version``, ``weakgrid_version``, ``failure`` (text or null), ``stats`` (the
  integrator's counters), ``n_instants``, ``n_samples`` and whatever the writer adds
  in ``meta`` (a study run adds ``study``, ``scenario``, ``controller``, ``dt``,
  ``tol``, ``events`` and ``aliases``: the figure keys → signal names).
"""

from __future__ import annotations

import fnmatch
import json
import math

import numpy as np

from .errors import DataError

__all__ = ["write_run", "run_table", "read_run", "read_samples", "read_meta", "run_signals",
           "match_signals", "FORMAT", "FORMAT_VERSION", "META_KEY", "SAMPLE_PREFIX"]

FORMAT = "weakgrid-run"
FORMAT_VERSION = 1
META_KEY = b"weakgrid.run"
SAMPLE_PREFIX = "sample."

# unit kind -> (pu label, SI label); the single table (results.py imports it)
UNIT_LABELS = {"pu": ("pu", "pu"), "power": ("pu (Sb)", "MW"), "apparent": ("pu (Sb)", "MVA"),
               "voltage": ("pu", "kV"),
               "angle": ("rad", "deg"), "speed": ("pu", "rad/s"),
               "current": ("pu (Sb)", "kA"), "time": ("s", "s"), "energy": ("pu·s", "MJ")}


def base_text(kind: str, si_factor: float) -> str:
    """The per-unit base of a signal of unit ``kind`` whose SI factor is ``si_factor``."""
    f = float(si_factor)
    if kind in ("power", "apparent"):
        return f"Sb = {f:g} MVA"
    if kind == "energy":
        return f"Sb = {f:g} MVA (1 pu·s = {f:g} MJ)"
    if kind == "voltage":
        return f"bus base {f:g} kV"
    if kind == "speed":
        return f"f = {f / (2 * math.pi):g} Hz"
    if kind == "current":
        return f"Sb/(sqrt(3) kV base) = {f:g} kA"
    if kind == "angle":
        return "rad (SI: deg)"
    return ""


def _field_meta(kind, factor) -> dict:
    pu, si = UNIT_LABELS.get(kind, ("pu", "pu"))
    return {b"unit": pu.encode(), b"kind": kind.encode(), b"si_unit": si.encode(),
            b"si_factor": repr(float(factor)).encode(), b"base": base_text(kind, factor).encode()}


def _pre_event(t) -> np.ndarray:
    t = np.asarray(t, float)
    pre = np.zeros(len(t), bool)
    if len(t) > 1:
        pre[:-1] = t[:-1] == t[1:]
    return pre


def _sample_columns(samples) -> dict:
    """``samples`` (dict or DataFrame; key ``t`` or ``tk`` the sample times) → flat columns."""
    if samples is None:
        return {}
    if hasattr(samples, "columns"):
        samples = {c: samples[c].to_numpy() for c in samples.columns}
    samples = dict(samples)
    if "t" not in samples and "tk" in samples:
        samples["t"] = samples.pop("tk")
    if "t" not in samples:
        raise DataError("run file", "samples", sorted(samples),
                        "give the sample times as samples['t'] [s]")
    n = len(np.atleast_1d(samples["t"]))
    out = {}
    for k, v in sorted(samples.items(), key=lambda kv: kv[0] != "t"):   # t first
        a = np.asarray(v, float)
        if a.ndim == 0 or a.shape[0] != n or a.ndim > 2:
            raise DataError("run file", f"samples['{k}']", f"shape {a.shape}",
                            f"give one value (or one row) per sample time ({n} samples)")
        if a.ndim == 1:
            out[f"{SAMPLE_PREFIX}{k}"] = a
        else:
            for j in range(a.shape[1]):
                out[f"{SAMPLE_PREFIX}{k}[{j}]"] = a[:, j]
    return out


def _padded(a, n):
    import pyarrow as pa

    a = np.asarray(a)
    if len(a) == n:
        return pa.array(a)
    mask = np.r_[np.zeros(len(a), bool), np.ones(n - len(a), bool)]
    return pa.array(np.r_[a, np.zeros(n - len(a), a.dtype)], mask=mask)


def write_run(path, results, *, samples=None, meta=None):
    """Write a simulation's trajectories (and controller samples) as one run file.

    The table is :func:`run_table`'s; the file is written atomically
    (:func:`weakgrid.fileio.replace_atomic`).

    Parameters
    ----------
    path : str or Path
        Target ``.parquet`` file (written atomically).
    results : weakgrid.sim.results.Results
        The trajectories: every recorded signal becomes a column named as in
        ``results.names``, values in per unit, units and bases in the field metadata.
    samples : dict or DataFrame, optional
        The controller's samples: ``t`` (or ``tk``) the sample times [s] and any 1-D
        (one value per sample) or 2-D (one row per sample) arrays, stored as
        ``sample.<key>`` / ``sample.<key>[j]``.
    meta : dict, optional
        JSON-serializable file-level metadata (study, scenario, controller, dt, tol,
        events, aliases, ...).

    Returns
    -------
    Path
        The written file.
    """
    import pyarrow.parquet as pq

    from ..fileio import replace_atomic

    table = run_table(results, samples=samples, meta=meta)
    return replace_atomic(path, lambda tmp: pq.write_table(table, tmp))


def run_table(results, *, samples=None, meta=None):
    """The :class:`pyarrow.Table` of a run file (arguments as :func:`write_run`'s)."""
    import pyarrow as pa

    from .. import __version__
    from ..fileio import json_safe

    t = np.asarray(results.t, float)
    scols = _sample_columns(samples)
    ns = len(scols.get(f"{SAMPLE_PREFIX}t", ()))
    n = max(len(t), ns)
    arrays, fields = [], []

    def add(name, values, kind, factor=1.0, dtype=pa.float64()):
        arrays.append(_padded(values, n))
        fields.append(pa.field(name, dtype, metadata=_field_meta(kind, factor)))

    add("t", t, "time")
    arrays.append(_padded(_pre_event(t), n))
    fields.append(pa.field("pre_event", pa.bool_(), metadata={
        b"description": b"True: the value before the event at a breakpoint (a second row "
                        b"with the same t follows: the value after it)"}))
    data = np.asarray(results.data, float).reshape(len(t), len(results.names))
    for j, (name, kind, fac) in enumerate(zip(results.names, results.kinds, results.si_factor)):
        add(name, data[:, j], kind, fac)
    for name, v in scols.items():
        add(name, v, "time" if name == f"{SAMPLE_PREFIX}t" else "pu")
    failure = getattr(results, "failure", None)
    info = {"format": FORMAT, "format_version": FORMAT_VERSION, "weakgrid_version": __version__,
            "failure": None if failure is None else str(failure),
            "stats": dict(getattr(results, "stats", {}) or {}),
            "n_instants": int(len(t)), "n_samples": int(ns)}
    info.update(meta or {})
    schema = pa.schema(fields, metadata={META_KEY: json.dumps(json_safe(info)).encode()})
    return pa.Table.from_arrays(arrays, schema=schema)


def _schema(path):
    import pyarrow.parquet as pq

    try:
        schema = pq.read_schema(path)
    except FileNotFoundError:
        raise
    except Exception as exc:   # pyarrow raises ArrowInvalid for a non-Parquet file
        raise DataError(f"run file {path}", "format", type(exc).__name__,
                        f"not a Parquet file ({exc}); give a run written by weakgrid") from None
    if schema.metadata is None or META_KEY not in schema.metadata:
        raise DataError(f"run file {path}", "metadata", None,
                        "not a weakgrid run file (no 'weakgrid.run' metadata): write it with "
                        "weakgrid.sim.runfile.write_run or `weakgrid simulate -o`")
    return schema


def read_meta(path) -> dict:
    """The file-level metadata of a run file (JSON of the ``weakgrid.run`` key)."""
    return json.loads(_schema(path).metadata[META_KEY])


def run_signals(path) -> list[str]:
    """Names of the signals of a run file (not ``t``, ``pre_event`` nor the samples)."""
    return [n for n in _schema(path).names
            if n not in ("t", "pre_event") and not n.startswith(SAMPLE_PREFIX)]


def match_signals(names, wanted, where="signals", field="signal") -> list[str]:
    """``wanted`` names or ``fnmatch`` patterns resolved against ``names`` (in order, once).

    Raises :class:`~weakgrid.sim.errors.DataError` (element ``where``, field ``field``) naming
    the closest names for one that matches nothing. The one matcher of signal names: run
    files, the recorder's ``record=`` and ``simulate --record``.
    """
    import difflib

    out = []
    for w in wanted:
        hits = [w] if w in names else fnmatch.filter(names, w) \
            if any(ch in w for ch in "*?[") else []
        if not hits:
            close = difflib.get_close_matches(w, names, n=8, cutoff=0.5) or \
                [n for n in names if w.split(".")[-1] in n][:8]
            raise DataError(where, field, w, f"no such signal; closest: {close or names[:8]}"
                            " (names are <device>.<signal>; fnmatch patterns like '*.omega' "
                            "allowed)")
        out += [h for h in hits if h not in out]
    return out


def _attrs(schema, cols, si):
    units, si_units, kinds, factors, bases = {}, {}, {}, {}, {}
    for c in cols:
        md = schema.field(c).metadata or {}
        if b"kind" not in md:
            continue
        kinds[c] = md[b"kind"].decode()
        factors[c] = float(md[b"si_factor"])
        si_units[c] = md[b"si_unit"].decode()
        units[c] = si_units[c] if si else md[b"unit"].decode()
        bases[c] = md[b"base"].decode()
    return {"units": units, "si_units": si_units, "kinds": kinds, "si_factor": factors,
            "bases": bases}


def read_run(path, signals=None, *, si: bool = False, pre_event: bool = False):
    """Read a run file: one row per instant, a ``t`` column and one column per signal.

    Parameters
    ----------
    path : str or Path
        A file written by :func:`write_run`.
    signals : list of str, optional
        Names or ``fnmatch`` patterns (``"*.omega"``, ``"bus*.v"``) of the signals to
        read (default: all). An unknown name raises
        :class:`~weakgrid.sim.errors.DataError` listing the closest names.
    si : bool
        Convert to SI units (MW, kV, rad/s, deg, kA, MJ) instead of per unit.
    pre_event : bool
        Keep the pre-event rows of breakpoints (two rows with the same ``t``) and the
        boolean ``pre_event`` column; default: only the value after each event, so
        ``t`` is strictly increasing.

    Returns
    -------
    pandas.DataFrame
        ``df.attrs``: ``units`` (per column, of the values returned), ``si_units``,
        ``kinds``, ``si_factor``, ``bases`` (the per-unit base of each column) and
        ``meta`` (the file-level metadata: study, scenario, controller, version, ...).
    """
    import pyarrow.parquet as pq

    schema = _schema(path)
    names = [n for n in schema.names if n not in ("t", "pre_event")
             and not n.startswith(SAMPLE_PREFIX)]
    cols = names if signals is None else match_signals(
        names, [signals] if isinstance(signals, str) else list(signals), where=str(path))
    table = pq.read_table(path, columns=["t", "pre_event", *cols])
    meta = json.loads(schema.metadata[META_KEY])
    n = int(meta.get("n_instants", table.num_rows))
    df = table.slice(0, n).to_pandas()
    if not pre_event:
        df = df[~df["pre_event"].to_numpy(bool)].drop(columns="pre_event").reset_index(drop=True)
    attrs = _attrs(schema, ["t", *cols], si)
    if si:
        for c in cols:
            f = attrs["si_factor"].get(c, 1.0)
            if f != 1.0:
                df[c] = df[c].to_numpy() * f
    df.attrs.update(attrs)
    df.attrs["meta"] = meta
    return df


def read_samples(path):
    """The controller's samples of a run file: ``t`` (sample times [s]) and one column per
    sampled quantity (``sample.`` prefix removed; 2-D quantities as ``key[j]``); empty if
    the run has none. ``df.attrs["meta"]``: the file-level metadata."""
    import pyarrow.parquet as pq

    schema = _schema(path)
    cols = [n for n in schema.names if n.startswith(SAMPLE_PREFIX)]
    meta = json.loads(schema.metadata[META_KEY])
    import pandas as pd

    if not cols:
        df = pd.DataFrame({"t": np.zeros(0)})
    else:
        df = pq.read_table(path, columns=cols).slice(0, int(meta.get("n_samples", 0))).to_pandas()
        df.columns = [c[len(SAMPLE_PREFIX):] for c in df.columns]
    df.attrs["meta"] = meta
    return df
