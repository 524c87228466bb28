"""The array namespace of the devices' evaluation (issue #21: an accelerator array backend).

A grid's device models are written against the `array API standard
<https://data-apis.org/array-api/latest/>`_: their evaluation (:meth:`System.evaluate`, the
residual every step and every batch evaluates) calls the namespace ``xp`` that the component
holds (:attr:`Component.xp`, NumPy by default), never NumPy by name, and indexes its arrays
only as the standard allows. :func:`on_namespace` gives a copy of a set-up grid whose arrays
live in another namespace (CuPy, PyTorch, ... through ``array_api_compat``, or
``array_api_strict`` to check that nothing outside the standard is used), evaluated by the same
code: the batched residual of many members could then run on an accelerator without a line of
the models changing. On NumPy every helper below is the NumPy indexing it replaces (the same
floats, the same cost).

What the standard lacks, written here once:

* :func:`take`: ``a[..., idx]`` for an integer index array (the standard indexes a single
  axis by an integer array only through ``take``);
* :func:`put` and :func:`add_at`: ``a[..., idx] = v`` and ``a[..., idx] += v`` (with
  repeated indices: ``numpy.add.at``), which the standard has no form of for index arrays:
  a selection (``where``) of the whole array, written back in place.

Only the models that say so themselves (:attr:`Component.array_api` set by the model's own
class, not inherited: a subclass may evaluate otherwise) are converted; :func:`on_namespace`
refuses a grid with any other, naming it. The linear solves of the simulators stay on NumPy
and LAPACK (each member's own factorization, for exactness: :mod:`weakgrid.sim.batch`).
"""

from __future__ import annotations

import copy
import functools
import operator
import types

import numpy as np

from .errors import DataError

__all__ = ["NUMPY", "add_at", "namespace_models", "on_arrays_of", "on_namespace", "put", "take",
           "to_numpy"]


def _numpy_namespace():
    """NumPy (its array-API namespace since 2.0) with the standard's functions that NumPy
    spells as a slower wrapper replaced by the same operations at C speed: a grid's residual
    calls them a few dozen times per evaluation (``numpy.all`` costs twice the method,
    ``numpy.real`` three times the attribute); ``astype`` for NumPy 2.0, which lacks it."""
    ns = types.ModuleType("weakgrid.sim.namespace.NUMPY", "NumPy, for the devices' evaluation")
    ns.__dict__.update({k: v for k, v in vars(np).items() if not k.startswith("__")})
    ns.all = functools.partial(np.logical_and.reduce, axis=None)
    ns.any = functools.partial(np.logical_or.reduce, axis=None)
    ns.real = operator.attrgetter("real")
    ns.imag = operator.attrgetter("imag")
    ns.astype = lambda x, dtype, /, *, copy=True: x.astype(dtype, copy=copy)
    return ns


#: the namespace of a grid evaluated on NumPy (the default of every component and block)
NUMPY = _numpy_namespace()


@functools.lru_cache(maxsize=None)
def on_arrays_of(fn, xp, **calls):
    """The module-level function ``fn`` (written with NumPy's functions, all in the standard)
    with the name ``np`` in it bound to the namespace ``xp``, and the names ``calls`` to other
    functions (the same code on another namespace's arrays; cached). A kernel's core runs so
    (:class:`~weakgrid.sim.kernels.Kernel`), and an array function it calls."""
    return types.FunctionType(fn.__code__, dict(fn.__globals__, np=xp, **calls), fn.__name__,
                              fn.__defaults__, fn.__closure__)


def take(xp, a, idx):
    """``a[..., idx]`` along the last axis: ``idx`` a slice or a 1-d integer array."""
    if xp is NUMPY or type(idx) is slice:
        return a[..., idx]
    return xp.take(a, idx, axis=-1)


def _scatter(xp, a, idx, v):
    """``a`` with ``a[..., idx]`` replaced by ``v`` (``idx`` unique), by selection."""
    cols = to_numpy(idx)
    where = np.full(a.shape[-1], -1)
    where[cols] = np.arange(len(cols))
    mask = xp.asarray(where >= 0)
    pos = xp.asarray(np.maximum(where, 0))
    v = xp.broadcast_to(xp.asarray(v, dtype=a.dtype), a.shape[:-1] + (int(idx.shape[0]),))
    return xp.where(mask, xp.take(v, pos, axis=-1), a)


