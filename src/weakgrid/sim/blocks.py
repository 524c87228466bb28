"""Reusable, vectorized control blocks.

Each block acts on arrays (one entry per device instance) and is described by
three pure functions of its state ``x`` and input ``u``:

* ``init(u0)`` -> initial state for a steady input ``u0``,
* ``output(x, u)`` -> block output ``y``,
* ``deriv(x, u)`` -> ``dx/dt``.

Time constants equal to zero bypass the dynamics (the block becomes a static
gain), as in PSS/E and ANDES. Blocks with *non-windup* limits (PSS/E
convention: the state itself is held at its limit while the input pushes it
outward) expose ``lower``/``upper`` arrays; the integrator enforces them on
the state (see :mod:`weakgrid.sim.integrate`).

All times are in seconds; signals are in per unit.
"""

from __future__ import annotations

import numpy as np

from .namespace import NUMPY


class Block:
    """Base of the blocks: their arrays' namespace (:mod:`weakgrid.sim.namespace`; NumPy unless
    the grid is evaluated on another, then in every block whose evaluation says so)."""

    xp = NUMPY


def _safe(T):
    T = np.asarray(T, dtype=float)
    return np.where(T > 0, T, 1.0)


class Lag(Block):
    r"""First-order lag :math:`K/(1+sT)`.

    Parameters
    ----------
    K : array_like
        Gain [pu/pu].
    T : array_like
        Time constant [s]; ``T = 0`` makes the block a pure gain.
    """

    nx = 1

    def __init__(self, K, T):
        self.K = np.asarray(K, dtype=float)
        self.T = np.asarray(T, dtype=float)
        self._on = self.T > 0
        self._Ts = _safe(self.T)
        self._all = bool(np.all(self._on))

    def init(self, u0):
        return self.K * u0

    def output(self, x, u):
        if self._all:
            return x
        return self.xp.where(self._on, x, self.K * u)

    def deriv(self, x, u):
        if self._all:
            return (self.K * u - x) / self._Ts
        return self.xp.where(self._on, (self.K * u - x) / self._Ts, 0.0)


class LagNonWindup(Lag):
    r"""First-order lag :math:`K/(1+sT)` whose state is held in ``[lower, upper]`` (non-windup).

    Parameters
    ----------
    K, T : array_like
        Gain [pu/pu] and time constant [s]; ``T = 0`` makes the block the limited gain
        ``clip(K*u, lower, upper)`` (its state is then unused), as in ANDES.
    lower, upper : array_like
        State (= output) limits [pu].
    """

    def __init__(self, K, T, lower, upper):
        super().__init__(K, T)
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)

    def output(self, x, u):
        if self._all:
            return x
        return self.xp.where(self._on, x, self.xp.clip(self.K * u, self.lower, self.upper))


class LeadLag(Block):
    r"""Lead-lag :math:`K(1+sT_1)/(1+sT_2)`.

    State ``x`` obeys :math:`T_2\dot x = u - x` and the output is
    :math:`y = K[(T_1/T_2)(u - x) + x]`. With ``T2 = 0`` the block is the gain ``K``.

    Parameters
    ----------
    T1, T2 : array_like
        Lead and lag time constants [s].
    K : array_like, optional
        Gain, default 1.
    """

    nx = 1

    def __init__(self, T1, T2, K=1.0):
        self.T1 = np.asarray(T1, dtype=float)
        self.T2 = np.asarray(T2, dtype=float)
        self.K = np.broadcast_to(np.asarray(K, dtype=float), self.T2.shape)
        self._on = self.T2 > 0
        self._T2s = _safe(self.T2)
        self._all = bool(np.all(self._on))
        self._r = self.T1 / self._T2s
        self._unit = bool(np.all(self.K == 1.0))

    def init(self, u0):
        return np.asarray(u0, dtype=float) * 1.0

    def output(self, x, u):
        if self._all:
            y = self._r * (u - x) + x
            return y if self._unit else self.K * y
        return self.K * self.xp.where(self._on, self._r * (u - x) + x, u)

    def deriv(self, x, u):
        if self._all:
            return (u - x) / self._T2s
        return self.xp.where(self._on, (u - x) / self._T2s, 0.0)

    def output_deriv(self, x, u):
        """``(output(x, u), deriv(x, u))``, the same values with ``u - x`` formed once."""
        if self._all:
            e = u - x
            y = self._r * e + x
            return (y if self._unit else self.K * y), e / self._T2s
        return self.output(x, u), self.deriv(x, u)


