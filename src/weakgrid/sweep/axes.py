"""Sweep axes over the fields of a nested input (a study as a dict).

A field is named by its dotted path, e.g. ``"upqc.rating"`` or
``"scenarios.0.fault.duration"`` (a list element by its ``id`` or its index; one
mechanism with study files: :mod:`weakgrid.dotted`). Axes combine
as a Cartesian product, or as listed points (every axis the same length,
the k-th values taken together).
"""

from __future__ import annotations

import copy
import itertools
import math
from dataclasses import dataclass, field

from ..dotted import get_path as _get, set_path as _set
from ..game.errors import ParameterError

__all__ = ["Axis", "Point", "expand", "get_path", "set_path"]


@dataclass(frozen=True)
class Axis:
    """One swept field.

    Attributes
    ----------
    path : str
        Dotted path of the field in the input, e.g. ``"upqc.rating"``.
    values : tuple
        The values it takes (numbers, strings or booleans).
    """

    path: str
    values: tuple

    def __post_init__(self):
        if not isinstance(self.path, str) or not self.path or any(p == "" for p in
                                                                 self.path.split(".")):
            raise ParameterError("sweep.axes.path", self.path,
                                 "give a dotted field path such as 'upqc.rating'")
        vals = tuple(self.values) if isinstance(self.values, (list, tuple)) else None
        if not vals:
            raise ParameterError(f"sweep.axes['{self.path}'].values", self.values,
                                 "give a non-empty list of values")
        for v in vals:
            if isinstance(v, float) and not math.isfinite(v):
                raise ParameterError(f"sweep.axes['{self.path}'].values", v,
                                     "every value must be finite")
        object.__setattr__(self, "values", vals)


@dataclass
class Point:
    """One run of a sweep: its axis values and its full input.

    Attributes
    ----------
    params : dict
        ``path -> value`` of the swept fields (the columns of the result table).
    inputs : dict
        The full input of the run (the base input with the swept fields set).
    """

    params: dict
    inputs: dict = field(repr=False)


def get_path(obj, path: str):
    """The value at dotted ``path`` of a nested dict/list ``obj`` (:func:`weakgrid.dotted.get_path`;
    a list element by its ``id``/``name`` or its index)."""
    return _get(obj, path, field="sweep.axes.path")


def set_path(obj, path: str, value):
    """Set the value at dotted ``path`` (the field must exist: a typo is an error)."""
    _set(obj, path, value, field="sweep.axes.path")


def expand(base: dict, axes, mode: str = "product", *, getter=None,
           setter=None) -> list[Point]:
    """The points of a sweep over ``base``.

    Parameters
    ----------
    base : dict
        The input every run starts from (not modified).
    axes : list of Axis or dict
        The swept fields; a dict maps path → list of values.
    mode : {"product", "points"}
        Cartesian product of the axes, or listed points (all axes equally long).
    getter, setter : callable, optional
        ``getter(obj, path)`` and ``setter(obj, path, value)`` addressing a field by its
        dotted path (default: :func:`get_path`, :func:`set_path` of this module). A caller
        whose input has its own path semantics passes them (the study engine passes
        :func:`weakgrid.study.studyfile.get_path`/``set_path``: list elements by ``id``).

    Returns
    -------
    list of Point
        In a stable order (the first axis varies slowest).
    """
    if isinstance(axes, dict):
        axes = [Axis(p, v) for p, v in axes.items()]
    axes = list(axes)
    if not axes:
        raise ParameterError("sweep.axes", axes, "give at least one axis")
    paths = [a.path for a in axes]
    if len(set(paths)) != len(paths):
        raise ParameterError("sweep.axes", paths, "each field may be swept by one axis only")
    getter = getter or get_path
    setter = setter or set_path
    for a in axes:
        getter(base, a.path)
    if mode == "product":
        combos = list(itertools.product(*(a.values for a in axes)))
    elif mode == "points":
        n = {len(a.values) for a in axes}
        if len(n) != 1:
            raise ParameterError("sweep.mode", mode, "with mode = 'points' every axis needs the "
                                 f"same number of values (got {[len(a.values) for a in axes]})")
        combos = list(zip(*(a.values for a in axes)))
    else:
        raise ParameterError("sweep.mode", mode, "choose 'product' or 'points'")
    out = []
    for combo in combos:
        inp = copy.deepcopy(base)
        for p, v in zip(paths, combo):
            setter(inp, p, v)
        out.append(Point(dict(zip(paths, combo)), inp))
    return out
