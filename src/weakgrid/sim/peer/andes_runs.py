"""Run the same case in ANDES and in weakgrid and compare trajectories.

Used by the peer tests (``tests/sim/test_andes_peer.py``) and the benchmark.
ANDES (GPL) is imported, never copied.
"""

from __future__ import annotations

import time

import numpy as np

from ..io.andes import device_name


def load_andes(case: str, fault=None, disable_toggles=False, add=(), edit=(), addfile=None):
    """Load an ANDES stock case with ``andes.load(..., setup=False)``; optionally add a fault.

    Parameters
    ----------
    case : str
        Stock case path, e.g. ``"kundur/kundur_full.xlsx"``.
    fault : (bus_idx, tf, tc) or None
        Add an ANDES ``Fault`` at that bus from ``tf`` to ``tc`` [s].
    disable_toggles : bool
        Set ``u = 0`` on all ``Toggle`` devices (e.g. the shipped line trip).
    add : sequence of (model, dict)
        Extra ANDES devices to add (e.g. ``("Toggle", {"model": "Line", "dev": "Line_8", "t": 3})``).
    addfile : str, optional
        A dynamic data file (e.g. a PSS/E ``.dyr``) to load with a ``.raw`` case.
    edit : sequence of (model, parameter, value)
        Set a parameter of every device of a model (e.g. ``("IEEEST", "T5", 0.0)``).
    """
    import andes

    andes.config_logger(40)
    ss = andes.load(andes.get_case(case), addfile=addfile, setup=False, no_output=True, default_config=True)
    if disable_toggles and "Toggle" in ss.models:
        for k in range(ss.Toggle.n):
            ss.Toggle.u.v[k] = 0
    if fault is not None:
        bus, tf, tc = fault
        ss.add("Fault", {"bus": bus, "tf": tf, "tc": tc})
    for model, data in add:
        ss.add(model, dict(data))
    for model, prm, value in edit:
        par = getattr(ss.models[model], prm)
        par.v[:] = [value] * len(par.v)
    return ss


def run_andes(case, tf=10.0, h=1 / 120, fault=None, disable_toggles=False, tol=1e-8, linesearch=None,
              add=(), edit=(), addfile=None, configure=None):
    """Simulate a stock case in ANDES with a fixed step ``h``.

    Returns
    -------
    dict with ``t``, ``omega`` (n_t, n_gen), ``delta`` (n_t, n_gen), ``wall`` [s] (TDS only),
    ``names`` (generator idx order).
    """
    ss = load_andes(case, fault, disable_toggles, add, edit, addfile)
    if configure is not None:   # e.g. model config flags: configure(ss) before setup
        configure(ss)
    ss.setup()
    ss.PFlow.config.tol = 1e-11
    ss.PFlow.run()
    ss.TDS.config.tf = tf
    ss.TDS.config.tstep = h
    ss.TDS.config.fixt = 1
    ss.TDS.config.shrinkt = 0
    ss.TDS.config.tol = tol
    ss.TDS.config.no_tqdm = 1
    if linesearch is not None:
        ss.TDS.config.linesearch = linesearch
    t0 = time.perf_counter()
    ss.TDS.run()
    wall = time.perf_counter() - t0
    gen = ss.GENROU if ss.GENROU.n else ss.GENCLS
    ts = ss.dae.ts
    return {"t": np.asarray(ts.t), "omega": np.asarray(ts.x[:, gen.omega.a]),
            "delta": np.asarray(ts.x[:, gen.delta.a]), "wall": wall,
            "names": [device_name(gen.class_name, ix) for ix in gen.idx.v],
            "ok": bool(ss.exit_code == 0)}


def build_weakgrid(case, fault=None, disable_toggles=False, add=(), edit=(), addfile=None,
                   conventions="standard"):
    """The same case imported into weakgrid through ANDES's loader; returns ``(system, events, machine names)``.

    ``conventions``: ``"standard"`` or ``"andes"`` (see :func:`weakgrid.sim.io.andes.from_andes`)."""
    from ..events import Fault
    from ..io.andes import from_andes

    ss = load_andes(case, None, disable_toggles, add, edit, addfile)
    system, events = from_andes(ss, conventions=conventions)
    if fault is not None:
        bus, tf, tc = fault
        events.append(Fault(system.andes_bus_id[bus], tf, tc))
    return system, events, list(system.machine_names)


def run_weakgrid(case, tf=10.0, h=1 / 120, fault=None, disable_toggles=False, tol=1e-8, add=(), edit=(), addfile=None,
                 conventions="standard", **kw):
    """Simulate the case in weakgrid with step ``h``; same outputs as :func:`run_andes`.

    ``tol=None`` uses the simulator's default (step-scaled) Newton tolerance; ``conventions``
    as in :func:`build_weakgrid`."""
    from ..integrate import Simulator

    system, events, names = build_weakgrid(case, fault, disable_toggles, add, edit, addfile, conventions)
    system.setup()
    sim = Simulator(system, dt=h, tol=tol, **kw)
    t0 = time.perf_counter()
    res = sim.run(tf, events=events)
    wall = time.perf_counter() - t0
    return {"t": res.t, "omega": np.column_stack([res[f"{n}.omega"] for n in names]),
            "delta": np.column_stack([res[f"{n}.delta"] for n in names]), "wall": wall,
            "names": names, "ok": res.ok, "stats": res.stats}


def interp_to(t_ref, t, y):
    """Linear interpolation of columns of ``y`` (possibly with repeated event times) onto ``t_ref``."""
    # keep the post-event sample of repeated times (continuous states make this immaterial)
    keep = np.r_[np.diff(t) > 0, True]
    return np.column_stack([np.interp(t_ref, t[keep], y[keep, j]) for j in range(y.shape[1])])


def compare(a, b, t_grid=None):
    """Largest speed difference [pu] and rotor-angle difference relative to generator 1 [deg]."""
    if t_grid is None:
        t_grid = np.linspace(max(a["t"][0], b["t"][0]), min(a["t"][-1], b["t"][-1]), 4001)
    wa, wb = interp_to(t_grid, a["t"], a["omega"]), interp_to(t_grid, b["t"], b["omega"])
    da, db = interp_to(t_grid, a["t"], a["delta"]), interp_to(t_grid, b["t"], b["delta"])
    ra = da - da[:, :1]
    rb = db - db[:, :1]
    return float(np.max(np.abs(wa - wb))), float(np.degrees(np.max(np.abs(ra - rb))))
