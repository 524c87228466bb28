r"""Single-mass shaft (swing equation), shared by all machine models.

.. math::

    \dot\delta = \omega_b(\omega - 1), \qquad
    M\dot\omega = \tau_m - \tau_e - D(\omega - 1)

with :math:`\omega_b = 2\pi f_n` [rad/s], :math:`M = 2H` [s] and damping ``D``
[pu torque / pu speed], both on the system power base (ANDES ``GENBase``).
Torques are in pu on the system base; speed in pu of nominal.
"""

from __future__ import annotations



def swing(omega, tm, te, M, D, wb):
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
    """
    dw = omega - 1.0
    return wb * dw, (tm - te - D * dw) / M
