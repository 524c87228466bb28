"""Base class of vectorized component models and the evaluation context.

A *component type* (e.g. :class:`~weakgrid.sim.machines.genrou.GENROU`) holds
all instances of that model in the system and evaluates them together with
numpy. States are laid out state-major, so state ``k`` of all instances is the
contiguous slice ``x[off + k*n : off + (k+1)*n]``.

Evaluation happens in two passes over all components (see
:meth:`weakgrid.sim.system.System.evaluate`):

1. ``compute(ctx)`` in the order machines/sources → PSS → exciters/governors →
   series devices: each component reads the states, bus voltages and the
   signals already published by earlier components, publishes its own output
   signals (e.g. ``vf``, ``tm``) and writes the derivatives it can already form;
2. ``finish(ctx)``: derivatives that need signals published later (e.g. the
   machine's field and shaft equations, which need ``vf`` and ``tm``).

Signals between the parts of a generator (machine + shaft + AVR + governor +
PSS) are arrays indexed by the global machine number, in ``ctx.sig``.
"""

from __future__ import annotations

import numpy as np

from .errors import DataError
from .namespace import NUMPY
from .params import Param, validate


class Context:
    """Scratch data for one evaluation of the system equations.

    Attributes
    ----------
    t : float
        Time [s].
    x : ndarray
        State vector.
    V : ndarray of complex
        Bus voltage phasors [pu].
    f : ndarray
        Output: state derivatives.
    I : ndarray of complex
        Output: current injected into each bus by the devices [pu].
    sig : dict of ndarray
        Machine-indexed signals (``omega``, ``delta``, ``Pe``, ``Qe``, ``Vt``,
        ``XadIfd``, ``vf``, ``tm``, ``vs``, ``Ecomp``) and other shared signals.
    out : dict of ndarray
        Recorded outputs, keyed ``"<Type>.<output>"``.
    """

    __slots__ = ("t", "x", "V", "f", "I", "sig", "out", "system")

    def __init__(self, system, t, x, V):
        self.system = system
        self.t = t
        self.x = x
        self.V = V
        xp = system.xp
        self.f = xp.zeros(x.shape, dtype=xp.float64)
        self.I = xp.zeros(V.shape, dtype=xp.complex128)
        # one copy of the stacked defaults; the dict holds row views of it
        S = system._sig_stack
        if x.ndim > 1 and S.ndim == 2:   # a batch of points (leading axis): one row block per
            # point (a batch simulator may bind its members' own, (n_sig, B, n): weakgrid.sim.batch)
            S = xp.broadcast_to(S[:, None, :], (S.shape[0],) + x.shape[:-1] + (S.shape[1],))
        if xp is NUMPY:
            self.sig = dict(zip(system._sig_keys, S.copy()))
        else:
            S = xp.asarray(S, copy=True)
            self.sig = {k: S[i, ...] for i, k in enumerate(system._sig_keys)}
        self.out = {}


def fast_index(idx):
    """A slice equal to the integer index array ``idx`` when it is a contiguous increasing run
    (basic indexing is cheaper than fancy indexing on small arrays), else ``idx`` itself."""
    idx = np.asarray(idx, dtype=int)
    if len(idx) and np.array_equal(idx, np.arange(idx[0], idx[0] + len(idx))):
        return slice(int(idx[0]), int(idx[0]) + len(idx))
    return idx


