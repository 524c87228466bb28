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
from .network import Network

SIGNALS = ("omega", "delta", "Pe", "Qe", "Vt", "theta", "XadIfd", "vf", "tm", "vs",
           "vf0", "tm0", "Pe0", "Qe0", "delta0", "Vt0", "theta0")


def _registry():
    from .exciters import EXDC2, SEXS
    from .governors import HYGOV, TGOV1
    from .machines import GENCLS, GENROU
    from .pss import IEEEST

    from .exciters import ESDC2A, ESST3A, EXAC1, EXST1, IEEET1, IEEEX1
    from .governors import IEEEG1, IEESGO, TG2, TGOV1N
    from .pss import ST2CUT

    return {c.__name__: c for c in (GENCLS, GENROU, EXDC2, SEXS, TGOV1, HYGOV, IEEEST,
                                    ESST3A, EXST1, IEEEX1, IEEET1, EXAC1, ESDC2A,
                                    IEEEG1, IEESGO, TG2, TGOV1N, ST2CUT)}


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

    def __init__(self, network):
        self.network = network if isinstance(network, Network) else Network(network)
        self.Sb = self.network.Sb
        self.components: dict[str, Component] = {}
        self._machines: list[tuple[str, str]] = []   # (type, name) in machine-number order
        self._machine_num: dict[str, int] = {}
        self.is_setup = False

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

    def add_pss(self, model: str, name: str, machine: str, **params):
        """Add a power system stabilizer whose output enters the exciter of ``machine``."""
        return self._add_control("pss", model, name, machine, params)

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
        s["theta"][m] = s["theta0"][m] = np.angle(V)
        s["omega"][m] = 1.0

    # ------------------------------------------------------------------- setup
    def setup(self, power_flow: bool = True):
        """Solve the power flow, build parameter arrays, lay out and initialize the states.

        After ``setup`` the initial point is in :attr:`z0`.
        """
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
        for c in self.comps:
            c.setup(self)
        # one machine per static generator
        for c in self.comps:
            if c.kind == "machine" or (c.kind == "device" and hasattr(c, "gen")):
                for i, g in enumerate(c.gen):
                    if g in gen_used:
                        raise DataError(c.element(i), "gen", int(g), f"gen row already used by {gen_used[g]}")
                    gen_used[g] = c.element(i)
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
        for kind in ("machine", "device", "pss", "exciter", "governor"):
            for c in self.comps:
                if c.kind == kind:
                    c.init(self, x0, self.sig_defaults)
        V0 = net.pf.V.copy()
        self.y_load = net.load_admittance(V0)
        self.branch_status = net.branch[:, 10] > 0
        self.fault_shunt = np.zeros(self.nb, dtype=complex)
        self.z0 = np.concatenate([x0, V0.real, V0.imag])
        # non-windup limits
        li, lo, hi = [], [], []
        self._var_lim = []   # components whose limits move with the solution (limit_values(ctx))
        for c in self.comps:
            start = sum(len(i) for i in li)
            for idx, l, h in c.limits():
                li.append(np.asarray(idx, int))
                lo.append(np.broadcast_to(np.asarray(l, float), len(idx)))
                hi.append(np.broadcast_to(np.asarray(h, float), len(idx)))
            if hasattr(c, "limit_values"):
                self._var_lim.append((c, slice(start, sum(len(i) for i in li))))
        self.lim_idx = np.concatenate(li) if li else np.zeros(0, int)
        self.lim_lo = np.concatenate(lo) if lo else np.zeros(0)
        self.lim_hi = np.concatenate(hi) if hi else np.zeros(0)
        self.update_network()
        self._build_pattern()
        self.is_setup = True
        return self

    def update_limits(self, ctx):
        """Refresh the non-windup limits that depend on the solution (e.g. ``VRMAX * Vt``) from ``ctx``."""
        for c, s in self._var_lim:
            self.lim_lo[s], self.lim_hi[s] = c.limit_values(ctx)

    # ----------------------------------------------------------------- network
    def update_network(self):
        """Rebuild the network admittance matrix after a topology/load/fault change."""
        Y = self.network.ybus(self.branch_status, self.y_load + self.fault_shunt)
        self.Y = Y
        G, B = Y.real, Y.imag
        self.Yr = np.block([[G, -B], [B, G]])
        self.net_version = getattr(self, "net_version", 0) + 1

    def bus_vars(self, b) -> list[int]:
        """Global variable indices (Vr, Vi) of bus position ``b``."""
        return [self.nx + b, self.nx + self.nb + b]

    def _build_pattern(self):
        N = self.N
        P = np.zeros((N, N), dtype=bool)
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
        for rows, cols in groups:
            if len(rows) and len(cols):
                P[np.ix_(np.asarray(rows, int), np.asarray(cols, int))] = True
        self.pattern = P
        # greedy column colouring: columns sharing no row get the same colour
        colour = -np.ones(N, dtype=int)
        used: list[np.ndarray] = []
        for j in range(N):
            rows = P[:, j]
            if not rows.any():
                continue
            for k, u in enumerate(used):
                if not (u & rows).any():
                    colour[j] = k
                    u |= rows
                    break
            else:
                colour[j] = len(used)
                used.append(rows.copy())
        self.colour = colour
        self.ncolours = len(used)
        self._pr, self._pc = np.nonzero(P)
        self._ccols = np.nonzero(colour >= 0)[0]
        self._pcol = colour[self._pc]

    # --------------------------------------------------------------- equations
    def evaluate(self, t: float, z: np.ndarray) -> Context:
        """Evaluate all components at ``(t, z)``; returns the context with ``f``, ``I``, ``out``.

        ``z`` may also be a batch of points, shape ``(B, N)`` (components index
        the last axis), as used by the finite-difference Jacobian.
        """
        nx, nb = self.nx, self.nb
        V = z[..., nx:nx + nb] + 1j * z[..., nx + nb:]
        ctx = Context(self, t, z[..., :nx], V)
        for c in self.comps:
            c.compute(ctx)
        for c in self.comps:
            c.finish(ctx)
        return ctx

    def device_residual(self, t, z):
        ctx = self.evaluate(t, z)
        I = ctx.I
        return np.concatenate([ctx.f, -I.real, -I.imag], axis=-1), ctx

    def residual(self, t, z):
        """Full residual ``F = [f; g]`` and the evaluation context."""
        F, ctx = self.device_residual(t, z)
        F[self.nx:] += self.Yr @ z[self.nx:]
        return F, ctx

    def jacobian_devices(self, t, z, F0=None):
        """Device part of ``dF/dz`` by coloured forward differences (dense array).

        All ``ncolours`` perturbed points (and the base point) are evaluated in
        one batched evaluation.
        """
        h = 1e-7 * np.maximum(1.0, np.abs(z))
        Z = np.repeat(z[None, :], self.ncolours + 1, axis=0)
        cols = self._ccols
        Z[self.colour[cols] + 1, cols] += h[cols]
        D = self.device_residual(t, Z)[0]
        if F0 is None:
            F0 = D[0]
        J = np.zeros((self.N, self.N))
        r, c = self._pr, self._pc
        J[r, c] = (D[self._pcol + 1, r] - F0[r]) / h[c]
        return J

    def jacobian(self, t, z):
        """Full Jacobian ``dF/dz`` (devices by coloured differences + analytic network)."""
        J = self.jacobian_devices(t, z)
        J[self.nx:, self.nx:] += self.Yr
        return J

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
        for c in self.comps:
            if inst in c.names and hasattr(c, "bus"):
                return float(self.network.base_kv[c.bus[c.names.index(inst)]])
        return 1.0

    def state_units(self) -> list[str]:
        units = ["pu"] * self.nx
        for c in self.comps:
            for k, s in enumerate(c.states):
                for i in range(c.n):
                    units[c.off + k * c.n + i] = c.units.get(s, "pu")
        return units
