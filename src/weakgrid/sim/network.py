"""Network data (MATPOWER case form), admittance matrices and the initializing power flow.

The network is held in MATPOWER case form (``baseMVA``, ``bus``, ``gen``,
``branch`` arrays with the standard MATPOWER columns). Branches are π-models
with series ``R + jX``, total charging ``B``, off-nominal ratio ``TAP`` (at the
from-bus) and phase shift ``SHIFT`` [deg]. Loads ``PD + jQD`` [MW, Mvar] become
constant admittances at their power-flow voltage in the time domain (as the
ANDES ``PQ`` model with ``p2z = q2z = 1``); shunts ``GS + jBS`` [MW, Mvar at 1 pu].

The power flow is *not* hand-written: :meth:`Network.solve_power_flow` runs
MATPOWER's Newton–Raphson method (PYPOWER's ``newtonpf``) on this module's own
admittance matrix, so that transformer taps, phase shifts and charging are the
same in the power flow and in the time domain, for either tap orientation (a
conversion to pandapower elements places the tap on the high-voltage side).
The solution is re-checked against the admittance matrix; a mismatch raises
:class:`~weakgrid.sim.errors.PowerFlowError`.
"""

from __future__ import annotations

import copy
import warnings
from dataclasses import dataclass

import numpy as np

from .errors import DataError, DataWarning, PowerFlowError

# MATPOWER column indices (0-based)
BUS_I, BUS_TYPE, PD, QD, GS, BS, BUS_AREA, VM, VA, BASE_KV = range(10)
GEN_BUS, PG, QG, QMAX, QMIN, VG, MBASE, GEN_STATUS = range(8)
F_BUS, T_BUS, BR_R, BR_X, BR_B, RATE_A, RATE_B, RATE_C, TAP, SHIFT, BR_STATUS = range(11)


@dataclass
class PowerFlowResult:
    """Solved operating point, all in system per unit.

    Attributes
    ----------
    V : ndarray of complex
        Bus voltage phasors [pu], in bus order.
    Pg, Qg : ndarray
        Generator injections [pu on ``baseMVA``], in gen-table order (0 for out-of-service gens).
    mismatch : float
        Largest bus power mismatch of the solution [pu], checked with this module's Ybus.
    """

    V: np.ndarray
    Pg: np.ndarray
    Qg: np.ndarray
    mismatch: float