class Component:
    """Base class of a vectorized component type.

    Attributes
    ----------
    kind : str
        ``"machine"``, ``"pss"``, ``"exciter"``, ``"governor"`` or ``"device"``.
    order : int
        Position in the ``compute`` pass (lower first).
    params : tuple of Param
        Declared parameters (standard PSS/E / ANDES names).
    states : tuple of str
        State names.
    outputs : tuple of str
        Names of recorded algebraic outputs (set in ``ctx.out``).
    """

    kind = "device"
    order = 0
    #: the array namespace its evaluation calls (:mod:`weakgrid.sim.namespace`)
    xp = NUMPY
    #: its evaluation (``compute``, ``finish``) is written for any array-API namespace
    #: (:func:`weakgrid.sim.namespace.on_namespace`), not NumPy's alone; said by each model
    #: class itself (a subclass does not inherit it)
    array_api = False
    params: tuple[Param, ...] = ()
    states: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    #: physical unit class of each state/output for SI conversion (default "pu")
    units: dict[str, str] = {}
    #: PSS/E ``.dyr`` record layout after ``IBUS 'MODEL' ID`` (ICONs first, then CONs, in the
    #: order of PSS/E's Program Application Guide): weakgrid parameter names, or names that
    #: :meth:`psse_params` converts; names starting with "_" are read but are not parameters.
    #: ``None``: the model has no PSS/E counterpart (its records are refused).
    psse_record: tuple[str, ...] | None = None
    #: how many of the last fields of :attr:`psse_record` may be missing (defaults apply)
    psse_record_optional: int = 0
    #: the model injects current and can be disconnected by a generator trip
    #: (:class:`~weakgrid.sim.events.GeneratorTrip`): its injection goes through :meth:`connected`
    disconnectable: bool = False
    #: attributes a run changes from outside (a controller's held output, e.g. UPQC ``u_p``):
    #: arrays over the instances that the batch simulator (:mod:`weakgrid.sim.batch`) holds per
    #: member, with a leading batch axis when the members are evaluated together
    batch_inputs: tuple[str, ...] = ()
    #: parameters (names of :attr:`params`) that the members of a batch may hold with different
    #: values (:mod:`weakgrid.sim.batch`): read from ``self.p`` only when evaluating (nothing is
    #: derived from them at setup), so a ``(B, n)`` array of them broadcasts as the batched
    #: variables do; and set-points that :meth:`init` computes from the operating point (an
    #: exciter's ``vref0``: attributes over the instances, read only when evaluating), so that
    #: grids at different loads share a batch. A parameter outside this list that differs puts
    #: members in different batches
    batch_params: tuple[str, ...] = ()
    #: attributes holding the last evaluation's intermediate values (not the grid's data):
    #: ignored when the batch simulator compares grids (:func:`weakgrid.sim.batch.system_fingerprint`)
    scratch: tuple[str, ...] = ()
    #: outputs that record zero once an instance is disconnected (its power and currents)
    injection_outputs: tuple[str, ...] = ()
    #: per instance 1.0 (connected) or 0.0 (disconnected by a generator trip); None: all connected
    live: np.ndarray | None = None

    @classmethod
    def psse_params(cls, values: dict, ctx) -> dict:
        """weakgrid parameters of one PSS/E ``.dyr`` record.

        Parameters
        ----------
        values : dict
            Record values by the names of :attr:`psse_record` (float, or str for quoted text).
        ctx : weakgrid.sim.io.psse.PsseContext
            The generator the record belongs to (bus, id, MBASE, ZSORCE, bus kV, ...) and
            ``where`` (file, line, record) for error messages.

        Returns
        -------
        dict
            Parameter name -> value; names starting with "_" are dropped by the reader.
        """
        return dict(values)

    def __init__(self):
        self.names: list[str] = []
        self.links: list[dict] = []
        self._values: list[dict] = []
        self.n = 0
        self.off = 0
        self.p: dict[str, np.ndarray] = {}

    @property
    def type_name(self) -> str:
        return type(self).__name__

    def element(self, i_or_name) -> str:
        name = self.names[i_or_name] if isinstance(i_or_name, (int, np.integer)) else i_or_name
        return f"{self.type_name} '{name}'"

    def add(self, name: str, link: dict, values: dict):
        """Register one instance; ``values`` are validated against :attr:`params`."""
        if name in self.names:
            raise DataError(self.element(name), "name", name, "names must be unique within a model type")
        self._values.append(validate(self.element(name), self.params, values))
        self.names.append(name)
        self.links.append(dict(link))
        self.n = len(self.names)

    def remove(self, name: str):
        """Unregister instance ``name`` (before :meth:`System.setup`, which lays the states out
        again)."""
        if name not in self.names:
            raise DataError(self.element(name), "name", name,
                            f"no such {self.type_name}; known: {self.names}")
        i = self.names.index(name)
        for lst in (self.names, self.links, self._values):
            del lst[i]
        self.n = len(self.names)

    def warn_instances(self, rows, what: str, detail, show: int = 5, stacklevel: int = 3):
        """One :class:`~weakgrid.sim.errors.DataWarning` for every instance ``rows`` of this
        model that shares an accepted but unusual condition ``what``, with their count and
        the first ``show`` of them (``detail(i)``: the instance's values), instead of one
        warning per instance (ANDES's ieee39: nine GENROU with xl >= xd2)."""
        import warnings

        from .errors import DataWarning

        rows = [int(i) for i in rows]
        if not rows:
            return
        shown = "; ".join(f"'{self.names[i]}' {detail(i)}" for i in rows[:show])
        more = f"; and {len(rows) - show} more" if len(rows) > show else ""
        warnings.warn(f"{self.type_name} ({len(rows)} of {self.n}): {what}: {shown}{more}",
                      DataWarning, stacklevel=stacklevel)

    # ------------------------------------------------------------------ setup
    def setup(self, system):
        """Build parameter arrays (system base). Subclasses extend with link resolution."""
        self.p = {p.name: np.array([v[p.name] for v in self._values], dtype=float) for p in self.params}

    def connected(self, I):
        """The currents ``I`` (last axis: instances) with those of disconnected instances
        removed (:mod:`weakgrid.sim.disconnect`)."""
        return I if self.live is None else I * self.live

    def resolve_gen_rows(self, system):
        """Set ``self.gen`` (the 0-based gen-table row of each instance's ``gen`` link) and
        ``self.bus`` (its bus position), refusing a row that does not exist or is out of
        service (naming the instance)."""
        from .network import GEN_BUS, GEN_STATUS

        net = system.network
        self.gen = np.zeros(self.n, int)
        self.bus = np.zeros(self.n, int)
        for i, lk in enumerate(self.links):
            g = lk.get("gen")
            try:
                ok = g is not None and int(g) == g and 0 <= int(g) < net.gen.shape[0]
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise DataError(self.element(i), "gen", g,
                                f"give the 0-based row of the gen table (0..{net.gen.shape[0] - 1})")
            g = int(g)
            if net.gen[g, GEN_STATUS] <= 0:
                raise DataError(self.element(i), "gen", g,
                                "this generator is out of service; set GEN_STATUS = 1")
            self.gen[i] = g
            self.bus[i] = net.index_of(int(net.gen[g, GEN_BUS]), self.element(i), "gen bus")

    def assign(self, off: int) -> int:
        """Reserve state indices starting at ``off``; return the next free index."""
        self.off = off
        self._sls = [slice(off + k * self.n, off + (k + 1) * self.n) for k in range(len(self.states))]
        return off + self.n * len(self.states)

    def sl(self, k: int) -> slice:
        """Slice of state number ``k`` (all instances) in the state vector."""
        return self._sls[k]

    def idx(self, state: str) -> np.ndarray:
        """Global indices of ``state`` for all instances."""
        k = self.states.index(state)
        return np.arange(self.off + k * self.n, self.off + (k + 1) * self.n)

    def instance_states(self, i: int) -> list[int]:
        """Global state indices of instance ``i``."""
        return [self.off + k * self.n + i for k in range(len(self.states))]

    def limits(self) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Non-windup limited states: list of ``(global_indices, lower, upper)``."""
        return []

    def limits_reset_if_pushing(self) -> list[np.ndarray] | None:
        """Optional, one boolean array per entry of :meth:`limits`: ``True`` where a state
        that crosses its limit is reset to it only while its derivative pushes outwards
        (``>= 0`` at an upper limit, ``<= 0`` at a lower one), as ANDES's ``AntiWindup``;
        a state beyond its limit moving back towards it then stays free. ``None``: every
        limit is a non-windup limit (the state never crosses it)."""
        return None

    # -------------------------------------------------------------- equations
    def init(self, system, x: np.ndarray, sig: dict):
        """Set initial states in ``x`` from the power flow and published signals."""

    def compute(self, ctx: Context):
        """First evaluation pass (outputs, signals, derivatives where possible)."""

    def finish(self, ctx: Context):
        """Second evaluation pass (derivatives needing later signals)."""

    def pattern(self, system):
        """Jacobian coupling groups: list of ``(rows, cols)`` global index lists.

        Default: handled by the system (grouped with the linked machine).
        """
        return None
