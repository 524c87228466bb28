"""Any ANDES case (file, or PSS/E ``.raw`` + ``.dyr``) in ANDES and in weakgrid, compared.

Generalizes :mod:`weakgrid.sim.peer.andes_runs` (stock cases by name, one machine
model) to any case file: machines of every model are matched by name
(:func:`weakgrid.sim.io.andes.device_name`, the names :func:`weakgrid.sim.io.andes.from_andes`
gives),
the case's own timed events can be replaced by one three-phase fault, PSS/E branch
data get their true base in ANDES's copy too
(:func:`weakgrid.sim.io.andes.fix_psse_branch_base`), and the ANDES system can be
modified before both tools read it (``modify(ss)``), so the two simulators always see
the same data. ANDES (GPL) is imported, never copied.
"""

from __future__ import annotations

import time

import numpy as np

from ..io.andes import device_name
from .andes_runs import interp_to

MACHINES = ("GENROU", "GENCLS")


def load_case(path, addfile=None, fault=None, keep_events=False, modify=None):
    """Load a case with ``andes.load(..., setup=False)``.

    Parameters
    ----------
    path : str
        Case file (``.xlsx``, ``.json``, ``.m``, ``.raw``, ...), or a stock case name
        (``"kundur/kundur_full.xlsx"``), resolved with ``andes.get_case``.
    addfile : str, optional
        PSS/E ``.dyr`` file read with a ``.raw``.
    fault : (bus_idx, tf, tc) or "auto" or None
        Add a three-phase fault at that ANDES bus from ``tf`` to ``tc`` [s]; ``"auto"``: at
        the bus of the first in-service PQ load, 1.0-1.05 s.
    keep_events : bool
        Keep the case's own ``Toggle``/``Fault``/``Alter`` devices (default: switch them off).
    modify : callable, optional
        ``modify(ss)`` applied after loading (e.g. adding devices with ``ss.add``).
    """
    import os

    import andes

    andes.config_logger(40)
    if not os.path.exists(path):
        path = andes.get_case(path)
    ss = andes.load(path, addfile=addfile, setup=False, no_output=True, default_config=True)
    if ss is None:
        raise RuntimeError(f"ANDES could not parse {path}")
    # PSS/E branches on the system base in ANDES too, as weakgrid reads them (SBASE != 100)
    from ..io.andes import fix_psse_branch_base

    fix_psse_branch_base(ss)
    if not keep_events:
        for ev in ("Toggle", "Fault", "Alter"):
            if ev in ss.models:
                for k in range(ss.models[ev].n):
                    ss.models[ev].u.v[k] = 0
    if modify is not None:
        modify(ss)
    if fault == "auto":
        fault = (auto_fault_bus(ss), 1.0, 1.05)
    if fault is not None:
        bus, tf, tc = fault
        ss.add("Fault", {"bus": bus, "tf": tf, "tc": tc})
    return ss


def auto_fault_bus(ss):
    """ANDES idx of the bus of the first in-service PQ load (else the first bus)."""
    pq = ss.PQ
    for k in range(pq.n):
        if pq.u.v[k] > 0:
            return pq.bus.v[k]
    return ss.Bus.idx.v[0]


def machine_names(ss):
    """weakgrid's names (:func:`weakgrid.sim.io.andes.device_name`) of the in-service machines
    of an ANDES system."""
    out = []
    for m in MACHINES:
        mdl = ss.models[m]
        out += [device_name(m, ix) for k, ix in enumerate(mdl.idx.v) if mdl.u.v[k] > 0]
    return out


def hold_andes_step(tds):
    """Make ANDES keep its step at ``config.tstep`` after every converged step.

    With ``fixt = 1`` ANDES's step is only an upper bound: after a step that needed more
    than 6 Newton iterations its step control shortens the next one (by 5 %, by half
    above 15) and lets it regrow by 10 % a step. This wraps the step control of the
    integration method that ``tds`` creates (in ``TDS.set_method``, called again by
    ``TDS.init``) so that ``deltat`` returns to ``tstep`` after each converged step. The
    points ANDES puts 1e-4 s before and after each event and the shortening of a step
    that would pass an event are kept, and so is the handling of a failed step
    (``shrinkt``). Only this ``tds`` object is changed.
    """
    set_method = tds.set_method

    def set_method_held(name="trapezoid"):
        set_method(name)
        calc_h = tds.method.calc_h

        def calc_h_held(t):
            calc_h(t)
            if t.converged and t.config.fixt:
                t.deltat = t.config.tstep

        tds.method.calc_h = calc_h_held

    tds.set_method = set_method_held
    set_method_held(tds.config.method)


