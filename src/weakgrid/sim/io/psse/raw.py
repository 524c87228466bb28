"""PSS/E ``.raw`` power-flow data, versions 29 to 35: the records weakgrid needs.

Read: the case identification (``SBASE`` [MVA], ``REV``, ``BASFRQ`` [Hz]), buses, loads
(their constant-power, constant-current and constant-admittance parts), fixed shunts,
generators (``MBASE``, ``ZSORCE``, status, ``PT``/``PB``), non-transformer branches,
system switching devices (v34+), two- and three-winding transformers, switched shunts (at
their solved susceptance ``BINIT``) and multi-section line groupings (whose sections are
ordinary branches). Areas, zones, owners, inter-area transfers, impedance correction tables,
substations and the system-wide data of v34/35 are bookkeeping for weakgrid and skipped. Two-
and multi-terminal dc lines, VSC dc lines, FACTS devices, GNE devices and induction machines
are kept as :attr:`RawCase.unsupported` (the builder refuses those in service).

Layouts by version (0-based field positions that differ):

========================  ==================  ==========================================
record                    versions            layout
========================  ==================  ==========================================
bus                       29, 30              I, NAME, BASKV, IDE, GL, BL, AREA, ZONE, VM, VA
bus                       31 to 35            I, NAME, BASKV, IDE, AREA, ZONE, OWNER, VM, VA
generator                 29 to 33            ..., VS, IREG, MBASE, ZR, ZX, RT, XT, GTAP, STAT
generator                 34, 35              ..., VS, IREG, NREG, MBASE, ZR, ..., STAT
branch                    29 to 33            I, J, CKT, R, X, B, RATEA..C, GI, BI, GJ, BJ, ST
branch                    34, 35              I, J, CKT, R, X, B, NAME, RATE1..12, GI, .., ST
========================  ==================  ==========================================

Sections are recognized by the ``BEGIN ... DATA`` comment PSS/E writes on each
section-ending ``0`` record, else by the version's section order. Lines starting with ``@!``
(comments, v34+) are skipped. Every error names the file, the line, the record and the field.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ...errors import DataError
from .tokens import split_line

VERSIONS = range(29, 36)

#: section names in file order, by version
_ORDER_29 = ["bus", "load", "generator", "branch", "transformer", "area", "two-terminal dc",
             "vsc dc", "switched shunt", "impedance correction", "multi-terminal dc",
             "multi-section line", "zone", "inter-area transfer", "owner", "facts"]
_ORDER_31 = ["bus", "load", "fixed shunt", "generator", "branch", "transformer", "area",
             "two-terminal dc", "vsc dc", "impedance correction", "multi-terminal dc",
             "multi-section line", "zone", "inter-area transfer", "owner", "facts",
             "switched shunt", "gne"]
_ORDER_33 = _ORDER_31 + ["induction machine"]
_ORDER_34 = (_ORDER_31[:5] + ["system switching device"] + _ORDER_31[5:]
             + ["induction machine", "substation"])

#: how a section-ending comment names each section (tested in this order: specific first)
_NAMES = [("system switching device", "system switching device"), ("switching device", "system switching device"),
          ("non-transformer branch", "branch"), ("impedance correction", "impedance correction"),
          ("two-terminal", "two-terminal dc"), ("multi-terminal", "multi-terminal dc"),
          ("vsc dc", "vsc dc"), ("voltage source converter", "vsc dc"), ("multi-section", "multi-section line"),
          ("inter-area", "inter-area transfer"), ("fixed shunt", "fixed shunt"),
          ("switched shunt", "switched shunt"), ("induction machine", "induction machine"),
          ("transformer", "transformer"), ("branch", "branch"), ("generator", "generator"),
          ("load", "load"), ("bus", "bus"), ("area", "area"), ("zone", "zone"), ("owner", "owner"),
          ("facts", "facts"), ("gne", "gne"), ("substation", "substation")]

#: sections whose devices weakgrid does not model (refused when in service)
UNSUPPORTED = ("two-terminal dc", "vsc dc", "multi-terminal dc", "facts", "gne", "induction machine")


def section_order(version: int) -> list[str]:
    """Section names of a ``.raw`` file of ``version``, in file order."""
    if version <= 30:
        return list(_ORDER_29)
    if version <= 32:
        return list(_ORDER_31)
    if version == 33:
        return list(_ORDER_33)
    return list(_ORDER_34)


@dataclass
class Record:
    """One record: its fields and where it was read.

    Attributes
    ----------
    section : str
    line : int
        1-based line number of its first line.
    lines : list of list of Field
        The fields of each of its lines (transformers have 4 or 5 lines).
    """

    section: str
    line: int
    lines: list


@dataclass
class RawCase:
    """The records of a ``.raw`` file weakgrid uses, as dicts of named values.

    Attributes
    ----------
    path : str
    version : int
        ``REV``.
    sbase : float
        System base [MVA].
    basfrq : float
        Nominal frequency [Hz] (60 if not given).
    title : list of str
        The two title lines.
    buses, loads, fixed_shunts, generators, branches, transformers, switched_shunts : list of dict
        Each dict has the record's fields by their PSS/E names (lower case) and ``line``.
    unsupported : dict
        Section name -> list of ``(line, in_service, label)`` of devices weakgrid lacks.
    notes : list of str
        What was skipped (bookkeeping sections).
    """

    path: str
    version: int
    sbase: float
    basfrq: float
    title: list = field(default_factory=list)
    buses: list = field(default_factory=list)
    loads: list = field(default_factory=list)
    fixed_shunts: list = field(default_factory=list)
    generators: list = field(default_factory=list)
    branches: list = field(default_factory=list)
    switching_devices: list = field(default_factory=list)
    transformers: list = field(default_factory=list)
    switched_shunts: list = field(default_factory=list)
    multi_section: list = field(default_factory=list)
    impedance_tables: list = field(default_factory=list)
    unsupported: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)


class _Reader:
    """Field access with errors naming the file, line, record and field."""

    def __init__(self, path):
        self.path = str(path)
        self.name = Path(path).name

    def where(self, line, record):
        return f"{self.name} line {line}, {record}"

    def num(self, fields, k, name, line, record, default=None, kind=float):
        f = fields[k] if k < len(fields) else None
        if f is None or f.text is None or (f.text == "" and not f.quoted):
            if default is None:
                raise DataError(self.where(line, record), name, None,
                                f"the record ends before field {k + 1} ({name}): complete the record "
                                "(truncated line?)")
            return default
        try:
            v = float(f.text.replace("D", "E").replace("d", "e"))
        except ValueError:
            raise DataError(self.where(line, record), name, f.text,
                            f"field {k + 1} ({name}) must be a number") from None
        if kind is int:
            if v != int(v):
                raise DataError(self.where(line, record), name, f.text,
                                f"field {k + 1} ({name}) must be an integer")
            return int(v)
        return v

    @staticmethod
    def text(fields, k, default=""):
        f = fields[k] if k < len(fields) else None
        return default if f is None or f.text is None else f.text.strip()


def _section_of(comment: str):
    """Section named after ``BEGIN`` in a section-ending comment, or None."""
    c = comment.lower()
    k = c.find("begin")
    if k < 0:
        return None
    c = c[k + 5:]
    for key, name in _NAMES:
        if key in c:
            return name
    return None


_ID_RECORD = "case identification (IC, SBASE, REV, XFRRAT, NXFRAT, BASFRQ)"


def _version(rd, f0, ln0, rec) -> int:
    """``REV`` of the case identification record, one of :data:`VERSIONS`."""
    rev_f = f0[2] if len(f0) > 2 else None
    if rev_f is None or rev_f.text is None:
        raise DataError(rd.where(ln0, rec), "REV", None,
                        "the case identification gives no PSS/E version; weakgrid reads versions "
                        "29 to 35: save the case from PSS/E with one of them (rawd_2 ... vernum)")
    rev = rd.num(f0, 2, "REV", ln0, rec)
    if rev != int(rev) or int(rev) not in VERSIONS:
        raise DataError(rd.where(ln0, rec), "REV", rev_f.text,
                        f"the file claims PSS/E version {rev_f.text}; weakgrid reads PSS/E .raw "
                        "versions 29 to 35; convert the case (e.g. save it from PSS/E as "
                        "version 33)")
    return int(rev)


def raw_version(path) -> int:
    """The PSS/E version (``REV``) a ``.raw`` file claims, checked to be one of 29-35 (as
    :func:`read_raw` checks it) without reading the rest: for readers of other libraries
    that would misread a layout they do not know."""
    path = Path(path)
    rd = _Reader(path)
    with open(path, encoding="latin-1") as fh:
        for k, s in enumerate(fh):
            if not s.lstrip().startswith("@!"):
                f0, _ = split_line(s.rstrip("\n"))
                return _version(rd, f0, k + 1, _ID_RECORD)
    raise DataError(rd.where(1, "case identification"), "IC", None, "the file is empty")


def read_raw(path) -> RawCase:
    """Read a PSS/E ``.raw`` file (versions 29-35).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    RawCase

    Raises
    ------
    DataError
        Naming the file, line, record and field: a version outside 29-35, a record with a
        missing or non-numeric field, a file that ends inside a section.
    """
    path = Path(path)
    if not path.exists():
        raise DataError("PSS/E .raw", "path", str(path), "the file does not exist")
    rd = _Reader(path)
    with open(path, encoding="latin-1") as fh:
        lines = fh.read().splitlines()
    # drop @! comment lines (v34+), keep line numbers
    numbered = [(k + 1, s) for k, s in enumerate(lines) if not s.lstrip().startswith("@!")]
    if not numbered:
        raise DataError(rd.where(1, "case identification"), "IC", None, "the file is empty")
    ln0, s0 = numbered[0]
    f0, _ = split_line(s0)
    rec = _ID_RECORD
    sbase = rd.num(f0, 1, "SBASE", ln0, rec, default=100.0)
    if not sbase > 0:
        raise DataError(rd.where(ln0, rec), "SBASE", sbase, "the system base must be > 0 MVA")
    version = _version(rd, f0, ln0, rec)
    basfrq = rd.num(f0, 5, "BASFRQ", ln0, rec, default=60.0)
    if not basfrq > 0:
        basfrq = 60.0
    def is_zero(line):
        flds, _ = split_line(line)
        return len(flds) == 1 and flds[0].text == "0" and not flds[0].quoted

    # two title lines; a writer that ends a (possibly empty) system-wide data section within them
    # ("0 / END OF SYSTEM-WIDE DATA", seen in v33 files) has no further title
    pos, title, sysdata_done = 1, [], False
    while pos < min(3, len(numbered)):
        if is_zero(numbered[pos][1]):
            pos += 1
            sysdata_done = True
            break
        title.append(numbered[pos][1])
        pos += 1
    case = RawCase(str(path), version, sbase, basfrq, title=title)
    if version >= 34 and not sysdata_done:   # system-wide data, up to its ending 0 record
        while pos < len(numbered):
            flds, _ = split_line(numbered[pos][1])
            pos += 1
            if flds and flds[0].text == "0" and not flds[0].quoted:
                break
        else:
            raise DataError(rd.where(numbered[-1][0], "system-wide data"), "0", None,
                            "the file ends inside the system-wide data section (no ending 0 record)")
    order = section_order(version)
    records = {name: [] for name in order}
    k_sec = 0
    current = order[0]
    while pos < len(numbered):
        ln, s = numbered[pos]
        flds, slash = split_line(s)
        head = flds[0].text if flds else None
        if not flds:
            pos += 1
            continue
        if head is not None and head.upper() == "Q" and not flds[0].quoted:
            break
        if head == "0" and not flds[0].quoted and len(flds) == 1:
            # end of the section; the comment may name the next one
            nxt = _section_of(s[s.find("/") + 1:]) if slash else None
            if nxt is None or nxt not in order:
                k_sec += 1
                nxt = order[k_sec] if k_sec < len(order) else None
            else:
                k_sec = order.index(nxt)
            pos += 1
            if nxt is None:
                break
            current = nxt
            continue
        nl = _record_lines(current, flds, version)
        if pos + nl > len(numbered):
            have = len(numbered) - pos
            first = _LINE_HEADS.get(current, ())
            field = first[have] if have < len(first) else f"line {have + 1}"
            raise DataError(rd.where(ln, f"{current} record"), field, None,
                            f"the file ends inside a {current} record: it has {have} of its {nl} lines, "
                            f"line {have + 1} (from {field}) and after are missing; complete it")
        rl = [flds] + [split_line(numbered[pos + j][1])[0] for j in range(1, nl)]
        records[current].append(Record(current, ln, rl))
        pos += nl
    else:
        if k_sec < len(order) - 1 and order.index(current) < order.index("switched shunt"):
            raise DataError(rd.where(numbered[-1][0], f"{current} data"), "0", None,
                            f"the file ends inside the {current} section (truncated file?): "
                            "each section ends with a 0 record, the file with Q")
    _parse(case, records, rd)
    return case


#: first field of each line of the multi-line records (PSS/E's POM), to name what a truncated one lacks
_LINE_HEADS = {"transformer": ("I", "R1-2", "WINDV1", "WINDV2", "WINDV3"),
               "two-terminal dc": ("NAME", "IPR", "IPI"), "vsc dc": ("NAME", "IBUS", "IBUS")}


def _record_lines(section, flds, version):
    """Number of lines of a record starting with ``flds``."""
    if section == "transformer":
        try:
            k = int(float(flds[2].text)) if len(flds) > 2 and flds[2].text else 0
        except ValueError:
            k = 0
        return 4 if k == 0 else 5
    if section in ("two-terminal dc", "vsc dc"):
        return 3
    return 1


def _parse(case: RawCase, records: dict, rd: _Reader):
    v = case.version
    num = rd.num
    for r in records.get("bus", []):
        f, ln, rec = r.lines[0], r.line, "bus record"
        b = {"line": ln, "i": num(f, 0, "I", ln, rec, kind=int), "name": rd.text(f, 1),
             "baskv": num(f, 2, "BASKV", ln, rec, default=0.0), "ide": num(f, 3, "IDE", ln, rec, default=1, kind=int)}
        if v <= 30:
            b.update(gl=num(f, 4, "GL", ln, rec, default=0.0), bl=num(f, 5, "BL", ln, rec, default=0.0),
                     vm=num(f, 8, "VM", ln, rec, default=1.0), va=num(f, 9, "VA", ln, rec, default=0.0))
        else:
            b.update(gl=0.0, bl=0.0, vm=num(f, 7, "VM", ln, rec, default=1.0),
                     va=num(f, 8, "VA", ln, rec, default=0.0))
        case.buses.append(b)
    for r in records.get("load", []):
        f, ln, rec = r.lines[0], r.line, "load record"
        case.loads.append({"line": ln, "i": num(f, 0, "I", ln, rec, kind=int), "id": rd.text(f, 1, "1"),
                           "status": num(f, 2, "STATUS", ln, rec, default=1, kind=int),
                           **{k.lower(): num(f, 5 + j, k, ln, rec, default=0.0)
                              for j, k in enumerate(("PL", "QL", "IP", "IQ", "YP", "YQ"))}})
    for r in records.get("fixed shunt", []):
        f, ln, rec = r.lines[0], r.line, "fixed shunt record"
        case.fixed_shunts.append({"line": ln, "i": num(f, 0, "I", ln, rec, kind=int), "id": rd.text(f, 1, "1"),
                                  "status": num(f, 2, "STATUS", ln, rec, default=1, kind=int),
                                  "gl": num(f, 3, "GL", ln, rec, default=0.0), "bl": num(f, 4, "BL", ln, rec, default=0.0)})
    for r in records.get("generator", []):
        f, ln, rec = r.lines[0], r.line, "generator record"
        o = 1 if v >= 34 else 0     # NREG (v34+) after IREG
        g = {"line": ln, "i": num(f, 0, "I", ln, rec, kind=int), "id": rd.text(f, 1, "1"),
             "pg": num(f, 2, "PG", ln, rec, default=0.0), "qg": num(f, 3, "QG", ln, rec, default=0.0),
             "qt": num(f, 4, "QT", ln, rec, default=9999.0), "qb": num(f, 5, "QB", ln, rec, default=-9999.0),
             "vs": num(f, 6, "VS", ln, rec, default=1.0), "ireg": num(f, 7, "IREG", ln, rec, default=0, kind=int),
             "mbase": num(f, 8 + o, "MBASE", ln, rec, default=case.sbase),
             "zr": num(f, 9 + o, "ZR", ln, rec, default=0.0), "zx": num(f, 10 + o, "ZX", ln, rec, default=1.0),
             "rt": num(f, 11 + o, "RT", ln, rec, default=0.0), "xt": num(f, 12 + o, "XT", ln, rec, default=0.0),
             "gtap": num(f, 13 + o, "GTAP", ln, rec, default=1.0),
             "stat": num(f, 14 + o, "STAT", ln, rec, default=1, kind=int),
             "pt": num(f, 16 + o, "PT", ln, rec, default=9999.0), "pb": num(f, 17 + o, "PB", ln, rec, default=-9999.0)}
        case.generators.append(g)
    for r in records.get("branch", []):
        f, ln, rec = r.lines[0], r.line, "non-transformer branch record"
        o = 10 if v >= 34 else 0    # NAME and RATE1..12 instead of RATEA..C (v34+)
        case.branches.append({
            "line": ln, "i": num(f, 0, "I", ln, rec, kind=int), "j": abs(num(f, 1, "J", ln, rec, kind=int)),
            "ckt": rd.text(f, 2, "1"), "r": num(f, 3, "R", ln, rec, default=0.0),
            "x": num(f, 4, "X", ln, rec), "b": num(f, 5, "B", ln, rec, default=0.0),
            **{k.lower(): num(f, 9 + o + j, k, ln, rec, default=0.0)
               for j, k in enumerate(("GI", "BI", "GJ", "BJ"))},
            "st": num(f, 13 + o, "ST", ln, rec, default=1, kind=int)})
    for r in records.get("system switching device", []):
        f, ln, rec = r.lines[0], r.line, "system switching device record"
        case.switching_devices.append({
            "line": ln, "i": num(f, 0, "I", ln, rec, kind=int), "j": abs(num(f, 1, "J", ln, rec, kind=int)),
            "ckt": rd.text(f, 2, "1"), "x": num(f, 3, "X", ln, rec, default=1e-4),
            "stat": num(f, 16, "STAT", ln, rec, default=1, kind=int)})
    for r in records.get("transformer", []):
        case.transformers.append(_transformer(r, rd, v))
    for r in records.get("switched shunt", []):
        case.switched_shunts.append(_switched_shunt(r, rd, v))
    for r in records.get("multi-section line", []):
        case.multi_section.append({"line": r.line, "fields": [x.text for x in r.lines[0]]})
    for r in records.get("impedance correction", []):
        f = r.lines[0]
        if f and f[0].text and not f[0].quoted:
            try:
                case.impedance_tables.append(int(float(f[0].text)))
            except ValueError:
                pass
    for sec in UNSUPPORTED:
        for r in records.get(sec, []):
            f = r.lines[0]
            on, label = _unsupported_status(sec, f, rd)
            if on is None:     # a continuation line of a multi-line record
                continue
            case.unsupported.setdefault(sec, []).append((r.line, on, label))
    skipped = [f"{sec} ({len(records[sec])})" for sec in ("area", "zone", "owner", "inter-area transfer",
                                                           "substation") if records.get(sec)]
    if skipped:
        case.notes.append(f"{Path(case.path).name}: bookkeeping records skipped: {', '.join(skipped)}")


def _unsupported_status(sec, f, rd):
    """``(in_service, label)`` of the first line of an unsupported device (None: not a record head)."""
    def txt(k):
        return f[k].text if k < len(f) and f[k].text is not None else ""

    def as_int(k):
        try:
            return int(float(txt(k)))
        except ValueError:
            return None
    if sec in ("two-terminal dc", "vsc dc"):
        mdc = as_int(1)
        return (mdc is None or mdc != 0), f"'{txt(0).strip()}'"
    if sec == "facts":
        mode = as_int(3)
        return (mode is None or mode != 0), f"'{txt(0).strip()}' (bus {txt(1)})"
    if sec == "induction machine":
        if len(f) < 3 or not f[1].quoted:
            return None, ""
        st = as_int(2)
        return (st is None or st != 0), f"bus {txt(0)} id '{txt(1).strip()}'"
    # multi-terminal dc, GNE: multi-line records of variable layout: any record counts
    if not f or not f[0].quoted:
        return None, ""
    return True, f"'{txt(0).strip()}'"


def _transformer(r: Record, rd: _Reader, v: int) -> dict:
    f1 = r.lines[0]
    ln = r.line
    rec = "transformer record"
    num = rd.num
    t = {"line": ln, "i": num(f1, 0, "I", ln, rec, kind=int), "j": abs(num(f1, 1, "J", ln, rec, kind=int)),
         "k": abs(num(f1, 2, "K", ln, rec, default=0, kind=int)), "ckt": rd.text(f1, 3, "1"),
         "cw": num(f1, 4, "CW", ln, rec, default=1, kind=int), "cz": num(f1, 5, "CZ", ln, rec, default=1, kind=int),
         "cm": num(f1, 6, "CM", ln, rec, default=1, kind=int),
         "mag1": num(f1, 7, "MAG1", ln, rec, default=0.0), "mag2": num(f1, 8, "MAG2", ln, rec, default=0.0),
         "name": rd.text(f1, 10), "stat": num(f1, 11, "STAT", ln, rec, default=1, kind=int)}
    for nm, val in (("CW", t["cw"]), ("CZ", t["cz"]), ("CM", t["cm"])):
        if val not in ((1, 2, 3) if nm != "CM" else (1, 2)):
            raise DataError(rd.where(ln, rec), nm, val,
                            f"{nm} must be {'1 or 2' if nm == 'CM' else '1, 2 or 3'} (PSS/E codes)")
    f2 = r.lines[1]
    l2 = ln + 1
    t.update(r12=num(f2, 0, "R1-2", l2, rec, default=0.0), x12=num(f2, 1, "X1-2", l2, rec),
             sb12=num(f2, 2, "SBASE1-2", l2, rec, default=0.0))
    nw = 3 if t["k"] else 2
    if nw == 3:
        t.update(r23=num(f2, 3, "R2-3", l2, rec, default=0.0), x23=num(f2, 4, "X2-3", l2, rec),
                 sb23=num(f2, 5, "SBASE2-3", l2, rec, default=0.0),
                 r31=num(f2, 6, "R3-1", l2, rec, default=0.0), x31=num(f2, 7, "X3-1", l2, rec),
                 sb31=num(f2, 8, "SBASE3-1", l2, rec, default=0.0),
                 vmstar=num(f2, 9, "VMSTAR", l2, rec, default=1.0), anstar=num(f2, 10, "ANSTAR", l2, rec, default=0.0))
    tab_k = 23 if v >= 34 else 13
    for w in range(1, nw + 1):
        fw = r.lines[1 + w]
        lw = ln + 1 + w
        t[f"windv{w}"] = num(fw, 0, f"WINDV{w}", lw, rec, default=1.0)
        t[f"nomv{w}"] = num(fw, 1, f"NOMV{w}", lw, rec, default=0.0)
        if w == 1 or nw == 3:
            t[f"ang{w}"] = num(fw, 2, f"ANG{w}", lw, rec, default=0.0)
            t[f"tab{w}"] = num(fw, tab_k, f"TAB{w}", lw, rec, default=0.0)
        else:
            t[f"ang{w}"] = 0.0
    return t


def _switched_shunt(r: Record, rd: _Reader, v: int) -> dict:
    """A switched shunt at its solved value ``BINIT`` [Mvar at 1 pu]; ``BINIT`` follows the
    quoted ``RMIDNT`` field (its position moved between versions)."""
    f, ln, rec = r.lines[0], r.line, "switched shunt record"
    q = [k for k, x in enumerate(f) if x.quoted]
    if v >= 35:
        q = [k for k in q if k > 1]   # v35: I, 'ID', MODSW, ...
    if q:
        k_rm = q[0]
    else:   # RMIDNT written unquoted (blank names): its version position
        k_rm = {29: 6, 30: 6, 34: 9, 35: 10}.get(v, 8)
    has_stat = k_rm - (1 if v >= 35 else 0) - (1 if v >= 34 else 0) >= 8
    stat_k = (4 if v >= 35 else 3)
    return {"line": ln, "i": rd.num(f, 0, "I", ln, rec, kind=int),
            "id": rd.text(f, 1, "1") if v >= 35 else "1",
            "stat": rd.num(f, stat_k, "STAT", ln, rec, default=1, kind=int) if has_stat else 1,
            "binit": rd.num(f, k_rm + 1, "BINIT", ln, rec, default=0.0)}