class Network:
    """A power network in MATPOWER case form.

    Parameters
    ----------
    case : dict
        ``{"baseMVA": float, "bus": (nb, >=13), "gen": (ng, >=10), "branch": (nl, >=11)}``.
        Optional keys: ``series_capacitors`` (branch rows whose negative ``BR_X`` is meant)
        and ``negative_resistance`` (branch rows whose negative ``BR_R`` is meant); other
        negative values are accepted with a :class:`~weakgrid.sim.errors.DataWarning`.
        A negative series resistance (legal in PSS/E and MATPOWER network equivalents,
        e.g. case9241pegase, ACTIVSg10k) enters the admittance matrix as given, so the power
        flow and the time domain see the same branch.
        ``gen_split`` says how several in-service generators of one bus share the bus's solved
        reactive power (and, at the slack bus, its active power): ``"equal"`` (default), or
        ``"case"`` — each keeps its own ``QG`` (``PG``) of the case and the difference between
        the solved total and their sum is shared equally (a solved PSS/E case: the split PSS/E
        initializes its machines from).
    f_hz : float
        Nominal frequency [Hz].

    Attributes
    ----------
    Sb : float
        System base power [MVA].
    bus_ids : ndarray of int
        External bus numbers; ``index_of(bus_id)`` maps them to 0-based positions.
    negative_resistance : set of int
        Branch rows with ``BR_R < 0`` (declared or not).
    bus_names : dict
        Bus number -> the source's bus name, where it has one (PSS/E, pandapower); optional
        case key ``bus_names``.
    branch_names : list
        Each branch row's identifier in its source (PSS/E ``"I-J-CKT"``, an ANDES ``Line`` idx,
        pandapower ``"line_3"``, a study's branch name), or None; optional case key
        ``branch_names``. :meth:`branch_label` prints them.
    """

    def __init__(self, case: dict, f_hz: float = 60.0):
        for key in ("baseMVA", "bus", "gen", "branch"):
            if key not in case:
                raise DataError("case", key, None, "a MATPOWER case needs baseMVA, bus, gen and branch")
        self.case = copy.deepcopy({k: case[k] for k in ("baseMVA", "bus", "gen", "branch")})
        # branches with a negative series reactance on purpose (series capacitors)
        self.series_capacitors = {int(k) for k in case.get("series_capacitors", ())}
        self.gen_split = case.get("gen_split", "equal")
        if self.gen_split not in ("equal", "case"):
            raise DataError("case", "gen_split", self.gen_split, 'use "equal" or "case"')
        self.Sb = float(self.case["baseMVA"])
        if not self.Sb > 0:
            raise DataError("case", "baseMVA", self.Sb, "must be > 0 MVA")
        self.f_hz = float(f_hz)
        bus = np.atleast_2d(np.asarray(self.case["bus"], dtype=float))
        gen = np.atleast_2d(np.asarray(self.case["gen"], dtype=float))
        branch = np.atleast_2d(np.asarray(self.case["branch"], dtype=float))
        if bus.shape[1] < 13:
            raise DataError("case", "bus", bus.shape, "bus table needs the 13 MATPOWER columns")
        if gen.size and gen.shape[1] < 10:
            gen = np.hstack([gen, np.zeros((gen.shape[0], 10 - gen.shape[1]))])
        if branch.shape[1] < 13:
            branch = np.hstack([branch, np.zeros((branch.shape[0], 13 - branch.shape[1]))])
        self.bus, self.gen, self.branch = bus, gen, branch
        self.case.update(bus=bus, gen=gen, branch=branch)
        self.bus_ids = bus[:, BUS_I].astype(int)
        if len(set(self.bus_ids)) != len(self.bus_ids):
            raise DataError("bus table", "BUS_I", list(self.bus_ids), "bus numbers must be unique")
        self._pos = {b: i for i, b in enumerate(self.bus_ids)}
        declared_r = {int(k) for k in case.get("negative_resistance", ())}
        neg_r = []
        for k, row in enumerate(branch):
            for col, nm in ((F_BUS, "F_BUS"), (T_BUS, "T_BUS")):
                self.index_of(int(row[col]), f"branch {k}", nm)
            el = f"branch {k} ({int(row[F_BUS])}-{int(row[T_BUS])})"
            for col, nm in ((BR_R, "BR_R"), (BR_X, "BR_X"), (BR_B, "BR_B"), (TAP, "TAP"),
                            (SHIFT, "SHIFT")):
                if not np.isfinite(row[col]):
                    raise DataError(el, nm, float(row[col]), "give a finite number (per unit)")
            if row[BR_R] == 0 and row[BR_X] == 0:
                raise DataError(f"branch {k}", "BR_X", 0.0, "a branch needs a non-zero impedance R + jX")
            if row[BR_R] < 0:
                neg_r.append(k)
            if row[BR_X] < 0 and k not in self.series_capacitors:
                # standard cases have them (series compensation, star equivalents of
                # three-winding transformers, e.g. MATPOWER's case300): accepted, not silently
                warnings.warn(f"{el}: BR_X = {float(row[BR_X]):g} pu < 0 is taken as a series "
                              "capacitor; declare it with series_capacitors = "
                              f"[{k}] in the case to silence this, or correct the sign",
                              DataWarning, stacklevel=3)
        # negative series resistances are legal in PSS/E and MATPOWER network equivalents
        # (case9241pegase, ACTIVSg10k): taken as given, in the power flow and the time domain
        # alike (one admittance matrix), and said once for all of them, not silently
        self.negative_resistance = set(neg_r)
        undeclared = [k for k in neg_r if k not in declared_r]
        if undeclared:
            shown = ", ".join(f"branch {k} ({int(branch[k, F_BUS])}-{int(branch[k, T_BUS])}) "
                              f"BR_R = {branch[k, BR_R]:g}" for k in undeclared[:5])
            more = f" and {len(undeclared) - 5} more" if len(undeclared) > 5 else ""
            warnings.warn(f"{len(undeclared)} branch(es) with a negative series resistance, taken "
                          f"as given (network equivalents; such a branch generates active power): "
                          f"{shown}{more}; declare them with negative_resistance = "
                          f"{undeclared[:5] if not more else '[...]'} in the case to silence "
                          "this, or correct the sign", DataWarning, stacklevel=2)
        # the columns the power flow and the simulator read must be finite (others, e.g.
        # MBASE from pandapower's converter, may be NaN)
        for name, table, cols in (
                ("bus", bus, {BUS_I: "BUS_I", BUS_TYPE: "BUS_TYPE", PD: "PD", QD: "QD", GS: "GS",
                              BS: "BS", BASE_KV: "BASE_KV"}),
                ("gen", gen, {GEN_BUS: "GEN_BUS", PG: "PG", VG: "VG", GEN_STATUS: "GEN_STATUS"})):
            for c, nm in cols.items():
                bad = np.nonzero(~np.isfinite(table[:, c]))[0] if table.size else []
                if len(bad):
                    r = int(bad[0])
                    label = f"bus {table[r, BUS_I]:g}" if name == "bus" else f"gen {r}"
                    raise DataError(label, nm, float(table[r, c]), "give a finite number")
        for k, row in enumerate(gen):
            self.index_of(int(row[GEN_BUS]), f"gen {k}", "GEN_BUS")
        kv = bus[:, BASE_KV]
        for i in np.nonzero(~(kv > 0))[0]:
            raise DataError(f"bus {self.bus_ids[i]}", "BASE_KV", kv[i], "give the bus base voltage in kV (> 0)")
        if not np.any(bus[:, BUS_TYPE] == 3):
            raise DataError("bus table", "BUS_TYPE", "no 3", "one bus must be the slack (BUS_TYPE = 3)")
        self.nb = bus.shape[0]
        self.nl = branch.shape[0]
        self.base_kv = kv.copy()
        self.pf: PowerFlowResult | None = None
        self.bus_names = {int(k): str(v) for k, v in dict(case.get("bus_names") or {}).items()}
        names = list(case.get("branch_names") or [])
        self.branch_names = (names + [None] * self.nl)[:self.nl]

    # ------------------------------------------------------------------ lookup
    def index_of(self, bus_id, element: str = "element", field: str = "bus") -> int:
        """0-based position of external bus number ``bus_id``; :class:`DataError` if unknown."""
        try:
            return self._pos[int(bus_id)]
        except (KeyError, TypeError, ValueError):
            raise DataError(element, field, bus_id,
                            "no such bus; known buses are "
                            f"{sorted(int(b) for b in self._pos)}") from None

    def bus_label(self, bus_id) -> str:
        """A bus as a user knows it: its number, and its source name where it differs,
        e.g. ``'5 ("6")'`` (pandapower index 5, named "6"), ``'101 ("BUS 1")'``, ``'7'``."""
        name = self.bus_names.get(int(bus_id))
        return f'{int(bus_id)} ("{name}")' if name and name != str(int(bus_id)) else str(int(bus_id))

    def branch_label(self, k) -> str:
        """A branch row as a user knows it: its source name and end buses, e.g.
        ``'"101-102-1" (101-102)'``, or ``'row 3 (5-7)'`` without a name."""
        k = int(k)
        ends = f"{int(self.branch[k, F_BUS])}-{int(self.branch[k, T_BUS])}"
        name = self.branch_names[k] if 0 <= k < len(self.branch_names) else None
        return f'"{name}" ({ends})' if name is not None else f"row {k} ({ends})"

    # ------------------------------------------------------------- admittances
    def branch_admittances(self):
        """Two-port admittances of all branches (ignoring status).

        Returns
        -------
        f, t : ndarray of int
            From/to bus positions.
        Yff, Yft, Ytf, Ytt : ndarray of complex
            Branch admittance entries [pu] (MATPOWER ``makeYbus`` convention).
        """
        br = self.branch
        f = np.array([self._pos[int(b)] for b in br[:, F_BUS]], dtype=int)
        t = np.array([self._pos[int(b)] for b in br[:, T_BUS]], dtype=int)
        ys = 1.0 / (br[:, BR_R] + 1j * br[:, BR_X])
        bc = br[:, BR_B]
        tap = np.where(br[:, TAP] == 0, 1.0, br[:, TAP]) * np.exp(1j * np.deg2rad(br[:, SHIFT]))
        Ytt = ys + 0.5j * bc
        Yff = Ytt / (tap * np.conj(tap))
        Yft = -ys / np.conj(tap)
        Ytf = -ys / tap
        return f, t, Yff, Yft, Ytf, Ytt

    def ybus(self, branch_status=None, shunt=None) -> np.ndarray:
        """Dense bus admittance matrix [pu].

        Parameters
        ----------
        branch_status : array_like of bool, optional
            In-service flags per branch (default: the ``BR_STATUS`` column).
        shunt : array_like of complex, optional
            Extra shunt admittance per bus [pu] (loads, faults), added to the diagonal.
        """
        f, t, Yff, Yft, Ytf, Ytt = self.branch_admittances()
        st = self.branch[:, BR_STATUS] > 0 if branch_status is None else np.asarray(branch_status, bool)
        Y = np.zeros((self.nb, self.nb), dtype=complex)
        np.add.at(Y, (f[st], f[st]), Yff[st])
        np.add.at(Y, (f[st], t[st]), Yft[st])
        np.add.at(Y, (t[st], f[st]), Ytf[st])
        np.add.at(Y, (t[st], t[st]), Ytt[st])
        Y[np.diag_indices(self.nb)] += (self.bus[:, GS] + 1j * self.bus[:, BS]) / self.Sb
        if shunt is not None:
            Y[np.diag_indices(self.nb)] += np.asarray(shunt, dtype=complex)
        return Y

    def ybus_coo(self, branch_status=None, shunt=None):
        """Bus admittance matrix in coordinate form with a *fixed* pattern [pu].

        Every branch contributes its four entries (zeros when out of service) and
        every bus its diagonal, so the pattern (``rows``, ``cols``; duplicates are
        summed) does not change with branch status, loads or faults. This is what
        the sparse simulator assembles from.

        Returns
        -------
        rows, cols : ndarray of int
            Entry positions (length ``4 nl + nb``; repeated positions add up).
        vals : ndarray of complex
            Entry values.
        """
        f, t, Yff, Yft, Ytf, Ytt = self.branch_admittances()
        st = self.branch[:, BR_STATUS] > 0 if branch_status is None else np.asarray(branch_status, bool)
        on = st.astype(float)
        d = np.arange(self.nb)
        ysh = (self.bus[:, GS] + 1j * self.bus[:, BS]) / self.Sb
        if shunt is not None:
            ysh = ysh + np.asarray(shunt, dtype=complex)
        rows = np.concatenate([f, f, t, t, d])
        cols = np.concatenate([f, t, f, t, d])
        vals = np.concatenate([Yff * on, Yft * on, Ytf * on, Ytt * on, ysh])
        return rows, cols, vals

    def ybus_sparse(self, branch_status=None, shunt=None):
        """Bus admittance matrix [pu] as a ``scipy.sparse`` CSR matrix (see :meth:`ybus`)."""
        import scipy.sparse as sp

        r, c, v = self.ybus_coo(branch_status, shunt)
        return sp.csr_matrix((v, (r, c)), shape=(self.nb, self.nb))

    def load_admittance(self, V) -> np.ndarray:
        """Constant-impedance equivalent of the bus loads at voltages ``V`` [pu]."""
        S = (self.bus[:, PD] + 1j * self.bus[:, QD]) / self.Sb
        return np.conj(S) / np.abs(V) ** 2

    # -------------------------------------------------------------- power flow
    def solve_power_flow(self, tol_mva: float = 1e-9, check_tol: float = 1e-6) -> PowerFlowResult:
        """Solve the power flow on this network's own Ybus (MATPOWER's Newton method, by PYPOWER).

        The Newton–Raphson power flow of MATPOWER (``pypower.newtonpf``) is run on
        :meth:`ybus` itself, so every branch (transformer taps on either side,
        phase shifters, charging) is modelled exactly as in the time domain and as
        in MATPOWER/ANDES. PV buses without an in-service generator are PQ buses;
        generator reactive limits are not enforced (as ANDES's default). The
        Newton iteration starts from the case's ``VM``/``VA`` with generator set
        points; if it does not converge it is restarted from a flat start.

        Parameters
        ----------
        tol_mva : float
            Convergence tolerance on the largest bus power mismatch [MVA].
        check_tol : float
            Largest acceptable power mismatch [pu] when re-checked with :meth:`ybus`.

        Raises
        ------
        PowerFlowError
            If Newton does not converge (naming the bus with the largest mismatch) or
            the solution does not satisfy the network equations.
        """
        from pypower.newtonpf import newtonpf
        from pypower.ppoption import ppoption

        self.check_connected()

        bus, gen = self.bus, self.gen
        nb = self.nb
        Y = self.ybus_sparse()
        on = gen[:, GEN_STATUS] > 0 if gen.size else np.zeros(0, bool)
        gbus = np.array([self._pos[int(b)] for b in gen[:, GEN_BUS]], dtype=int) if gen.size else np.zeros(0, int)
        btype = bus[:, BUS_TYPE].astype(int).copy()
        has_gen = np.zeros(nb, bool)
        has_gen[gbus[on]] = True
        btype[(btype == 2) & ~has_gen] = 1
        ref = np.nonzero(btype == 3)[0]
        pv = np.nonzero(btype == 2)[0]
        pq = np.nonzero(btype == 1)[0]
        Sg = np.zeros(nb, dtype=complex)
        np.add.at(Sg, gbus[on], gen[on, PG] + 1j * gen[on, QG])
        Sbus = (Sg - (bus[:, PD] + 1j * bus[:, QD])) / self.Sb
        vm = np.where(bus[:, VM] > 0, bus[:, VM], 1.0)
        vg = vm.copy()
        for g in np.nonzero(on)[0][::-1]:      # the first in-service generator of a bus sets its voltage
            if btype[gbus[g]] in (2, 3):
                vg[gbus[g]] = gen[g, VG]
        starts = [vg * np.exp(1j * np.deg2rad(bus[:, VA])),
                  vg * np.exp(1j * np.deg2rad(bus[ref[0], VA]))]
        opt = ppoption(VERBOSE=0, OUT_ALL=0, PF_TOL=tol_mva / self.Sb, PF_MAX_IT=30)
        V = None
        # the mismatch cannot go below round-off in V·conj(Y V): with a very small impedance
        # (|Y| ~ 1e7 pu) that floor is above PF_TOL; Newton then stalls there, converged
        floor = 1e3 * np.finfo(float).eps * max(1.0, float(abs(Y).max()))

        def mismatch(Vs):
            mis = Vs * np.conj(Y @ Vs) - Sbus
            mis[ref] = 0
            mis[pv] = mis[pv].real
            return mis

        for V0 in starts:
            with warnings.catch_warnings(), np.errstate(all="ignore"):
                warnings.simplefilter("ignore")
                Vs, ok, _ = newtonpf(Y, Sbus, V0, ref, pv, pq, opt)
            if np.all(np.isfinite(Vs)) and (ok or np.max(np.abs(mismatch(Vs))) < floor):
                V = Vs
                break
        if V is None:
            mis = mismatch(Vs)
            k = int(np.nanargmax(np.where(np.isfinite(mis), np.abs(mis), np.inf)))
            raise PowerFlowError(
                f"Newton power flow did not converge (case and flat starts, 30 iterations each); "
                f"largest mismatch {abs(mis[k]):.3g} pu at bus {self.bus_ids[k]}. Fix: check the "
                "loads, generation, voltage set points and branch data near that bus; reduce loading")
        return self._finish_pf(V, check_tol)

    def check_connected(self, branch_status=None):
        """Raise :class:`DataError` naming a bus that no in-service branch links to a slack bus."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        st = self.branch[:, BR_STATUS] > 0 if branch_status is None else np.asarray(branch_status, bool)
        f = np.array([self._pos[int(b)] for b in self.branch[st, F_BUS]], dtype=int)
        t = np.array([self._pos[int(b)] for b in self.branch[st, T_BUS]], dtype=int)
        g = coo_matrix((np.ones(len(f)), (f, t)), shape=(self.nb, self.nb))
        _, label = connected_components(g, directed=False)
        slack = np.nonzero(self.bus[:, BUS_TYPE] == 3)[0]
        live = np.isin(label, label[slack]) | (self.bus[:, BUS_TYPE] == 4)
        if not live.all():
            i = int(np.nonzero(~live)[0][0])
            n = int((~live).sum())
            raise DataError(f"bus {self.bus_ids[i]}", "branches", "none in service to a slack bus",
                            f"the bus is islanded ({n} bus(es) cut off from the slack): connect "
                            "it with an in-service branch, add a slack bus to its island, or "
                            "set BUS_TYPE = 4 (isolated)")

    def _split(self, total, stored):
        """Share ``total`` [pu] among the generators of one bus, whose case values are
        ``stored`` [MW or Mvar] (see ``gen_split``)."""
        n = len(stored)
        if self.gen_split == "equal" or n == 1:
            return np.full(n, total / n)
        own = np.asarray(stored, dtype=float) / self.Sb
        return own + (total - own.sum()) / n

    def _finish_pf(self, V, check_tol):
        Y = self.ybus_sparse()
        Sinj = V * np.conj(Y @ V)
        Sload = (self.bus[:, PD] + 1j * self.bus[:, QD]) / self.Sb
        Sgen_bus = Sinj + Sload
        gen = self.gen
        ng = gen.shape[0]
        Pg = np.zeros(ng)
        Qg = np.zeros(ng)
        on = gen[:, GEN_STATUS] > 0 if ng else np.zeros(0, bool)
        gbus = np.array([self._pos[int(b)] for b in gen[:, GEN_BUS]], dtype=int) if ng else np.zeros(0, int)
        btype = self.bus[:, BUS_TYPE]
        mismatch = 0.0
        for i in range(self.nb):
            g = np.nonzero(on & (gbus == i))[0]
            if len(g) == 0:
                mismatch = max(mismatch, abs(Sgen_bus[i]))
                continue
            if btype[i] == 3:
                Pg[g] = self._split(Sgen_bus[i].real, gen[g, PG])
            else:
                Pg[g] = gen[g, PG] / self.Sb
                mismatch = max(mismatch, abs(Sgen_bus[i].real - Pg[g].sum()))
            Qg[g] = self._split(Sgen_bus[i].imag, gen[g, QG])
        if not np.all(np.isfinite(V)) or mismatch > check_tol:
            raise PowerFlowError(f"power flow solution has a bus mismatch of {mismatch:.3g} pu "
                                 f"(> {check_tol:g}). Fix: check branch data and loading; "
                                 "the case may have no feasible operating point")
        self.pf = PowerFlowResult(V=V, Pg=Pg, Qg=Qg, mismatch=mismatch)
        return self.pf

    @classmethod
    def from_pandapower(cls, net) -> "Network":
        """Build a :class:`Network` from a pandapower network (via ``pandapower.converter.to_ppc``).

        Buses keep their pandapower index as their number (bus ``5`` is ``net.bus.loc[5]``;
        buses that pandapower's conversion fuses through closed bus-bus switches take the
        smallest index among them); buses the conversion adds (e.g. the star point of a
        three-winding transformer) are numbered above the largest index. The result's
        ``pandapower_bus`` maps every pandapower bus index to its number, ``bus_names`` each
        number to the pandapower bus name (where it has one), ``branch_names`` each branch row
        to its element and ``gen_names`` each gen row to its ``ext_grid`` or ``gen``: the
        element's name where it is unique and non-empty, else ``"<table>_<index>"``
        (``"line_3"``, ``"trafo_0"``, ``"gen_1"``); ``gen_source`` holds ``(table, index, name)``
        per gen row.
        """
        from pandapower.converter.pypower import to_ppc

        ppc = to_ppc(net, init="flat", calculate_voltage_angles=True, trafo_model="pi")
        bus = np.asarray(ppc["bus"])[:, :13].real.copy()
        gen = np.asarray(ppc["gen"])[:, :21].real.copy()
        branch = np.asarray(ppc["branch"])[:, :13].real.copy()
        lookups = net._pd2ppc_lookups            # written by to_ppc: pandapower -> ppc positions
        pos_of = lookups["bus"]
        pos = bus[:, BUS_I].astype(int)          # ppc numbers its buses by position
        number = {}
        for i in sorted(int(i) for i in net.bus.index):
            p = int(pos_of[i]) if i < len(pos_of) else -1
            if p >= 0 and p not in number:
                number[p] = i
        top = max([int(i) for i in net.bus.index] + [-1])
        for p in pos:                            # buses the conversion added
            if int(p) not in number:
                top += 1
                number[int(p)] = top
        renum = np.vectorize(lambda p: number[int(p)], otypes=[float])
        bus[:, BUS_I] = renum(bus[:, BUS_I])
        if gen.size:
            gen[:, GEN_BUS] = renum(gen[:, GEN_BUS])
        if branch.size:
            branch[:, F_BUS] = renum(branch[:, F_BUS])
            branch[:, T_BUS] = renum(branch[:, T_BUS])
        pandapower_bus = {int(i): number[int(pos_of[i])] for i in net.bus.index
                          if i < len(pos_of) and int(pos_of[i]) >= 0}
        bus_names = {}
        for i, name in net.bus["name"].items():
            text = _text(name)
            if text and int(i) in pandapower_bus:
                bus_names.setdefault(pandapower_bus[int(i)], text)
        branch_names = [None] * branch.shape[0]
        for table, (a, b) in (lookups.get("branch") or {}).items():
            tab = getattr(net, table, None)
            if tab is not None and b - a == len(tab):    # the table's rows, in order
                for k, i in enumerate(tab.index):
                    branch_names[a + k] = (table, int(i), tab.at[i, "name"] if "name" in tab
                                           else None)
        branch_names = _element_names(branch_names)
        out = cls({"baseMVA": ppc["baseMVA"], "bus": bus, "gen": gen, "branch": branch,
                   "bus_names": bus_names, "branch_names": branch_names}, f_hz=float(net.f_hz))
        out.pandapower_bus = pandapower_bus
        out.gen_source = [None] * gen.shape[0]
        for table in ("ext_grid", "gen"):
            rows = lookups.get(table)
            tab = getattr(net, table)
            if rows is None or tab is None or not len(tab):
                continue
            rows = np.asarray(rows).ravel()
            for k, (i, row) in enumerate(tab.iterrows()):
                if k < len(rows) and 0 <= int(rows[k]) < len(out.gen_source):
                    name = row.get("name")
                    out.gen_source[int(rows[k])] = (table, int(i), _text(name))
        out.gen_names = _element_names(out.gen_source)
        return out


def _element_names(elements) -> list:
    """pandapower elements ``(table, index, name)`` (or None) as identifiers: the element's
    name where it is a non-empty string that no other element has (and that is not another
    element's ``"<table>_<index>"``), else ``"<table>_<index>"``; unique by construction."""
    own = [None if e is None else f"{e[0]}_{e[1]}" for e in elements]
    reserved = {o for o in own if o is not None}
    count = {}
    for e in elements:
        if e is not None and _text(e[2]):
            count[_text(e[2])] = count.get(_text(e[2]), 0) + 1
    out = []
    for e, o in zip(elements, own):
        t = None if e is None else _text(e[2])
        out.append(t if t and count[t] == 1 and (t not in reserved or t == o) else o)
    return out


def _text(name):
    """A pandapower element name as text (numbers too, e.g. case9's buses 1..9), or None when
    missing (None, NaN, blank)."""
    if name is None or (isinstance(name, float) and name != name):
        return None
    if isinstance(name, float) and name.is_integer():
        name = int(name)
    text = str(name).strip()
    return text or None