class Washout(Block):
    r"""Washout (high-pass) :math:`sK/(1+sT)`.

    State ``x`` obeys :math:`T\dot x = u - x`, output :math:`y = (K/T)(u - x)`.
    The classical washout :math:`sT/(1+sT)` is obtained with ``K = T``
    (ANDES/PSS/E naming). ``T = 0`` gives a zero output.

    Parameters
    ----------
    K : array_like
        Gain [pu·s].
    T : array_like
        Time constant [s].
    """

    nx = 1

    def __init__(self, K, T):
        self.K = np.asarray(K, dtype=float)
        self.T = np.asarray(T, dtype=float)
        self._on = self.T > 0
        self._Ts = _safe(self.T)
        self._all = bool(np.all(self._on))
        self._g = self.K / self._Ts

    def init(self, u0):
        return np.asarray(u0, dtype=float) * 1.0

    def output(self, x, u):
        if self._all:
            return self._g * (u - x)
        return self.xp.where(self._on, self._g * (u - x), 0.0)

    def deriv(self, x, u):
        if self._all:
            return (u - x) / self._Ts
        return self.xp.where(self._on, (u - x) / self._Ts, 0.0)

    def output_deriv(self, x, u):
        """``(output(x, u), deriv(x, u))``, the same values with ``u - x`` formed once."""
        if self._all:
            e = u - x
            return self._g * e, e / self._Ts
        return self.output(x, u), self.deriv(x, u)


class WashoutBypass(Washout):
    r"""Washout :math:`sT/(1+sT)` that is bypassed (output = input) when ``T = 0``.

    The convention of the second washouts ``TW2``/``TW4`` of the IEEE 421.5 / PSS/E dual-input
    stabilizers (PSS2A, PSS2B): a zero time constant removes the block. State ``x`` obeys
    :math:`T\dot x = u - x` (derivative 0 when bypassed), output :math:`y = u - x`.

    Parameters
    ----------
    T : array_like
        Time constant [s] (>= 0; 0 bypasses the block).
    """

    def __init__(self, T):
        super().__init__(T, T)

    def output(self, x, u):
        if self._all:
            return u - x
        return self.xp.where(self._on, u - x, u)

    def output_deriv(self, x, u):
        """``(output(x, u), deriv(x, u))``, the same values with ``u - x`` formed once."""
        if self._all:
            e = u - x
            return e, e / self._Ts
        return self.output(x, u), self.deriv(x, u)


class Integrator(Block):
    r"""Integrator :math:`K/s`, output = state.

    Parameters
    ----------
    K : array_like
        Gain [1/s].
    """

    nx = 1

    def __init__(self, K):
        self.K = np.asarray(K, dtype=float)

    def output(self, x, u=None):
        return x

    def deriv(self, x, u):
        return self.K * u


class PINonWindup(Block):
    r"""PI controller :math:`K_p + K_i/s` with non-windup output limits.

    The integrator state is held in ``[lower, upper]`` by the integrator
    (non-windup) and the output :math:`y = K_p u + x` is clipped to the same range.

    Parameters
    ----------
    Kp : array_like
        Proportional gain [pu/pu].
    Ki : array_like
        Integral gain [1/s].
    lower, upper : array_like
        Output limits [pu].
    """

    nx = 1

    def __init__(self, Kp, Ki, lower, upper):
        self.Kp = np.asarray(Kp, dtype=float)
        self.Ki = np.asarray(Ki, dtype=float)
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)

    def init(self, y0, u0=0.0):
        return np.asarray(y0, dtype=float) - self.Kp * u0

    def output(self, x, u):
        return self.xp.clip(self.Kp * u + x, self.lower, self.upper)

    def deriv(self, x, u):
        return self.Ki * u


