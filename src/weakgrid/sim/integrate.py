"""Implicit trapezoidal integration of the DAE with Newton iterations and exact events.

Method (as in PSS/E-class and ANDES time-domain tools)
------------------------------------------------------
For a step ``h`` from ``t`` to ``t + h`` the unknown ``z = [x; y]`` solves::

    x - x_n - h/2 (f(z_n) + f(z)) = 0
    g(z) = 0

by a chord ("very dishonest") Newton method: the iteration matrix
``[I - h/2 df/dz; dg/dz]`` is factored once and reused over many steps; it is
refreshed when Newton converges slowly or fails, after events, or when ``h``
changes. A failed step is retried with a fresh Jacobian, then with halved steps.

Non-windup limits: a limited state that would cross its limit is held at the
limit (its row becomes ``x - limit = 0``) until its derivative points back
inside, and the step is recomputed.

Discontinuities (events, controller samples) are breakpoints: the integrator
steps exactly onto them, applies them, and re-solves the algebraic variables
with the states fixed (consistent re-initialization) before continuing.

Failures raise :class:`~weakgrid.sim.errors.SimulationError` with time and
cause (``newton``, ``divergence``, ``loss of synchronism``, ``controller``),
or, with ``on_failure="return"``, are recorded in ``Results.failure``.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import DataError, SimulationError
from .linsolve import make_solver
from .results import Results


def lu_solve(lu, b):
    """Solve with a factorization from :mod:`weakgrid.sim.linsolve` (dense or sparse)."""
    return lu.solve(b)


def default_tol(dt: float) -> float:
    """Default Newton tolerance [pu] for step ``dt`` [s]: ``1e-7 (dt / (1/120 s))**3`` in ``[1e-10, 1e-7]``.

    Each accepted step carries an iteration error up to ``tol`` that, in lightly damped
    swings, accumulates over the ``T/dt`` steps of a run, while the trapezoidal rule's own
    global error falls as ``dt**2``; a tolerance that falls like the local error ``dt**3``
    keeps the iteration error a fixed small fraction of the step error at every step size.
    Measured on ANDES's SMIB case (10 s, lightly damped): with a fixed 1e-7, at 1/480 s the
    result moved 2.5e-5 pu between tolerances 1e-7 and 1e-12, as much as halving the step
    (2.4e-5 pu); with this default the tolerance effect is < 1/10 of the step effect from
    1/120 s to 1/1920 s. ``1e-7`` at 1/120 s keeps the PSS/E-class steps as fast as before;
    the ``1e-10`` floor stays far above round-off.
    """
    return float(min(1e-7, max(1e-10, 1e-7 * (dt * 120.0) ** 3)))


class Simulator:
    """Time-domain simulation of a set-up :class:`~weakgrid.sim.system.System`.

    Parameters
    ----------
    system : System
        A system after :meth:`~weakgrid.sim.system.System.setup`.
    dt : float
        Nominal step [s].
    tol : float, optional
        Newton convergence tolerance on the largest update [pu]. Default: scaled with
        the step like the method's local error, ``1e-7 (dt / (1/120 s))**3``, within
        ``[1e-10, 1e-7]`` (see :func:`default_tol`), so that the step, not the
        tolerance, sets the error of a run.
    max_iter : int
        Newton iterations before the Jacobian is refreshed / the step is halved.
    max_angle_spread : float
        Loss-of-synchronism threshold [deg] on the spread of the machines' rotor-angle
        excursions from the operating point the simulation started at,
        ``max(delta - delta0) - min(delta - delta0)``: the spread of the angles themselves
        is not a measure of synchronism, large grids operate with more than 180° between
        their machines (case9241pegase 178°, ACTIVSg10k 236°).
    save_every : int
        Record every n-th step (breakpoints are always recorded).
    linear_solver : {"auto", "dense", "sparse"}
        Linear algebra backend (:mod:`weakgrid.sim.linsolve`): ``"auto"`` is dense
        for small systems and sparse for large ones.
    sparse_lu : {"auto", "klu", "superlu"}
        Sparse LU library of the sparse backend: ``"auto"`` is KLU when ``kvxopt`` (the
        extra ``weakgrid[klu]``) is installed, else SciPy's SuperLU
        (:func:`weakgrid.sim.linsolve.sparse_lu`).
    record : None, "all", "machines" or list of str
        What :meth:`run` records (:meth:`Results.recorder`): ``None`` records
        everything for small systems and the machine speeds and angles for large
        ones; a list selects variables by name (or by a ``"*.omega"``-style pattern).
    """

    def __init__(self, system, dt=1 / 120, tol=None, max_iter=8, max_angle_spread=180.0,
                 save_every=1, min_step=None, linear_solver="auto", sparse_lu="auto", record=None):
        if not system.is_setup:
            system.setup()
        if not dt > 0:
            raise DataError("simulation", "dt", dt, "give a positive time step in seconds")
        self.sys = system
        self.dt = float(dt)
        self.tol = default_tol(self.dt) if tol is None else float(tol)
        self.max_iter = int(max_iter)
        self.max_spread = math.radians(max_angle_spread)
        self.save_every = int(save_every)
        self.min_step = float(min_step) if min_step else self.dt / 64
        self.t = 0.0
        self.z = system.z0.copy()
        nx = system.nx
        self.nx = nx
        self.frozen = np.zeros(len(system.lim_idx), dtype=np.int8)  # +1 upper, -1 lower
        self.stats = {"steps": 0, "newton": 0, "jac": 0, "lu": 0, "evals": 0}
        self._Jdev = None
        self.linsolver = make_solver(system, linear_solver, sparse_lu)
        self.record = record
        self._lu = None
        self._lu_key = None
        self._lu_h = None
        self._alg_lu = None
        self._alg_key = None
        self.events = []
        self.controllers = []
        self._delta0 = None   # rotor angles at the start of the first run [rad]

    # ----------------------------------------------------------- linear algebra
    def _refresh_jacobian(self, t, z):
        self._refresh_next = False
        self._Jdev = self.sys.device_jacobian_values(t, z)
        self.linsolver.set_device_jacobian(self._Jdev)
        self.stats["jac"] += 1
        self.stats["evals"] += self.sys.ncolours + 1
        self._lu_key = None
        self._alg_key = None

    def _step_diagnosis(self, t, z):
        """If dt is large against the fastest time constant, say so (the real cause)."""
        if self.sys.N > 3000:  # a dense eigen-analysis would cost more than it tells
            return ""
        try:
            J = self.sys.jacobian(t, z)
            nx = self.nx
            A = J[:nx, :nx] - J[:nx, nx:] @ np.linalg.solve(J[nx:, nx:], J[nx:, :nx])
            lam, vec = np.linalg.eig(A)
            k = int(np.argmax(np.abs(lam)))
            tau = 1.0 / abs(lam[k])
            name = self.sys.var_name(int(np.argmax(np.abs(vec[:, k]))))
        except Exception:  # the diagnosis must never hide the failure
            return ""
        if self.dt <= 5 * tau:
            return ""
        return (f"; the step dt = {self.dt:g} s is too large relative to the fastest time "
                f"constant of the system, ≈ {tau:.3g} s (mode dominated by {name}): use dt ≤ "
                f"{2 * tau:.2g} s")

    def _iteration_lu(self, h):
        key = (self.sys.net_version, self.frozen.tobytes())
        # a step that differs from the factored one only by round-off (steps onto
        # sampling breakpoints) reuses the chord matrix
        if self._lu_key != key or abs(h - self._lu_h) > 1e-9 * h:
            fi = self.sys.lim_idx[self.frozen != 0] if len(self.frozen) else None
            self._lu = self.linsolver.factor_iteration(h, fi)
            self._lu_key = key
            self._lu_h = h
            self.stats["lu"] += 1
        return self._lu

    def _alg_lu_get(self):
        key = self.sys.net_version
        if self._alg_key != key:
            self._alg_lu = self.linsolver.factor_algebraic()
            self._alg_key = key
        return self._alg_lu

    # ------------------------------------------------------------------ solves
    def solve_algebraic(self, t, z, max_iter=30, return_eval=False, y_guess=None, path=None):
        """Re-solve the network (algebraic) variables with the states fixed.

        First a chord iteration with the current factorization (cheap; enough after
        small jumps such as consecutive controller samples), started from ``y_guess``
        if given. If it diverges or stalls, Newton's method with a fresh Jacobian at
        every iterate and a backtracking line search on the network residual, started
        again from the pre-jump point: after a large jump (a fault cleared, a UPQC
        series voltage stepping by its whole rating) the chord matrix of the previous
        operating point does not contract and full Newton steps can overshoot.

        Converged when the Newton update of the algebraic variables is below
        ``tol``; the point returned is the last one *evaluated* (its distance to
        the solution is that update, i.e. < ``tol``), so that with
        ``return_eval=True`` the residual ``F`` and context evaluated there are
        returned too (``(z, F, ctx)``) and need not be recomputed.

        ``path(s, z)``, if given, moves the system along the jump itself (``s = 0``: before
        it, ``s = 1``: after it; e.g. the controllers' outputs from their held to their new
        values) and returns the point with the states at ``s``. When Newton fails, the
        network is then followed along that path (:meth:`_alg_path`); if its solution branch
        ends at a fold, the jump has no network solution: ``SimulationError`` with cause
        ``"voltage collapse"``.
        """
        nx = self.nx
        z_start = z.copy()
        z = z.copy()
        if y_guess is not None:   # first attempt from a predicted algebraic solution
            z[nx:] = y_guess
        out = self._alg_chord(t, z, max_iter)
        if out is None:
            out = self._alg_newton(t, z_start, max_iter)
        if out is None and path is not None:
            out, s_fold, info = self._alg_path(t, z_start, path, max_iter)
            if out is None and info is not None:
                raise self._collapse(t, s_fold, info, "the step of the controllers' outputs")
        if out is None:
            out, s_reached = self._alg_continuation(t, z_start, max_iter)
            if out is None:
                raise SimulationError(
                    t, "newton", "no network solution after the jump: chord, Newton with line search and "
                    f"continuation from the pre-jump point all failed (continuation reached {s_reached:.3g} "
                    "of the jump: the network likely has no operating point beyond it, e.g. voltage collapse)")
        return out if return_eval else out[0]

    def _alg_chord(self, t, z, max_iter):
        """Chord iteration on the algebraic variables; ``(z, F, ctx)`` or None if it diverges/stalls."""
        nx = self.nx
        lu = self._alg_lu_get()
        prev = math.inf
        grow = 0
        for it in range(max_iter):
            F, ctx = self.sys.residual(t, z)
            self.stats["evals"] += 1
            dy = lu_solve(lu, F[nx:])
            nrm = float(np.max(np.abs(dy)))
            if not math.isfinite(nrm):
                return None
            if nrm < self.tol:
                return z, F, ctx
            grow = grow + 1 if nrm > 0.9 * prev else 0
            if grow >= 2:            # not contracting: give up early
                return None
            prev = nrm
            z[nx:] -= dy
        return None

    def _alg_newton(self, t, z, max_iter, shift=None):
        """Newton with a fresh Jacobian per iterate and backtracking on ``|g|``; ``(z, F, ctx)`` or None.

        With ``shift`` the equations solved are ``g(y) - shift = 0`` (continuation).
        """
        nx = self.nx
        if shift is None:
            residual = self.sys.residual
        else:
            def residual(t_, z_):
                F_, c_ = self.sys.residual(t_, z_)
                F_[nx:] -= shift
                return F_, c_
        z = z.copy()
        F, ctx = residual(t, z)
        self.stats["evals"] += 1
        r = float(np.linalg.norm(F[nx:]))
        for it in range(max_iter):
            self._refresh_jacobian(t, z)
            dy = lu_solve(self._alg_lu_get(), F[nx:])
            nrm = float(np.max(np.abs(dy)))
            if not math.isfinite(nrm):
                return None
            if nrm < self.tol:
                return z, F, ctx
            lam = 1.0
            while True:
                zt = z.copy()
                zt[nx:] -= lam * dy
                Ft, ct = residual(t, zt)
                self.stats["evals"] += 1
                rt = float(np.linalg.norm(Ft[nx:]))
                if (math.isfinite(rt) and rt <= (1.0 - 1e-4 * lam) * r) or lam < 1 / 256:
                    break
                lam *= 0.5
            if not math.isfinite(rt):
                return None
            z, F, ctx, r = zt, Ft, ct, rt
        return None

    def _alg_continuation(self, t, z, max_iter):
        """Newton homotopy from the pre-jump point ``z`` (whose network residual is ``g0``).

        Solves ``g(y) - (1 - s) g0 = 0`` for ``s`` from 0 (solved by ``z`` itself) to 1
        with adaptive steps, each by :meth:`_alg_newton`. Returns ``((z, F, ctx), 1.0)``
        or ``(None, s)`` with the largest ``s`` reached (a fold: no solution beyond it).
        """
        nx = self.nx
        F0, _ = self.sys.residual(t, z)
        g0 = F0[nx:].copy()
        s, ds = 0.0, 0.25
        z = z.copy()
        while s < 1.0:
            s1 = min(1.0, s + ds)
            out = self._alg_newton(t, z, max_iter, shift=(1.0 - s1) * g0)
            if out is None:
                ds /= 4
                if ds < 1e-4:
                    return None, s
                continue
            z = out[0]
            s = s1
            ds = min(2 * ds, 1.0)
        return out, 1.0

    def _alg_tangent(self, t, z, path, s, ds=1e-6):
        """``|dy/ds|`` of the network solution ``z`` at ``s`` of ``path`` (one solve)."""
        nx = self.nx
        z1 = path(s + ds, z)
        g1 = self.sys.residual(t, z1)[0][nx:]
        path(s, z)
        g0 = self.sys.residual(t, z)[0][nx:]
        self._refresh_jacobian(t, z)
        return float(np.linalg.norm(lu_solve(self._alg_lu_get(), (g1 - g0) / ds)))

    def _alg_path(self, t, z, path, max_iter):
        """Natural continuation of the network solution along the physical ``path`` of a jump.

        Steps ``s`` from 0 (the network solved there first, from ``z``: another jump at the
        same instant, e.g. an event, may have moved it) to 1, each step by
        :meth:`_alg_newton` from the previous solution, the step cut by 4 on failure. Returns
        ``(out, 1.0, None)`` on success, else ``(None, s, info)``: ``s`` the last point
        solved and ``info`` (its ``(z, ctx)``, the growth of the tangent ``|dy/ds|`` from
        ``s = 0``) when the branch ends there at a fold — the tangent grows without bound
        as a saddle-node is approached (``|dy/ds| ~ (s* - s)^(-1/2)``) — or ``info = None``
        when the continuation stalled for another reason.
        """
        s, ds, out = 0.0, 0.25, None
        try:
            o = self._alg_newton(t, path(0.0, z.copy()), max_iter)
            if o is None:
                return None, 0.0, None
            zs = z0 = o[0]
            tan0 = self._alg_tangent(t, z0, path, 0.0)
            while s < 1.0:
                s1 = min(1.0, s + ds)
                zt = path(s1, zs.copy())
                o = self._alg_newton(t, zt, max_iter)
                if o is None:
                    ds /= 4
                    if ds < 1e-6:
                        break
                    continue
                out, zs, s = o, o[0], s1
                ds = min(2 * ds, 0.25)
            if s >= 1.0:
                return out, 1.0, None
            tan = self._alg_tangent(t, zs, path, s, ds=min(1e-6, 1e-3 * max(ds, 1e-9)))
            growth = tan / max(tan0, 1e-12)
            if not growth > 10.0:      # not a fold: let the caller try another homotopy
                return None, s, None
            ctx = self.sys.residual(t, zs)[1]
            return None, s, {"z": zs, "z0": z0, "ctx": ctx, "growth": growth}
        finally:
            path(1.0, z)

    def _collapse(self, t, s, info, what):
        """The :class:`SimulationError` of a fold of the network equations (voltage collapse)."""
        ctx = info["ctx"]
        vm = np.abs(np.asarray(ctx.V))
        b = int(np.argmin(vm))
        err = SimulationError(
            t, "voltage collapse",
            f"no network solution: following {what}, the network's operating point ends at a fold "
            f"(saddle-node) at {s:.4g} of it (|dy/ds| grew {info['growth']:.3g}x), lowest voltage "
            f"{vm[b]:.3g} pu at bus {self.sys.network.bus_ids[b]}")
        err.fold = {"s": float(s), "z": info["z"], "z0": info["z0"], "V": np.asarray(ctx.V).copy(),
                    "outputs": {k: np.array(v, copy=True) for k, v in ctx.out.items()}}
        return err

    def _impasse(self, t, z_n, f_n):
        """At a step failure: does the network lose its solution as the states move on?

        Follows the network solution along the states' explicit prediction
        ``x_n + s dt f_n`` for ``s`` in [0, 1] (:meth:`_alg_path`). A fold before ``s = 1``
        is an impasse: the states carry the grid to a point where the network equations have
        no solution (voltage collapse); returns the error to raise, else None.
        """
        nx, dt = self.nx, self.dt
        x_n = z_n[:nx].copy()

        def path(s, z):
            z[:nx] = x_n + s * dt * f_n
            return z

        try:
            out, s, info = self._alg_path(t, z_n.copy(), path, 30)
        except Exception:      # the diagnosis must never hide the failure
            return None
        if out is not None or info is None:
            return None
        return self._collapse(t + s * dt, s, info, f"the states' motion from t = {t:.6g} s")

    def _predict(self, lu, h, z_n, f_n, fi, limval):
        """Linearly implicit trapezoidal step from ``z_n`` with the chord matrix ``lu``."""
        R = np.zeros(len(z_n))
        R[:self.nx] = -h * f_n
        if fi is not None:
            R[fi] = z_n[fi] - limval
        return z_n - lu_solve(lu, R)

    def _newton(self, t1, h, z_n, f_n, z=None, corr=None):
        """Chord Newton for the trapezoidal step; returns ``(z, nit, last)``.

        Without a starting point ``z`` the iteration starts from the linearly
        implicit trapezoidal predictor: one chord-Newton update from ``z_n``,
        whose residual ``[-h f_n; g(z_n) ~ 0]`` is known without an evaluation.
        It is exact for linear dynamics, so stiff modes that ring under the
        trapezoidal rule (high-gain exciters) are predicted correctly.

        The accepted point is the last *evaluated* one (its Newton update is below
        ``tol``, i.e. it is within ``tol`` of the solution), so ``last = (f, ctx)``,
        its state derivative and evaluation context, need no further evaluation.
        """
        nx = self.nx
        lu = self._iteration_lu(h)
        li = self.sys.lim_idx
        fi = limval = None
        if len(li) and self.frozen.any():
            fz = self.frozen != 0
            fi = li[fz]
            limval = np.where(self.frozen > 0, self.sys.lim_hi, self.sys.lim_lo)[fz]
        x_n = z_n[:nx]
        if z is None:
            z = self._predict(lu, h, z_n, f_n, fi, limval)
            self._pred = z.copy()
            if corr is not None:
                z += corr
            if fi is not None:
                z[fi] = limval
            if self._refresh_next:
                # refresh the chord matrix at the predicted point (close to the solution,
                # so the chord iteration contracts fast)
                self._refresh_jacobian(t1, z)
                lu = self._iteration_lu(h)
                # the predictor with the new matrix, for the next step's correction
                self._pred = self._predict(lu, h, z_n, f_n, fi, limval)
        else:
            z = z.copy()
        if fi is not None:
            z[fi] = limval
        residual = self.sys.residual
        tol = self.tol
        hh = 0.5 * h
        c = x_n + hh * f_n
        var_lim = fi is not None and bool(self.sys._var_lim)
        for it in range(self.max_iter):
            F, ctx = residual(t1, z)
            if var_lim:   # held at a limit that moves with the solution (VRMAX*Vt): implicit in the limit
                self.sys.update_limits(ctx)
                limval = np.where(self.frozen > 0, self.sys.lim_hi, self.sys.lim_lo)[fz]
                if not np.all(np.isfinite(limval)):
                    # the limit switched off (e.g. REGCA1's LVPL above Brkpt): release the held
                    # states and redo the step; they resume from the value they were held at
                    self.frozen[np.nonzero(fz)[0][~np.isfinite(limval)]] = 0
                    return None, it + 1, "release"
            f = F[:nx].copy()
            R = F
            Rx = R[:nx]
            np.subtract(z[:nx], c, out=Rx)
            Rx -= hh * f
            if fi is not None:
                R[fi] = z[fi] - limval
            dz = lu_solve(lu, R)
            nrm = float(np.abs(dz).max())
            if not math.isfinite(nrm):
                break
            if nrm < tol:
                # converged: the evaluated point is within tol of the solution; keep it
                # with its derivative and outputs (no further evaluation needed)
                self.stats["evals"] += it + 1
                self.stats["newton"] += it + 1
                return z, it + 1, (f, ctx)
            z -= dz
        self.stats["evals"] += it + 1
        self.stats["newton"] += it + 1
        return None, it + 1, None

    def _step(self, h):
        """Advance one step of size ``h`` (may be shortened on failure). Returns the step taken."""
        t, z_n, f_n = self.t, self.z, self._f
        li = self.sys.lim_idx
        guess = None            # linearly implicit predictor (see _newton)
        refreshed = False
        corr = self._corr if (self._corr is not None and abs(self._corr_h - h) <= 1e-9 * h) else None
        if self.sys._var_lim:   # limits that move with the solution, taken at t_n
            self.sys.update_limits(self._ctx)
        while True:
            z, nit, last = self._newton(t + h, h, z_n, f_n, guess, corr)
            if z is None and last == "release":
                guess = corr = None
                continue
            if z is None:
                if self.sys._var_lim:   # a failed attempt leaves its (diverged) iterate's limits
                    self.sys.update_limits(self._ctx)   # (VRMAX*Vt): every retry starts from t_n's
                if not refreshed:
                    self._refresh_jacobian(t, z_n)
                    refreshed = True
                    guess = corr = None
                    continue
                if h / 2 < self.min_step:
                    # a step far too large for the fastest time constant is the cause before any
                    # fold that the (then meaningless) predicted motion runs into
                    too_large = self._step_diagnosis(t, z_n)
                    collapse = None if too_large else self._impasse(t, z_n, f_n)
                    if collapse is not None:
                        raise collapse
                    raise SimulationError(t, "newton",
                                          f"no convergence with step {h:.3g} s even with a fresh "
                                          f"Jacobian{too_large}")
                h /= 2
                refreshed = False
                guess = corr = None
                continue
            f1, ctx = last      # evaluated at the accepted point
            if self.sys._var_lim:   # limits at the new point
                self.sys.update_limits(ctx)
            if len(li):
                xl = z[li]
                new_hi = (self.frozen == 0) & (xl > self.sys.lim_hi + 1e-9)
                new_lo = (self.frozen == 0) & (xl < self.sys.lim_lo - 1e-9)
                if self.sys.any_pushing:   # reset only while pushing outwards (ANDES)
                    fl, push = f1[li], self.sys.lim_pushing
                    new_hi &= ~push | (fl >= 0)
                    new_lo &= ~push | (fl <= 0)
                if new_hi.any() or new_lo.any():
                    self.frozen[new_hi] = 1
                    self.frozen[new_lo] = -1
                    guess = z
                    if (self.sys.lim_pushing & (new_hi | new_lo)).any():
                        # a state reset from beyond its limit jumps (ANDES's AntiWindup): start
                        # from the network solved with it at its limit, as after an event
                        g = z.copy()
                        g[li[new_hi]] = self.sys.lim_hi[new_hi]
                        g[li[new_lo]] = self.sys.lim_lo[new_lo]
                        guess = self.solve_algebraic(t + h, g)
                        self._refresh_jacobian(t + h, guess)
                    continue
                self._release_held(f1)
            # nonlinear correction to the predictor, extrapolated to the next step
            self._corr = z - self._pred if guess is None else None
            self._corr_h = h
            if nit > self.max_iter // 2 - 1:   # refresh the chord matrix after slow convergence (cheap: batched)
                self._refresh_next = True   # at the next step's predicted point
            self.z, self._f, self._ctx = z, f1, ctx
            self.t = t + h
            if self.sys._accepting:
                self.sys.accept(self.t, ctx)
            self.stats["steps"] += 1
            return h

    def _release_held(self, f):
        """Release held states whose derivative ``f`` (of the whole state vector) points back inside."""
        li = self.sys.lim_idx
        if len(li) and self.frozen.any():
            fl = f[li]
            rel = ((self.frozen > 0) & (fl < 0)) | ((self.frozen < 0) & (fl > 0))
            self.frozen[rel] = 0

    # -------------------------------------------------------------------- run
    def _check(self):
        z = self.z
        if not np.abs(z).max() <= 1e6:   # one reduction: NaN fails the comparison too
            bad = np.nonzero(~np.isfinite(z) | (np.abs(z) > 1e6))[0]
            raise SimulationError(self.t, "divergence", f"variable {self.sys.var_name(int(bad[0]))} ran away")
        d = self._ctx.sig["delta"]
        if len(d) > 1:
            e = d - self._delta0 if self._delta0 is not None and len(self._delta0) == len(d) else d
            spread = e.max() - e.min()
            if spread > self.max_spread:
                names = self.sys.machine_names
                i, j = int(e.argmax()), int(e.argmin())
                raise SimulationError(self.t, "loss of synchronism",
                                      f"rotor angle spread {math.degrees(spread):.1f} deg between "
                                      f"'{names[i]}' and '{names[j]}' (their swings from the "
                                      f"initial angles: {math.degrees(e[i]):+.1f} and "
                                      f"{math.degrees(e[j]):+.1f} deg)")

    def run(self, t_end, events=(), controllers=(), on_failure="raise", progress=None) -> Results:
        """Simulate from the current time to ``t_end`` [s].

        Parameters
        ----------
        t_end : float
            Final time [s].
        events : iterable of Event
            Timed events (:mod:`weakgrid.sim.events`).
        controllers : iterable of DigitalController
            Sampled controllers (:mod:`weakgrid.sim.controllers`).
        on_failure : {"raise", "return"}
            Raise :class:`SimulationError`, or return the results up to the failure
            with ``Results.failure`` set.
        progress : callable, optional
            ``progress(t)`` after every step, with the time reached [s] (a progress bar).
        """
        sys = self.sys
        from .events import prepare as prepare_events

        try:
            t_end = float(t_end)
        except (TypeError, ValueError):
            raise DataError("simulation", "t_end", t_end, "give the final time in seconds") from None
        if not (math.isfinite(t_end) and t_end > self.t):
            raise DataError("simulation", "t_end", t_end,
                            f"give a finite final time after the current time {self.t:g} s")
        events = prepare_events(events, sys, t_end)
        controllers = list(controllers)
        for c in controllers:
            c.bind(sys)
        rec = Results.recorder(sys, self.record)
        self._corr = self._corr_h = None
        self._refresh_next = False
        self.z = self.solve_algebraic(self.t, self.z) if self._Jdev is not None else self.z
        if self._Jdev is None:
            self._refresh_jacobian(self.t, self.z)
            self.z = self.solve_algebraic(self.t, self.z)
        F, self._ctx = sys.residual(self.t, self.z)
        failure = None
        try:   # a controller's first sample (or the re-solve after it) can fail like any other
            for c in controllers:
                if c.due(self.t):
                    c.sample(self, self.t, self.z)
            if controllers:
                self.z = self.solve_algebraic(self.t, self.z)
        except SimulationError as exc:
            if on_failure == "raise":
                raise
            failure = exc
        F, self._ctx = sys.residual(self.t, self.z)
        self._f = F[:self.nx].copy()
        if self._delta0 is None:
            self._delta0 = np.array(self._ctx.sig["delta"], dtype=float, copy=True)
        if sys._accepting:
            sys.accept(self.t, self._ctx)
        rec.add(self.t, self.z, self._ctx)
        if failure is not None:
            return rec.finish(failure=failure, stats=dict(self.stats))
        ev_i = 0
        eps = 1e-12
        self._jump, self._jump_t = None, -math.inf
        jump_gap = min([c.T for c in controllers if hasattr(c, "T")] or [0.0])
        nstep = 0
        try:
            while self.t < t_end - eps:
                # next breakpoint
                tb = t_end
                if ev_i < len(events):
                    tb = min(tb, events[ev_i].t)
                for c in controllers:
                    tb = min(tb, c.next_time(self.t))
                h = min(self.dt, tb - self.t)
                if tb - (self.t + h) < 1e-3 * self.dt:
                    h = tb - self.t
                if h > eps:
                    h = self._step(h)
                    nstep += 1
                    self._check()
                    if progress is not None:
                        progress(self.t)
                hit = abs(self.t - tb) <= eps * max(1.0, abs(tb)) * 10
                discont = False
                new_jac = False
                if hit:
                    self.t = tb
                    rec.add(self.t, self.z, self._ctx)
                    while ev_i < len(events) and events[ev_i].t <= self.t + 1e-12:
                        events[ev_i].apply(self)
                        ev_i += 1
                        discont = new_jac = True
                    u_held = [_held(c) for c in controllers]
                    for c in controllers:
                        if c.due(self.t):
                            discont |= c.sample(self, self.t, self.z)
                    if discont:
                        y_before = self.z[self.nx:]
                        du = _held_change(controllers, u_held)
                        guess = None
                        if new_jac:
                            self._refresh_jacobian(self.t, self.z)
                            self._jump = None
                            self._corr = None
                        elif self._jump is not None and self._jump_t > self.t - 1.5 * jump_gap:
                            # consecutive ZOH samples of a smooth control: start the re-solve
                            # from the previous jump, scaled to this sample's output change
                            guess = jump_guess(y_before, self._jump, du)
                        self.z, F, self._ctx = self.solve_algebraic(self.t, self.z, return_eval=True,
                                                                    y_guess=guess,
                                                                    path=_output_path(controllers, u_held))
                        if not new_jac:
                            self._jump = (self.z[self.nx:] - y_before, du)
                            self._jump_t = self.t
                        self._f = F[:self.nx].copy()
                        # a held state whose input fell inside its limit at the event (a fault
                        # cleared: Vt and with it the drive of a regulator drop back) is released
                        # now; held, it would follow a limit that moves with the event (VRMAX*Vt)
                        self._release_held(self._f)
                        if sys._accepting:
                            sys.accept(self.t, self._ctx)
                        rec.add(self.t, self.z, self._ctx)
                elif nstep % self.save_every == 0:
                    rec.add(self.t, self.z, self._ctx)
        except SimulationError as exc:
            if on_failure == "raise":
                raise
            failure = exc
        return rec.finish(failure=failure, stats=dict(self.stats))


def _held(c):
    """The output a controller's target holds (None if it cannot tell)."""
    get = getattr(getattr(c, "target", None), "get", None)
    return None if get is None else np.array(get(), dtype=float)


