"""The simulated system: network + components, the DAE residual and its Jacobian.

Variables are ``z = [x; Vr; Vi]`` (states, then real and imaginary parts of
the bus voltages in pu). The DAE is

.. math::

    \\dot x = f(t, x, V), \\qquad 0 = g(x, V) = Y V - I(x, V)

where ``Y`` is the network admittance matrix with constant-impedance loads,
shunts and applied faults, and ``I`` the currents injected by the devices.
``g`` is stored as its real part (rows ``nx..nx+nb``) and imaginary part.

The Jacobian ``dF/dz`` is the sum of the analytic network part (``Y`` in real
form) and a device part obtained by *coloured* finite differences: devices
declare coupling groups (a generator with its controls and its bus; a GTI and
its buses, ...) and columns that never share a row are perturbed together.
"""

from __future__ import annotations

import numpy as np

from .component import Component, Context
from .errors import DataError
from .namespace import NUMPY
from .network import Network

SIGNALS = ("omega", "delta", "Pe", "Qe", "Vt", "theta", "XadIfd", "vf", "tm", "vs",
           "vf0", "tm0", "Pe0", "Qe0", "delta0", "Vt0", "theta0", "Ecomp", "Ecomp0")


#: systems with at most this many buses keep a dense copy of the network matrix for the residual
DENSE_NETWORK_MAX = 150


def colour_columns(P):
    """Greedy (first-fit, in column order) colouring of the columns of a sparse pattern.

    Two columns get different colours when they share a row. Equivalent to the
    first-fit scan "column ``j`` takes the first colour whose rows do not meet
    its own", in O(sum over columns of the entries of their neighbour rows).

    Parameters
    ----------
    P : scipy.sparse matrix (N × N)

    Returns
    -------
    colour : ndarray of int
        Colour of each column; -1 for empty columns.
    ncolours : int
    """
    import scipy.sparse as sp

    P = sp.csc_matrix(P, dtype=bool)
    R = P.tocsr()
    N = P.shape[1]
    colour = -np.ones(N, dtype=np.int64)
    cind, cptr = P.indices, P.indptr
    rind, rptr = R.indices, R.indptr
    ncol = 0
    for j in range(N):
        a, b = cptr[j], cptr[j + 1]
        if a == b:
            continue
        rows = cind[a:b]
        if len(rows) == 1:
            nb = rind[rptr[rows[0]]:rptr[rows[0] + 1]]
        else:
            nb = np.concatenate([rind[rptr[i]:rptr[i + 1]] for i in rows])
        used = colour[nb]
        used = used[used >= 0]
        if len(used) == 0:
            k = 0
        else:
            taken = np.zeros(ncol + 1, dtype=bool)
            taken[used] = True
            k = int(np.argmin(taken))
        colour[j] = k
        ncol = max(ncol, k + 1)
    return colour, ncol


def _registry():
    from .exciters import EXDC2, SEXS
    from .governors import HYGOV, TGOV1
    from .machines import GENCLS, GENROE, GENROU, GENSAE, GENSAL
    from .pss import IEEEST
    from .loads import ZIP
    from .renewables import ESD1, PVD1, REECA1, REECB1, REGCA1, REPCA1
    from .sources import InfiniteBus, PVSource

    from .exciters import (AC8B, ESAC1A, ESDC1A, ESDC2A, ESST1A, ESST3A, ESST4B, EXAC1, EXAC4, EXST1,
                           IEEET1, IEEET3, IEEEVC, IEEEX1)
    from .governors import GAST, IEEEG1, IEESGO, TG2, TGOV1N
    from .governors import DEGOV, DEGOV1, GGOV1, PIDGOV, WPIDHY
    from .pss import PSS2A, PSS2B, PSS2C, ST2CUT, STAB1
    from .renewables import WTARA1, WTDTA1, WTPTA1, WTTQA1
    from .exciters import ESAC6A, EXAC2, EXPIC1, SCRX, ST6B, ST8C

    return {c.__name__: c for c in (GENCLS, GENROU, GENSAL, GENSAE, GENROE, EXDC2, SEXS, TGOV1, HYGOV, IEEEST,
                                    ESST3A, EXST1, IEEEX1, IEEET1, EXAC1, ESDC2A,
                                    ESST1A, ESAC1A, ESDC1A, IEEET3, ESST4B, EXAC4, AC8B, IEEEVC,
                                    IEEEG1, IEESGO, TG2, TGOV1N, GAST, ST2CUT)
            + (DEGOV1, DEGOV, PIDGOV, WPIDHY, GGOV1)
            + (STAB1, PSS2A, PSS2B, PSS2C)
            + (REGCA1, REECA1, REECB1, REPCA1, PVD1, ESD1, ZIP)
            + (WTDTA1, WTARA1, WTPTA1, WTTQA1)    # after REECA1: the ANDES importer links in this order
            + (InfiniteBus, PVSource)
            + (SCRX, ST6B, ST8C, ESAC6A, EXAC2, EXPIC1)}


