"""Splitting PSS/E ``.raw`` and ``.dyr`` lines into fields.

PSS/E data are free format: fields are separated by commas or blanks (a comma between
blanks counts once; two commas with nothing between them leave a field empty: its default),
text is quoted with ``'`` or ``"`` and may hold blanks, commas and slashes, and an unquoted
``/`` ends the data of the line (what follows is a comment; in a ``.dyr`` file it also ends
the record).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Field:
    """One field of a line.

    Attributes
    ----------
    text : str or None
        The field's text without quotes (``None``: empty, between two commas).
    quoted : bool
        Written in quotes (a text field).
    """

    text: str | None
    quoted: bool = False


def split_line(line: str) -> tuple[list[Field], bool]:
    """Fields of one line and whether an unquoted ``/`` ended it.

    Parameters
    ----------
    line : str
        One line of a ``.raw`` or ``.dyr`` file.

    Returns
    -------
    fields : list of Field
    slash : bool
        ``True`` if the line's data ended at an unquoted ``/`` (end of a ``.dyr`` record).
    """
    fields: list[Field] = []
    n = len(line)
    i = 0
    comma = False     # the last separator was a comma with no field after it yet
    while i < n:
        c = line[i]
        if c in " \t\r\n":
            i += 1
        elif c == ",":
            if comma or not fields:
                fields.append(Field(None))
            comma = True
            i += 1
        elif c == "/":
            return fields, True
        elif c in "'\"":
            j = line.find(c, i + 1)
            if j < 0:
                j = n
            fields.append(Field(line[i + 1:j], True))
            comma = False
            i = j + 1
        else:
            j = i
            while j < n and line[j] not in " \t\r\n,/":
                j += 1
            fields.append(Field(line[i:j]))
            comma = False
            i = j
    return fields, False
