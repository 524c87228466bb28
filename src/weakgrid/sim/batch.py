"""Batched simulation: many scenarios of one grid advanced by one simulator pass.

Every component type is vectorized over its instances and :meth:`System.evaluate` already
takes a leading batch axis (it is how the coloured finite-difference Jacobian evaluates its
perturbed points), so a batch of ``B`` *members* — the same grid under different events and
controllers — is one ``(B, N)`` array of variables evaluated by one call per Newton iteration.
The Python overhead of a step (the main cost of a small grid) is paid once for the batch.

What each member keeps of its own, so that its trajectory is the one of its one-by-one run
(:class:`~weakgrid.sim.integrate.Simulator`):

* a :class:`Simulator` of its own (on a copy of the grid: its network, events, held limits,
  chord matrix and its LU, Jacobian refresh decisions, predictor and statistics) — the
  batch vectorizes the residual, the Jacobian's finite differences, the Newton updates and
  the held-limit logic (one ``(B, n_lim)`` array whose rows are the members' ``frozen``), and
  calls the member's own methods for the rest (its LU, the consistent re-solve after a jump
  when the chord iteration does not converge);
* its time and its steps: each member takes the steps of its run alone (its own next
  breakpoint: events, controller samples); the members taking the same step size are advanced
  by one Newton call whatever their times — the evaluations of a batchable grid do not read
  the time (every component that does, a delay or a timer, has discrete memory and is refused
  by :func:`batch_unsupported`);
* its Newton convergence: a member whose update is below ``tol`` is left at the point it
  evaluated (converged members are not moved by further iterations of the others), and keeps
  that evaluation's context (what is recorded and measured at its accepted point), as its run
  alone does;
* its failure: a member that loses synchronism, diverges, or whose re-solve fails stops
  alone with the failure its one-by-one run reports; a member whose Newton fails even with a
  fresh Jacobian halves its step in the batch (the members halving at one instant together)
  and goes on from there on its own time grid, as :meth:`Simulator._step` does; only a step
  that would fall below ``min_step`` (its run alone fails there) makes :func:`simulate_batch`
  re-run the member one-by-one, to report that failure.

:func:`simulate_batch` groups the members by their breakpoints off the step grid
(``exact=True``) so that a batch's members keep one step size; results equal one-by-one runs
either way.

Most of a step is the devices' evaluation of every member in one call, written for any
array-API namespace (:mod:`weakgrid.sim.namespace`: an accelerator's arrays could replace
NumPy's there); the batch's own arithmetic around it (the Newton updates, the held limits,
the recorder) is NumPy's, and the linear solves stay per member (LAPACK through
:mod:`weakgrid.sim.linsolve`, exactly the one-by-one factorization and solve).

Per-member parameters: a member may bring its own grid (``scenario["system"]``, e.g. built by a
sweep at its point) that differs from the others only in its operating point (its loads, its
generators' dispatch and voltage set points, power flow, initial point and the machines' initial
signals: each member's network matrix is its own)
and in the parameters its components declare
batchable (:attr:`Component.batch_params`, e.g. the UPQC's rating ``Vmax``): these are held as
``(B, n)`` arrays, a row per member, bound into the evaluating copy like the controllers'
inputs. Members whose grids differ in anything else (:func:`system_fingerprint`) go to different
batches.

Scope: dense networks (``nb <= system.DENSE_NETWORK_MAX``), members whose grids differ only in
their loads and batchable parameters, events that change the network (:class:`Fault`,
:class:`LineTrip`, :class:`LoadStep`). A member outside it (a :class:`GeneratorTrip`, a model
whose limits move with the solution or with discrete memory, an event that changes the network
rows of an ideal source's bus) is run one-by-one by
:func:`simulate_batch`; the results are the same, only slower.
"""

from __future__ import annotations

import copy
import hashlib
import logging
import math
import pickle
import time
from collections.abc import Mapping

import numpy as np

from .component import fast_index
from .errors import DataError, SimulationError
from .integrate import Simulator, _held, _held_change, _output_path, jump_guess
from .results import Results

log = logging.getLogger(__name__)

#: parts of a batched step timed by :attr:`BatchSimulator.timing` [s]
TIMED = ("residual", "jacobian", "lu", "newton", "record", "events")


class _Rows(Mapping):
    """Row ``k`` of each batched array of a context's ``sig`` / ``out`` dict (read-only view)."""

    __slots__ = ("d", "k")

    def __init__(self, d, k):
        self.d, self.k = d, k

    def __getitem__(self, key):
        v = self.d[key]
        return v[self.k] if np.ndim(v) >= 2 else v

    def __iter__(self):
        return iter(self.d)

    def __len__(self):
        return len(self.d)


class _RowCtx:
    """One member's view of a batched evaluation context (what recorders and measurements read)."""

    __slots__ = ("t", "x", "V", "f", "I", "sig", "out", "system")

    def __init__(self, ctx, k, system):
        self.system = system
        self.t = ctx.t
        self.x, self.V, self.f, self.I = ctx.x[k], ctx.V[k], ctx.f[k], ctx.I[k]
        self.sig, self.out = _Rows(ctx.sig, k), _Rows(ctx.out, k)


