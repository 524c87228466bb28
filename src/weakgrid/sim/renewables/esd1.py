"""ESD1: WECC distributed energy storage (PVD1 with charging and a state of charge; ANDES ``ESD1``).

The PVD1 current source (see :mod:`weakgrid.sim.renewables.pvd1`) that may also absorb power,
with a state of charge that stops discharging when empty and charging when full::

    active power command clipped to [-pmx, pmx] (PVD1: [0, pmx])
    SOC: Tf dSOC/dt = Sb / (3600 En) * (-P EtaC  if P < 0 (charging)
                                         -P / EtaD otherwise),      P = Ipout v,  SOC(0) = SOCinit
    SOC <= SOCmin: Ipmax = 0 (no discharge);   SOC >= SOCmax: Ipmin = 0 (no charge)
    Ipcmd = R clip(Ipul, -Ipmin_mag, Ipmax)      (PVD1: clip(Ipul, 0, Ipmax))

``En`` [MWh] is the rated energy, ``Sb`` [MVA] the system base, ``P`` [pu, system base]; ``Tf``
[s] the SOC integrator's time constant (1 s: SOC in pu of ``En``). The frequency measurement
takes the BusFreq constants as ``Tf_meas``, ``Tw_meas`` (``Tf`` is the SOC's, as in ANDES).
"""

from __future__ import annotations

from ..params import Param
from .pvd1 import PVD1

_MEAS = {"Tf": "Tf_meas", "Tw": "Tw_meas"}


class ESD1(PVD1):
    """Distributed energy storage (WECC ESD1): PVD1 + charging + state of charge."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    params = tuple(Param(_MEAS.get(p.name, p.name), p.default, p.unit, p.info, p.rule, p.base)
                   for p in PVD1.params) + (
        Param("Tf", 1.0, "s", "time constant of the state-of-charge integrator", "pos"),
        Param("SOCmin", 0.0, "pu", "state of charge below which discharging stops", ""),
        Param("SOCmax", 1.0, "pu", "state of charge above which charging stops", ""),
        Param("SOCinit", 0.5, "pu", "initial state of charge", ""),
        Param("En", 100.0, "MWh", "rated energy", "pos"),
        Param("EtaC", 1.0, "-", "charging efficiency", "pos"),
        Param("EtaD", 1.0, "-", "discharging efficiency", "pos"),
    )
    states = PVD1.states + ("SOC",)
    outputs = PVD1.outputs + ("SOC",)
    freq_params = ("Tf_meas", "Tw_meas")
    #: the state of charge moves whenever the storage exchanges power, also at a steady state
    integrating_states = ("SOC",)
    pmin_frac = -1.0

    def setup(self, system):
        super().setup(system)
        p = self.p
        self._kE = system.Sb / (3600.0 * p["En"] * p["Tf"])     # dSOC/dt per pu of power

    def _gates_of(self, soc):
        xp, p = self.xp, self.p
        return -xp.astype(soc < p["SOCmax"], xp.float64), xp.astype(soc > p["SOCmin"], xp.float64)

    def _init_gates(self):
        return self._gates_of(self.p["SOCinit"])

    def _ip_gates(self, x):
        return self._gates_of(x[..., self._sls[4]])

    def init(self, system, x, sig):
        super().init(system, x, sig)
        x[self.sl(4)] = self.p["SOCinit"]

    def compute(self, ctx):
        ipout, v = super().compute(ctx)
        xp, p = self.xp, self.p
        P = ipout * v
        ctx.f[..., self._sls[4]] = -self._kE * xp.where(P < 0.0, P * p["EtaC"], P / p["EtaD"])
        ctx.out[self._key["SOC"]] = ctx.x[..., self._sls[4]]
