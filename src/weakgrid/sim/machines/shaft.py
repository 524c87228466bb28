r"""Single-mass shaft (swing equation), shared by all machine models.

.. math::

    \dot\delta = \omega_b(\omega - 1), \qquad
    M\dot\omega = \tau_m - \tau_e - D(\omega - 1)

with :math:`\omega_b = 2\pi f_n` [rad/s], :math:`M = 2H` [s] and damping ``D``
[pu torque / pu speed], both on the system power base (ANDES ``GENBase``).
Torques are in pu on the system base; speed in pu of nominal.

PSS/E's shaft (every PSS/E ``GEN*`` model; machine parameter ``psse_shaft = 1``) takes
the mechanical input as *power* ``Pm``: the mechanical torque is ``(Pm - D dw)/omega``
(the electrical torque ``te`` is the air-gap torque as in ANDES's form):

.. math::

    M\dot\omega = \frac{P_m - D(\omega - 1)}{\omega} - \tau_e

Both forms agree at rated speed (same initial point); they differ by :math:`\sim P_m\,\Delta\omega`
in a swing. On PSID's PSS/E benchmark (line trip, 20 s; GENROU, GENROE, GENSAL, GENSAE)
ANDES's form leaves 0.5–1.4 % of PSS/E's rotor-angle swing, PSS/E's 0.05–0.13 %.
PSS/E's GENCLS passes ``te/omega`` (its air-gap power over the speed; see
:mod:`weakgrid.sim.machines.gencls`): its swing is damped by ``D`` alone, as PSS/E's OMIB results show.
"""

from __future__ import annotations

import numpy as np


def swing(omega, tm, te, M, D, wb, psse=None, xp=np):
    """Return ``(d delta/dt, d omega/dt)`` of the single-mass shaft.

    Parameters
    ----------
    omega : ndarray
        Rotor speed [pu].
    tm, te : ndarray
        Mechanical and electrical torque [pu, system base].
    M, D : ndarray
        Inertia constant 2H [s] and damping [pu], system base.
    wb : ndarray
        Base angular frequency [rad/s].
    psse : ndarray of bool or None
        Where true, PSS/E's shaft: ``tm`` is the mechanical power and
        ``(tm - D dw) / omega`` the mechanical torque. ``None``: ANDES's everywhere.
    xp : module
        The arrays' namespace (:mod:`weakgrid.sim.namespace`).
    """
    dw = omega - 1.0
    if psse is None:
        return wb * dw, (tm - te - D * dw) / M
    tmd = tm - D * dw
    return wb * dw, (xp.where(psse, tmd / omega, tmd) - te) / M