class _BatchRecorder:
    """Records every member of a batch: one vectorized row block per recording instant, split
    into one :class:`Results` per member at the end (same columns as :meth:`Results.recorder`)."""

    def __init__(self, system, record):
        self.rec = Results.recorder(system, record)   # its layout (names, units, columns)
        self.sys = system
        self.blocks = []
        self._ocols = None      # the columns of the outputs, in the order of ``rec._outs``
        self._pieces = None     # with ``record``: where each selected column comes from

    def add(self, t, members, Z, ctx, pos):
        """Record members ``members`` (their points ``Z``, one row each) whose rows in the
        batched ``ctx`` are ``pos``."""
        rec = self.rec
        if not rec._layout_done:
            rec._layout(_RowCtx(ctx, pos[0], self.sys))
            rec._plan()
            if rec.sel is not None:
                self._pieces = self._selected_pieces()
        if rec.sel is not None:
            self.blocks.append((t, np.asarray(members), self._selected(Z, ctx, pos)))
            return
        nx, nb = self.sys.nx, self.sys.nb
        row = np.empty((len(members), rec._ncol))
        row[:, :nx] = Z[:, :nx]
        Vr, Vi = Z[:, nx:nx + nb], Z[:, nx + nb:]
        bus = row[:, rec._bus]
        bus[:, 0::4], bus[:, 1::4] = Vr, Vi
        bus[:, 2::4] = np.hypot(Vr, Vi)
        bus[:, 3::4] = np.arctan2(Vi, Vr)
        if self._ocols is None:
            self._ocols = fast_index([c for _, sl in rec._outs for c in range(sl.start, sl.stop)])
            self._okeys = [(key, sl.stop - sl.start) for key, sl in rec._outs]
        n = ctx.x.shape[0]
        every = len(pos) == n and list(pos) == list(range(n))    # all rows, in order: no gather
        if self._okeys:    # every output of the rows in one gather
            out = ctx.out
            cols = [v if getattr(v, "ndim", 0) >= 2 else np.broadcast_to(v, (n, w))
                    for v, w in ((out[key], w) for key, w in self._okeys)]
            cat = np.concatenate(cols, axis=1)
            row[:, self._ocols] = cat if every else cat[pos]
        tm, vs = ctx.sig["tm"], ctx.sig["vs"]
        row[:, rec._tm] = tm if every else tm[pos]
        row[:, rec._vs] = vs if every else vs[pos]
        self.blocks.append((t, np.asarray(members), row))

    def _selected_pieces(self) -> list:
        """Where each selected column of a row comes from (a recorder with ``record``): a
        list of ``(source, columns of the row, indices in the source)``, the sources
        ``"z"`` (the point: states, ``Vr``, ``Vi``), ``"v"``/``"a"`` (a bus's magnitude and
        angle, by bus), ``("out", key)`` (a model's output, by instance), ``"tm"``, ``"vs"``
        (by machine)."""
        rec = self.rec
        nx, nb = self.sys.nx, self.sys.nb
        parts: dict = {}
        for j, c in enumerate(rec.sel.tolist()):
            if c < nx:
                src, i = "z", c
            elif c < rec._bus.stop:
                b, q = divmod(c - nx, 4)
                src, i = (("z", nx + b), ("z", nx + nb + b), ("v", b), ("a", b))[q]
            elif c >= rec._vs.start:
                src, i = "vs", c - rec._vs.start
            elif c >= rec._tm.start:
                src, i = "tm", c - rec._tm.start
            else:
                key, sl = next((k, sl) for k, sl in rec._outs if sl.start <= c < sl.stop)
                src, i = ("out", key), c - sl.start
            cols, idx = parts.setdefault(src, ([], []))
            cols.append(j)
            idx.append(i)
        return [(src, fast_index(cols), fast_index(idx)) for src, (cols, idx) in parts.items()]

    def _selected(self, Z, ctx, pos):
        """The selected columns of the rows ``pos`` of ``ctx`` (points ``Z``): each computed
        alone, the same floats as those of the whole row (elementwise operations)."""
        n = ctx.x.shape[0]
        every = len(pos) == n and list(pos) == list(range(n))
        nx, nb = self.sys.nx, self.sys.nb
        row = np.empty((len(Z), len(self.rec.sel)))
        for src, cols, idx in self._pieces:
            if src == "z":
                row[:, cols] = Z[:, idx]
                continue
            if src in ("v", "a"):
                Vr, Vi = Z[:, nx:nx + nb][:, idx], Z[:, nx + nb:][:, idx]
                row[:, cols] = np.hypot(Vr, Vi) if src == "v" else np.arctan2(Vi, Vr)
                continue
            v = ctx.out[src[1]] if isinstance(src, tuple) else ctx.sig[src]
            if getattr(v, "ndim", 0) < 2:   # the same for every row
                row[:, cols] = np.asarray(v)[idx]
            else:
                row[:, cols] = (v if every else v[pos])[:, idx]
        return row

    def finish(self, B, failures, stats):
        """One :class:`Results` per member ``0..B-1``."""
        rec = self.rec
        if not rec._layout_done:    # nothing recorded (every member failed at t = 0)
            return [Results(np.zeros(0), [], np.zeros((0, 0)), [], [], failure=failures[k], stats=stats[k])
                    for k in range(B)]
        recorded = bool(self.blocks)
        if recorded:
            # each recorded row straight to its place in the rows sorted by member (stable: in
            # time within a member), block by block, each block released once placed: one copy
            # of the records, not a concatenation and a gather of it (two copies, 3× the memory)
            K = np.concatenate([m for _, m, _ in self.blocks])
            order = np.argsort(K, kind="stable")
            cut = np.searchsorted(K[order], np.arange(B + 1))
            dest = np.empty_like(order)
            dest[order] = np.arange(len(order))
            T = np.empty(len(K))
            D = np.empty((len(K), self.blocks[0][2].shape[1]))
            s = 0
            blocks, self.blocks = self.blocks, []
            for i, (t, m, d) in enumerate(blocks):
                at = dest[s:s + len(m)]
                T[at] = t
                D[at] = d
                s += len(m)
                blocks[i] = None
        out = []
        for k in range(B):
            if recorded:
                a, b = cut[k], cut[k + 1]
                t, data = T[a:b], D[a:b]     # views of the arrays sorted above: no copy
            else:
                t, data = np.zeros(0), np.zeros((0, len(rec.names)))
            out.append(Results(t, list(rec.names), data, list(rec.kinds), list(rec.fac),
                               failure=failures[k], stats=stats[k]))
        return out


def batch_unsupported(system, events=()) -> str | None:
    """Why a member with ``events`` on ``system`` cannot join a batch (None if it can)."""
    from .events import GeneratorTrip, flatten
    from .system import DENSE_NETWORK_MAX

    if system.nb > DENSE_NETWORK_MAX:
        return f"sparse network ({system.nb} buses > {DENSE_NETWORK_MAX})"
    if system._var_lim:
        return "limits that move with the solution (" + ", ".join(c.type_name for c, _ in system._var_lim) + ")"
    if system._accepting:
        return "components with discrete memory (" + ", ".join(c.type_name for c in system._accepting) + ")"
    if system.disconnected is not None:
        return "a disconnected unit"
    if any(isinstance(e, GeneratorTrip) for e in flatten(list(events))):
        return "a GeneratorTrip event (it changes the devices, not the network)"
    return _source_rows_changed(system, events)


def _source_rows_changed(system, events) -> str | None:
    """Why ``events`` cannot be batched on ``system`` because one changes the network rows of
    a bus an ideal source holds (None if none does). An ideal source
    (:class:`~weakgrid.sim.sources.InfiniteBus`, :class:`~weakgrid.sim.sources.PVSource`)
    balances its bus with the evaluating grid's rows of the network matrix, and the batch
    evaluates every member on one grid whose network the members' events do not change: a
    fault or load step at the source's bus, or a trip of a branch ending there, would leave the
    member on the pre-event rows."""
    from .events import LineTrip, LoadStep, _FaultSwitch, flatten
    from .network import F_BUS, T_BUS
    from .sources.ideal import _BusConstraint

    held = {int(b): c for c in system.comps if isinstance(c, _BusConstraint) for b in np.atleast_1d(c.bus)}
    if not held:
        return None
    net = system.network
    for e in flatten(list(events)):
        if isinstance(e, _FaultSwitch):
            buses = [e.owner.bus]
        elif isinstance(e, LoadStep):
            buses = [e.bus]
        elif isinstance(e, LineTrip) and isinstance(e.branch, (int, np.integer)) and 0 <= e.branch < len(net.branch):
            buses = [int(net.branch[e.branch, F_BUS]), int(net.branch[e.branch, T_BUS])]
        else:
            continue
        try:
            hit = sorted({net.index_of(b) for b in buses} & held.keys())
        except DataError:      # an unknown bus: the member's run reports it
            continue
        if hit:
            return (f"{e!r} changes the network rows of bus {net.bus_ids[hit[0]]}, which "
                    f"{held[hit[0]].type_name} holds (an ideal source balances its bus with the "
                    "evaluating grid's rows, which the batch does not change per member)")
    return None


#: attributes of a set-up :class:`System` that are its operating point, not its structure:
#: the initial point, the power flow's result, the load admittances and the network matrices
#: they enter, the machines' initial signals (held per member by :class:`BatchSimulator`)
OPERATING_POINT = ("z0", "y_load", "Yr", "Yr_dense", "_Yr_mv", "Yr_coo", "sig_defaults",
                   "_sig_stack")


#: attributes a component's ``init`` leaves for :meth:`System.setup`'s checks only (the initial
#: values of its static limits and gates, ``initial_bounds``): the operating point's, never
#: evaluated, so masked with it
INIT_CHECKS = ("initial_bounds",)


def _bp_get(c, name):
    """Value of the batchable parameter ``name`` of component ``c``: a parameter (``c.p``)
    or a set-point its initialization computed (an attribute)."""
    return c.p[name] if name in c.p else getattr(c, name, None)


def _bp_set(c, name, value):
    if name in c.p:
        c.p[name] = value
    else:
        setattr(c, name, value)


