"""Simulation results: every state, algebraic variable and recorded output by name, in pu and SI.

Names
-----
* states: ``"<instance>.<state>"``, e.g. ``"G1.omega"``, ``"G1.avr.VR"``;
* network: ``"bus<id>.Vr"``, ``"bus<id>.Vi"`` (the algebraic variables) and the
  derived ``"bus<id>.v"`` (magnitude) and ``"bus<id>.a"`` (angle);
* outputs: ``"<instance>.<output>"``, e.g. ``"G1.Pe"``, ``"upqc.P_series"``;
  machines also have ``"<machine>.vf"``, ``".tm"``, ``".vs"``.

Per-unit bases: powers on the system base ``Sb`` [MVA]; voltages on the bus
base [kV]; speeds in pu of nominal; angles in rad. :meth:`Results.to_frame`
with ``si=True`` converts to MW/Mvar, kV, rad/s and degrees.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import DataError
from .runfile import UNIT_LABELS as _LABEL  # unit kind -> (pu label, SI label)
from .runfile import match_signals

#: systems with more DAE variables than this record only machine speeds and angles by default
RECORD_ALL_MAX = 3000



class Results:
    """Trajectories of a simulation.

    Attributes
    ----------
    t : ndarray
        Time points [s] (a breakpoint appears twice: before and after the event).
    names : list of str
        Variable names (columns of :attr:`data`).
    data : ndarray, shape (len(t), len(names))
        Values in per unit.
    failure : SimulationError or None
        Set when the run stopped early with ``on_failure="return"``.
    stats : dict
        Integrator counters (steps, Newton iterations, Jacobians, LU factorizations, evaluations).
    """

    def __init__(self, t, names, data, kinds, si_factor, failure=None, stats=None):
        self.t = np.asarray(t)
        self.names = list(names)
        self.data = np.asarray(data)
        self.kinds = list(kinds)
        self.si_factor = np.asarray(si_factor, dtype=float)
        self.failure = failure
        self.stats = stats or {}
        self._col = {n: i for i, n in enumerate(self.names)}

    @property
    def ok(self) -> bool:
        return self.failure is None

    def __contains__(self, name):
        return name in self._col

    def __getitem__(self, name) -> np.ndarray:
        """Trajectory of variable ``name`` in per unit."""
        try:
            return self.data[:, self._col[name]]
        except KeyError:
            close = [n for n in self.names if name.split(".")[-1] in n][:8]
            raise KeyError(f"no variable '{name}' in results; e.g. {close}") from None

    def si(self, name) -> np.ndarray:
        """Trajectory of ``name`` in SI units (see :meth:`unit`)."""
        return self[name] * self.si_factor[self._col[name]]

    def unit(self, name, si=False) -> str:
        return _LABEL[self.kinds[self._col[name]]][1 if si else 0]

    def select(self, pattern: str) -> list[str]:
        """Names containing ``pattern``."""
        return [n for n in self.names if pattern in n]

    def to_frame(self, si: bool = False, names=None):
        """A :class:`pandas.DataFrame`: a ``t`` column [s] and one column per variable, named
        as the variable (``"G1.omega"``); the units are in ``df.attrs["units"]`` (name →
        unit label, SI labels with ``si=True``), not in the names. Every recorded row is
        kept (a breakpoint's pre- and post-event values share a ``t``)."""
        import pandas as pd

        names = self.names if names is None else list(names)
        cols = {"t": self.t}
        for n in names:
            cols[n] = self.si(n) if si else self[n]
        df = pd.DataFrame(cols)
        df.attrs["units"] = {"t": "s", **{n: self.unit(n, si) for n in names}}
        return df

    def to_csv(self, path, si: bool = False, names=None):
        """Write the trajectories to CSV (atomically: the previous file survives a failure).
        CSV has no metadata: the column names are the variables' names; their units are
        those of :meth:`unit` (``si`` as given). Prefer :meth:`to_parquet`, which keeps them."""
        from ..fileio import replace_atomic

        df = self.to_frame(si, names)
        return replace_atomic(path, lambda tmp: df.to_csv(tmp, index=False))

    def to_parquet(self, path, names=None, *, samples=None, meta=None):
        """Write a run file (:func:`weakgrid.sim.runfile.write_run`): every variable (or
        ``names``) in per unit, units and per-unit bases as Parquet field metadata,
        breakpoints' pre-event rows flagged; read it with :func:`weakgrid.read_run`."""
        from .runfile import write_run

        res = self if names is None else self.subset(names)
        return write_run(path, res, samples=samples, meta=meta)

    def subset(self, names) -> "Results":
        """These results restricted to the variables ``names`` (in that order)."""
        names = list(names)
        cols = [self._col[n] if n in self._col else self[n] for n in names]
        return Results(self.t, names, self.data[:, cols], [self.kinds[c] for c in cols],
                       self.si_factor[cols], failure=self.failure, stats=self.stats)

    def plot(self, names, si: bool = False, ax=None, title=None):
        """Plot variables against time; axes labelled with units. Returns the matplotlib axes."""
        import matplotlib.pyplot as plt

        if isinstance(names, str):
            names = [names]
        if ax is None:
            _, ax = plt.subplots(figsize=(7, 3.5))
        units = set()
        for n in names:
            ax.plot(self.t, self.si(n) if si else self[n], label=n)
            units.add(self.unit(n, si))
        ax.set_xlabel("time [s]")
        ax.set_ylabel(" / ".join(sorted(units)) if units else "")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=8)
        if title:
            ax.set_title(title)
        return ax

    # ------------------------------------------------------------- recording
    @staticmethod
    def recorder(system, record=None):
        """A recorder of ``system``'s trajectories.

        Parameters
        ----------
        record : None, "all", "machines" or list of str
            ``"all"``: every state, bus voltage and output; ``"machines"``: the
            speed and rotor angle of every machine (``"<m>.omega"``,
            ``"<m>.delta"``); a list: those names, or ``fnmatch`` patterns such
            as ``"*.omega"`` or ``"bus12.*"``; ``None``: ``"all"`` up to
            :data:`RECORD_ALL_MAX` DAE variables, ``"machines"`` above (memory
            and time of recording stay proportional to what is kept).
        """
        return _Recorder(system, record)


