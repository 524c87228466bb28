"""DEGOV: Woodward diesel governor without droop (PSS/E DEGOV).

DEGOV1 (:mod:`weakgrid.sim.governors.degov1`) without its droop loop: an isochronous governor
(the actuator integrator returns the speed to exactly 1 pu after any load change)::

    dw = omega - 1
    -dw --[ (1+sT3)/(1+sT1+s^2 T1 T2) ]--> y1                      (electric control box)
    y1 --[ (1+sT4)/((1+sT5)(1+sT6)) ]--> y2 --[ K/s, non-windup TMIN..TMAX ]--> THR   (actuator)
    THR --[ e^{-sTD} ]--> THRD,   PMECH = THRD*(1 + dw),   tm = PMECH (the PSS/E shaft divides by omega)

Machine base, engine dead time by stored history (exact, no Padé approximation), output torque
and initialization as DEGOV1 (see there). The state ``PEF`` of DEGOV1 is present and stays 0.

Against PSS/E's own results (PowerSimulationsDynamics.jl's benchmark case 57: GENCLS + DEGOV,
line trip; ``tests/sim/test_governors_psse.py``): rotor speed within 4.7e-5 pu without the
delay and 3.05e-5 pu with TD = 1 s, on swings of 9.2e-4 pu (PSID's own tolerances 4.7e-5 and
3.1e-5); the remainder grows linearly in time (PSS/E's swing period is 0.5 % shorter).

PSS/E record: CONs ``T1 T2 T3 K T4 T5 T6 TD TMAX TMIN``.
"""

from __future__ import annotations

from .degov1 import DEGOV1


class DEGOV(DEGOV1):
    """Woodward diesel governor, isochronous (PSS/E DEGOV). Parameters: T1..T6, TD [s]; K [pu];
    TMAX, TMIN [pu, machine base]."""

    params = tuple(prm for prm in DEGOV1.params if prm.name not in ("M", "DROOP", "TE"))
    #: PSS/E .dyr record after ``IBUS 'DEGOV' ID`` (CONs only)
    psse_record = ("T1", "T2", "T3", "K", "T4", "T5", "T6", "TD", "TMAX", "TMIN")
    droop_flag = False
