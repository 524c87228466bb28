"""Dynamic-data templates: a static case (MATPOWER / pandapower) made simulable in one call.

A power-flow case has no dynamic data. :func:`classical_system` puts a
classical machine (``GENCLS``) at every in-service generator with one generic
set of parameters on each machine's own rating, so that any MATPOWER case —
including those pandapower ships (``case118``, ``case300``,
``case1354pegase``, ``case2869pegase``, ...) — can be simulated, and the same
data can be given to another tool (:func:`classical_parameters`).

The machine rating ``Sn`` is not in most cases (``MBASE`` is often missing or
the system base). By default it is derived from the generator's own data:
``Sn = max(PMAX, |PG + j QG| / 0.8, Sn_min)`` [MVA], so that the transient
reactance and inertia scale with the unit's size. Pass ``Sn=<number>`` for one
rating for all.
"""

from __future__ import annotations

import numpy as np

from .errors import DataError
from .network import GEN_STATUS, PG, QG, Network
from .system import System

PMAX = 8

__all__ = ["classical_parameters", "classical_system", "machine_id", "matpower_case"]


def _is_pandapower(case) -> bool:
    return hasattr(case, "bus") and hasattr(case, "f_hz")


def matpower_case(case) -> dict:
    """The MATPOWER case dict of ``case``.

    Parameters
    ----------
    case : dict, Network, pandapower network or str
        A MATPOWER case dict, a :class:`Network`, a pandapower network, or the
        name of a function of :mod:`pandapower.networks` returning one (e.g.
        ``"case118"``). pandapower networks are converted by
        :meth:`Network.from_pandapower`: a bus keeps its pandapower index as its number, and
        the dict carries the elements' identifiers (``gen_names``, ``bus_names``,
        ``branch_names``: the element's name when unique and non-empty, else
        ``"<table>_<index>"``).

    Returns
    -------
    dict with ``baseMVA``, ``bus``, ``gen``, ``branch`` (and, from pandapower, ``gen_names``,
    ``bus_names``, ``branch_names``).
    """
    if isinstance(case, dict) and not _is_pandapower(case):   # a pandapower net is a dict too
        return case
    if isinstance(case, Network):
        return dict(case.case)
    if isinstance(case, str):
        import pandapower.networks as pn

        fn = getattr(pn, case, None)
        if fn is None or not callable(fn):
            raise DataError("case", "name", case, "not a function of pandapower.networks (e.g. 'case118')")
        case = fn()
    if _is_pandapower(case):
        net = Network.from_pandapower(case)
        c = {k: np.array(v, dtype=float) for k, v in net.case.items() if k != "baseMVA"}
        c["baseMVA"] = net.Sb
        c.update(gen_names=list(net.gen_names), bus_names=dict(net.bus_names),
                 branch_names=list(net.branch_names))
        mb = c["gen"][:, 6]
        c["gen"][:, 6] = np.where(np.isfinite(mb) & (mb > 1), mb, c["baseMVA"])
        return c
    raise DataError("case", "type", type(case).__name__,
                    "give a MATPOWER dict, a Network, a pandapower network or a pandapower.networks name")


def machine_id(case, g) -> str:
    """Source identifier of generator row ``g`` of a MATPOWER case dict.

    From pandapower (``case["gen_names"]``): the ``ext_grid`` / ``gen`` element's name when it
    is unique and non-empty, else ``"<table>_<index>"``. MATPOWER (no generator ids):
    ``"<bus>_<k>"``, the bus number and the generator's place among those of its bus in the gen
    table (1 for the first; PSS/E's default machine id), e.g. ``"30_1"``.
    """
    names = case.get("gen_names") if isinstance(case, dict) else None
    if names and g < len(names) and names[g]:
        return str(names[g])
    gen = np.atleast_2d(np.asarray(case["gen"], dtype=float))
    bus = int(gen[g, 0])
    k = int(np.sum(gen[:g + 1, 0].astype(int) == bus))
    return f"{bus}_{k}"


