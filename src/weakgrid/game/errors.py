"""Errors raised by the game layer.

Every error names the cause and the fix; several carry the numbers that explain
them as attributes so that callers (the CLI, a γ search) can act on them.
"""

from __future__ import annotations


def _restore(cls, args, state):
    """An error of class ``cls`` with its ``args`` and attributes, without calling its
    ``__init__`` (see :meth:`WeakgridError.__reduce__`)."""
    err = cls.__new__(cls, *args)
    err.args = args
    err.__dict__.update(state)
    return err


class WeakgridError(Exception):
    """Base class of every error raised by weakgrid.

    Picklable whatever its ``__init__`` takes (an error raised in a Dask worker, or a failed
    run's cause carried in its record, travels to the client by pickle; Python's default would
    call ``__init__`` with the message alone and fail for errors with several fields).
    """

    def __reduce__(self):
        return _restore, (type(self), self.args, dict(self.__dict__))


class ParameterError(WeakgridError, ValueError):
    """A parameter is non-physical or malformed (names the field, the value and the fix)."""

    def __init__(self, field: str, value, fix: str, owner: str | None = None):
        self.field = field
        self.value = value
        self.fix = fix
        where = f"{owner}.{field}" if owner else field
        super().__init__(f"{where} = {value!r} is invalid: {fix}")


class ShapeError(WeakgridError, ValueError):
    """An array has the wrong shape."""

    def __init__(self, field: str, shape, expected: str):
        self.field = field
        self.shape = tuple(shape)
        super().__init__(f"{field} has shape {tuple(shape)}, expected {expected}")


class NonFiniteError(WeakgridError, FloatingPointError):
    """A NaN or an infinity appeared where a number was expected."""


class GammaTooSmallError(WeakgridError):
    """The attenuation level γ is below what the system (or the basis) allows.

    In the policy iteration: ``Yw = h'∇²J h − 2γ²P`` is not negative definite on
    the training region, so the inner (disturbance) loop would diverge. In the LQ
    game: ``γ²P − E'SE`` is not positive definite or the game Riccati equation has
    no stabilizing solution.

    Attributes
    ----------
    gamma : float
    n_bad, n_points : int or None
        Mesh points where Yw is not negative definite, out of all.
    worst_state : ndarray or None
        Mesh point with the largest eigenvalue of Yw.
    worst_eig : float or None
    """

    FIX = ("Increase gamma (or the disturbance weight P), or shrink the training region; "
           "`weakgrid gamma` finds the smallest admissible gamma.")

    def __init__(self, gamma, reason, n_bad=None, n_points=None, worst_state=None,
                 worst_eig=None):
        self.gamma = gamma
        self.n_bad = n_bad
        self.n_points = n_points
        self.worst_state = worst_state
        self.worst_eig = worst_eig
        self.reason = reason
        super().__init__(f"gamma = {gamma:g} is too small: {reason}. {self.FIX}")

    @classmethod
    def from_mesh(cls, gamma, n_bad, n_points, worst_state, worst_eig, where=""):
        reason = (
            f"Yw = h'∇²J h − 2γ²P is not negative definite at {n_bad} of {n_points} mesh "
            f"points{where} (worst at x = {[round(float(v), 6) for v in worst_state]}, "
            f"largest eigenvalue {worst_eig:.3g})"
        )
        import numpy as np   # here: the errors are imported by the CLI before any NumPy work

        return cls(gamma, reason, n_bad, n_points, np.asarray(worst_state), worst_eig)


class ControlHessianError(WeakgridError):
    """``Yu = g'∇²J g + 2R`` is not positive definite somewhere on the mesh."""


class ConvergenceError(WeakgridError):
    """The policy iteration did not converge within its iteration caps.

    Attributes
    ----------
    history : list
        The iterations done so far (see :class:`~weakgrid.game.hji.IterationRecord`).
    """

    def __init__(self, message, history=None):
        self.history = history or []
        super().__init__(message)


class InitialPolicyError(WeakgridError):
    """The initial policy does not stabilize the system (it must, for policy iteration)."""
