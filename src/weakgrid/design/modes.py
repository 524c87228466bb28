"""Small-signal analysis of a set-up simulator system.

The DAE ``dx/dt = f(x, y)``, ``0 = g(x, y)`` (y: bus voltages) is linearized at the initial
operating point from :meth:`System.jacobian` and the algebraic variables are eliminated::

    A = fx − fy · gy⁻¹ · gx

Eigenvalues ``λ = σ ± jω`` give the modes: frequency ``ω/2π`` (Hz), damping ratio
``ζ = −σ/|λ|``. Participation factors ``p_ki = |v_ki·w_ik|`` (right and left eigenvectors,
``W = V⁻¹``), normalized to a sum of 1 per mode, tell which states take part in which mode.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Modes", "linearize", "modes", "machine_mode"]


def linearize(system, t: float = 0.0, z=None) -> np.ndarray:
    """State matrix ``A`` (nx × nx) of the set-up ``system`` at ``z`` (default: its initial point)."""
    z = system.z0 if z is None else np.asarray(z, float)
    J = system.jacobian(t, z)
    nx = system.nx
    fx, fy = J[:nx, :nx], J[:nx, nx:]
    gx, gy = J[nx:, :nx], J[nx:, nx:]
    return fx - fy @ np.linalg.solve(gy, gx)


@dataclass
class Modes:
    """Eigen-analysis of a linearized system.

    Attributes
    ----------
    eigenvalues : ndarray (n,) complex
    participation : ndarray (n states, n modes), normalized per mode
    state_names : list of str
    """

    eigenvalues: np.ndarray
    participation: np.ndarray
    state_names: list

    @property
    def frequency_hz(self):
        return np.abs(self.eigenvalues.imag) / (2 * np.pi)

    @property
    def damping_ratio(self):
        lam = self.eigenvalues
        mag = np.abs(lam)
        return np.where(mag > 0, -lam.real / np.where(mag > 0, mag, 1.0), 1.0)

    def dominant_states(self, k: int, n: int = 3):
        """The ``n`` states participating most in mode ``k``: ``[(name, factor)]``."""
        p = self.participation[:, k]
        idx = np.argsort(p)[::-1][:n]
        return [(self.state_names[i], float(p[i])) for i in idx]

    def table(self, oscillatory_only: bool = True, min_hz: float = 0.0):
        """Rows ``{mode, real, imag, f_hz, zeta, dominant}`` (upper half-plane representatives)."""
        rows = []
        for k, lam in enumerate(self.eigenvalues):
            if lam.imag < 0 or (oscillatory_only and lam.imag <= 2 * np.pi * max(min_hz, 1e-6)):
                continue
            rows.append({"mode": k, "real": float(lam.real), "imag": float(lam.imag),
                         "f_hz": float(self.frequency_hz[k]), "zeta": float(self.damping_ratio[k]),
                         "dominant": ", ".join(f"{n} {p:.2f}" for n, p in self.dominant_states(k))})
        rows.sort(key=lambda r: r["f_hz"])
        return rows


def modes(system, t: float = 0.0, z=None) -> Modes:
    """Eigenvalues and participation factors of the set-up ``system`` at its operating point."""
    A = linearize(system, t, z)
    lam, V = np.linalg.eig(A)
    W = np.linalg.inv(V)
    P = np.abs(V * W.T)
    s = P.sum(axis=0)
    P = P / np.where(s > 0, s, 1.0)
    return Modes(lam, P, system.state_names())


def machine_mode(m: Modes, states):
    """The oscillatory mode in which the named states participate most.

    ``states``: state names (e.g. ``["SG.delta", "SG.omega"]``) or a prefix ``"SG"`` (every
    ``SG.*`` state). Returns ``(k, participation)`` or ``(None, 0.0)``.
    """
    if isinstance(states, str):
        rows = [i for i, n in enumerate(m.state_names) if n.startswith(states + ".")]
    else:
        rows = [i for i, n in enumerate(m.state_names) if n in set(states)]
    if not rows:
        return None, 0.0
    best, bp = None, 0.0
    for k, lam in enumerate(m.eigenvalues):
        if lam.imag <= 1e-6:
            continue
        p = float(m.participation[rows, k].sum())
        if p > bp:
            best, bp = k, p
    return best, bp
