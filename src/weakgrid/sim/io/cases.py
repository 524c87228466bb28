"""A plain case file → a :class:`~weakgrid.sim.system.System`, its format told by the file.

One entry point, :func:`load_case`, for the formats the importers read:

* ``.raw`` (+ ``.dyr``): PSS/E, weakgrid's own reader (:func:`weakgrid.sim.io.psse.from_psse`);
  buses keep their PSS/E numbers, generators without a machine record are ideal sources (as
  ANDES runs them);
* ``.m``, ``.mat``: MATPOWER (:func:`weakgrid.sim.io.matpower.load_matpower`), a power-flow
  case: a classical machine at every in-service generator
  (:func:`weakgrid.sim.templates.classical_system`);
* ``.json``: pandapower (``pandapower.to_json``, recognised by its ``pandapowerNet`` marker;
  classical machines as for MATPOWER, buses numbered by their pandapower index), else an ANDES
  JSON case;
* ``.xlsx``: an ANDES case (:func:`weakgrid.sim.io.andes.from_andes`; needs the optional ANDES,
  ``pip install 'weakgrid[andes]'``).

A ``.dyr`` file may accompany a ``.raw`` (weakgrid's reader) or an ANDES case (ANDES's
``addfile``). The timed events a case file holds (ANDES ``Toggle``, ``Fault``) are returned
with the system.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..errors import DataError

__all__ = ["CASE_SUFFIXES", "Case", "case_format", "load_case"]

#: file suffix → format
CASE_SUFFIXES = {".raw": "psse", ".m": "matpower", ".mat": "matpower", ".json": "json",
                 ".xlsx": "andes"}


@dataclass
class Case:
    """A loaded case.

    Attributes
    ----------
    system : System
        Not yet set up.
    format : str
        ``"psse"``, ``"matpower"``, ``"pandapower"`` or ``"andes"``.
    events : list
        The timed events of the file (ANDES cases), else empty.
    notes : list of str
        What the import converted, approximated or skipped (``system.import_notes``), and
        the dynamic data added to a power-flow case.
    """

    system: object
    format: str
    events: list = field(default_factory=list)
    notes: list = field(default_factory=list)


def case_format(path) -> str | None:
    """The format of case file ``path`` by its suffix (``"json"``: pandapower or ANDES), or
    None for anything else."""
    return CASE_SUFFIXES.get(Path(str(path)).suffix.lower())


def _is_pandapower_json(path: Path) -> bool:
    with open(path, "rb") as fh:
        head = fh.read(1 << 16)
    return b"pandapowerNet" in head


def load_case(path, dyr=None, *, f_hz: float = 60.0) -> Case:
    """Read the case file ``path`` (and the PSS/E dynamic data ``dyr``) into a System.

    Parameters
    ----------
    path : str or Path
        ``.raw``, ``.m``/``.mat``, ``.json`` (pandapower or ANDES) or ``.xlsx`` (ANDES).
    dyr : str or Path, optional
        PSS/E dynamic data for a ``.raw`` or an ANDES case.
    f_hz : float
        Nominal frequency [Hz] of a MATPOWER or pandapower case (PSS/E and ANDES files carry
        their own).

    Raises
    ------
    DataError
        An unknown suffix, a missing file, a ``.dyr`` given to a power-flow format, a file
        the importer refuses, or ANDES missing for an ANDES format (naming the extra).
    """
    path = Path(str(path))
    fmt = case_format(path)
    if fmt is None:
        raise DataError("case", "file", str(path), "unknown case format "
                        f"'{path.suffix or '(none)'}': give a PSS/E .raw, a MATPOWER .m/.mat, "
                        "a pandapower .json or an ANDES .xlsx/.json file")
    if not path.is_file():
        raise DataError("case", "file", str(path), "no such file")
    if dyr is not None:
        dyr = Path(str(dyr))
        if dyr.suffix.lower() != ".dyr":
            raise DataError("case", "dyr", str(dyr), "give a PSS/E dynamic data file (.dyr)")
        if not dyr.is_file():
            raise DataError("case", "dyr", str(dyr), "no such file")
    if fmt == "json":
        fmt = "pandapower" if _is_pandapower_json(path) else "andes"
    if fmt in ("matpower", "pandapower") and dyr is not None:
        raise DataError("case", "dyr", str(dyr), f"a {fmt} case is a power-flow case: its "
                        "machines are classical (GENCLS) ones; a .dyr goes with a PSS/E .raw "
                        "or an ANDES case")
    if fmt == "psse":
        from .psse import from_psse

        system, events = from_psse(path, dyr)
        return Case(system, fmt, list(events), list(getattr(system, "import_notes", [])))
    if fmt == "andes":
        return _andes_case(path, dyr)
    from ..templates import classical_system

    if fmt == "matpower":
        from .matpower import load_matpower

        case = load_matpower(path)
    else:
        case = _pandapower_net(path)
        f_hz = float(getattr(case, "f_hz", None) or f_hz)
    system = classical_system(case, setup=False, f_hz=f_hz)
    notes = [f"{len(system.machine_names)} classical machine(s) (GENCLS, H = 4 s, x'd = 0.3 pu "
             "on each machine's rating) added to the power-flow case: "
             "weakgrid.sim.templates.classical_system"]
    system.import_notes = notes
    return Case(system, fmt, [], notes)


def _pandapower_net(path):
    import warnings

    import pandapower as pp

    from ...logs import quiet_loggers

    with warnings.catch_warnings(), quiet_loggers("pandapower"):
        warnings.simplefilter("ignore")
        try:
            return pp.from_json(str(path))
        except Exception as exc:  # pandapower's own parser errors carry no common type
            raise DataError("pandapower case", "file", str(path),
                            f"pandapower.from_json could not read it ({type(exc).__name__}: "
                            f"{exc})") from None


def _andes_case(path, dyr):
    try:
        import andes
    except ImportError:
        raise DataError("case", "file", str(path), "an ANDES case needs the optional ANDES "
                        "parser: pip install 'weakgrid[andes]'") from None
    from ...logs import quiet_loggers
    from .andes import from_andes

    with quiet_loggers("andes"):
        ss = andes.load(str(path), addfile=None if dyr is None else str(dyr), setup=False,
                        no_output=True, default_config=True)
    if ss is None:
        raise DataError("ANDES case", "file", str(path), "ANDES could not parse it")
    system, events = from_andes(ss)
    return Case(system, "andes", list(events), list(getattr(system, "import_notes", [])))