def _masked(system):
    """``[(setter, saved value)]`` after setting everything of ``system`` that members of a
    batch may hold of their own to None: the batchable parameters
    (:attr:`Component.batch_params`), the last evaluation's values (:attr:`Component.scratch`),
    the initialization's checks (:data:`INIT_CHECKS`), :data:`OPERATING_POINT` and the
    network's loads (``PD``, ``QD``), dispatch and voltage set points (the generators' ``PG``,
    ``QG``, ``VG``: the power flow's inputs, read by nothing else) and power flow."""
    from .network import PD, PG, QD, QG, VG

    saved = []

    def put(setter, old, new):
        saved.append((setter, old))
        setter(new)

    for c in system.comps:
        for name in getattr(c, "batch_params", ()):
            if name in c.p:
                put(lambda v, c=c, n=name: c.p.__setitem__(n, v), c.p[name], None)
                for v in c._values:
                    put(lambda x, v=v, n=name: v.__setitem__(n, x), v.get(name), None)
            elif hasattr(c, name):
                put(lambda v, c=c, n=name: setattr(c, n, v), getattr(c, name), None)
        for name in (*getattr(c, "scratch", ()), *INIT_CHECKS):
            if hasattr(c, name):
                put(lambda v, c=c, n=name: setattr(c, n, v), getattr(c, name), None)
    for name in OPERATING_POINT:
        if hasattr(system, name):
            put(lambda v, n=name: setattr(system, n, v), getattr(system, name), None)
    net = system.network
    put(lambda v: setattr(net, "pf", v), getattr(net, "pf", None), None)
    case = net.case if isinstance(getattr(net, "case", None), dict) else {}
    for key, table, cols in (("bus", net.bus, [PD, QD]), ("gen", net.gen, [PG, QG, VG])):
        for tab in [table] + ([case[key]] if key in case else []):
            def setter(v, tab=tab, cols=cols):
                tab[:, cols] = v
            put(setter, tab[:, cols].copy(), 0.0)
    return saved


def system_fingerprint(system) -> str:
    """A digest of everything of a set-up ``system`` but what the members of a batch hold of
    their own: its batchable parameters (:attr:`Component.batch_params`, including the
    set-points its initialization computed), its loads, its generators' dispatch and voltage
    set points and its operating point (the initial point, the power flow, the load
    admittances: :data:`OPERATING_POINT`). Grids with equal
    fingerprints can be members of one batch; grids that differ in their topology, lines,
    shunts, devices, models or other parameters cannot."""
    saved = _masked(system)
    try:
        blob = pickle.dumps(system, protocol=pickle.HIGHEST_PROTOCOL)
    finally:
        for setter, val in reversed(saved):
            setter(val)
    return hashlib.sha256(blob).hexdigest()


def member_params(systems) -> list:
    """``[(component index, name, (B, n) array)]``: the batchable parameters (and
    initialization set-points) whose values differ between the member grids ``systems``
    (equal :func:`system_fingerprint`), a row per member."""
    out = []
    for j, c in enumerate(systems[0].comps):
        for name in getattr(c, "batch_params", ()):
            if _bp_get(c, name) is None:
                continue
            rows = [np.asarray(_bp_get(s.comps[j], name)) for s in systems]
            rows = [r.astype(complex if np.iscomplexobj(r) else float) for r in rows]   # a phasor stays one
            if any(not np.array_equal(r, rows[0]) for r in rows[1:]):
                out.append((j, name, np.stack(rows)))
    return out


def member_signals(systems):
    """The machines' initial signals (``System._sig_stack``, ``(n_sig, n_machines)``) of the
    member grids ``systems`` stacked on a batch axis, ``(n_sig, B, n_machines)``; None when
    they are equal."""
    rows = [s._sig_stack for s in systems]
    if all(np.array_equal(r, rows[0]) for r in rows[1:]):
        return None
    return np.stack(rows, axis=1)


def _member_system(system, scenario):
    """The grid of a member: its own (``scenario["system"]``, set up) or the batch's."""
    s = scenario.get("system")
    if s is None:
        return system
    if not s.is_setup:
        s.setup()
    return s


