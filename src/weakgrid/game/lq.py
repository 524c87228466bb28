"""The linear-quadratic game: the exact special case of the HJI solver.

For ``x+ = A x + B u + E w`` and the cost ``Σ x'Qx + u'Ru − γ² w'Pw`` the value is
``J(x) = x'Sx`` with ``S`` the stabilizing solution of the discrete game Riccati
equation (docs/theory.md, "The LQ game")

    S = Q + A'SA − A'SB̃ (R̃ + B̃'SB̃)⁻¹ B̃'SA,   B̃ = [B E],  R̃ = blkdiag(R, −γ²P)

and the saddle point ``u* = −K x``, ``w* = −L x``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .errors import GammaTooSmallError, NonFiniteError, ParameterError, ShapeError, WeakgridError

__all__ = ["LQGameSolution", "solve_game_riccati", "dlqr", "attenuation_limit", "LQRError",
           "policy_attenuation_limit"]


class LQRError(WeakgridError):
    """The discrete LQR problem has no stabilizing solution."""


def _as_matrices(A, B, E=None):
    A = np.atleast_2d(np.asarray(A, float))
    n = A.shape[0]
    if A.shape != (n, n):
        raise ShapeError("A", A.shape, "(n, n)")
    B = np.asarray(B, float)
    B = B[:, None] if B.ndim == 1 else B
    if B.shape[0] != n or B.ndim != 2:
        raise ShapeError("B", B.shape, f"({n}, m)")
    out = [A, B]
    if E is not None:
        E = np.asarray(E, float)
        E = E[:, None] if E.ndim == 1 else E
        if E.shape[0] != n or E.ndim != 2:
            raise ShapeError("E", E.shape, f"({n}, q)")
        out.append(E)
    for nm, M in zip("ABE", out):
        if not np.all(np.isfinite(M)):
            raise NonFiniteError(f"{nm} contains NaN or inf")
    return out


def _weight(M, k, name, definite):
    M = np.atleast_2d(np.asarray(M, float))
    if M.shape == (1, 1) and k > 1:
        M = M[0, 0] * np.eye(k)
    if M.shape != (k, k):
        raise ShapeError(name, M.shape, f"({k}, {k}) or a scalar")
    if not np.allclose(M, M.T):
        raise ParameterError(name, M.tolist(), "weights must be symmetric")
    ev = np.linalg.eigvalsh(M)
    if definite == "pd" and ev.min() <= 0:
        raise ParameterError(name, M.tolist(), "must be positive definite")
    if definite == "psd" and ev.min() < -1e-12 * max(1.0, ev.max()):
        raise ParameterError(name, M.tolist(), "must be positive semidefinite")
    return 0.5 * (M + M.T)


@dataclass(frozen=True)
class LQGameSolution:
    """Solution of the LQ game.

    Attributes
    ----------
    S : ndarray (n, n)
        Value matrix, ``J(x) = x'Sx``.
    K : ndarray (m, n)
        Control gain, ``u* = −K x``.
    L : ndarray (q, n)
        Worst-case disturbance gain, ``w* = −L x``.
    spectral_radius : float
        Of the closed loop ``A − BK − EL``.
    min_eig_control : float
        Smallest eigenvalue of ``R + B'SB`` (must be > 0).
    min_eig_disturbance : float
        Smallest eigenvalue of ``γ²P − E'SE`` (must be > 0).
    """

    S: np.ndarray
    K: np.ndarray
    L: np.ndarray
    gamma: float
    spectral_radius: float
    min_eig_control: float
    min_eig_disturbance: float


def solve_game_riccati(A, B, E, Q, R, P, gamma) -> LQGameSolution:
    """Stabilizing solution of the discrete game Riccati equation, conditions checked.

    Raises
    ------
    GammaTooSmallError
        No stabilizing solution, or ``γ²P − E'SE`` not positive definite.
    """
    A, B, E = _as_matrices(A, B, E)
    n, m, q = A.shape[0], B.shape[1], E.shape[1]
    Q = _weight(Q, n, "Q", "psd")
    R = _weight(R, m, "R", "pd")
    P = _weight(P, q, "P", "pd")
    gamma = float(gamma)
    if not np.isfinite(gamma) or gamma <= 0:
        raise ParameterError("gamma", gamma, "gamma must be a positive number")
    Bt = np.hstack([B, E])
    Rt = sla.block_diag(R, -(gamma**2) * P)
    try:
        S = sla.solve_discrete_are(A, Bt, Q, Rt)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise GammaTooSmallError(gamma, f"the game Riccati equation has no stabilizing "
                                        f"solution ({exc})") from None
    if not np.all(np.isfinite(S)):
        raise GammaTooSmallError(gamma, "the game Riccati solution is not finite")
    S = 0.5 * (S + S.T)
    G = Rt + Bt.T @ S @ Bt
    KL = np.linalg.solve(G, Bt.T @ S @ A)
    K, L = KL[:m], KL[m:]
    rho = float(np.max(np.abs(np.linalg.eigvals(A - Bt @ KL))))
    ec = float(np.linalg.eigvalsh(R + B.T @ S @ B).min())
    ed = float(np.linalg.eigvalsh(gamma**2 * P - E.T @ S @ E).min())
    res = S - (Q + A.T @ S @ A - A.T @ S @ Bt @ KL)
    scale = max(1.0, np.abs(S).max())
    if np.abs(res).max() > 1e-6 * scale:
        raise GammaTooSmallError(gamma, f"the game Riccati equation is solved only to "
                                        f"{np.abs(res).max():.2e}: no reliable solution")
    if ed <= 0:
        raise GammaTooSmallError(gamma, f"γ²P − E'SE is not positive definite (smallest "
                                        f"eigenvalue {ed:.3g})")
    if ec <= 0:
        raise GammaTooSmallError(gamma, f"R + B'SB is not positive definite ({ec:.3g})")
    if rho >= 1.0:
        raise GammaTooSmallError(gamma, f"the saddle-point closed loop is not Schur "
                                        f"(spectral radius {rho:.6f})")
    if np.linalg.eigvalsh(S).min() < -1e-9 * scale:
        raise GammaTooSmallError(gamma, "the game Riccati solution is not positive semidefinite")
    return LQGameSolution(S, K, L, gamma, rho, ec, ed)


def attenuation_limit(A, B, E, Q, R, P, *, rtol=1e-6, upper=None) -> float:
    """Smallest γ for which :func:`solve_game_riccati` succeeds (bisection).

    The set of admissible γ is an interval ``(γ*, ∞)``: the game value is monotone in γ.

    Parameters
    ----------
    rtol : float
        Relative width of the final bracket.
    upper : float, optional
        A γ known to be admissible (found by doubling otherwise).
    """
    def ok(g):
        try:
            solve_game_riccati(A, B, E, Q, R, P, g)
            return True
        except GammaTooSmallError:
            return False

    hi = 1.0 if upper is None else float(upper)
    k = 0
    while not ok(hi):
        hi *= 2.0
        k += 1
        if k > 200:
            raise GammaTooSmallError(hi, "no admissible gamma found up to 2^200: "
                                         "is (A, B) stabilizable?")
    lo = hi / 2.0
    while ok(lo) and lo > 1e-12:
        hi, lo = lo, lo / 2.0
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if ok(mid):
            hi = mid
        else:
            lo = mid
    return hi


def dlqr(A, B, Q, R):
    """Discrete LQR: ``u = −K x`` minimizing ``Σ x'Qx + u'Ru``.

    Returns
    -------
    K : ndarray (m, n)
    S : ndarray (n, n)
    closed_loop_eigenvalues : ndarray (n,)
    """
    A, B = _as_matrices(A, B)
    n, m = A.shape[0], B.shape[1]
    Q = _weight(Q, n, "Q", "psd")
    R = _weight(R, m, "R", "pd")
    try:
        S = sla.solve_discrete_are(A, B, Q, R)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise LQRError(f"discrete LQR has no stabilizing solution ({exc}); check that (A, B) "
                       "is stabilizable and (A, Q) detectable") from None
    K = np.linalg.solve(R + B.T @ S @ B, B.T @ S @ A)
    return K, S, np.linalg.eigvals(A - B @ K)


def policy_attenuation_limit(A, B, E, K, Q, R, P, *, rtol=1e-6) -> float:
    """Smallest γ at which the fixed policy ``u = −Kx`` still admits the maximizing
    disturbance (the inner loop of the policy iteration started from ``K`` converges).

    It is the attenuation limit of the closed loop ``A − BK`` with state weight
    ``Q + K'RK``; it is never below :func:`attenuation_limit`.
    """
    A, B, E = _as_matrices(A, B, E)
    K = np.atleast_2d(np.asarray(K, float))
    if K.shape != (B.shape[1], A.shape[0]):
        raise ShapeError("K", K.shape, f"({B.shape[1]}, {A.shape[0]})")
    R = _weight(R, B.shape[1], "R", "pd")
    Ac = A - B @ K
    Qk = _weight(Q, A.shape[0], "Q", "psd") + K.T @ R @ K
    # a zero control column with a unit weight leaves the game unchanged
    Z = np.zeros((A.shape[0], 1))
    return attenuation_limit(Ac, Z, E, Qk, np.eye(1), P, rtol=rtol)
