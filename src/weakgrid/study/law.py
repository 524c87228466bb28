"""The law of a study run's digital controller: measured signals → design state → policy.

A run's :class:`~weakgrid.sim.controllers.DigitalController` calls a :class:`StudyLaw`: the
measured signals ``y`` (of the GTI or the SG, :attr:`weakgrid.study.build.Setup.measure_signals`)
mapped to the design state ``x = [ϕ̂ (rad), υ (rad/s)]`` (the run's own operating point,
:attr:`~weakgrid.study.build.Setup.state_map`), then ``u = policy(x)`` [pu] (zeros for an
idle UPQC); both ``y`` and ``x`` of every active sample are logged for the run's record.

Every run has a law object of its own (its own log, its own state map), but runs of one
batch (:mod:`weakgrid.sim.batch`) whose policies compute the same law — decided by the
content of the policy (:func:`policy_key`: a trained controller's weights, basis, cost and
design model; a fixed law's parameters), never by a run's or a case's name — share one
:meth:`StudyLaw.batch_key`, and the batch simulator evaluates them in one call
(:meth:`StudyLaw.rows`: the state maps of all the rows in one array operation, the policy once
on the stacked design states — its ``rows`` method if it has one — each run's log appended).
Trained controllers that differ only in their weights and input bounds (one per UPQC rating in
a sweep: :meth:`~weakgrid.game.controller.GameController.family_key`) share a call too, each row
computed with its own (:meth:`~weakgrid.game.controller.GameController.rows_of`).
Each row equals the run's own call bit for bit for the project's laws (a trained controller's
:meth:`~weakgrid.game.controller.GameController.rows`, the linear and (29) laws: term-by-term
arithmetic, :mod:`weakgrid.game.rowwise`): a closed loop would amplify a last-bit difference.
"""

from __future__ import annotations

import functools
import hashlib
import pickle
import types

import numpy as np

__all__ = ["StudyLaw", "policy_key"]

_FUNCTIONS = (types.FunctionType, types.BuiltinFunctionType, types.MethodType,
              functools.partial)


def _law_state(obj):
    """What determines the outputs of a policy object: a trained controller's design model,
    basis, weights and cost (not its training history); else the object's attributes."""
    if all(hasattr(obj, k) for k in ("system", "basis", "weights", "cost")):
        return obj.system, obj.basis, np.asarray(obj.weights), obj.cost
    return vars(obj) if hasattr(obj, "__dict__") else obj


def policy_key(policy) -> str:
    """A content key of ``policy`` (``u = policy(x)``): equal keys compute the same outputs.

    ``"idle"`` for None; for a bound method (e.g. ``GameController.control``) or a policy
    object, the SHA-256 of the pickled class, method and state (:func:`_law_state`); for a
    function (its law is its code and closure) or anything that cannot be pickled, its
    identity (shared only by the same object, alive while its runs are).
    """
    if policy is None:
        return "idle"
    owner, func = getattr(policy, "__self__", None), getattr(policy, "__func__", None)
    if owner is not None and func is not None and hasattr(owner, "__dict__"):
        content = (type(owner).__module__, type(owner).__qualname__, func.__name__,
                   _law_state(owner))
    elif isinstance(policy, _FUNCTIONS) or not hasattr(policy, "__dict__"):
        return f"object:{id(policy)}"     # a function's law is its code and closure
    else:
        content = (type(policy).__module__, type(policy).__qualname__, _law_state(policy))
    try:
        return hashlib.sha256(pickle.dumps(content, protocol=pickle.HIGHEST_PROTOCOL)).hexdigest()
    except Exception:   # not picklable: only the same object is the same law
        return f"object:{id(policy)}"


class StudyLaw:
    """``u = policy(state_map(y))`` with the samples logged (see the module).

    Parameters
    ----------
    policy : callable or None
        ``u = policy(x)`` for the design state ``x`` (shape ``(2,)`` or ``(n, 2)``) → ``u``
        ``[Vup, Vuq]`` [pu]; None: the UPQC idle (``u = 0``).
    state_map : callable
        ``x = state_map(y)`` (:class:`weakgrid.sim.design_states.GTIStateMap` or
        :class:`~weakgrid.sim.design_states.SGStateMap`, which map many rows at once).
    key : str, optional
        The policy's content key (default :func:`policy_key`).

    Attributes
    ----------
    xs, ys : list of ndarray
        The design states and the measured signals of every call, in order.
    """

    def __init__(self, policy, state_map, key=None):
        self.policy, self.state_map = policy, state_map
        self.key = policy_key(policy) if key is None else key
        fam = getattr(policy, "family_key", None)
        # policies of one family (e.g. one trained controller per UPQC rating) share a call
        self.family = (("family", fam()) if callable(fam) and hasattr(type(policy), "rows_of")
                       else None)
        self.xs, self.ys = [], []

    def __call__(self, y):
        y = np.asarray(y, float)
        m = self.state_map(y)
        u = np.zeros(2) if self.policy is None else np.asarray(self.policy(m), float).reshape(2)
        self.ys.append(y.copy())
        self.xs.append(m.copy())
        return u

    def batch_key(self):
        """Laws with equal keys are evaluated in one call (:meth:`rows`): the same policy
        (its content, :func:`policy_key`), or policies of one family — controllers that differ
        only in their weights and input bounds
        (:meth:`~weakgrid.game.controller.GameController.family_key`), each row computed with
        its own."""
        return "study-law", self.family or self.key

    @staticmethod
    def rows(laws, Y):
        """``laws[i](Y[i])`` for every row of the measured signals ``Y`` ``(n, p)`` (the laws
        share :meth:`batch_key`): the state maps in one array operation, the policy of
        ``laws[0]`` once on the ``(n, 2)`` design states (one row, or a policy known only by
        its identity: called on each row, as alone; the laws' policies of one family, not all
        the same: their ``rows_of``, each row with its own policy); each law logs its row.
        Returns the ``(n, 2)`` outputs."""
        Y = np.asarray(Y, float)
        maps = [law.state_map for law in laws]
        kind = type(maps[0])
        if hasattr(kind, "map_rows") and all(type(mp) is kind for mp in maps):
            X = kind.map_rows(maps, Y)
        else:
            X = np.stack([mp(y) for mp, y in zip(maps, Y)])
        pol = laws[0].policy
        n = len(laws)
        if pol is None:
            U = np.zeros((n, 2))
        elif n == 1 or laws[0].key.startswith("object:"):
            # one row: the run's own call (the same arithmetic as alone); a policy known only
            # by its identity (a function) is not assumed to take rows
            U = np.stack([np.asarray(pol(x), float).reshape(2) for x in X])
        elif any(law.key != laws[0].key for law in laws):   # one family: each row its own
            U = np.asarray(type(pol).rows_of([law.policy for law in laws], X),
                           float).reshape(n, 2)
        else:   # a policy's ``rows``: each row's floats those of its call on that row alone
            U = np.asarray(getattr(pol, "rows", pol)(X), float).reshape(n, 2)
        for law, y, x in zip(laws, Y, X):
            law.ys.append(y.copy())
            law.xs.append(x.copy())
        return U