class PID(Block):
    r"""PID controller :math:`K_p + K_i/s + K_d s/(1+sT_d)` (no limits).

    States: integrator ``xi`` and derivative-filter state ``xd``
    (:math:`T_d\dot x_d = u - x_d`, derivative output :math:`K_d(u-x_d)/T_d`).

    Parameters
    ----------
    kp, ki, kd : array_like
        Gains [pu/pu], [1/s], [s].
    Td : array_like
        Derivative filter time constant [s] (> 0).
    """

    nx = 2

    def __init__(self, kp, ki, kd, Td):
        self.kp = np.asarray(kp, dtype=float)
        self.ki = np.asarray(ki, dtype=float)
        self.kd = np.asarray(kd, dtype=float)
        self.Td = _safe(Td)

    def output(self, xi, xd, u):
        return self.kp * u + xi + self.kd * (u - xd) / self.Td

    def deriv(self, xi, xd, u):
        return self.ki * u, (u - xd) / self.Td


def quad_saturation_coeffs(E1, SE1, E2, SE2):
    r"""Coefficients ``(A, B)`` of the quadratic saturation :math:`S(x) = B(x-A)^2/x` for ``x > A``.

    The curve passes through ``(E1, SE1)`` and ``(E2, SE2)``. Following the
    ANDES ``ExcQuadSat`` convention, saturation is disabled (``B = 0``) when
    ``SE1 = 0`` or ``E1 = 0`` (and ``SE2 = 0`` is corrected to keep the
    expressions finite).

    Parameters
    ----------
    E1, SE1, E2, SE2 : array_like
        Saturation points [pu] and values [pu/pu].

    Returns
    -------
    A, B : ndarray
    """
    E1, SE1, E2, SE2 = (np.asarray(v, dtype=float) for v in (E1, SE1, E2, SE2))
    z2 = (SE2 != 0).astype(float)
    E2c = E2 + 2 * (1 - z2)
    SE2c = SE2 + 2 * (1 - z2)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (SE2c != 0) * np.sqrt(np.abs(SE1 * E1 / (SE2c * E2c)))
        A = E2c - (E1 - E2c) / (a - 1)
        B = np.where(a != 0, SE2c * E2c * (a - 1) ** 2 / (E1 - E2c) ** 2, 0.0)
    A = np.where(np.isfinite(A), A, 0.0)
    B = np.where(np.isfinite(B), B, 0.0)
    return A, B


def quad_saturation(x, A, B, xp=np):
    r"""Quadratic saturation product :math:`x\,S(x) = B(x-A)^2` for ``x >= A`` else 0 (``xp``:
    the arrays' namespace)."""
    return xp.where(x >= A, B * (x - A) ** 2, 0.0)