def fix_andes_esdc1a(ss):
    """Point ANDES 2.0's ESDC1A regulator at its constant limits ``VRMAX``, ``VRMIN``.

    ANDES's ESDC1A derives from its ESDC2A and replaces the limit services ``VRU = VRMAX*v``,
    ``VRL = VRMIN*v`` by constants after its anti-windup regulator ``LA`` was built; the block
    keeps the discarded services, never evaluated (value 0), and ANDES's initialization stops
    (``TypeError`` while adjusting the limit). This re-points the block and its limiter at the
    constant services, i.e. the DC1A diagram. Use as ``run_andes_ss(..., configure=...)``
    (after ``ss.setup()``); a no-op without ESDC1A devices. ANDES's code is not changed.
    """
    if "ESDC1A" not in ss.models or ss.ESDC1A.n == 0:
        return
    m = ss.ESDC1A
    for blk in (m.LA, m.LA.lim):
        blk.upper, blk.lower = m.VRU, m.VRL


def fix_andes_exac2(ss):
    """Point ANDES 2.0's EXAC2 regulator lag at its own limits ``VAMAX``, ``VAMIN``.

    ANDES's EXAC2 derives from its EXAC1 and sets ``LA.lower = VAMIN``, ``LA.upper = VAMAX``
    after the anti-windup lag ``LA`` was built: the block's limiter keeps EXAC1's ``VRMIN``,
    ``VRMAX`` (``ss.EXAC2.LA.lim.upper`` is ``VRMAX``), so its regulator is held at the exciter
    limits instead of the regulator's. This re-points the limiter, i.e. the AC2 diagram. Use as
    ``run_andes_ss(..., configure=...)`` (after ``ss.setup()``); a no-op without EXAC2 devices.
    ANDES's code is not changed.
    """
    if "EXAC2" not in ss.models or ss.EXAC2.n == 0:
        return
    m = ss.EXAC2
    m.LA.lim.upper, m.LA.lim.lower = m.VAMAX, m.VAMIN


def run_andes_ss(ss, tf, h, tol=1e-8, hold_step=False, configure=None):
    """Set up, solve the power flow and simulate ``ss`` in ANDES at the fixed step ``h``.

    ``hold_step=True``: a truly fixed step (:func:`hold_andes_step`); by default ANDES may
    shorten its step after slow Newton convergence. ``configure(ss)`` is called after the
    setup (e.g. to set a model's or a routine's config)."""
    ss.setup()
    if hold_step:
        hold_andes_step(ss.TDS)
    if configure is not None:
        configure(ss)
    ss.PFlow.config.tol = 1e-11
    ss.PFlow.run()
    if not ss.PFlow.converged:
        return {"ok": False, "error": "ANDES power flow did not converge"}
    ss.TDS.config.tf = tf
    ss.TDS.config.tstep = h
    ss.TDS.config.fixt = 1
    ss.TDS.config.shrinkt = 0
    ss.TDS.config.tol = tol
    ss.TDS.config.no_tqdm = 1
    t0 = time.perf_counter()
    ss.TDS.run()
    wall = time.perf_counter() - t0
    ts = ss.dae.ts
    om, de, names = [], [], []
    for m in MACHINES:
        mdl = ss.models[m]
        for k, ix in enumerate(mdl.idx.v):
            if mdl.u.v[k] > 0:
                om.append(mdl.omega.a[k])
                de.append(mdl.delta.a[k])
                names.append(device_name(m, ix))
    out = {"t": np.asarray(ts.t), "omega": np.asarray(ts.x[:, om]), "delta": np.asarray(ts.x[:, de]),
           "names": names, "wall": wall, "ok": bool(ss.exit_code == 0), "ss": ss}
    if not out["ok"]:
        out["error"] = (f"ANDES exit code {ss.exit_code} (its run reached t = {float(ss.dae.t):.3g} s of {tf:g}; "
                        "see its log, e.g. a failed TDS initialization check)")
    return out


