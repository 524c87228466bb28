"""The paper's design model (10)/(16)/(17): a GTI or SG behind a UPQC series branch.

States ``x = [ϕ̂, υ]`` (phase error in rad and its rate in rad/s), controls
``u = [u1, u2] = [Vup, Vuq]`` (UPQC series voltage in quadrature and in phase
with the shunt-bus voltage, pu), disturbance ``w`` (shunt-bus voltage deviation
from V̄r, pu). Forward Euler of (9) with step T gives (10):

    f = [ϕ̂ + T·υ ;  υ + T·a·V̄r·(sin ϕs0 − sin(ϕ̂ + ϕs0))]
    g = [[0, 0] ; [T·a·cos(ϕ̂ + ϕs0), −T·a·sin(ϕ̂ + ϕs0)]]
    h = [0 ; −T·a·sin(ϕ̂ + ϕs0)]

with ``a = τ'·Vs·B/C`` (GTI) or ``a = E'·B/M``, ``M = 2H/ωs`` (SG, Remark 5); the
equilibrium satisfies ``Pm = Vs·V̄r·B·sin ϕs0``, so ``(τ'/C)·Pm = a·V̄r·sin ϕs0``.
The reduced UPQC (Section II-D) gives the same form (16).
"""

from __future__ import annotations

import numpy as np

from ..game.errors import ParameterError
from ..game.system import ControlAffineSystem, register_system

__all__ = ["UPQCDesignModel", "gti_design_model", "sg_design_model"]

STATE_NAMES = ["phi_hat", "upsilon"]


def _positive(owner, **kw):
    for k, v in kw.items():
        if v is None:
            continue
        try:
            fv = float(v)
        except (TypeError, ValueError):
            raise ParameterError(k, v, "must be a number", owner) from None
        if not np.isfinite(fv) or fv <= 0:
            raise ParameterError(k, v, "must be a positive finite number", owner)


class UPQCDesignModel(ControlAffineSystem):
    """Discrete-time design model (10) in the calibrated form ``(T, a, V̄r, ϕs0)``.

    Parameters
    ----------
    T : float
        Sampling period, s.
    a : float
        Input gain ``τ'·Vs·B/C`` (GTI) or ``E'·B·ωs/(2H)`` (SG), rad/s² per pu.
    Vr_bar : float
        Known part of the shunt-bus voltage magnitude, pu.
    phi_s0 : float
        Equilibrium angle of the source w.r.t. the UPQC shunt bus, rad (``|ϕs0| < π/2``).
    machine : {"gti", "sg"}
        What the states describe (GTI phase / dc-link energy, or SG angle / speed).
    upqc : {"conventional", "reduced"}
        UPQC structure (the design model is the same, (16)).
    source : dict, optional
        The physical parameters this model was derived from (recorded in files).
    """

    kind = "upqc-design"
    n_states, n_controls, n_disturbances = 2, 2, 1

    def __init__(self, T, a, Vr_bar, phi_s0, machine="gti", upqc="conventional", source=None):
        _positive("UPQCDesignModel", T=T, a=a, Vr_bar=Vr_bar)
        if not np.isfinite(phi_s0) or abs(phi_s0) >= np.pi / 2:
            raise ParameterError("phi_s0", phi_s0, "the equilibrium angle must lie in "
                                 "(−π/2, π/2) rad (stable branch of the power-angle curve)",
                                 "UPQCDesignModel")
        if T > 0.1:
            raise ParameterError("T", T, "sampling period above 0.1 s: the Euler model (10) "
                                 "is not meaningful; use seconds (e.g. 1e-3)", "UPQCDesignModel")
        if machine not in ("gti", "sg"):
            raise ParameterError("machine", machine, "use 'gti' or 'sg'", "UPQCDesignModel")
        if upqc not in ("conventional", "reduced"):
            raise ParameterError("upqc", upqc, "use 'conventional' or 'reduced'",
                                 "UPQCDesignModel")
        self.T, self.a, self.Vr_bar, self.phi_s0 = float(T), float(a), float(Vr_bar), float(phi_s0)
        self.machine, self.upqc = machine, upqc
        self.source = dict(source or {})
        self.state_names = list(STATE_NAMES)

    # (10)
    def open_loop_dynamics(self, x):
        x = np.asarray(x, float)
        ph, up = x[..., 0], x[..., 1]
        T, a = self.T, self.a
        out = np.empty_like(x)
        out[..., 0] = ph + T * up
        out[..., 1] = up + T * a * self.Vr_bar * (np.sin(self.phi_s0) - np.sin(ph + self.phi_s0))
        return out

    def open_loop_jacobian(self, x):
        x = np.asarray(x, float)
        J = np.zeros(x.shape + (2,))
        J[..., 0, 0] = 1.0
        J[..., 0, 1] = self.T
        J[..., 1, 0] = -self.T * self.a * self.Vr_bar * np.cos(x[..., 0] + self.phi_s0)
        J[..., 1, 1] = 1.0
        return J

    def control_directions(self, x):
        x = np.asarray(x, float)
        ang = x[..., 0] + self.phi_s0
        g = np.zeros(x.shape[:-1] + (2, 2))
        g[..., 1, 0] = self.T * self.a * np.cos(ang)
        g[..., 1, 1] = -self.T * self.a * np.sin(ang)
        return g

    def disturbance_directions(self, x):
        x = np.asarray(x, float)
        h = np.zeros(x.shape[:-1] + (2, 1))
        h[..., 1, 0] = -self.T * self.a * np.sin(x[..., 0] + self.phi_s0)
        return h

    def continuous_rhs(self, x, u=None, w=None):
        """The continuous model (9): ``[dϕ̂/dt, dυ/dt]`` (for reference simulations)."""
        x = np.asarray(x, float)
        nxt = self.step(x, u, w)
        return (nxt - x) / self.T

    def to_dict(self):
        return {"kind": self.kind, "T": self.T, "a": self.a, "Vr_bar": self.Vr_bar,
                "phi_s0": self.phi_s0, "machine": self.machine, "upqc": self.upqc,
                "source": self.source}

    @classmethod
    def from_dict(cls, d):
        return cls(d["T"], d["a"], d["Vr_bar"], d["phi_s0"], d.get("machine", "gti"),
                   d.get("upqc", "conventional"), d.get("source"))

    def __repr__(self):
        return (f"UPQCDesignModel(T={self.T:g}, a={self.a:g}, Vr_bar={self.Vr_bar:g}, "
                f"phi_s0={self.phi_s0:g}, machine={self.machine!r}, upqc={self.upqc!r})")