def exp_saturation_coeffs(E1, SE1, E2, SE2):
    r"""Coefficients ``(A, B)`` of the exponential saturation :math:`S(x) = B\,x^A` (PSS/E GENROE, GENSAE).

    The curve passes through ``(E1, SE1)`` and ``(E2, SE2)``:
    :math:`A = \ln(SE2/SE1)/\ln(E2/E1)`, :math:`B = SE1/E1^A` (PSS/E: ``E1 = 1.0``,
    ``E2 = 1.2``, so ``B = S(1.0)`` and ``A = ln(S(1.2)/S(1.0)) / ln 1.2``).
    ``SE1 = 0`` disables saturation (``A = B = 0``, i.e. :math:`S \equiv 0`). The models
    refuse ``SE2 < SE1`` (a curve falling with flux) before calling this; ``SE2 = 0`` with
    ``SE1 > 0`` has no exponential through both points and gives ``A = B = 0`` here.

    Parameters
    ----------
    E1, SE1, E2, SE2 : array_like
        Saturation points [pu] (``0 < E1 != E2``) and values [pu/pu].

    Returns
    -------
    A, B : ndarray
        Exponent [-] and factor [pu/pu].
    """
    E1, SE1, E2, SE2 = (np.asarray(v, dtype=float) for v in (E1, SE1, E2, SE2))
    on = (SE1 > 0) & (SE2 > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        A = np.where(on, np.log(np.where(on, SE2 / SE1, 1.0)) / np.log(E2 / E1), 0.0)
        B = np.where(on, SE1 / E1 ** A, 0.0)
    return A, B


def exp_saturation(x, A, B):
    r"""Exponential saturation factor :math:`S(x) = B\,x^A` for ``x > 0`` else 0 (arrays of
    any namespace: the name ``np`` is rebound where a kernel runs it on another, and ``x``
    is kept off 0 where it is not used)."""
    x = np.asarray(x, dtype=np.float64)
    return np.where(x > 0, B * np.abs(np.where(x > 0, x, 1.0)) ** A, 0.0)


class LagRate(Block):
    r"""First-order lag :math:`K/(1+sT)` with a rate limit, ANDES 2.0 convention.

    :math:`T\dot x = \mathrm{clip}(Ku - x,\ r_{lo},\ r_{hi})`: the limits bound
    :math:`T\dot x` (ANDES ``RateLimiter`` clips the equation value of a state
    whose time constant is ``T``), i.e. :math:`\dot x` is bounded by ``r/T``.
    A limit with ``enable = False`` is inactive.

    Parameters
    ----------
    K, T : array_like
        Gain and time constant [s] (> 0).
    r_lo, r_hi : array_like
        Rate limits [pu] on ``T dx/dt``.
    """

    nx = 1

    def __init__(self, K, T, r_lo=-np.inf, r_hi=np.inf):
        self.K = np.asarray(K, dtype=float)
        self.T = _safe(T)
        self.r_lo = np.asarray(r_lo, dtype=float)
        self.r_hi = np.asarray(r_hi, dtype=float)

    def init(self, u0):
        return self.K * np.asarray(u0, dtype=float)

    def deriv(self, x, u):
        return self.xp.clip(self.K * u - x, self.r_lo, self.r_hi) / self.T


def piecewise_linear(u, points, values, xp=NUMPY):
    """Continuous piecewise-linear characteristic through ``(points[k], values[k])``, flat outside.

    ``points`` and ``values`` are sequences of arrays (one entry per device); points must
    be non-decreasing. ``xp``: the arrays' namespace.
    """
    u = xp.asarray(u, dtype=xp.float64)
    y = xp.asarray(xp.broadcast_to(xp.asarray(values[0], dtype=xp.float64), u.shape), copy=True)
    for k in range(1, len(points)):
        x0, x1 = points[k - 1], points[k]
        y0, y1 = values[k - 1], values[k]
        dx = x1 - x0      # a vertical step (dx = 0) is never on a segment: divided by 1 there
        seg = y0 + (u - x0) * (y1 - y0) / xp.where(dx == 0, 1.0, dx)
        y = xp.where(u > x0, xp.where(u <= x1, seg, y1), y)
    return y


class WashoutOrLag(Washout):
    r"""Washout :math:`sK/(1+sT)` that becomes the lag :math:`1/(1+sT)` when ``K <= 0``.

    The PSS/E/ANDES convention for a washout whose numerator time constant is
    zero (e.g. ``T3 = 0`` of ST2CUT): the block does not switch the signal off,
    it degenerates into a low-pass filter. State ``x`` obeys :math:`T\dot x = u - x`.

    Parameters
    ----------
    K : array_like
        Numerator gain [pu·s] (``K = T_num`` for the classical washout).
    T : array_like
        Time constant [s] (> 0).
    """

    def __init__(self, K, T):
        super().__init__(K, T)
        self._lag = self.K <= 0
        self._all = self._all and not bool(np.any(self._lag))

    def output(self, x, u):
        if self._all:
            return self._g * (u - x)
        xp = self.xp
        return xp.where(self._lag, x, xp.where(self._on, self._g * (u - x), 0.0))


class IntegratorNonWindup(Integrator):
    r"""Integrator :math:`K/s` whose state is held in ``[lower, upper]`` (non-windup).

    Parameters
    ----------
    K : array_like
        Gain [1/s].
    lower, upper : array_like
        State (= output) limits.
    """

    def __init__(self, K, lower, upper):
        super().__init__(K)
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)


def hard_limit(u, lower, upper, xp=NUMPY):
    """Static (windup) limiter: ``u`` clipped to ``[lower, upper]`` (no state involved;
    ``xp``: the arrays' namespace)."""
    return xp.minimum(xp.maximum(u, lower), upper)