def run_weakgrid_ss(ss, tf, h, tol=1e-8, conventions="standard", **kw):
    """Import ``ss`` (not set up) into weakgrid with its events and simulate at step ``h``.

    ``conventions="andes"`` imports with ANDES 2.0's departures from the standard models
    (:data:`weakgrid.sim.io.andes.ANDES_CONVENTIONS`)."""
    from ..integrate import Simulator
    from ..io.andes import from_andes

    system, events = from_andes(ss, conventions=conventions)
    system.setup()
    sim = Simulator(system, dt=h, tol=tol, **kw)
    t0 = time.perf_counter()
    res = sim.run(tf, events=events)
    wall = time.perf_counter() - t0
    names = list(system.machine_names)
    return {"t": res.t, "omega": np.column_stack([res[f"{n}.omega"] for n in names]),
            "delta": np.column_stack([res[f"{n}.delta"] for n in names]), "names": names,
            "wall": wall, "ok": res.ok, "res": res, "system": system}


def compare_named(a, b, t_grid=None):
    """Largest speed difference [pu] and rotor-angle difference [deg] relative to the first
    common machine, over machines matched by name."""
    common = [n for n in a["names"] if n in b["names"]]
    ia = [a["names"].index(n) for n in common]
    ib = [b["names"].index(n) for n in common]
    if t_grid is None:
        t_grid = np.linspace(max(a["t"][0], b["t"][0]), min(a["t"][-1], b["t"][-1]), 4001)
    wa = interp_to(t_grid, a["t"], a["omega"][:, ia])
    wb = interp_to(t_grid, b["t"], b["omega"][:, ib])
    da = interp_to(t_grid, a["t"], a["delta"][:, ia])
    db = interp_to(t_grid, b["t"], b["delta"][:, ib])
    ra, rb = da - da[:, :1], db - db[:, :1]
    return float(np.max(np.abs(wa - wb))), float(np.degrees(np.max(np.abs(ra - rb))))


def solve_network_at_clearing(ss, tol=1e-10, max_iter=30):
    """Start ANDES's first Newton iterate after a fault clearing on the network's solution.

    At a clearing ANDES's ``Fault`` (config ``restore = 1``) sets every algebraic variable
    but the bus angles back to its pre-fault value, and the step after it starts its Newton
    iteration there. ANDES evaluates its discrete services (``VarService``: REECA1's
    ``Volt_dip``; ``ExtendedEvent``: its Thld/Thld2 timers; ``VarHold``: the held Ipmax) and
    the freezes of its blocks at *every* iterate and keeps what they record there, so that
    first iterate, which is not a solution (v = 1.0 pu, inside REECA1's normal band, where
    the solution is outside it), can end a voltage dip that goes on at every accepted point.

    This wraps the clearing callback of ``ss.Fault`` (only this system's): after ANDES's
    restore, the algebraic equations are solved for the algebraic variables by Newton's method
    with the states fixed at the clearing instant and every ``VarService`` kept at its value
    there (limiters and anti-windups are evaluated as usual; the states and the state
    derivatives that the trapezoidal step uses are put back). ANDES's own first step then
    starts from that solution; nothing else of ANDES changes. A test-side diagnosis (the
    peer harness), not a change of ANDES's method: ``test_reeca1_peer.py`` measures it with
    and without. Pass it as ``run_andes_ss(..., configure=solve_network_at_clearing)``
    (called after ``ss.setup()``).
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    fault = ss.Fault
    clear = fault.tc.callback

    def clear_and_solve(is_time):
        action = clear(is_time)
        if not action:
            return action
        dae = ss.dae
        models = ss.exist.pflow_tds
        x0, f0 = dae.x.copy(), dae.f.copy()
        for it in range(max_iter):
            dae.clear_fg()
            ss.l_update_var(models, niter=it, err=None)
            ss.f_update(models)
            ss.l_update_eq(models, niter=it)
            ss.g_update(models)
            ss.fg_to_dae()
            dae.x[:] = x0
            if np.max(np.abs(dae.g)) < tol:
                break
            ss.j_update(models)
            gy = dae.gy
            A = sp.csc_matrix((np.asarray(gy.V).ravel(), (np.asarray(gy.I).ravel(), np.asarray(gy.J).ravel())),
                              shape=gy.size)
            dae.y[:] -= spla.spsolve(A, np.asarray(dae.g).ravel())
            ss.vars_to_models()
        else:
            raise RuntimeError(f"the network after the clearing at t = {float(dae.t):g} s did not converge "
                               f"in {max_iter} Newton iterations (|g| = {np.max(np.abs(dae.g)):.3g})")
        dae.x[:] = x0
        dae.f[:] = f0
        ss.vars_to_models()
        return action

    fault.tc.callback = clear_and_solve
