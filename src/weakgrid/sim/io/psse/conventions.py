"""PSS/E conventions shared by the models' ``psse_params``."""

from __future__ import annotations

from ...errors import DataError


def local_bus(values: dict, field: str, ctx) -> None:
    """Accept a remote-bus ICON that means the machine's own bus.

    PSS/E: a remote bus number 0 means "the bus of the machine" (local sensing); so does the
    machine's own bus number. Any other bus is refused naming the record (the models measure
    their own terminal only).

    Parameters
    ----------
    values : dict
        Record values (``values[field]`` is the ICON).
    field : str
        Name of the ICON in ``psse_record`` (e.g. ``"_BUSR"``).
    ctx : PsseContext
    """
    b = values.get(field, 0)
    if b in (0, None) or int(b) == int(ctx.bus):
        return
    raise DataError(ctx.where, field.lstrip("_"), b,
                    f"remote bus {int(b)}: this model measures the machine's own bus only; "
                    "use 0 (PSS/E: the machine's bus)")