def rectifier_fex(IN, xp=NUMPY):
    r"""Rectifier regulation factor :math:`F_{EX}(I_N)` of IEEE 421.5 AC/ST exciters.

    :math:`F_{EX} = 1` for :math:`I_N \le 0`; :math:`1 - 0.577 I_N` up to 0.433;
    :math:`\sqrt{0.75 - I_N^2}` up to 0.75; :math:`1.732(1 - I_N)` up to 1; 0 beyond.
    ``IN = KC * XadIfd / VE`` is the normalized field current (load of the rectifier);
    ``xp``: the arrays' namespace.
    """
    IN = xp.asarray(IN, dtype=xp.float64)
    return xp.where(IN <= 0, 1.0, xp.where(IN <= 0.433, 1 - 0.577 * IN, xp.where(
        IN <= 0.75, xp.sqrt(xp.abs(0.75 - IN * IN)), xp.where(IN <= 1.0, 1.732 * (1 - IN), 0.0))))


class PITrackAW(Block):
    r"""PI controller :math:`K_p + K_i/s` with a tracking anti-windup (back-calculation).

    The unlimited output :math:`y_s = K_p u + x` is clipped to ``[lower, upper]``; the
    integrator is driven back by the part of the output the limiter cut:
    :math:`\dot x = K_i\,(u - K_s (y_s - y))` (WECC REEC/REPC convention; ANDES ``PITrackAW``).
    Limits may be arrays that move with the solution (given at each call).

    Parameters
    ----------
    Kp, Ki : array_like
        Proportional gain [pu/pu] and integral gain [1/s].
    Ks : float or array_like
        Tracking gain [pu/pu] (2 in ANDES's default configuration).
    """

    nx = 1

    def __init__(self, Kp, Ki, Ks=2.0):
        self.Kp = np.asarray(Kp, dtype=float)
        self.Ki = np.asarray(Ki, dtype=float)
        self.Ks = np.asarray(Ks, dtype=float)

    def unlimited(self, x, u):
        return self.Kp * u + x

    def output(self, x, u, lower, upper):
        return self.xp.clip(self.Kp * u + x, lower, upper)

    def deriv(self, x, u, lower, upper):
        ys = self.Kp * u + x
        return self.Ki * (u - self.Ks * (ys - self.xp.clip(ys, lower, upper)))


def deadband(u, lower, upper, xp=NUMPY):
    """Dead band without offset: 0 inside ``[lower, upper]``, ``u - upper`` above, ``u - lower``
    below (``xp``: the arrays' namespace)."""
    return xp.where(u > upper, u - upper, xp.where(u < lower, u - lower, 0.0))


class LeadLag2(Block):
    r"""Second-order lead-lag :math:`(1 + sA)/(1 + sB + s^2 C)` (unit gain).

    Realized in controllable canonical form, states ``x1`` (the lagged input) and
    ``x2 = dx1/dt``::

        C > 0:          dx1/dt = x2,  C dx2/dt = u - x1 - B x2,  y = x1 + A x2
        C = 0, B > 0:   B dx1/dt = u - x1 (x2 unused),  y = (A/B)(u - x1) + x1
        C = 0, B = 0:   y = u (states unused)

    The steady state for a constant input ``u0`` is ``x1 = u0``, ``x2 = 0``. A lead ``A > 0``
    without a lag (``B = C = 0``) is improper; models refuse it (:meth:`improper`).

    Parameters
    ----------
    A : array_like
        Lead time constant [s].
    B : array_like
        First-order denominator coefficient [s] (e.g. ``T1`` or ``T5 + T6``).
    C : array_like
        Second-order denominator coefficient [s^2] (e.g. ``T1*T2`` or ``T5*T6``).
    """

    nx = 2

    def __init__(self, A, B, C):
        self.A = np.asarray(A, dtype=float)
        self.B = np.asarray(B, dtype=float)
        self.C = np.asarray(C, dtype=float)
        self._two = self.C > 0
        self._one = ~self._two & (self.B > 0)
        self._Cs = np.where(self._two, self.C, 1.0)
        self._Bs = np.where(self._one, self.B, 1.0)
        self._r = self.A / self._Bs

    def improper(self):
        """Boolean array: a lead without any lag (``A != 0`` with ``B = C = 0``)."""
        return (self.A != 0) & ~self._two & ~self._one

    def init(self, u0):
        u0 = np.asarray(u0, dtype=float)
        return u0 * 1.0, np.zeros_like(u0)

    def output(self, x1, x2, u):
        xp = self.xp
        return xp.where(self._two, x1 + self.A * x2,
                        xp.where(self._one, self._r * (u - x1) + x1, u))

    def deriv(self, x1, x2, u):
        xp = self.xp
        d1 = xp.where(self._two, x2, xp.where(self._one, (u - x1) / self._Bs, 0.0))
        d2 = xp.where(self._two, (u - x1 - self.B * x2) / self._Cs, 0.0)
        return d1, d2