class BatchSimulator:
    """Advance ``B`` members (copies of one set-up grid, each with its events and controllers)
    together from ``t = 0`` (see the module docstring).

    Parameters
    ----------
    system : System
        The grid, set up; each member simulates a deep copy (the argument is not changed).
    scenarios : list of dict
        One per member: ``{"events": [...], "controllers": [...], "system": System}`` (all
        optional), the arguments of :meth:`Simulator.run` and the member's own grid (default
        ``system``; it may differ from ``system`` only in batchable parameters:
        :func:`system_fingerprint`). Event and controller objects must not be shared between
        members (they hold per-run state).
    **sim_kw
        Keyword arguments of :class:`Simulator` (``dt``, ``tol``, ``max_iter``,
        ``max_angle_spread``, ``save_every``, ``record``; ``linear_solver`` must be dense).

    Attributes
    ----------
    timing : dict
        Wall time [s] spent in each part of the batched steps (:data:`TIMED`).
    steps : int
        Batched steps taken.
    """

    def __init__(self, system, scenarios, **sim_kw):
        if not system.is_setup:
            system.setup()
        why = batch_unsupported(system)
        if why:
            raise DataError("simulate_batch", "system", why, "run these scenarios one by one (Simulator.run)")
        if sim_kw.get("linear_solver", "dense") not in ("dense", "auto"):
            raise DataError("simulate_batch", "linear_solver", sim_kw["linear_solver"],
                            'the batch uses the dense solver: leave linear_solver at "auto"')
        sim_kw = dict(sim_kw, linear_solver="dense")
        self.sim_kw = sim_kw
        self.tmpl = copy.deepcopy(system)      # evaluates the devices of every member
        self.scen = [dict(s) for s in scenarios]
        self.B = len(self.scen)
        self.sims = []
        own = [_member_system(system, sc) for sc in self.scen]
        fp = system_fingerprint(system) if any(s is not system for s in own) else None
        for k, (sc, msys) in enumerate(zip(self.scen, own)):
            why = batch_unsupported(msys, sc.get("events", ()))
            if why:
                raise DataError("simulate_batch", "events", why, "run this scenario one by one (Simulator.run)")
            if msys is not system and system_fingerprint(msys) != fp:
                raise DataError("simulate_batch", f"scenarios[{k}].system", "a different grid",
                                "a member's grid may differ from the batch's only in its loads and "
                                "batchable parameters (Component.batch_params); batch it with its own grid "
                                "(simulate_batch groups them)")
            self.sims.append(Simulator(copy.deepcopy(msys), **sim_kw))
        # batchable parameters that differ: one (B, n) array each, bound like the inputs
        self._params = [(self.tmpl.comps[j], name, stack)
                        for j, name, stack in member_params([s.sys for s in self.sims])]
        self._signals = member_signals([s.sys for s in self.sims])   # initial signals
        self.nx, self.N = system.nx, system.N
        # controller outputs and other inputs a member changes: one (B, n) array per attribute,
        # each member's component holding a row view of it (Component.batch_inputs)
        self._inputs = []
        for c in self.tmpl.comps:
            for attr in getattr(c, "batch_inputs", ()):
                stack = np.stack([np.asarray(getattr(s.sys.components[c.type_name], attr), dtype=float)
                                  for s in self.sims])
                for k, s in enumerate(self.sims):
                    setattr(s.sys.components[c.type_name], attr, stack[k])
                self._inputs.append((c, attr, stack))
        # the states held at a limit: one (B, n_lim) array, each member's ``frozen`` a row view
        self._nlim = len(system.lim_idx)
        self.frozen = np.zeros((self.B, self._nlim), dtype=np.int8)
        for k, s in enumerate(self.sims):
            s.frozen = self.frozen[k]
        # each member's limits (fixed: limits that move with the solution are refused)
        self.lim_hi = np.stack([s.sys.lim_hi for s in self.sims])
        self.lim_lo = np.stack([s.sys.lim_lo for s in self.sims])
        nb = system.nb
        self.Y = np.empty((self.B, 2 * nb, 2 * nb))
        self._ynet = [None] * self.B
        self.timing = dict.fromkeys(TIMED, 0.0)
        self.steps = 0
        self.halved = 0
        self._all = list(range(self.B))     # every member, in order (see _every)
        self._bound = None                  # (rows, rep) bound in self.tmpl (_bind_inputs)

    # ------------------------------------------------------------- evaluations
    def _every(self, rows):
        """Whether ``rows`` are all the members in order (then the batched arrays are used as
        they are: no gather)."""
        return len(rows) == self.B and list(rows) == self._all

    def _bind_inputs(self, rows, rep=1):
        """Bind the rows ``rows`` of the members' inputs, parameters and initial signals into
        the evaluating copy (each repeated ``rep`` times, for the Jacobian's perturbed points).
        Every member in order: the batched arrays themselves (no gather). The parameters and
        signals do not change during a run: bound again only for other rows; the inputs (a
        controller's hold writes their rows) whenever they are copies."""
        every = self._every(rows)
        key = (True if every else tuple(rows), rep)
        same = key == self._bound
        if same and every and rep == 1:
            return      # the stacks themselves are bound (row writes show through)
        for c, attr, stack in self._inputs:
            a = stack if every else stack[rows]
            setattr(c, attr, a if rep == 1 else np.repeat(a, rep, axis=0))
        if same:
            return
        for c, name, stack in self._params:
            a = stack if every else stack[rows]
            _bp_set(c, name, a if rep == 1 else np.repeat(a, rep, axis=0))
        if self._signals is not None:   # Context reads them with the batch axis
            a = self._signals if every else self._signals[:, rows]
            self.tmpl._sig_stack = a if rep == 1 else np.repeat(a, rep, axis=1)
        self._bound = key

    def _sync_network(self, rows):
        for k in rows:
            s = self.sims[k].sys
            if self._ynet[k] != s.net_version:
                self.Y[k] = s.Yr_dense
                self._ynet[k] = s.net_version

    def residual(self, t, Z, rows):
        """``F = [f; g]`` of members ``rows`` at the points ``Z`` (one row each) and the context
        (its row ``i`` the member ``rows[i]``).

        A single member is evaluated as two copies of its row: NumPy rounds a complex product
        of a ``(1, 1)`` array and a broadcast ``(1,)`` parameter otherwise than the same
        product of ``(1,)`` arrays (its run alone) or of ``(B, 1)`` arrays, B ≥ 2 (measured
        on NumPy 2.4: 45 % of random products differ in the last bit). Case 1's HJI run and
        its batch, once the batch's Newton iteration had that run alone left, differed by one
        ulp in the UPQC's series power, then by 1.4e-8 rad in the SG's angle after 6 s."""
        t0 = time.perf_counter()
        nx = self.nx
        one = len(rows) == 1
        if one:
            self._bind_inputs(rows, 2)
            Z = np.repeat(Z, 2, axis=0)
        else:
            self._bind_inputs(rows)
        F, ctx = self.tmpl.device_residual(t, Z)
        Y = self.Y if self._every(rows) else self.Y[rows]
        F[:, nx:] += np.matmul(Y, Z[:, nx:, None])[..., 0]
        self.timing["residual"] += time.perf_counter() - t0
        return (F[:1], ctx) if one else (F, ctx)

    def refresh_jacobian(self, t, Z, rows):
        """Device Jacobians of members ``rows`` at ``Z`` by coloured differences, all in one
        evaluation; stored in each member's simulator as its own refresh would."""
        t0 = time.perf_counter()
        s = self.tmpl
        nc, N = s.ncolours, self.N
        H = 1e-7 * np.maximum(1.0, np.abs(Z))
        P = np.repeat(Z[:, None, :], nc + 1, axis=1)
        cols = s._ccols
        P[:, s.colour[cols] + 1, cols] += H[:, cols]
        self._bind_inputs(rows, nc + 1)
        D = s.device_residual(t, P.reshape(-1, N))[0].reshape(len(rows), nc + 1, N)
        vals = (D[:, s._pcol + 1, s._pr] - D[:, 0, s._pr]) / H[:, s._pc]
        for j, k in enumerate(rows):
            sim = self.sims[k]
            sim._refresh_next = False
            sim._Jdev = vals[j]
            sim.linsolver.set_device_jacobian(vals[j])
            sim.stats["jac"] += 1
            sim.stats["evals"] += nc + 1
            sim._lu_key = None
            sim._alg_key = None
        self.timing["jacobian"] += time.perf_counter() - t0

    # ------------------------------------------------------------------ solves
    def _alg_chord(self, t, Z, rows):
        """Chord iteration on the network variables of members ``rows`` (each member's own
        algebraic matrix, :meth:`_alg_solve`), as :meth:`Simulator._alg_chord`; returns
        ``{k: (z, F, (ctx, row))}`` of the members that converged (the others diverged or
        stalled)."""
        nx = self.nx
        done = {}
        n = len(rows)
        live = np.arange(n)
        prev = np.full(n, math.inf)
        grow = np.zeros(n, dtype=int)
        tol = np.asarray([self.sims[k].tol for k in rows])
        Z = Z.copy()
        for it in range(30):
            if not len(live):
                break
            idx = [rows[j] for j in live.tolist()]
            F, ctx = self.residual(t, Z[live], idx)
            dy = self._alg_solve(idx, F[:, nx:])
            nrm = np.abs(dy).max(axis=1)
            fin = np.isfinite(nrm)
            conv = fin & (nrm < tol[live])
            for i in np.nonzero(conv)[0].tolist():
                j = int(live[i])
                done[rows[j]] = (Z[j].copy(), F[i].copy(), (ctx, i))
                self.sims[rows[j]].stats["evals"] += it + 1   # a member that falls back counts its own
            g = np.where(nrm > 0.9 * prev[live], grow[live] + 1, 0)
            go = fin & ~conv & (g < 2)
            grow[live] = g
            keep = live[go]
            prev[keep] = nrm[go]
            Z[keep, nx:] -= dy[go]
            live = keep
        return done

    def _alg_solve(self, ks, R):
        """``A_k x = R[i]`` for members ``k = ks[i]``, ``A_k`` the member's algebraic block
        ``J_yy``, each with the member's own factor (:meth:`Simulator._alg_lu_get`, LAPACK
        ``getrs``: the arithmetic of its run alone). A stacked ``numpy.linalg.solve`` was tried:
        bit-equal where NumPy and SciPy share one LAPACK (NumPy 2 with SciPy's OpenBLAS), 1e-8
        off with another Newton count under NumPy 1.26's own OpenBLAS (then supported), and it
        saved little (the chord's time is its residual evaluations)."""
        return np.stack([self.sims[k]._alg_lu_get().solve(r) for k, r in zip(ks, R)])

    def _solve(self, lus, idx, R):
        """Chord solves ``M_j x = R[i]`` for ``j = idx[i]`` with each member's LU factors (LAPACK
        ``getrs``: the arithmetic of its run alone; a batched product with the inverses was
        slower here — more refreshes, a factorization's inverse per refresh — and not exact)."""
        out = np.empty(R.shape)
        for i, j in enumerate(idx):
            out[i] = lus[j].solve(R[i])
        return out

    def _newton(self, t1, h, Zn, Fn, rows, guess, corr):
        """One chord-Newton attempt of the trapezoidal step for members ``rows`` (as
        :meth:`Simulator._newton`, one member per row). Returns ``{k: (z, nit, f, (ctx, row))}``
        for the converged members (``ctx`` the evaluation at ``z``, its row ``row``) and the set
        of those that did not converge."""
        nx, N = self.nx, self.N
        n = len(rows)
        t0 = time.perf_counter()
        lus = [self.sims[k]._iteration_lu(h) for k in rows]
        self.timing["lu"] += time.perf_counter() - t0
        FZ = LV = None             # rows held at a limit (mask) and their values
        if self._nlim:
            FR = self.frozen[rows]
            fz = FR != 0
            if fz.any():
                li = self.tmpl.lim_idx
                FZ, LV = np.zeros((n, N), dtype=bool), np.zeros((n, N))
                FZ[:, li] = fz
                LV[:, li] = np.where(fz, np.where(FR > 0, self.lim_hi[rows], self.lim_lo[rows]), 0.0)
        # linearly implicit predictor of every member (used by those without a guess)
        Rp = np.zeros((n, N))
        Rp[:, :nx] = -h * Fn
        if FZ is not None:
            Rp = np.where(FZ, Zn - LV, Rp)
        Zp = Zn - self._solve(lus, range(n), Rp)
        Z = Zp.copy()
        refresh = []
        for j, k in enumerate(rows):
            sim = self.sims[k]
            if guess[k] is None:
                sim._pred = Zp[j]
                if corr[k] is not None:
                    Z[j] += corr[k]
                if sim._refresh_next:
                    refresh.append(j)
            else:
                Z[j] = guess[k]
        if FZ is not None:
            Z = np.where(FZ, LV, Z)
        if refresh:   # the chord matrix refreshed at the predicted points (all in one evaluation)
            self.refresh_jacobian(t1, Z[refresh], [rows[j] for j in refresh])
            t0 = time.perf_counter()
            for j in refresh:
                lus[j] = self.sims[rows[j]]._iteration_lu(h)
            self.timing["lu"] += time.perf_counter() - t0
            P = Zn[refresh] - self._solve(lus, refresh, Rp[refresh])
            for i, j in enumerate(refresh):
                self.sims[rows[j]]._pred = P[i]
        hh = 0.5 * h
        C = Zn[:, :nx] + hh * Fn
        done, failed = {}, set()
        live = np.arange(n)
        max_iter = self.sims[rows[0]].max_iter
        tol = self.sims[rows[0]].tol
        for it in range(max_iter):
            F, ctx = self.residual(t1, Z[live], [rows[j] for j in live.tolist()])
            t0 = time.perf_counter()
            f = F[:, :nx].copy()
            R = F
            R[:, :nx] = Z[live, :nx] - C[live] - hh * f
            if FZ is not None:
                R = np.where(FZ[live], Z[live] - LV[live], R)
            dz = self._solve(lus, live.tolist(), R)
            nrm = np.abs(dz).max(axis=1)
            bad = ~np.isfinite(nrm)
            conv = nrm < tol
            stop = bad | conv
            if stop.any():
                for i in np.nonzero(stop)[0].tolist():
                    j = int(live[i])
                    k = rows[j]
                    st = self.sims[k].stats
                    st["evals"] += it + 1
                    st["newton"] += it + 1
                    if bad[i]:
                        failed.add(k)
                    else:
                        done[k] = (Z[j], it + 1, f[i], (ctx, i))
                go = ~stop
                Z[live[go]] -= dz[go]
                live = live[go]
            else:
                Z[live] -= dz
            self.timing["newton"] += time.perf_counter() - t0
            if not len(live):
                break
        for j in live.tolist():
            k = rows[j]
            self.sims[k].stats["evals"] += max_iter
            self.sims[k].stats["newton"] += max_iter
            failed.add(k)
        return done, failed

    def _limits(self, ks, Zd, F1):
        """States of members ``ks`` (accepted points ``Zd``, derivatives ``F1``, one row each)
        that newly cross a limit (as :meth:`Simulator._step`): ``(new_hi, new_lo)`` masks."""
        s, li = self.tmpl, self.tmpl.lim_idx
        FR = self.frozen[ks]
        XL = Zd[:, li]
        new_hi = (FR == 0) & (XL > self.lim_hi[ks] + 1e-9)
        new_lo = (FR == 0) & (XL < self.lim_lo[ks] - 1e-9)
        if s.any_pushing:
            FL, push = F1[:, li], s.lim_pushing
            new_hi &= ~push | (FL >= 0)
            new_lo &= ~push | (FL <= 0)
        return new_hi, new_lo

    def _release(self, ks, F1):
        """Release the held states of members ``ks`` whose derivative (rows of ``F1``) points
        back inside (:meth:`Simulator._release_held`, for the batch at once)."""
        FR = self.frozen[ks]
        if not FR.any():
            return
        FL = F1[:, self.tmpl.lim_idx]
        rel = ((FR > 0) & (FL < 0)) | ((FR < 0) & (FL > 0))
        if rel.any():
            FR[rel] = 0
            self.frozen[ks] = FR

    def _step(self, h, act, retry=False):
        """One attempt at the step ``h`` of every member in ``act`` (as :meth:`Simulator._step`;
        ``retry``: the attempt after halving, without the previous step's correction). Returns
        the members whose Newton failed even with a fresh Jacobian (their step must be halved)."""
        t = self.t
        zn = {k: self.sims[k].z for k in act}
        fn = {k: self.sims[k]._f for k in act}
        guess = dict.fromkeys(act)
        refreshed = dict.fromkeys(act, False)
        corr = {}
        for k in act:
            sim = self.sims[k]
            ok = not retry and sim._corr is not None and abs(sim._corr_h - h) <= 1e-9 * h
            corr[k] = sim._corr if ok else None
        pending = list(act)
        eject = []
        while pending:
            Zn = np.stack([zn[k] for k in pending])
            Fn = np.stack([fn[k] for k in pending])
            done, failed = self._newton(t + h, h, Zn, Fn, pending, guess, corr)
            nxt = []
            fresh = []
            for k in pending:
                if k in failed:
                    if not refreshed[k]:
                        fresh.append(k)
                        refreshed[k] = True
                        guess[k] = corr[k] = None
                        nxt.append(k)
                    else:
                        eject.append(k)
            ok = [k for k in pending if k in done]
            if ok and self._nlim:
                Zd = np.stack([done[k][0] for k in ok])
                F1 = np.stack([done[k][2] for k in ok])
                new_hi, new_lo = self._limits(ok, Zd, F1)
                hit = (new_hi | new_lo).any(axis=1)
                for j in np.nonzero(hit)[0].tolist():   # redo the step with them held
                    k = ok[j]
                    sim, s, li = self.sims[k], self.sims[k].sys, self.tmpl.lim_idx
                    z, nh, nl = done[k][0], new_hi[j], new_lo[j]
                    sim.frozen[nh] = 1
                    sim.frozen[nl] = -1
                    guess[k] = z
                    if (s.lim_pushing & (nh | nl)).any():
                        g = z.copy()
                        g[li[nh]] = s.lim_hi[nh]
                        g[li[nl]] = s.lim_lo[nl]
                        guess[k] = sim.solve_algebraic(t + h, g)
                        sim._refresh_jacobian(t + h, guess[k])
                    nxt.append(k)
                if hit.any():
                    keep = ~hit
                    ok = [k for k, y in zip(ok, keep.tolist()) if y]
                    F1 = F1[keep]
                self._release(ok, F1)
            for k in ok:
                z, nit, f1, self._cx[k] = done[k]   # its context: Newton's evaluation at z
                sim = self.sims[k]
                sim._corr = z - sim._pred if guess[k] is None else None
                sim._corr_h = h
                if nit > sim.max_iter // 2 - 1:
                    sim._refresh_next = True
                sim.z, sim._f = z, f1
                sim.t = sim.t + h     # its own time (the batch's to round-off)
                sim.stats["steps"] += 1
            if fresh:
                self.refresh_jacobian(t, np.stack([zn[k] for k in fresh]), fresh)
            pending = nxt
        return eject

    # -------------------------------------------------------------------- run
    def run(self, t_end):
        """Simulate every member from 0 to ``t_end`` [s]; returns ``(results, rerun)``: one
        :class:`Results` per member (None for the members listed in ``rerun``, which left the
        lockstep and must be run one by one)."""
        from .events import prepare as prepare_events

        t_end = float(t_end)
        B, nx = self.B, self.nx
        evs, ctls, recs = [], [], []
        for sc, sim in zip(self.scen, self.sims):
            events = prepare_events(sc.get("events", ()), sim.sys, t_end)
            controllers = list(sc.get("controllers", ()))
            for c in controllers:
                c.bind(sim.sys)
            evs.append(events)
            ctls.append(controllers)
            sim._corr = sim._corr_h = None
            sim._refresh_next = False
            sim._jump, sim._jump_t = None, -math.inf
        recs = _BatchRecorder(self.sims[0].sys, self.sims[0].record)
        failures, fstats = [None] * B, [None] * B
        rerun = []
        act = list(range(B))
        self._sync_network(act)
        self.t = 0.0

        self._failed = set()
        self._cx = {}

        def fail(k, exc):
            failures[k], fstats[k] = exc, dict(self.sims[k].stats)
            act.remove(k)
            self._failed.add(k)

        # initial point: network solved with the initial Jacobian, controllers' first samples
        Z = np.stack([self.sims[k].z for k in act])
        self.refresh_jacobian(0.0, Z, act)
        self._solve_jump(0.0, act, {}, {}, fail)
        with_ctl = [k for k in act if ctls[k]]
        if with_ctl:
            self._accept_all(act)
            self._sample(0.0, with_ctl, ctls, fail)
            self._solve_jump(0.0, [k for k in with_ctl if k in act], {}, {}, fail)
        self._accept_all(act)
        for k in act:
            ctx, j = self._cx[k]
            self.sims[k]._delta0 = np.array(ctx.sig["delta"][j], dtype=float, copy=True)
        self._record(act, recs)
        ev_i = [0] * B
        nstep = [0] * B
        eps = 1e-12
        dt = self.sims[0].dt
        save_every = self.sims[0].save_every
        while act:
            live = [k for k in act if self.sims[k].t < t_end - eps]
            if not live:
                break
            tb, hk, ends = {}, {}, {}
            for k in live:     # each member's next breakpoint and step, as in its run alone
                t = self.sims[k].t
                b = t_end
                if ev_i[k] < len(evs[k]):
                    b = min(b, evs[k][ev_i[k]].t)
                for c in ctls[k]:
                    b = min(b, c.next_time(t))
                h = min(dt, b - t)
                if b - (t + h) < 1e-3 * dt:
                    h = b - t
                tb[k], hk[k] = b, h
                ends.setdefault(t, set()).add(t + h)
            live = self._catching_up(live, ends, 10 * eps)
            groups = {}
            for k in live:
                groups.setdefault(hk[k], []).append(k)
            # the members taking the same step take it together, whatever their times (the
            # evaluations of a batchable grid do not read the time, see batch_unsupported)
            stepped = []
            for h, grp in groups.items():
                if h > eps:
                    self.t = self.sims[grp[0]].t
                    for k in self._advance(h, grp):
                        act.remove(k)
                        rerun.append(k)
                    for k in grp:
                        if k in act:
                            nstep[k] += 1
                            stepped.append(k)
                    self.steps += 1
            live = [k for k in live if k in act]
            self.t = max(self.sims[k].t for k in live) if live else self.t
            self._accept_all(live)
            self._check(stepped, fail)
            live = [k for k in live if k in act]
            own = [k for k in live if abs(self.sims[k].t - tb[k]) <= eps * max(1.0, abs(tb[k])) * 10]
            for k in own:
                self.sims[k].t = tb[k]
            own_set = set(own)
            self._record([k for k in live if k in own_set or nstep[k] % save_every == 0], recs)
            at = {}
            for k in own:
                at.setdefault(tb[k], []).append(k)
            for t_g, G in sorted(at.items()):
                self.t = t_g
                self._breakpoint(G, evs, ev_i, ctls, recs, fail)
        for k in act:
            fstats[k] = dict(self.sims[k].stats)
        results = recs.finish(B, failures, fstats)
        for k in rerun:
            results[k] = None
        return results, rerun

    def _catching_up(self, live, ends, tol):
        """Members ``live`` that take their step now (``ends``: the times the members at each
        time reach with their steps): those a member behind them reaches with this step wait
        for it.

        A member that halved its step (:meth:`_advance`) reaches its breakpoint one iteration
        after the others; stepping on, it would stay a step behind them to its end, the batch
        advancing in two sub-batches per step, each at a batched step's fixed cost (case 1's
        map batch with 0.3-s faults, 2026-12-07: 4 944 breakpoints in 4 groups after t = 1 s,
        21.5 s instead of 10). Members behind that do not land on the others' time (no
        controller sample to meet at: their own step grid) step beside them, as before."""
        if len(ends) == 1:
            return live
        wait = {t for t in ends if any(
            t0 < t and any(abs(e - t) <= tol * max(1.0, abs(t)) for e in es)
            for t0, es in ends.items())}
        return [k for k in live if self.sims[k].t not in wait]

    def _advance(self, h, rows, retry=False):
        """One step ``h`` of members ``rows`` from :attr:`t`; a member whose Newton fails even
        with a fresh Jacobian halves its step and retries, as :meth:`Simulator._step` does —
        the members halving together in one sub-batch. Returns the members whose step would fall
        below ``min_step`` (their run alone fails there: it is re-run to report that failure)."""
        eject = self._step(h, rows, retry)
        if not eject:
            return []
        again = [k for k in eject if h / 2 < self.sims[k].min_step]
        sub = [k for k in eject if h / 2 >= self.sims[k].min_step]
        if sub:
            self.halved += len(sub)
            again += self._advance(h / 2, sub, retry=True)
        return again

    def _breakpoint(self, own, evs, ev_i, ctls, recs, fail):
        """Members ``own`` at their breakpoint :attr:`t` (recorded there, their contexts
        kept): apply their events, take their controllers' samples,
        re-solve the network of those that jumped and record them again (as :meth:`Simulator.run`)."""
        nx = self.nx
        jumps, new_jac, held = {}, {}, {}
        t0 = time.perf_counter()
        for k in list(own):
            sim = self.sims[k]
            events = evs[k]
            try:
                while ev_i[k] < len(events) and events[ev_i[k]].t <= sim.t + 1e-12:
                    events[ev_i[k]].apply(sim)
                    ev_i[k] += 1
                    new_jac[k] = True
            except SimulationError as exc:
                fail(k, exc)
                continue
            held[k] = [_held(c) for c in ctls[k]]
            if new_jac.get(k):
                jumps[k] = None
        self.timing["events"] += time.perf_counter() - t0
        own = [k for k in own if k not in self._failed]
        changed = self._sample(self.t, own, ctls, fail)
        for k in own:
            if k not in self._failed and (k in jumps or changed.get(k)):
                jumps[k] = None
        jumps = [k for k in jumps if k not in self._failed]
        if not jumps:
            return
        self._sync_network(jumps)
        guesses, du = {}, {}
        fresh = [k for k in jumps if new_jac.get(k)]
        if fresh:
            self.refresh_jacobian(self.t, np.stack([self.sims[k].z for k in fresh]), fresh)
        for k in jumps:
            sim = self.sims[k]
            if new_jac.get(k):
                sim._jump = None
                sim._corr = None
            elif sim._jump is not None and sim._jump_t > self.t - 1.5 * _gap(ctls[k]):
                du[k] = _held_change(ctls[k], held[k])
                guesses[k] = jump_guess(sim.z[nx:], sim._jump, du[k])
        paths = {k: (ctls[k], held[k]) for k in jumps}   # the jump's path, made if it is needed
        y_before = {k: self.sims[k].z[nx:] for k in jumps}
        self._solve_jump(self.t, jumps, guesses, paths, fail)
        jk = [k for k in jumps if k not in self._failed]
        for k in jk:
            sim = self.sims[k]
            if not new_jac.get(k):
                sim._jump = (sim.z[nx:] - y_before[k],
                             du[k] if k in du else _held_change(ctls[k], held[k]))
                sim._jump_t = self.t
            sim._release_held(sim._f)
        if jk:
            self._accept_all(jk)
            self._record(jk, recs)

    def _accept_all(self, act):
        """The contexts of members ``act`` at their accepted points: each member keeps the one of
        the evaluation that accepted its point (Newton's last iterate, the re-solve's last, as
        its run alone does) in ``_cx`` (``{k: (ctx, row)}``); the members without one are
        evaluated together, once."""
        miss = [k for k in act if k not in self._cx]
        if miss:
            F, ctx = self.residual(self.t, np.stack([self.sims[k].z for k in miss]), miss)
            for j, k in enumerate(miss):
                self._cx[k] = (ctx, j)

    def _by_ctx(self, rows):
        """Members ``rows`` grouped by their context: ``[(ctx, members, their rows)]``."""
        groups = {}
        for k in rows:
            ctx, j = self._cx[k]
            g = groups.setdefault(id(ctx), (ctx, [], []))
            g[1].append(k)
            g[2].append(j)
        return list(groups.values())

    def _record(self, rows, recs):
        """Record members ``rows`` at their times, from their contexts (:meth:`_accept_all`)."""
        if not rows:
            return
        t0 = time.perf_counter()
        for ctx, ks, pos in self._by_ctx(rows):
            recs.add(np.asarray([self.sims[k].t for k in ks]), ks, np.stack([self.sims[k].z for k in ks]),
                     ctx, pos)
        self.timing["record"] += time.perf_counter() - t0

    def _check(self, act, fail):
        """Divergence and loss of synchronism of members ``act`` (from their contexts,
        :meth:`_accept_all`), per member (as :meth:`Simulator._check`)."""
        if not act:
            return
        Z = np.stack([self.sims[k].z for k in act])
        bad = ~(np.abs(Z).max(axis=1) <= 1e6)
        d = None
        at = {k: j for j, k in enumerate(act)}
        for ctx, ks, pos in self._by_ctx(act):
            dg = ctx.sig["delta"]
            if d is None:
                d = np.empty((len(act), dg.shape[-1]))
            d[[at[k] for k in ks]] = dg[pos]
        if d.shape[-1] > 1:
            e = d - np.stack([self.sims[k]._delta0 for k in act])
            bad |= (e.max(axis=1) - e.min(axis=1)) > self.sims[act[0]].max_spread
        for j in np.nonzero(bad)[0].tolist():
            k = act[j]
            sim = self.sims[k]
            sim._ctx = sim.sys.residual(sim.t, sim.z)[1]   # the member's own evaluation
            try:
                sim._check()
            except SimulationError as exc:
                fail(k, exc)

    def _sample(self, t, rows, ctls, fail):
        """Take the due samples of members ``rows``; ``{k: changed}``. The ``j``-th controllers
        of the members declared ``batched`` are sampled together (:meth:`_sample_groups`:
        those that measure the same signals in one measurement and one hold, those that
        share a law — :meth:`DigitalController.batch_key` — in one call of it); the others
        one by one (:meth:`DigitalController.sample`)."""
        t0 = time.perf_counter()
        changed = {k: False for k in rows}
        for j in range(max((len(ctls[k]) for k in rows), default=0)):
            groups = {}
            for k in rows:
                if k not in changed or j >= len(ctls[k]):
                    continue
                c = ctls[k][j]
                if not c.due(t):
                    continue
                key = c.batch_key() if hasattr(c, "batch_key") else None
                if key is not None:
                    groups.setdefault(key, []).append(k)
                    continue
                sim = self.sims[k]
                sim._ctx = _RowCtx(*self._cx[k], sim.sys)   # what the measurement reads
                try:
                    changed[k] |= c.sample(sim, t, sim.z)
                except SimulationError as exc:
                    fail(k, exc)
                    del changed[k]
            merged = {}    # the law groups that measure the same signals: measured together
            for key, ks in groups.items():
                cs = [ctls[k][j] for k in ks]
                mkey = getattr(cs[0].measure, "key", None)
                merged.setdefault(("signals", mkey) if mkey is not None else ("law", key),
                                  []).append((ks, cs))
            for parts in merged.values():
                self._sample_groups(t, parts, changed, fail)
        self.timing["events"] += time.perf_counter() - t0
        return changed

    def _sample_groups(self, t, parts, changed, fail):
        """Sample the controllers ``cs`` of members ``ks`` for each ``(ks, cs)`` of ``parts``
        (one law each, all measuring the same signals): the measurements of the enabled
        ones stacked (:meth:`_measure`), each law called once on its rows (:meth:`_call_law`),
        and every output (the bypass of the disabled) held at once (:meth:`_hold`); each
        member's samples equal its run alone."""
        hk, hc, hu = [], [], []
        on_k, on_c, law = [], [], {}
        for g, (ks, cs) in enumerate(parts):
            for k, c in zip(ks, cs):
                if c.active(t):
                    on_k.append(k)
                    on_c.append(c)
                    law[k] = g
                else:
                    hk.append(k)
                    hc.append(c)
                    hu.append(c.bypass)
        if on_k:
            mk, mc, M = self._measure(t, on_k, on_c, fail)
            rows = {}
            for i, k in enumerate(mk):
                rows.setdefault(law[k], []).append(i)
            for pos in rows.values():
                self._call_law(t, [mk[i] for i in pos], [mc[i] for i in pos], M[pos], changed,
                               fail, (hk, hc, hu))
        if hk:
            for k, ch in zip(hk, self._hold(t, hk, hc, hu)):
                changed[k] |= ch

    def _call_law(self, t, mk, mc, M, changed, fail, held):
        """The outputs of the controllers ``mc`` (members ``mk``, one law) at their
        measurements ``M``: one call (:meth:`DigitalController.call_rows`; if it raises, each
        member alone, :meth:`_call_alone`), each output checked (a bad one fails its member
        with its run alone's message); the good ones appended to ``held`` (members,
        controllers, outputs)."""
        try:
            U = mc[0].call_rows(mc, M)
        except Exception:    # a member's own error: each called alone, as in its run
            U, mk, mc, M = self._call_alone(t, mk, mc, M, changed, fail)
        try:
            U = np.asarray(U, dtype=float)
            if mk and (U.ndim != 2 or U.shape[0] != len(mk)):
                raise ValueError(f"a batched policy returned {U.shape[0] if U.ndim else 0} rows "
                                 f"for {len(mk)} (an array of shape {U.shape})")
        except Exception as exc:
            for k, c in zip(mk, mc):
                fail(k, SimulationError(t, "controller", f"'{c.name}' raised {exc!r}"))
                del changed[k]
            return
        ok = (np.isfinite(U).all(axis=1) if mk and U.shape[1] == mc[0].target.size
              else np.zeros(len(mk), dtype=bool))
        for i, (k, c) in enumerate(zip(mk, mc)):
            if not ok[i]:    # its own message (as its run alone)
                try:
                    c.check(t, U[i], M[i])
                except SimulationError as exc:
                    fail(k, exc)
                    del changed[k]
                    continue
            held[0].append(k)
            held[1].append(c)
            held[2].append(U[i])

    def _call_alone(self, t, ks, cs, M, changed, fail):
        """The policies of controllers ``cs`` (members ``ks``) called one by one on their rows
        of ``M`` (after the batched call raised): a member whose policy raises fails alone, with
        the message of its run alone. Returns the outputs and the members, controllers and
        measurements left."""
        U, mk, mc, mm = [], [], [], []
        for k, c, m in zip(ks, cs, M):
            try:
                try:
                    u = c.K(m)
                except Exception as exc:
                    raise SimulationError(t, "controller", f"'{c.name}' raised {exc!r}") from exc
                u = c.check(t, u, m)
            except SimulationError as exc:
                fail(k, exc)
                del changed[k]
                continue
            U.append(u)
            mk.append(k)
            mc.append(c)
            mm.append(m)
        if not mk:
            return np.zeros((0, 0)), mk, mc, M[:0]
        return np.stack(U), mk, mc, np.stack(mm)

    def _measure(self, t, ks, cs, fail):
        """The measurements of controllers ``cs`` of members ``ks`` at their accepted points:
        one gather per context when the measurement reads rows of a batched context (its
        ``rows``), else one by one. Returns the members measured, their controllers and the
        ``(n, m)`` measurements."""
        fns = [c.measure for c in cs]
        rows_of = getattr(fns[0], "rows", None)
        at = {k: i for i, k in enumerate(ks)}
        if rows_of is not None:
            blocks = []
            for ctx, g, pos in self._by_ctx(ks):
                Y = rows_of([fns[at[k]] for k in g], [self.sims[k] for k in g], t, ctx, pos)
                if Y is None:
                    break
                blocks.append(([at[k] for k in g], np.asarray(Y, dtype=float)))
            else:
                if len(blocks) == 1:      # one context: the rows in the members' order
                    return list(ks), list(cs), blocks[0][1]
                M = np.empty((len(ks), blocks[0][1].shape[1]))
                for idx, Y in blocks:
                    M[idx] = Y
                return list(ks), list(cs), M
        mk, mc, M = [], [], []
        for k, c in zip(ks, cs):
            sim = self.sims[k]
            sim._ctx = _RowCtx(*self._cx[k], sim.sys)   # what the measurement reads
            try:
                m = c.measurement(sim, t)
            except SimulationError as exc:
                fail(k, exc)
                continue
            mk.append(k)
            mc.append(c)
            M.append(np.asarray(m, dtype=float))
        return mk, mc, (np.stack(M) if M else np.zeros((0, 0)))

    def _hold(self, t, ks, cs, U):
        """Hold output ``U[i]`` (checked) on the target of controller ``cs[i]`` of member
        ``ks[i]`` from sample ``t`` on; whether each held output changed. The targets that
        name their slots in the members' batched inputs (``target.slots()``, e.g. the UPQC's
        ``u_p``, ``u_q``) are read and written for all the members at once."""
        for c, u in zip(cs, U):
            c.logged(t, u)
        slots = getattr(cs[0].target, "slots", None)
        slots = slots() if slots is not None else None
        where = {(c.type_name, attr): stack for c, attr, stack in self._inputs}
        if slots is None or any(s[:2] not in where for s in slots) or \
                any(getattr(c.target, "slots", lambda: None)() != slots for c in cs[1:]):
            out = []
            for c, u in zip(cs, U):
                ch = not np.array_equal(c.target.get(), u)
                if ch:
                    c.target.apply(u)
                out.append(ch)
            return out
        U = np.stack([np.asarray(u, dtype=float) for u in U])
        rows = np.asarray(ks)
        old = np.stack([where[(typ, attr)][rows, i] for typ, attr, i in slots], axis=1)
        ch = (old != U).any(axis=1)
        if ch.any():
            r = rows[ch]
            for e, (typ, attr, i) in enumerate(slots):
                where[(typ, attr)][r, i] = U[ch, e]
        return ch.tolist()

    def _solve_jump(self, t, rows, guesses, paths, fail):
        """Consistent network re-solve of members ``rows`` after a jump: the batched chord
        iteration, then each member's own :meth:`Simulator.solve_algebraic` for those whose
        chord iteration did not converge (Newton, path following, continuation; ``paths[k]``:
        the member's controllers and their held outputs, for :func:`_output_path`)."""
        if not rows:
            return
        nx = self.nx
        Z = np.stack([self.sims[k].z for k in rows])
        for j, k in enumerate(rows):
            if guesses.get(k) is not None:
                Z[j, nx:] = guesses[k]
        done = self._alg_chord(t, Z, rows)
        for k in rows:
            sim = self.sims[k]
            if k in done:
                sim.z, F, self._cx[k] = done[k]
                sim._f = F[:nx].copy()
                continue
            self._cx.pop(k, None)
            try:   # the member's own re-solve: its chord iteration again, then Newton and the rest
                sim.t = t
                p = paths.get(k)
                z, F, sctx = sim.solve_algebraic(t, sim.z, return_eval=True, y_guess=guesses.get(k),
                                                 path=_output_path(*p) if p else None)
            except SimulationError as exc:
                fail(k, exc)
                continue
            sim.z, sim._f = z, F[:nx].copy()
            self._sync_network([k])


