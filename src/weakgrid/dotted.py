"""Fields of nested data (a study as a dict) addressed by a dotted path (layer-neutral).

One mechanism for every caller: study files (:mod:`weakgrid.study.studyfile`), sweep axes
(:mod:`weakgrid.sweep.axes`) and ``--set`` on the command line. A path is a chain of keys,
``"upqc.rating"``; in a list (an array of tables) a part selects the element whose ``id``
(else ``name``) equals it, or, being a whole number, the element at that index:
``"scenarios.c1-high-conv.t_end"``, ``"scenarios.0.events.1.xf"``.

Every miss raises :class:`~weakgrid.game.errors.ParameterError` naming the path, the part
that is missing and what exists at that level (the keys of a table, the ids and indices of
a list).
"""

from __future__ import annotations

from .game.errors import ParameterError

__all__ = ["get_path", "set_path", "parts_of"]


def parts_of(path: str, field: str | None = None) -> list[str]:
    """The parts of a dotted ``path`` (a non-empty string without empty parts)."""
    if not isinstance(path, str) or not path or any(p == "" for p in path.split(".")):
        raise ParameterError(field or "path", path, "give a dotted field path such as "
                             "'upqc.rating' or 'scenarios.<id>.t_end'")
    return path.split(".")


def _element(lst: list, key: str):
    """Index of the element ``key`` of ``lst`` (by id, by name, or by index), or None."""
    for i, el in enumerate(lst):
        if isinstance(el, dict) and str(el.get("id", el.get("name"))) == key:
            return i
    if key.lstrip("-").isdigit() and -len(lst) <= int(key) < len(lst):
        return int(key) % len(lst)
    return None


def _miss(obj, key, where, path, field):
    """The error for a missing ``key`` at ``where`` (what exists there is listed)."""
    at = where or "the top level"
    if isinstance(obj, dict):
        fix = f"no field '{key}' in {at}; fields there: {sorted(map(str, obj))}"
    elif isinstance(obj, list):
        ids = [el.get("id", el.get("name")) for el in obj if isinstance(el, dict)]
        ids = [i for i in ids if i is not None]
        fix = (f"{at} has no element '{key}'; give one of the indices 0..{len(obj) - 1}"
               + (f" or one of the ids {ids}" if ids else "")) if obj else f"{at} is empty"
    else:
        fix = f"{at} is a value ({obj!r}), not a table: '{key}' cannot be below it"
    return ParameterError(field or path, path, fix)


def _step(obj, key, where, path, field):
    if isinstance(obj, dict) and key in obj:
        return obj[key]
    if isinstance(obj, list):
        i = _element(obj, key)
        if i is not None:
            return obj[i]
    raise _miss(obj, key, where, path, field)


def get_path(obj, path: str, *, field: str | None = None):
    """The value at dotted ``path`` of the nested dicts/lists ``obj``.

    Parameters
    ----------
    obj : dict or list
        The data (not modified).
    path : str
        E.g. ``"upqc.rating"``, ``"scenarios.c1-high-conv.events.0.xf"``.
    field : str, optional
        What the error names as the faulty input (e.g. ``"--set"``, ``"sweep.axes.path"``);
        default: the path itself.

    Raises
    ------
    ParameterError
        A part of the path does not exist (the message lists what exists at that level).
    """
    cur = obj
    done = []
    for key in parts_of(path, field):
        cur = _step(cur, key, ".".join(done), path, field)
        done.append(key)
    return cur


def set_path(obj, path: str, value, *, create: bool = False, field: str | None = None):
    """Set the value at dotted ``path`` of ``obj`` (in place); returns ``obj``.

    Parameters
    ----------
    obj : dict or list
        The data, modified in place.
    path : str
        The field (see :func:`get_path`).
    value
        The new value.
    create : bool
        ``False``: the field must exist (a typo is an error naming what exists).
        ``True``: missing tables on the way and a missing last key of a table are created
        (an optional field absent from a file; the caller validates the result). An
        element of a list is never created.
    field : str, optional
        See :func:`get_path`.
    """
    keys = parts_of(path, field)
    cur = obj
    for i, key in enumerate(keys[:-1]):
        if create and isinstance(cur, dict) and key not in cur:
            cur[key] = {}
        cur = _step(cur, key, ".".join(keys[:i]), path, field)
    last, where = keys[-1], ".".join(keys[:-1])
    if isinstance(cur, dict) and (create or last in cur):
        cur[last] = value
    elif isinstance(cur, list) and _element(cur, last) is not None:
        cur[_element(cur, last)] = value
    else:
        raise _miss(cur, last, where, path, field)
    return obj