class TransportDelay(Block):
    r"""Pure transport delay :math:`e^{-sT_D}` from a stored history of the delayed signal.

    The phasor simulator integrates with a fixed-step implicit method; a delay is represented
    exactly (no Padé approximation) by the history of its input at the accepted points:
    ``record(t, u)`` is called at every accepted point, and ``output(t, u)`` returns
    ``u(t - TD)`` interpolated linearly between the stored points (second order, as the
    trapezoidal rule). Before the first stored time the input is its initial (steady) value.
    When ``t - TD`` falls after the last stored point (a delay shorter than the step) the value
    is interpolated between that point and the current input ``u`` (so it depends on the
    current state, and the Jacobian sees it). ``TD = 0`` passes the input through.

    Parameters
    ----------
    TD : array_like
        Delay [s] (>= 0), one per device.
    """

    def __init__(self, TD):
        self.TD = np.asarray(TD, dtype=float)
        self._on = self.TD > 0
        self.any = bool(np.any(self._on))
        self._t = np.zeros(0)
        self._v = np.zeros((0, self.TD.size))
        self._k = 0

    def reset(self, t0, u0):
        """Start the history at time ``t0`` with the steady input ``u0`` (also valid before ``t0``)."""
        cap = 1024
        self._t = np.zeros(cap)
        self._v = np.zeros((cap, self.TD.size))
        self._t[0] = t0
        self._v[0] = u0
        self._k = 1

    def record(self, t, u):
        """Store the input ``u`` at an accepted time ``t`` (a repeated time overwrites; an earlier
        time, a new run from the start, drops the history after it)."""
        if not self.any:
            return
        k = self._k
        if k and t < self._t[k - 1] - 1e-12:
            k = int(np.searchsorted(self._t[:k], t - 1e-12))
            if k == 0:
                self.reset(t, u)
                return
        if k and abs(t - self._t[k - 1]) <= 1e-12:
            self._v[k - 1] = u
            self._k = k
            return
        if k == len(self._t):
            # drop what no delay reaches back to, else grow
            keep = int(np.searchsorted(self._t[:k], self._t[k - 1] - self.TD.max() - 1e-9)) - 1
            if keep > k // 2:
                self._t[:k - keep] = self._t[keep:k]
                self._v[:k - keep] = self._v[keep:k]
                k -= keep
            else:
                self._t = np.concatenate([self._t, np.zeros(len(self._t))])
                self._v = np.concatenate([self._v, np.zeros_like(self._v)])
        self._t[k] = t
        self._v[k] = u
        self._k = k + 1

    def output(self, t, u):
        """``u(t - TD)``: the stored history, or the current input ``u`` where ``TD = 0``."""
        if not self.any:
            return u
        k = self._k
        ts, vs = self._t[:k], self._v[:k]
        td = t - self.TD
        j = np.clip(np.searchsorted(ts, td, side="right"), 1, max(k - 1, 1))   # ts[j-1] <= td < ts[j]
        cols = np.arange(self.TD.size)
        if k > 1:
            t0, t1 = ts[j - 1], ts[j]
            w = np.clip((td - t0) / np.where(t1 > t0, t1 - t0, 1.0), 0.0, 1.0)
            hist = vs[j - 1, cols] + w * (vs[j, cols] - vs[j - 1, cols])
        else:
            hist = vs[0]
        hist = np.where(td <= ts[0], vs[0], hist)
        tl, vl = ts[k - 1], vs[k - 1]
        inside = td > tl                                  # delay shorter than the step
        w = np.where(inside, (td - tl) / max(t - tl, 1e-300), 0.0)
        recent = vl + w * (u - vl)
        return np.where(self._on, np.where(inside, recent, hist), u)