def put(xp, a, idx, v):
    """``a[..., idx] = v`` along the last axis, in place (``idx`` a slice or a 1-d integer
    array without repeats)."""
    if xp is NUMPY or type(idx) is slice:
        a[..., idx] = v
    else:
        a[...] = _scatter(xp, a, idx, v)


def add_at(xp, a, idx, v, unique):
    """``a[..., idx] += v`` along the last axis, in place; with repeated indices
    (``unique=False``) every repeat adds its share in order, as :func:`numpy.add.at`."""
    if xp is NUMPY:
        if unique:
            a[..., idx] += v
        else:   # unbuffered: every repeated index receives its share (two devices on one bus)
            np.add.at(a, (Ellipsis, idx), v)
        return
    if type(idx) is slice:
        a[..., idx] = a[..., idx] + v
        return
    v = xp.broadcast_to(xp.asarray(v, dtype=a.dtype), a.shape[:-1] + (int(idx.shape[0]),))
    order = np.asarray(to_numpy(idx))
    # the k-th occurrences of the indices added in the k-th pass: numpy.add.at's order
    rank = np.array([np.count_nonzero(order[:i] == order[i]) for i in range(len(order))], int)
    for r in range(int(rank.max(initial=-1)) + 1):
        sel = np.nonzero(rank == r)[0]
        cols = xp.asarray(order[sel])
        part = xp.take(v, xp.asarray(sel), axis=-1)
        a[...] = _scatter(xp, a, cols, xp.take(a, cols, axis=-1) + part)


def to_numpy(a):
    """A NumPy array of the values of ``a`` (an array of any namespace, by DLPack)."""
    if isinstance(a, np.ndarray) or np.isscalar(a):
        return np.asarray(a)
    return np.from_dlpack(a)


def _convert(v, xp):
    if isinstance(v, np.ndarray) and v.dtype.kind in "biufc":
        return xp.asarray(np.ascontiguousarray(v))
    if isinstance(v, dict):
        return {k: _convert(w, xp) for k, w in v.items()}
    if isinstance(v, (list, tuple)) and any(isinstance(w, np.ndarray) for w in v):
        return type(v)(_convert(w, xp) for w in v)
    return v


def namespace_models(system) -> list[str]:
    """The model types of ``system`` that are not written for another namespace (empty: it can
    be evaluated on any, :func:`on_namespace`)."""
    return sorted({c.type_name for c in system.comps if not type(c).__dict__.get("array_api")})


def on_namespace(system, xp):
    """A copy of the set-up grid ``system`` whose devices are evaluated on the array namespace
    ``xp``: every array of its components (parameters, constants, control blocks, indices) and
    of the grid that the evaluation reads, converted by ``xp.asarray``.

    Raises :class:`~weakgrid.sim.errors.DataError` naming the models that are not written for
    another namespace (:func:`namespace_models`)."""
    if not system.is_setup:
        system.setup()
    left = namespace_models(system)
    if left:
        raise DataError("the grid", "models", ", ".join(left),
                        "these models run on NumPy only: evaluate this grid on NumPy")
    from .blocks import Block

    s = copy.deepcopy(system)
    for c in s.comps:
        for k, v in list(vars(c).items()):
            blocks = [v] if isinstance(v, Block) else [
                b for b in v if isinstance(b, Block)] if isinstance(v, (list, tuple)) else []
            for b in blocks:        # its control blocks: their arrays and namespace
                for kb, vb in list(vars(b).items()):
                    setattr(b, kb, _convert(vb, xp))
                b.xp = xp
            if not blocks:
                setattr(c, k, _convert(v, xp))
        c.xp = xp
    for k in ("_sig_stack", "branch_status"):
        setattr(s, k, _convert(getattr(s, k), xp))
    s.xp = xp
    return s