def _gap(controllers):
    return min([c.T for c in controllers if hasattr(c, "T")] or [0.0])


def breakpoint_key(scenario, dt):
    """The breakpoints of a scenario that are not on the step grid (multiples of ``dt``) and its
    controllers' sampling (``T``, ``t0``): members with equal keys take the same steps together
    as alone."""
    from .events import flatten

    off = off_grid([ev.t for ev in flatten(list(scenario.get("events", ())))], dt)
    ctl = tuple(sorted((round(getattr(c, "T", 0.0), 12), round(getattr(c, "t0", 0.0), 12))
                       for c in scenario.get("controllers", ())))
    return off, ctl


def off_grid(times, dt) -> tuple:
    """The instants of ``times`` [s] that are not multiples of the step ``dt`` [s], sorted,
    rounded to 1e-12 s (what separates members in :func:`breakpoint_key`)."""
    off = set()
    for t in times:
        q = t / dt
        if abs(q - round(q)) > 1e-9 * max(1.0, abs(q)):
            off.add(round(t, 12))
    return tuple(sorted(off))


def simulate_batch(system, scenarios, t_end, batch_size=64, exact=True, on_failure="return",
                   stats=None, **sim_kw) -> list[Results]:
    """Simulate ``scenarios`` of one grid in batches; one :class:`Results` per scenario, in order.

    Parameters
    ----------
    system : System
        The grid (set up); every scenario runs on a deep copy of it.
    scenarios : list of dict
        ``{"events": [...], "controllers": [...], "system": System}`` per scenario (fresh
        objects per scenario; ``system``: the scenario's own grid, default the argument).
        Scenarios whose grids differ only in their loads (operating point) and batchable
        parameters share batches, each with its own values (:func:`system_fingerprint`).
    t_end : float
        Final time [s].
    batch_size : int
        Largest number of members advanced together.
    exact : bool
        Group the members by their breakpoints off the step grid (:func:`breakpoint_key`), so
        that a batch's members take equal steps. ``False`` batches them regardless: each member
        still takes the steps of its run alone (results equal to one-by-one runs to round-off
        either way), members at different step sizes in separate Newton calls.
    on_failure : {"return", "raise"}
        A member's failure is in its ``Results.failure``; ``"raise"`` raises the first one after
        every member has run.
    stats : dict, optional
        Filled with ``batches``, ``steps`` (batched steps, :attr:`BatchSimulator.steps`),
        ``halved`` (halved steps taken in the batch), ``rerun`` (members re-run one by one: a
        step below ``min_step``), ``alone`` (members run one by one from the start) and
        ``timing`` (summed :attr:`BatchSimulator.timing`).
    **sim_kw
        :class:`Simulator` keyword arguments (``dt``, ``tol``, ``record``, ...).

    Examples
    --------
    >>> res = simulate_batch(sys, [{"events": [Fault(3, 0.2, 0.25, xf=x)]} for x in (0.05, 0.1)],
    ...                      5.0, dt=5e-3)                          # doctest: +SKIP
    """
    if on_failure not in ("return", "raise"):
        raise DataError("simulate_batch", "on_failure", on_failure, 'use "return" or "raise"')
    if not (isinstance(batch_size, int) and batch_size >= 1):
        raise DataError("simulate_batch", "batch_size", batch_size, "give a positive integer")
    if not system.is_setup:
        system.setup()
    scenarios = [dict(s) for s in scenarios]
    dt = float(sim_kw.get("dt", 1 / 120))
    out = [None] * len(scenarios)
    st = {"batches": 0, "steps": 0, "rerun": 0, "halved": 0, "alone": 0, "timing": dict.fromkeys(TIMED, 0.0)}
    groups = {}
    alone = []
    fps = {}    # per grid object: its fingerprint (only when some scenario brings its own grid)
    own = any(sc.get("system") is not None for sc in scenarios)
    for i, sc in enumerate(scenarios):
        msys = _member_system(system, sc)
        if batch_unsupported(msys, sc.get("events", ())):
            alone.append(i)
            continue
        if id(msys) not in fps:
            fps[id(msys)] = system_fingerprint(msys) if own else None
        key = (fps[id(msys)],) + ((breakpoint_key(sc, dt),) if exact else ())
        groups.setdefault(key, []).append(i)

    def one(i):
        sc = scenarios[i]
        for c in sc.get("controllers", ()):
            if hasattr(c, "log_t"):
                c.log_t, c.log_u = [], []
        sim = Simulator(copy.deepcopy(_member_system(system, sc)), **sim_kw)
        return sim.run(t_end, events=sc.get("events", ()), controllers=sc.get("controllers", ()),
                       on_failure="return")

    for members in groups.values():
        for a in range(0, len(members), batch_size):
            part = members[a:a + batch_size]
            bs = BatchSimulator(_member_system(system, scenarios[part[0]]),
                                [scenarios[i] for i in part], **sim_kw)
            res, rerun = bs.run(t_end)
            st["batches"] += 1
            st["halved"] += bs.halved
            st["steps"] += bs.steps
            for key, v in bs.timing.items():
                st["timing"][key] += v
            for j, i in enumerate(part):
                out[i] = res[j]
            for j in rerun:
                log.info("scenario %d left the batch (its step had to be shortened): run alone", part[j])
                out[part[j]] = one(part[j])
                st["rerun"] += 1
    for i in alone:
        out[i] = one(i)
        st["alone"] += 1
    if stats is not None:
        stats.update(st)
    if on_failure == "raise":
        for r in out:
            if r.failure is not None:
                raise r.failure
    return out