register_system(UPQCDesignModel.kind, UPQCDesignModel.from_dict)


def _equilibrium_angle(owner, P, Vs, Vr_bar, B, pname):
    pmax = Vs * Vr_bar * B
    ratio = P / pmax
    if not np.isfinite(ratio) or abs(ratio) >= 1:
        raise ParameterError(pname, P, f"exceeds the transfer limit Vs·V̄r·B = {pmax:.4g} pu: "
                             "no equilibrium; reduce the power or raise B or the voltages",
                             owner)
    return float(np.arcsin(ratio))


def gti_design_model(*, C, tau, Vs, B, Vr_bar, T, chi=0.0, Pin=None, phi_s0=None,
                     upqc="conventional"):
    """Design model (10) of a GTI with dc link from physical parameters (pu, s).

    Parameters
    ----------
    C : float
        dc-link capacitance in the per-unit energy sense: ``C·Vc·dVc/dt`` in pu power, s.
    tau : float
        GTI phase-control gain τ of (5), rad/s per pu energy.
    Vs : float
        Inverter output voltage magnitude, pu.
    B : float
        Susceptance between the inverter and bus 1 (filter + line), pu.
    Vr_bar : float
        Steady-state shunt-bus voltage, pu.
    T : float
        Sampling period, s.
    chi : float
        Inverter losses χ ≥ 0 (Pe = (1+χ)·P_ac).
    Pin : float, optional
        Renewable input power, pu (gives ϕs0 from ``Pm = Pin/(1+χ) = Vs·V̄r·B·sin ϕs0``).
    phi_s0 : float, optional
        Equilibrium angle (rad), instead of Pin.
    upqc : {"conventional", "reduced"}
    """
    owner = "gti"
    _positive(owner, C=C, tau=tau, Vs=Vs, B=B, Vr_bar=Vr_bar, T=T)
    if not np.isfinite(chi) or chi < 0 or chi >= 1:
        raise ParameterError("chi", chi, "inverter losses must satisfy 0 ≤ χ < 1", owner)
    if (Pin is None) == (phi_s0 is None):
        raise ParameterError("Pin", Pin, "give exactly one of Pin and phi_s0", owner)
    tau_p = (1.0 + chi) * tau
    if phi_s0 is None:
        Pm = Pin / (1.0 + chi)
        phi_s0 = _equilibrium_angle(owner, Pm, Vs, Vr_bar, B, "Pin")
    a = tau_p * Vs * B / C
    src = {"machine": "gti", "C": C, "tau": tau, "chi": chi, "Vs": Vs, "B": B,
           "Vr_bar": Vr_bar, "T": T, "Pin": Pin, "phi_s0": float(phi_s0)}
    return UPQCDesignModel(T, a, Vr_bar, phi_s0, machine="gti", upqc=upqc, source=src)


def sg_design_model(*, H, E_prime, B, Vr_bar, T, f_nominal=50.0, Pm=None, delta0=None):
    """Design model of a classical SG behind a UPQC (Remark 5), pu on the machine base.

    ``M = 2H/ωs`` replaces ``C/τ``, ``E'`` replaces ``Vs``, the rotor angle δ
    (w.r.t. the UPQC shunt bus) replaces ϕs and the speed deviation (rad/s) υ.

    Parameters
    ----------
    H : float
        Inertia constant, s.
    E_prime : float
        Internal (transient) voltage, pu.
    B : float
        Susceptance from the internal voltage to the UPQC bus (1/(X'd + X_line)), pu.
    Vr_bar : float
        Steady-state shunt-bus voltage, pu.
    T : float
        Sampling period, s.
    f_nominal : float
        Nominal frequency, Hz (ωs = 2π·f).
    Pm : float, optional
        Mechanical power, pu; or ``delta0`` (rad).
    """
    owner = "sg"
    _positive(owner, H=H, E_prime=E_prime, B=B, Vr_bar=Vr_bar, T=T, f_nominal=f_nominal)
    if (Pm is None) == (delta0 is None):
        raise ParameterError("Pm", Pm, "give exactly one of Pm and delta0", owner)
    ws = 2 * np.pi * f_nominal
    M = 2 * H / ws
    if delta0 is None:
        delta0 = _equilibrium_angle(owner, Pm, E_prime, Vr_bar, B, "Pm")
    a = E_prime * B / M
    src = {"machine": "sg", "H": H, "E_prime": E_prime, "B": B, "Vr_bar": Vr_bar, "T": T,
           "f_nominal": f_nominal, "Pm": Pm, "delta0": float(delta0)}
    return UPQCDesignModel(T, a, Vr_bar, delta0, machine="sg", source=src)