class System:
    """A network with dynamic components, ready to be simulated.

    Parameters
    ----------
    network : Network or dict
        The network, or a MATPOWER case dict.

    Examples
    --------
    >>> sys = System(case)                                   # doctest: +SKIP
    >>> sys.add_generator("G1", gen=0, machine=("GENROU", {...}),
    ...                   exciter=("EXDC2", {...}), governor=("TGOV1", {...}))
    >>> sys.setup()
    """

    #: the array namespace of its evaluation (:func:`weakgrid.sim.namespace.on_namespace`)
    xp = NUMPY

    def __init__(self, network):
        self.network = network if isinstance(network, Network) else Network(network)
        self.Sb = self.network.Sb
        self.components: dict[str, Component] = {}
        self._machines: list[tuple[str, str]] = []   # (type, name) in machine-number order
        self._machine_num: dict[str, int] = {}
        self.is_setup = False
        self.disconnected = None

    # ---------------------------------------------------------------- building
    def _component(self, type_name: str, kind: str | None = None) -> Component:
        if type_name not in self.components:
            reg = _registry()
            if type_name not in reg:
                raise DataError("model", "type", type_name, f"unknown model; available: {sorted(reg)}")
            self.components[type_name] = reg[type_name]()
        comp = self.components[type_name]
        if kind is not None and comp.kind != kind:
            raise DataError(f"{type_name}", "kind", comp.kind, f"{type_name} is not a {kind} model")
        return comp

    def add_component(self, comp: Component):
        """Add a user-constructed component type instance (e.g. GTI, UPQC) to the system."""
        if comp.type_name in self.components and self.components[comp.type_name] is not comp:
            raise DataError(comp.type_name, "type", comp.type_name, "this component type is already present")
        self.components[comp.type_name] = comp
        self.is_setup = False
        return comp

    def add_machine(self, model: str, name: str, gen: int, **params):
        """Add a synchronous machine replacing row ``gen`` (0-based) of the gen table."""
        if name in self._machine_num:
            raise DataError(f"machine '{name}'", "name", name, "machine names must be unique")
        self._component(model, "machine").add(name, {"gen": gen}, params)
        self._machine_num[name] = len(self._machines)
        self._machines.append((model, name))
        self.is_setup = False
        return name

    def _add_control(self, kind, model, name, machine, params, link=None):
        if machine not in self._machine_num:
            raise DataError(f"{model} '{name}'", "machine", machine,
                            f"no such machine; known machines are {sorted(self._machine_num)}")
        comp = self._component(model, kind)
        for c in self.components.values():
            if c.kind == kind and machine in [lk.get("machine") for lk in c.links]:
                raise DataError(f"{model} '{name}'", "machine", machine, f"this machine already has a {kind}")
        comp.add(name, {"machine": machine, **(link or {})}, params)
        self.is_setup = False
        return name

    def add_exciter(self, model: str, name: str, machine: str, **params):
        """Add an exciter (AVR) driving the field voltage of ``machine``."""
        return self._add_control("exciter", model, name, machine, params)

    def add_governor(self, model: str, name: str, machine: str, machine2: str | None = None, **params):
        """Add a turbine-governor driving the mechanical torque of ``machine`` (and of the
        low-pressure ``machine2`` of a cross-compound unit, IEEEG1)."""
        if machine2 is not None and machine2 not in self._machine_num:
            raise DataError(f"{model} '{name}'", "machine2", machine2,
                            f"no such machine; known machines are {sorted(self._machine_num)}")
        return self._add_control("governor", model, name, machine, params,
                                 None if machine2 is None else {"machine2": machine2})

    def add_compensator(self, model: str, name: str, machine: str, **params):
        """Add a voltage compensator (IEEEVC) changing the input voltage of ``machine``'s exciter."""
        return self._add_control("compensator", model, name, machine, params)

    def add_pss(self, model: str, name: str, machine: str, **params):
        """Add a power system stabilizer whose output enters the exciter of ``machine``."""
        return self._add_control("pss", model, name, machine, params)

    def controls_of(self, machine: str, kind: str = "pss") -> list[tuple[str, str]]:
        """``(model, name)`` of every control of ``kind`` ("pss", "exciter", "governor",
        "compensator") linked to ``machine``: a machine's stabilizer(s), whatever their model
        (IEEEST, STAB1, ST2CUT, PSS2A/B/C)."""
        self.machine_number(machine)   # an unknown machine is refused, naming the known ones
        return [(c.type_name, nm) for c in self.components.values() if c.kind == kind
                for nm, lk in zip(c.names, c.links) if lk.get("machine") == machine]

    def remove_controls(self, machine: str, kind: str = "pss") -> list[tuple[str, str]]:
        """Take every control of ``kind`` linked to ``machine`` out of the system.

        The system must then be set up again (:meth:`setup`): the states are laid out and
        initialized without them, and the initial point is checked, so the grid starts at
        equilibrium (zeroing a gain after the initialization would not: a stabilizer's
        washout state holds the initial signal, and its output would jump at t = 0+).

        Returns
        -------
        list of (str, str)
            ``(model, name)`` of the controls removed (empty if the machine has none).
        """
        out = self.controls_of(machine, kind)
        for model, nm in out:
            comp = self.components[model]
            comp.remove(nm)
            if comp.n == 0:
                del self.components[model]
        self.is_setup = False
        return out

    def add_generator(self, name: str, gen: int, machine, exciter=None, governor=None, pss=None):
        """Add a generator = machine + shaft + AVR + governor + PSS.

        Parameters
        ----------
        name : str
            Generator name; the parts are named ``name`` (machine) and ``name.avr``,
            ``name.gov``, ``name.pss``.
        gen : int
            0-based row of the network's gen table.
        machine, exciter, governor, pss : (str, dict) or None
            ``(model_name, parameters)`` of each part.
        """
        self.add_machine(machine[0], name, gen, **machine[1])
        if exciter is not None:
            self.add_exciter(exciter[0], f"{name}.avr", name, **exciter[1])
        if governor is not None:
            self.add_governor(governor[0], f"{name}.gov", name, **governor[1])
        if pss is not None:
            self.add_pss(pss[0], f"{name}.pss", name, **pss[1])
        return name

    def machine_number(self, name: str) -> int:
        """Global machine number of machine ``name``."""
        try:
            return self._machine_num[name]
        except KeyError:
            raise DataError(f"machine '{name}'", "name", name,
                            f"no such machine; known machines are {sorted(self._machine_num)}") from None

    @property
    def machine_names(self) -> list[str]:
        return [nm for _, nm in self._machines]

    def set_machine_initial(self, m, *, vf0, tm0, XadIfd, Pe, Qe, delta, V):
        """Called by machine models during initialization to publish their steady state."""
        s = self.sig_defaults
        s["vf"][m] = vf0
        s["vf0"][m] = vf0
        s["tm"][m] = tm0
        s["tm0"][m] = tm0
        s["XadIfd"][m] = XadIfd
        s["Pe"][m] = s["Pe0"][m] = Pe
        s["Qe"][m] = s["Qe0"][m] = Qe
        s["delta"][m] = s["delta0"][m] = delta
        s["Vt"][m] = s["Vt0"][m] = np.abs(V)
        s["Ecomp"][m] = s["Ecomp0"][m] = np.abs(V)   # exciter input; a compensator (IEEEVC) changes it
        s["theta"][m] = s["theta0"][m] = np.angle(V)
        s["omega"][m] = 1.0

    # ------------------------------------------------------------------- setup
    def setup(self, power_flow: bool = True, limits: str = "raise", init_tol: float = 1e-6):
        """Solve the power flow, build parameter arrays, lay out and initialize the states.

        After ``setup`` the initial point is in :attr:`z0`; it is verified (see
        :meth:`check_initial_point`): limited states must start within their limits,
        and the initial point must solve the DAE.

        Parameters
        ----------
        power_flow : bool
            Solve the power flow again (else reuse ``network.pf`` if present).
        limits : {"raise", "warn"}
            An initial value beyond a limit (a TGOV1 valve above VMAX, an exciter output
            above VRMAX, ...) raises :class:`DataError` naming the device, the field, the
            value and the limit; ``"warn"`` issues a warning instead (as ANDES does) and
            the state is held at its limit from the first step (the grid then drifts).
        init_tol : float
            Largest acceptable residual of the DAE at the initial point [pu].
        """
        if limits not in ("raise", "warn"):
            raise DataError("System.setup", "limits", limits, 'use "raise" or "warn"')
        net = self.network
        if power_flow or net.pf is None:
            net.solve_power_flow()
        gen_used = {}
        self.comps = sorted(self.components.values(), key=lambda c: c.order)
        nm = len(self._machines)
        # machine-indexed signal defaults: rows of one array (copied once per evaluation)
        self._sig_keys = SIGNALS
        self._sig_stack = np.zeros((len(SIGNALS), nm))
        self.sig_defaults = dict(zip(SIGNALS, self._sig_stack))
        self.disconnected = None   # units a GeneratorTrip disconnected (weakgrid.sim.disconnect)
        for c in self.comps:
            c.live = None
            c.setup(self)
        # one dynamic model per static generator, or several that share it (gammap, gammaq)
        shares = {}
        for c in self.comps:
            if c.kind == "machine" or (c.kind == "device" and hasattr(c, "gen")):
                shared = getattr(c, "gen_shared", False)
                for i, g in enumerate(c.gen):
                    if g in gen_used and not (shared and gen_used[g][1]):
                        raise DataError(c.element(i), "gen", int(g), f"gen row already used by {gen_used[g][0]}")
                    gen_used[g] = (c.element(i), shared)
                    if shared:
                        shares.setdefault(int(g), []).append(
                            (c.element(i), c.p.get("gammap", np.ones(c.n))[i], c.p.get("gammaq", np.ones(c.n))[i]))
                for i, rows in enumerate(getattr(c, "gen_also", ())):   # an ideal source's other units
                    for g in rows:
                        if g in gen_used:
                            raise DataError(c.element(i), "also", int(g), f"gen row already used by {gen_used[g][0]}")
                        gen_used[g] = (c.element(i), False)
        for g, devs in shares.items():
            for k, f in ((1, "gammap"), (2, "gammaq")):
                tot = sum(d[k] for d in devs)
                if abs(tot - 1.0) > 1e-9:
                    raise DataError(devs[0][0], f, float(devs[0][k]),
                                    f"the {f} of the devices on gen row {g} ({', '.join(d[0] for d in devs)}) "
                                    f"sum to {tot:g}; they must sum to 1")
        from .network import GEN_STATUS

        for g in range(net.gen.shape[0]):
            if net.gen[g, GEN_STATUS] > 0 and g not in gen_used:
                raise DataError(f"gen {g}", "GEN_STATUS", 1,
                                "every in-service generator needs a dynamic machine model "
                                "(System.add_machine/add_generator) or GEN_STATUS = 0")
        off = 0
        for c in self.comps:
            off = c.assign(off)
        self.nx = off
        self.nb = net.nb
        self.N = self.nx + 2 * self.nb
        x0 = np.zeros(self.nx)
        for kind in ("machine", "device", "compensator", "pss", "exciter", "governor"):
            for c in self.comps:
                if c.kind == kind:
                    c.init(self, x0, self.sig_defaults)
        V0 = net.pf.V.copy()
        self.y_load = net.load_admittance(V0)
        self.branch_status = net.branch[:, 10] > 0
        self.fault_shunt = np.zeros(self.nb, dtype=complex)
        self.z0 = np.concatenate([x0, V0.real, V0.imag])
        # non-windup limits
        li, lo, hi, pushing = [], [], [], []
        self._var_lim = []   # components whose limits move with the solution (limit_values(ctx))
        for c in self.comps:
            start = sum(len(i) for i in li)
            cond = c.limits_reset_if_pushing()
            for k, (idx, l, h) in enumerate(c.limits()):
                li.append(np.asarray(idx, int))
                lo.append(np.broadcast_to(np.asarray(l, float), len(idx)))
                hi.append(np.broadcast_to(np.asarray(h, float), len(idx)))
                pushing.append(np.zeros(len(idx), bool) if cond is None
                               else np.broadcast_to(np.asarray(cond[k], bool), len(idx)))
            if hasattr(c, "limit_values"):
                self._var_lim.append((c, slice(start, sum(len(i) for i in li))))
        self.lim_idx = np.concatenate(li) if li else np.zeros(0, int)
        self.lim_lo = np.concatenate(lo) if lo else np.zeros(0)
        self.lim_hi = np.concatenate(hi) if hi else np.zeros(0)
        # limits that reset a crossing state only while its derivative pushes outwards (ANDES)
        self.lim_pushing = np.concatenate(pushing) if pushing else np.zeros(0, bool)
        self.any_pushing = bool(self.lim_pushing.any())
        # components with discrete memory (dip timers, held values) updated at accepted points
        self._accepting = [c for c in self.comps if hasattr(c, "accept")]
        self.update_network()
        self._build_pattern()
        self.check_initial_point(limits=limits, tol=init_tol)
        self.is_setup = True
        return self

    def check_initial_point(self, limits: str = "raise", tol: float = 1e-6):
        """Verify that the initial point ``z0`` is a steady state of the DAE within its limits.

        Limits first: each non-windup limited state must start inside ``[lower, upper]``
        (to 1e-9), else the integrator would clamp it at t = 0+ and the grid would drift
        with no event. Then the residual ``F(0, z0) = [f; g]``: every state derivative
        and every bus current mismatch must be below ``tol`` (except the derivatives of the
        states a component lists in ``integrating_states``, which move at a steady state:
        a storage's state of charge).

        ``tol = 1e-6`` pu: the power flow is solved to 1e-9 MVA and the models initialize
        in closed form, so a consistent initial point has residuals of ~1e-10; any real
        inconsistency (a machine's current missing at a shared bus, a wrong base) is
        orders of magnitude larger; and it is 10x the integrator's Newton tolerance.

        Raises
        ------
        DataError
            Naming the device and field, the value and the limit (limits), or the
            state / bus with the largest residual and its size.
        """
        import warnings

        def beyond(element, name, v, lo, hi, flo, fhi, what, fate):
            """Refuse (or warn about) an initial value ``v`` outside ``[lo, hi]``."""
            if lo - 1e-9 <= v <= hi + 1e-9:
                return
            fld, lim, side = (fhi, hi, "above") if v > hi else (flo, lo, "below")
            msg = (f"initial value of {name} = {v:.6g} pu is {side} {fld} = {lim:.6g} pu "
                   f"(system base): the operating point needs a {what} beyond its limit")
            if limits == "warn":
                warnings.warn(f"{element}: {msg}; it is {fate} at the limit from t = 0+ and the grid "
                              "drifts before any event", stacklevel=4)
                return
            raise DataError(element, fld, float(lim),
                            f"{msg}. Raise the limit, change the dispatch/voltage set point, "
                            f'or pass System.setup(limits="warn") to {"clamp" if fate == "held" else "cut"} it '
                            "(as ANDES does)")

        x0 = self.z0[:self.nx]
        for c in self.comps:
            fields = getattr(c, "limit_fields", {})
            for idx, lo, hi in c.limits():
                idx = np.asarray(idx, int)
                lo = np.broadcast_to(np.asarray(lo, float), idx.shape)
                hi = np.broadcast_to(np.asarray(hi, float), idx.shape)
                for k, j in enumerate(idx):
                    st = self.var_name(int(j)).rsplit(".", 1)
                    flo, fhi = fields.get(st[-1], ("lower limit", "upper limit"))
                    beyond(f"{c.type_name} '{st[0]}'", st[-1], x0[j], lo[k], hi[k], flo, fhi,
                           "state", "held")
        # static (windup) limits and gates whose initial input must lie inside them
        # (components set ``initial_bounds`` in init: (signal, value, lower, upper, lower_field,
        # upper_field), arrays over the component's devices); beyond them the output would be
        # cut at t = 0+ and the grid would drift with no event, as for a non-windup state
        for c in self.comps:
            for sig, val, lo, hi, flo, fhi in getattr(c, "initial_bounds", ()):
                val, lo, hi = (np.broadcast_to(np.asarray(a, float), (c.n,)) for a in (val, lo, hi))
                for k in range(c.n):
                    beyond(f"{c.type_name} '{c.names[k]}'", sig, val[k], lo[k], hi[k], flo, fhi,
                           "signal", "cut")
        F, _ = self.residual(0.0, self.z0)
        nx = self.nx
        if not np.all(np.isfinite(F)):
            k = int(np.nonzero(~np.isfinite(F))[0][0])
            raise DataError("initial point", self.var_name(k), float(F[k]),
                            "the initialization produced a non-finite residual; check this element's data")
        Fx = F[:nx].copy()
        for c in self.comps:   # states that integrate at a steady state (a storage's SOC)
            for st in getattr(c, "integrating_states", ()):
                Fx[c.idx(st)] = 0.0
        worst_x = float(np.max(np.abs(Fx))) if nx else 0.0
        mis = np.abs(F[nx:nx + self.nb] + 1j * F[nx + self.nb:])
        worst_g = float(mis.max()) if self.nb else 0.0
        if worst_x > tol:
            k = int(np.argmax(np.abs(Fx)))
            raise DataError(f"initial point: state {self.var_name(k)}", "derivative", float(F[k]),
                            f"the initialization does not solve the DAE (|dx/dt| = {abs(F[k]):.3g} > "
                            f"{tol:g}); check this device's data and its link to the power flow")
        if worst_g > tol:
            b = int(np.argmax(mis))
            raise DataError(f"initial point: bus {self.network.bus_ids[b]}", "current mismatch", worst_g,
                            f"the devices' currents do not balance the network at this bus "
                            f"({worst_g:.3g} pu > {tol:g}); check the machines/devices connected to it")

    def accept(self, t, ctx):
        """Tell components with discrete memory (e.g. REECA1's voltage-dip timers) that the point
        evaluated in ``ctx`` at time ``t`` was accepted by the integrator."""
        for c in self._accepting:
            c.accept(t, ctx)

    def update_limits(self, ctx):
        """Refresh the non-windup limits that depend on the solution (e.g. ``VRMAX * Vt``) from ``ctx``."""
        for c, s in self._var_lim:
            self.lim_lo[s], self.lim_hi[s] = c.limit_values(ctx)

    # ----------------------------------------------------------------- network
    def update_network(self):
        """Rebuild the network admittance matrix after a topology/load/fault change.

        Sets :attr:`Yr_coo` (``rows, cols, vals`` of ``Y`` in real form
        ``[[G, -B], [B, G]]`` with a fixed pattern, see :meth:`Network.ybus_coo`),
        :attr:`Yr` (the same as a CSR matrix) and, for systems with at most
        :data:`DENSE_NETWORK_MAX` buses, :attr:`Yr_dense` (used for the residual,
        where a dense product is faster).
        """
        import scipy.sparse as sp

        r, c, v = self.network.ybus_coo(self.branch_status, self.y_load + self.fault_shunt)
        nb = self.nb
        G, B = v.real, v.imag
        rr = np.concatenate([r, r, r + nb, r + nb])
        cc = np.concatenate([c, c + nb, c, c + nb])
        vv = np.concatenate([G, -B, B, G])
        self.Yr_coo = (rr, cc, vv)
        self.Yr = sp.csr_matrix((vv, (rr, cc)), shape=(2 * nb, 2 * nb))
        self.Yr_dense = self.Yr.toarray() if nb <= DENSE_NETWORK_MAX else None
        self._Yr_mv = self.Yr_dense if self.Yr_dense is not None else self.Yr
        self.net_version = getattr(self, "net_version", 0) + 1

    @property
    def Y(self):
        """Dense complex bus admittance matrix as currently applied [pu] (for inspection)."""
        return self.network.ybus(self.branch_status, self.y_load + self.fault_shunt)

    def bus_vars(self, b) -> list[int]:
        """Global variable indices (Vr, Vi) of bus position ``b``."""
        return [self.nx + b, self.nx + self.nb + b]

    def _build_pattern(self):
        """Device Jacobian pattern (sparse, computed once) and its column colouring.

        Sets :attr:`pattern` (CSC boolean matrix), ``_pr, _pc`` (rows and columns
        of its entries, column-major), :attr:`colour` (colour of each column,
        -1 for columns without device entries) and :attr:`ncolours`.
        Columns of one colour share no row, so they are perturbed together.
        """
        import scipy.sparse as sp

        N = self.N
        groups = []
        mgroups = {m: [] for m in range(len(self._machines))}
        for c in self.comps:
            if c.kind == "machine":
                for i in range(c.n):
                    mgroups[c.m[i]] += c.instance_states(i) + self.bus_vars(c.bus[i])
            elif c.kind in ("exciter", "governor", "pss"):
                for i in range(c.n):
                    mgroups[c.mach[i]] += c.instance_states(i)
                groups += c.pattern(self) or []   # couplings beyond the own machine (IEEEG1 machine2)
            else:
                groups += c.pattern(self) or []
        for idx in mgroups.values():
            groups.append((idx, idx))
        rs, cs = [np.zeros(0, int)], [np.zeros(0, int)]
        for rows, cols in groups:
            rows, cols = np.asarray(rows, int), np.asarray(cols, int)
            if len(rows) and len(cols):
                rs.append(np.repeat(rows, len(cols)))
                cs.append(np.tile(cols, len(rows)))
        rs, cs = np.concatenate(rs), np.concatenate(cs)
        P = sp.csc_matrix((np.ones(len(rs), dtype=bool), (rs, cs)), shape=(N, N))
        P.sum_duplicates()
        P.sort_indices()
        self.pattern = P
        self.colour, self.ncolours = colour_columns(P)
        self._pc = np.repeat(np.arange(N), np.diff(P.indptr))
        self._pr = P.indices.astype(np.int64)
        self._ccols = np.nonzero(self.colour >= 0)[0]
        self._pcol = self.colour[self._pc]

    # --------------------------------------------------------------- equations
    def evaluate(self, t: float, z: np.ndarray) -> Context:
        """Evaluate all components at ``(t, z)``; returns the context with ``f``, ``I``, ``out``.

        ``z`` may also be a batch of points, shape ``(B, N)`` (components index
        the last axis), as used by the finite-difference Jacobian.
        """
        nx, nb = self.nx, self.nb
        V = z[..., nx:nx + nb] + 1j * z[..., nx + nb:]   # complex128 on every namespace
        ctx = Context(self, t, z[..., :nx], V)
        for c in self.comps:
            c.compute(ctx)
        for c in self.comps:
            c.finish(ctx)
        if self.disconnected is not None:
            self.disconnected.apply(ctx)
        return ctx

    def disconnect_unit(self, gen) -> list[str]:
        """Disconnect the unit on gen-table row ``gen`` (0-based) from now on: its machine or
        converter and their controls (:mod:`weakgrid.sim.disconnect`). Returns their names."""
        from .disconnect import Disconnected, unit_instances

        inst = unit_instances(self, gen)
        if self.disconnected is None:
            self.disconnected = Disconnected()
        self.disconnected.add(inst)
        return [c.names[i] for c, i in inst]

    def device_residual(self, t, z):
        ctx = self.evaluate(t, z)
        I = ctx.I
        nx, nb = self.nx, self.nb
        xp = self.xp
        F = xp.empty(z.shape, dtype=xp.float64)
        F[..., :nx] = ctx.f
        F[..., nx:nx + nb] = -xp.real(I)
        F[..., nx + nb:] = -xp.imag(I)
        return F, ctx

    def residual(self, t, z):
        """Full residual ``F = [f; g]`` and the evaluation context."""
        F, ctx = self.device_residual(t, z)
        F[self.nx:] += self._Yr_mv @ z[self.nx:]
        return F, ctx

    def device_jacobian_values(self, t, z, F0=None):
        """Values of the device part of ``dF/dz`` on :attr:`pattern` (entries ``_pr, _pc``).

        Coloured forward differences: all ``ncolours`` perturbed points (and the
        base point) are evaluated in one batched evaluation. Cost
        O(``ncolours`` N).
        """
        h = 1e-7 * np.maximum(1.0, np.abs(z))
        Z = np.repeat(z[None, :], self.ncolours + 1, axis=0)
        cols = self._ccols
        Z[self.colour[cols] + 1, cols] += h[cols]
        D = self.device_residual(t, Z)[0]
        if F0 is None:
            F0 = D[0]
        r, c = self._pr, self._pc
        return (D[self._pcol + 1, r] - F0[r]) / h[c]

    def jacobian_devices(self, t, z, F0=None):
        """Device part of ``dF/dz`` as a dense array (see :meth:`device_jacobian_values`)."""
        J = np.zeros((self.N, self.N))
        J[self._pr, self._pc] = self.device_jacobian_values(t, z, F0)
        return J

    def jacobian(self, t, z):
        """Full Jacobian ``dF/dz`` as a dense array (devices by coloured differences + analytic network)."""
        J = self.jacobian_devices(t, z)
        r, c, v = self.Yr_coo
        np.add.at(J, (r + self.nx, c + self.nx), v)
        return J

    def jacobian_sparse(self, t, z):
        """Full Jacobian ``dF/dz`` as a ``scipy.sparse`` CSC matrix."""
        import scipy.sparse as sp

        r, c, v = self.Yr_coo
        nx = self.nx
        return sp.csc_matrix((np.concatenate([self.device_jacobian_values(t, z), v]),
                              (np.concatenate([self._pr, r + nx]), np.concatenate([self._pc, c + nx]))),
                             shape=(self.N, self.N))

    # ---------------------------------------------------------------- naming
    def state_names(self) -> list[str]:
        names = [""] * self.nx
        for c in self.comps:
            for k, s in enumerate(c.states):
                for i, nm in enumerate(c.names):
                    names[c.off + k * c.n + i] = f"{nm}.{s}"
        return names

    def var_name(self, k: int) -> str:
        """Name of global variable ``k`` of ``z``."""
        if k < self.nx:
            return self.state_names()[k]
        b = (k - self.nx) % self.nb
        part = "Vr" if k - self.nx < self.nb else "Vi"
        return f"bus{self.network.bus_ids[b]}.{part}"

    def element_kv(self, name: str) -> float:
        """Base kV of the bus of the element in variable ``name`` (machines/devices); system default 1."""
        inst = name.rsplit(".", 1)[0]
        cache = getattr(self, "_kv_cache", None)
        if cache is None or cache[0] is not self.comps:
            kv = {}
            for c in reversed(self.comps):   # the first component holding a name wins
                if hasattr(c, "bus"):
                    kv.update({nm: float(self.network.base_kv[c.bus[i]]) for i, nm in enumerate(c.names)})
            cache = self._kv_cache = (self.comps, kv)
        return cache[1].get(inst, 1.0)

    def state_units(self) -> list[str]:
        units = ["pu"] * self.nx
        for c in self.comps:
            for k, s in enumerate(c.states):
                for i in range(c.n):
                    units[c.off + k * c.n + i] = c.units.get(s, "pu")
        return units
