"""Generic state-feedback policies (initial policies of the policy iteration)."""

from __future__ import annotations

import numpy as np

from .errors import ShapeError
from .rowwise import matvec

__all__ = ["LinearPolicy", "describe_policy"]


class LinearPolicy:
    """``u = −K x``.

    Parameters
    ----------
    K : ndarray (m, n)
    name : str
    """

    def __init__(self, K, name="linear state feedback"):
        K = np.atleast_2d(np.asarray(K, float))
        if K.ndim != 2:
            raise ShapeError("K", K.shape, "(m, n)")
        self.K = K
        self.name = name

    def __call__(self, x):
        """``u = −K x`` at a state (n,) or each row of (..., n) (term by term: a row's floats
        do not depend on the rows computed with it, :mod:`weakgrid.game.rowwise`)."""
        return -matvec(self.K, x)

    def to_dict(self):
        return {"kind": "linear", "name": self.name, "K": self.K.tolist()}


def describe_policy(policy) -> dict:
    """A JSON-able record of a policy (its ``to_dict`` if it has one)."""
    if hasattr(policy, "to_dict"):
        return policy.to_dict()
    return {"kind": "callable", "name": getattr(policy, "__name__", repr(policy))}
