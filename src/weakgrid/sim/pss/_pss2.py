"""Common structure of the IEEE 421.5 dual-input stabilizers PSS2A / PSS2B (PSS/E models).

Block diagram (IEEE Std 421.5-2005 §8.2, PSS/E Model Library PSS2A/PSS2B; pu, times in s)::

    VSI1 -[clip VSI1 (2B)]-[sTW1/(1+sTW1)]-[sTW2/(1+sTW2)]-[1/(1+sT6)]-----------+ yt1
                                                                                  |
    VSI2 -[clip VSI2 (2B)]-[sTW3/(1+sTW3)]-[sTW4/(1+sTW4)]-[KS2/(1+sT7)]--+ yt2    |
                                                                           |       v
                              +-----------------------[KS3]----------------+--> (+) -> RTF --(+)--+
                              |                                            |                 (-)  |
                              +--------------------------------------------+------------------+   |
                                                                                                  v
      RTF = [(1+sT8)/(1+sT9)^M]^N        vs = clip(VSTMIN, VSTMAX)(KS1 * (RTF(yt1+KS3 yt2) - yt2)
                                               * (1+sT1)/(1+sT2) * (1+sT3)/(1+sT4) [* (1+sT10)/(1+sT11) (2B)])

Inputs by code (PSS/E ICONs ``ICS1``/``ICS2``): 1 rotor speed deviation ``omega - 1`` [pu];
3 electrical power of the machine on its own base ``Pe*Sb/Sn`` [pu, MBASE]; 5 terminal
voltage [pu]. Codes 2 (bus frequency deviation), 4 (accelerating power: the governor's
mechanical power is published after the stabilizers are evaluated, so weakgrid cannot give
it to them) and 6 (derivative of the bus voltage) are refused naming the ICON. The remote bus
ICONs (``REMBUS1``/``REMBUS2``) matter only to the bus quantities (codes 2, 5, 6): a remote bus
other than 0 or the machine's own bus is refused for code 5; PSS/E ignores them for codes 1
and 3, and so does weakgrid.

Zero-parameter conventions (IEEE 421.5 / PSS/E): ``TW2 = 0`` / ``TW4 = 0`` bypass the second
washouts; ``T6 = 0`` makes ``1/(1+sT6)`` a unit gain and ``T7 = 0`` makes ``KS2/(1+sT7)`` the
gain ``KS2``; ``M = N = 0`` (or ``N = 0``) bypasses the ramp-tracking filter; a lead-lag with
zero lag time constant is a unit gain. ``TW1`` and ``TW3`` must be > 0. The ramp-tracking
filter has at most 8 states (``M*N <= 8``, PSS/E's limit); ``M = 0`` with ``N > 0`` and
``T8 > 0`` (an improper filter) and ``T9 = 0`` with ``T8 > 0`` are refused.

Every washout blocks a constant input, so in steady state all states downstream of the first
washouts are 0 and ``vs = 0``; the first washouts start at the initial input.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Block, Lag, LeadLag, Washout, WashoutBypass, hard_limit
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import put, take
from ..params import Param

#: PSS/E input signal codes of the dual-input stabilizers.
INPUT_CODES = {1: "rotor speed deviation", 2: "bus frequency deviation",
               3: "generator electrical power on MBASE", 4: "generator accelerating power",
               5: "bus voltage", 6: "derivative of bus voltage", 7: "compensated frequency (PSS2C)"}
SUPPORTED_CODES = (1, 3, 5)
_CODE_FIX = ("weakgrid provides input codes 1 (rotor speed deviation), 3 (electrical power on "
             "MBASE) and 5 (bus voltage); 2 (bus frequency), 4 (accelerating power), 6 (dV/dt) and 7 "
             "(compensated frequency) are not available to stabilizers")
N_RTF = 8   # states of the ramp-tracking filter (M*N <= 8)


def check_codes(element, values, bus=None):
    """Refuse input codes and ramp-tracking filter orders weakgrid cannot represent.

    ``values`` holds ``ICS1``, ``ICS2``, ``M``, ``N``, ``T8``, ``T9`` (and, from a PSS/E record,
    ``_REMBUS1``/``_REMBUS2`` with ``bus`` the machine's PSS/E bus number)."""
    for k in (1, 2):
        fld = f"ICS{k}"
        code = values[fld]
        if code not in SUPPORTED_CODES:
            what = INPUT_CODES.get(int(code), "unknown code") if float(code).is_integer() else "unknown code"
            raise DataError(element, fld, code, f"input signal #{k} code {code:g} ({what}): {_CODE_FIX}")
        rb = values.get(f"_REMBUS{k}", 0)
        if code == 5 and rb not in (0, bus):
            raise DataError(element, f"REMBUS{k}", rb,
                            f"input signal #{k} is the voltage of a remote bus; weakgrid measures the "
                            "machine's terminal voltage only: give 0 (local)")
    M, N = values["M"], values["N"]
    for fld, v in (("M", M), ("N", N)):
        if not (float(v).is_integer() and v >= 0):
            raise DataError(element, fld, v, "the ramp-tracking filter orders M and N are integers >= 0")
    if M * N > N_RTF:
        raise DataError(element, "M", M, f"M*N = {M * N:g} > {N_RTF}: PSS/E's ramp-tracking filter has at "
                        f"most {N_RTF} states; reduce M or N")
    if N > 0 and values["T8"] > 0 and (M == 0 or values["T9"] <= 0):
        fld, v = ("M", M) if M == 0 else ("T9", values["T9"])
        raise DataError(element, fld, v, "the ramp-tracking filter [(1+sT8)/(1+sT9)^M]^N would be "
                        "improper (a lead without a lag): give M >= 1 and T9 > 0, or T8 = 0, or N = 0")


class RampTrackingFilter(Block):
    r"""Ramp-tracking filter :math:`[(1+sT_8)/(1+sT_9)^M]^N` as a chain of first-order stages.

    Section ``j`` (``N`` sections) is the lead-lag :math:`(1+sT_8)/(1+sT_9)` followed by ``M-1``
    lags :math:`1/(1+sT_9)`; stage ``k`` has state :math:`x_k`, :math:`T_9\dot x_k = u_k - x_k`
    and output :math:`x_k + c_k(u_k - x_k)` with :math:`c_k = T_8/T_9` for the first stage of a
    section and 0 for the others. Stages ``k >= M*N`` (and all stages when ``T9 = 0``, then
    ``T8 = 0``) pass their input. ``M``, ``N`` may differ between instances.
    """

    nx = N_RTF

    def __init__(self, T8, T9, M, N):
        T8, T9 = np.asarray(T8, float), np.asarray(T9, float)
        M, N = np.asarray(M, int), np.asarray(N, int)
        k = np.arange(N_RTF)[:, None]
        active = k < M * N
        self.on = active & (T9 > 0)
        T9s = np.where(T9 > 0, T9, 1.0)
        first = (k % np.maximum(M, 1)) == 0
        self.c = np.where(first & self.on, T8 / T9s, 0.0)
        self.T9 = T9s
        self.nst = int(np.max(M * N * (T9 > 0), initial=0))   # stages in use by some instance

    def step(self, k, x, u):
        """Output and derivative of stage ``k`` (state ``x``, input ``u``)."""
        xp = self.xp
        on = self.on[k, ...]
        y = xp.where(on, x + self.c[k, ...] * (u - x), u)
        return y, xp.where(on, (u - x) / self.T9, 0.0)


#: parameters shared by PSS2A and PSS2B (PSS/E names), in PSS/E's CON order after the ICONs
BASE_PARAMS = (
    Param("ICS1", 1.0, "-", "input signal #1 code (1 speed, 3 Pe, 5 voltage)", "pos"),
    Param("ICS2", 3.0, "-", "input signal #2 code (1 speed, 3 Pe, 5 voltage)", "pos"),
    Param("M", 5.0, "-", "ramp-tracking filter: order of the lag (1+sT9)^M", "nonneg"),
    Param("N", 1.0, "-", "ramp-tracking filter: number of sections", "nonneg"),
    Param("TW1", 2.0, "s", "first washout of input 1", "pos"),
    Param("TW2", 2.0, "s", "second washout of input 1 (0: bypassed)", "nonneg"),
    Param("T6", 0.0, "s", "transducer time constant of input 1 (0: bypassed)", "nonneg"),
    Param("TW3", 2.0, "s", "first washout of input 2", "pos"),
    Param("TW4", 0.0, "s", "second washout of input 2 (0: bypassed)", "nonneg"),
    Param("T7", 2.0, "s", "integrator-approximation time constant of input 2 (0: gain KS2)", "nonneg"),
    Param("KS2", 0.25, "pu", "gain of input 2 (typically T7/2H)", ""),
    Param("KS3", 1.0, "pu", "gain of input 2 into the ramp-tracking filter", ""),
    Param("T8", 0.5, "s", "ramp-tracking filter lead", "nonneg"),
    Param("T9", 0.1, "s", "ramp-tracking filter lag", "nonneg"),
    Param("KS1", 10.0, "pu", "stabilizer gain", ""),
    Param("T1", 0.15, "s", "first lead", "nonneg"),
    Param("T2", 0.03, "s", "first lag", "nonneg"),
    Param("T3", 0.15, "s", "second lead", "nonneg"),
    Param("T4", 0.03, "s", "second lag", "nonneg"),
)
OUT_PARAMS = (
    Param("VSTMAX", 0.1, "pu", "output upper limit", ""),
    Param("VSTMIN", -0.1, "pu", "output lower limit", ""),
)
PSSE_ICONS = ("ICS1", "_REMBUS1", "ICS2", "_REMBUS2", "M", "N")


class DualInputPSS(MachineControl):
    """Base of PSS2A / PSS2B (see the module docstring). Subclasses set ``params``,
    ``states`` (``LEAD_LAGS`` names the lead-lag pairs) and ``psse_record``."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "pss"
    order = 1
    #: (lead, lag) parameter pairs of the phase-compensation lead-lags, in series
    LEAD_LAGS = (("T1", "T2"), ("T3", "T4"))
    _HEAD = ("W1", "W2", "L6", "W3", "W4", "L7") + tuple(f"RTF{k + 1}" for k in range(N_RTF))
    outputs = ("sig", "sig2", "vss", "vs")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E record -> parameters: the remote-bus ICONs are checked (see the module
        docstring) and dropped; unsupported input codes are refused naming their ICON."""
        v = dict(values)
        check_codes(ctx.where, v, bus=ctx.bus)
        v.pop("_REMBUS1", None)
        v.pop("_REMBUS2", None)
        return v

    def setup(self, system):
        super().setup(system)
        p = self.p
        for i in range(self.n):
            check_codes(self.element(i), {k: p[k][i] for k in ("ICS1", "ICS2", "M", "N", "T8", "T9")})
        self.W1 = Washout(p["TW1"], p["TW1"])
        self.W2 = WashoutBypass(p["TW2"])
        self.L6 = Lag(1.0, p["T6"])
        self.W3 = Washout(p["TW3"], p["TW3"])
        self.W4 = WashoutBypass(p["TW4"])
        self.L7 = Lag(p["KS2"], p["T7"])
        self.RTF = RampTrackingFilter(p["T8"], p["T9"], p["M"], p["N"])
        self.LL = [LeadLag(p[a], p[b]) for a, b in self.LEAD_LAGS]
        self._pe_scale = system.Sb / self.Sn
        self._k0 = len(self._HEAD)   # first lead-lag state

    # ---------------------------------------------------------------- signals
    def _signal(self, code, omega, Pe, Vt):
        xp = self.xp     # numpy.select's choice in its order, 0 for none
        return xp.where(code == 1, omega - 1.0,
                        xp.where(code == 3, Pe * self._pe_scale, xp.where(code == 5, Vt, 0.0)))

    def _limit_inputs(self, u1, u2):
        """Input limits (none in PSS2A)."""
        return u1, u2

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        one = np.ones(self.n)
        u1, u2 = self._limit_inputs(self._signal(p["ICS1"], one, sig["Pe0"][m], sig["Vt0"][m]),
                                    self._signal(p["ICS2"], one, sig["Pe0"][m], sig["Vt0"][m]))
        for k in range(len(self.states)):
            x[self.sl(k)] = 0.0
        x[self.sl(0)] = u1    # first washouts at the initial inputs; everything after them is 0
        x[self.sl(3)] = u2

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        s = ctx.sig
        f = ctx.f
        sl = self._sls
        X = [ctx.x[..., k] for k in sl]
        omega, Pe, Vt = take(xp, s["omega"], m), take(xp, s["Pe"], m), take(xp, s["Vt"], m)
        r1 = self._signal(p["ICS1"], omega, Pe, Vt)
        r2 = self._signal(p["ICS2"], omega, Pe, Vt)
        u1, u2 = self._limit_inputs(r1, r2)
        # input 1: two washouts and the transducer lag
        y = self.W1.output(X[0], u1)
        f[..., sl[0]] = self.W1.deriv(X[0], u1)
        y1 = self.W2.output(X[1], y)
        f[..., sl[1]] = self.W2.deriv(X[1], y)
        yt1 = self.L6.output(X[2], y1)
        f[..., sl[2]] = self.L6.deriv(X[2], y1)
        # input 2: two washouts and KS2/(1+sT7)
        y = self.W3.output(X[3], u2)
        f[..., sl[3]] = self.W3.deriv(X[3], u2)
        y2 = self.W4.output(X[4], y)
        f[..., sl[4]] = self.W4.deriv(X[4], y)
        yt2 = self.L7.output(X[5], y2)
        f[..., sl[5]] = self.L7.deriv(X[5], y2)
        # ramp-tracking filter on yt1 + KS3*yt2, then the second input subtracted
        y = yt1 + p["KS3"] * yt2
        for k in range(self.RTF.nst):
            y, f[..., sl[6 + k]] = self.RTF.step(k, X[6 + k], y)
        y = p["KS1"] * (y - yt2)
        # phase compensation
        for j, LL in enumerate(self.LL):
            k = self._k0 + j
            f[..., sl[k]] = LL.deriv(X[k], y)
            y = LL.output(X[k], y)
        vs = hard_limit(y, p["VSTMIN"], p["VSTMAX"], xp)
        put(xp, s["vs"], m, vs)
        name = self.type_name
        o = ctx.out
        o[f"{name}.sig"], o[f"{name}.sig2"], o[f"{name}.vss"], o[f"{name}.vs"] = r1, r2, y, vs