class _Recorder:
    def __init__(self, sys, record=None):
        if record is None:
            record = "all" if sys.N <= RECORD_ALL_MAX else "machines"
        if isinstance(record, str) and record not in ("all", "machines"):
            record = [record]
        self.record = record
        self.sys = sys
        net = sys.network
        names, kinds = [], []
        for nm, u in zip(sys.state_names(), sys.state_units()):
            names.append(nm)
            kinds.append(u)
        self._out_keys = []
        self._layout_done = False
        self.names, self.kinds = names, kinds
        self.fn = net.f_hz
        self.sel = None

    def _layout(self, ctx):
        sys = self.sys
        net = sys.network
        names, kinds = self.names, self.kinds
        for b, bid in enumerate(net.bus_ids):
            names += [f"bus{bid}.Vr", f"bus{bid}.Vi", f"bus{bid}.v", f"bus{bid}.a"]
            kinds += ["voltage", "voltage", "voltage", "angle"]
        for c in sys.comps:
            for o in c.outputs:
                key = f"{c.type_name}.{o}"
                if key in ctx.out:
                    self._out_keys.append((key, c.n))
                    names += [f"{nm}.{o}" for nm in c.names]
                    kinds += [c.units.get(o, "pu")] * c.n
        for s in ("tm", "vs"):
            names += [f"{m}.{s}" for m in sys.machine_names]
            kinds += ["power" if s == "tm" else "pu"] * len(sys.machine_names)
        # SI factors
        fac = []
        bus_kv = {f"bus{bid}": net.base_kv[i] for i, bid in enumerate(net.bus_ids)}
        for n, k in zip(names, kinds):
            if k in ("power", "apparent"):
                fac.append(sys.Sb)
            elif k == "angle":
                fac.append(180 / math.pi)
            elif k == "speed":
                fac.append(2 * math.pi * self.fn)
            elif k == "voltage":
                fac.append(bus_kv.get(n.split(".")[0], sys.element_kv(n)))
            elif k == "current":
                kvb = sys.element_kv(n)
                fac.append(sys.Sb / (math.sqrt(3) * kvb))
            elif k == "energy":
                fac.append(sys.Sb)
            else:
                fac.append(1.0)
        self.fac = fac
        self._select()
        self._layout_done = True

    def _select(self):
        rec = self.record
        if rec == "all":
            return
        if rec == "machines":
            want = [f"{m}.{s}" for m in self.sys.machine_names for s in ("delta", "omega")]
        else:
            want = list(rec)
        col = {n: i for i, n in enumerate(self.names)}
        sel = [col[n] for n in match_signals(self.names, want, "simulation", "record")]
        sel = np.array(sorted(set(sel)), dtype=int)
        self.sel = sel
        self.names = [self.names[i] for i in sel]
        self.kinds = [self.kinds[i] for i in sel]
        self.fac = [self.fac[i] for i in sel]

    def _plan(self):
        """Column ranges of each part of a row (set once, after the layout)."""
        sys = self.sys
        nx, nb, nm = sys.nx, sys.nb, len(sys.machine_names)
        c = nx + 4 * nb
        self._bus = slice(nx, c)
        self._outs = []
        for key, n in self._out_keys:
            self._outs.append((key, slice(c, c + n)))
            c += n
        self._tm = slice(c, c + nm)
        self._vs = slice(c + nm, c + 2 * nm)
        self._ncol = c + 2 * nm
        self._states_only = self.sel is not None and (len(self.sel) == 0 or self.sel.max() < nx)
        self._row = np.empty(self._ncol)
        self._buf = np.empty((256, self._ncol if self.sel is None else len(self.sel)))
        self._tbuf = np.empty(256)
        self._n = 0

    def add(self, t, z, ctx):
        if not self._layout_done:
            self._layout(ctx)
            self._plan()
        if self._n == len(self._tbuf):   # grow (amortized doubling)
            self._buf = np.concatenate([self._buf, np.empty_like(self._buf)])
            self._tbuf = np.concatenate([self._tbuf, np.empty_like(self._tbuf)])
        sys = self.sys
        nx, nb = sys.nx, sys.nb
        row = self._buf[self._n] if self.sel is None else self._row
        if self._states_only:     # selected states only: no derived quantities needed
            self._buf[self._n] = z[self.sel]
            self._tbuf[self._n] = t
            self._n += 1
            return
        row[:nx] = z[:nx]
        Vr, Vi = z[nx:nx + nb], z[nx + nb:]
        bus = row[self._bus]
        bus[0::4], bus[1::4] = Vr, Vi
        bus[2::4] = np.hypot(Vr, Vi)
        bus[3::4] = np.arctan2(Vi, Vr)
        out = ctx.out
        for key, sl in self._outs:
            row[sl] = out[key]
        row[self._tm] = ctx.sig["tm"]
        row[self._vs] = ctx.sig["vs"]
        if self.sel is not None:
            self._buf[self._n] = row[self.sel]
        self._tbuf[self._n] = t
        self._n += 1

    def finish(self, failure=None, stats=None):
        if self._layout_done:
            data = self._buf[:self._n].copy()
            t = self._tbuf[:self._n].copy()
        else:
            data, t = np.zeros((0, len(self.names))), np.zeros(0)
        return Results(t, self.names, data, self.kinds, self.fac, failure=failure, stats=stats)