def _held_change(controllers, held):
    """The change of every controller's held output since ``held`` (their outputs before a
    sample), one flat array; None if a target cannot tell its output."""
    parts = []
    for c, u0 in zip(controllers, held):
        u1 = _held(c)
        if u0 is None or u1 is None:
            return None
        parts.append(u1 - u0)
    return np.concatenate(parts) if parts else None


def jump_guess(y, jump, du):
    """A start for the network re-solve after a sample: the algebraic variables ``y`` moved
    by the previous jump ``jump = (Δy, Δu)`` scaled to this sample's output change ``du``.

    The network's response to the held outputs is nearly linear over one sample,
    ``Δy ≈ S·Δu``; with ``c = ⟨du, Δu⟩ / ⟨Δu, Δu⟩`` (the least-squares multiple of the
    previous change, on Python floats: the same in a batch and alone) the guess is
    ``y + c·Δy``, exact when the output changes along the previous direction. A control
    signal that turns (``du`` against ``Δu``) gets a guess on the right side, where
    ``y + Δy`` would double the distance. Without a usable ``Δu``: ``y + Δy``.
    """
    dy, du_prev = jump
    if du is None or du_prev is None or du.shape != du_prev.shape:
        return y + dy
    a, b = du.tolist(), du_prev.tolist()
    nb = sum(x * x for x in b)
    if not nb > 0.0:
        return y + dy
    return y + (sum(x * z for x, z in zip(a, b)) / nb) * dy


def _output_path(controllers, held):
    """``path(s, z)`` moving every controller's target from its held output (``s = 0``) to
    its new one (``s = 1``); None if no output changed (e.g. the jump is an event)."""
    moves = []
    for c, u0 in zip(controllers, held):
        if u0 is not None:
            u1 = _held(c)
            if not np.array_equal(u0, u1):
                moves.append((c.target, u0, u1))
    if not moves:
        return None

    def path(s, z):
        s = min(max(float(s), 0.0), 1.0)
        for tg, u0, u1 in moves:
            tg.apply(u1 if s == 1.0 else u0 + s * (u1 - u0))
        return z

    return path


def simulate(system, t_end, dt=1 / 120, events=(), controllers=(), on_failure="raise", **kw) -> Results:
    """Convenience wrapper: set up ``system`` if needed and simulate it from 0 to ``t_end``.

    See :class:`Simulator` for the keyword arguments.
    """
    sim = Simulator(system, dt=dt, **kw)
    return sim.run(t_end, events=events, controllers=controllers, on_failure=on_failure)
