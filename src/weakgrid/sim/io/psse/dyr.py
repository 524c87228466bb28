"""PSS/E ``.dyr`` dynamic data: records ``IBUS 'MODEL' ID values /``.

A record may span lines and ends at an unquoted ``/`` (what follows on that line is a
comment; a line starting with ``//`` is an empty record). Model names and text values
may be quoted (``'GENROU'``, ``'EG'``, ``'0 '``); the machine ``ID`` may be quoted or bare
(``1``, ``EG``). Values are kept as written: an unquoted value must be a number, a quoted one
is text (e.g. a circuit id ICON). Lines starting with ``@!`` are comments.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ...errors import DataError
from .tokens import split_line


@dataclass
class DyrRecord:
    """One ``.dyr`` record.

    Attributes
    ----------
    file : str
        File name (no directory), for messages.
    line : int
        1-based line of the record's first field.
    bus : int
        ``IBUS``.
    model : str
        Model name, upper case, no quotes.
    id : str
        Machine identifier, stripped.
    values : list of (float or str)
        The record's values after ``ID`` (ICONs, CONs; text values as str).
    value_lines : list of int
        Line of each value.
    """

    file: str
    line: int
    bus: int
    model: str
    id: str
    values: list
    value_lines: list

    @property
    def where(self) -> str:
        return f"{self.file} line {self.line}, {self.model} at bus {self.bus} id '{self.id}'"


def read_dyr(path) -> list[DyrRecord]:
    """Read every record of a ``.dyr`` file.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    list of DyrRecord, in file order.

    Raises
    ------
    DataError
        Naming the file, line, record and field: a non-numeric bus number or value, a record
        without a model name or id, a record not ended by ``/`` at the end of the file.
    """
    path = Path(path)
    if not path.exists():
        raise DataError("PSS/E .dyr", "path", str(path), "the file does not exist")
    name = path.name
    with open(path, encoding="latin-1") as fh:
        lines = fh.read().splitlines()
    out = []
    cur = []   # (Field, line) of the record being read
    for ln, s in enumerate(lines, start=1):
        if s.lstrip().startswith("@!"):
            continue
        fields, slash = split_line(s)
        cur.extend((f, ln) for f in fields if f.text is not None)
        if slash:
            if cur:
                out.append(_record(name, cur))
            cur = []
    if cur:
        f0, ln0 = cur[0]
        raise DataError(f"{name} line {ln0}, record {' '.join(f.text for f, _ in cur[:3])}", "/", None,
                        f"the record starting on line {ln0} is not ended by '/' (truncated file?): "
                        "end each record with /")
    return out


def _record(name, cur) -> DyrRecord:
    (fb, lb) = cur[0]
    if len(cur) < 3:
        raise DataError(f"{name} line {lb}, record {' '.join(f.text for f, _ in cur)}", "ID", None,
                        "a record starts with IBUS 'MODEL' ID: give all three")
    try:
        bus = int(float(fb.text))
    except ValueError:
        raise DataError(f"{name} line {lb}, record {fb.text} {cur[1][0].text}", "IBUS", fb.text,
                        "the record's first field is its bus number (an integer)") from None
    model = cur[1][0].text.strip().upper()
    rid = cur[2][0].text.strip()
    rec = DyrRecord(name, lb, bus, model, rid, [], [])
    for k, (f, ln) in enumerate(cur[3:]):
        if f.quoted:
            rec.values.append(f.text)
        else:
            try:
                rec.values.append(float(f.text.replace("D", "E").replace("d", "e")))
            except ValueError:
                raise DataError(f"{name} line {ln}, {model} at bus {bus} id '{rid}'", f"value {k + 1}", f.text,
                                "must be a number (text values are written in quotes)") from None
        rec.value_lines.append(ln)
    return rec