def classical_parameters(case, H=4.0, xd1=0.3, D=0.0, ra=0.0, Sn=None, Sn_min=10.0) -> list[dict]:
    """Parameters of the classical machines :func:`classical_system` adds (one dict per machine).

    Parameters
    ----------
    case : dict
        MATPOWER case dict.
    H : float
        Inertia constant [s, on ``Sn``] (``M = 2H``).
    xd1 : float
        Transient reactance x'd [pu on ``Sn``].
    D : float
        Damping [pu on ``Sn``].
    ra : float
        Armature resistance [pu on ``Sn``].
    Sn : float or None
        Machine rating [MVA] for all machines; ``None``: ``max(PMAX, |PG + j QG|/0.8, Sn_min)``.
    Sn_min : float
        Smallest derived rating [MVA].

    Returns
    -------
    list of dict with keys ``gen`` (0-based gen row), ``bus`` (bus number), ``name`` (the
    machine's name, :func:`machine_id`) and the ``GENCLS`` parameters ``Sn, M, D, ra, xd1``.
    """
    for nm, v in (("H", H), ("xd1", xd1)):
        if not (np.isfinite(v) and v > 0):
            raise DataError("classical template", nm, v, "must be a positive number")
    for nm, v in (("D", D), ("ra", ra)):
        if not (np.isfinite(v) and v >= 0):
            raise DataError("classical template", nm, v, "must be >= 0")
    gen = np.atleast_2d(np.asarray(case["gen"], dtype=float))
    out = []
    for g in range(gen.shape[0]):
        if gen[g, GEN_STATUS] <= 0:
            continue
        if Sn is None:
            pmax = gen[g, PMAX] if gen.shape[1] > PMAX and np.isfinite(gen[g, PMAX]) else 0.0
            sn = max(pmax, float(np.hypot(gen[g, PG], gen[g, QG])) / 0.8, Sn_min)
        else:
            sn = float(Sn)
            if not sn > 0:
                raise DataError("classical template", "Sn", Sn, "must be > 0 MVA")
        out.append(dict(gen=g, bus=int(gen[g, 0]), name=f"GENCLS_{machine_id(case, g)}",
                        Sn=float(sn), M=2.0 * H, D=float(D),
                        ra=float(ra), xd1=float(xd1)))
    return out


def classical_system(case, H=4.0, xd1=0.3, D=0.0, ra=0.0, Sn=None, Sn_min=10.0,
                     setup=True, f_hz=60.0) -> System:
    """A :class:`System` with a classical machine (``GENCLS``) at every in-service generator.

    Parameters
    ----------
    case : dict, Network, pandapower network or str
        See :func:`matpower_case` (e.g. ``"case2869pegase"``).
    H, xd1, D, ra, Sn, Sn_min
        See :func:`classical_parameters`.
    setup : bool
        Solve the power flow and initialize (``System.setup``).
    f_hz : float
        Nominal frequency [Hz].

    Returns
    -------
    System
        Machines are named ``GENCLS_<id>`` with the generator's source identifier
        (:func:`machine_id`: ``GENCLS_30_1`` for the first generator of MATPOWER bus 30,
        ``GENCLS_gen_1`` / ``GENCLS_<name>`` for a pandapower element).

    Examples
    --------
    >>> from weakgrid.sim.templates import classical_system      # doctest: +SKIP
    >>> from weakgrid.sim.integrate import simulate
    >>> from weakgrid.sim.events import Fault
    >>> s = classical_system("case1354pegase", H=4.0, xd1=0.3)
    >>> res = simulate(s, 10.0, events=[Fault(bus=10, t_on=1.0, t_off=1.05)])
    """
    mpc = matpower_case(case)
    s = System(Network(mpc, f_hz=f_hz))
    for p in classical_parameters(mpc, H=H, xd1=xd1, D=D, ra=ra, Sn=Sn, Sn_min=Sn_min):
        s.add_machine("GENCLS", p["name"], p["gen"], Sn=p["Sn"], M=p["M"], D=p["D"],
                      ra=p["ra"], xd1=p["xd1"], fn=f_hz)
    if setup:
        s.setup()
    return s
