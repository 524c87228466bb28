"""Import an ANDES system (loaded with ``andes.load(..., setup=False)``) into weakgrid.

Supported ANDES models: ``Bus``, ``Line``, ``PQ``, ``Shunt``, ``PV``, ``Slack``,
``GENCLS``, ``GENROU``, ``EXDC2``, ``SEXS``, ``TGOV1``, ``IEEEST`` (modes 1, 3,
4, 5), the exciters ``ESST3A``, ``EXST1``, ``IEEEX1``, ``IEEET1``, ``EXAC1``,
``ESDC2A``, the governors ``IEEEG1`` (with ``syn2``), ``IEESGO``, ``TG2``,
``TGOV1N``, the PSS ``ST2CUT`` (modes 0, 1, 3, 4, 5) and the events ``Toggle`` (of a ``Line``) and ``Fault``. Any other model
with devices raises :class:`~weakgrid.sim.errors.DataError`.

Raw ANDES input data are used (device bases); the per-unit conversions are
done by weakgrid exactly as ANDES does (impedances by ``(Vn^2/Sn)/(Vb^2/Sb)``,
powers and inertias by ``Sn/Sb``). PQ loads become constant impedances in the
time domain, as with ANDES's default ``p2z = q2z = 1``.

ANDES is an optional dependency and is not imported by this module; pass the
loaded ``andes.System``.
"""

from __future__ import annotations

import numpy as np

from ..errors import DataError
from ..events import Fault, LineTrip
from ..system import System

_SUPPORTED = {"Bus", "Line", "PQ", "Shunt", "PV", "Slack", "GENCLS", "GENROU", "EXDC2", "SEXS",
              "TGOV1", "IEEEST", "Toggle", "Fault", "Area", "Summary", "BusFreq", "COI"}
_SUPPORTED |= {"ESST3A", "EXST1", "IEEEX1", "IEEET1", "EXAC1", "ESDC2A", "IEEEG1", "IEESGO", "TG2", "TGOV1N",
               "ST2CUT"}
_EXCITERS = {"EXDC2", "SEXS", "ESST3A", "EXST1", "IEEEX1", "IEEET1", "EXAC1", "ESDC2A"}
_PSS = {"IEEEST", "ST2CUT"}

_MACHINE_FIELDS = {
    "GENCLS": ("Sn", "Vn", "fn", "D", "M", "ra", "xd1"),
    "GENROU": ("Sn", "Vn", "fn", "D", "M", "ra", "xd1", "xl", "xd", "xq", "xd2", "xq1", "xq2",
               "Td10", "Td20", "Tq10", "Tq20", "S10", "S12"),
}
_CONTROL_FIELDS = {
    "EXDC2": ("TR", "TA", "TC", "TB", "TE", "TF1", "KF1", "KA", "KE", "VRMAX", "VRMIN", "E1", "SE1", "E2", "SE2"),
    "SEXS": ("TATB", "TB", "K", "TE", "EMIN", "EMAX"),
    "TGOV1": ("Tn", "wref0", "R", "VMAX", "VMIN", "T1", "T2", "T3", "Dt"),
    "IEEEST": ("MODE", "A1", "A2", "A3", "A4", "A5", "A6", "T1", "T2", "T3", "T4", "T5", "T6", "KS",
               "LSMAX", "LSMIN", "VCU", "VCL"),
    "ESST3A": ("TR", "VIMAX", "VIMIN", "KM", "TC", "TB", "KA", "TA", "VRMAX", "VRMIN", "KG", "KP", "KI",
               "VBMAX", "KC", "XL", "VGMAX", "THETAP", "TM", "VMMAX", "VMMIN"),
    "EXST1": ("TR", "VIMAX", "VIMIN", "TC", "TB", "KA", "TA", "VRMAX", "VRMIN", "KC", "KF", "TF"),
    "IEEEX1": ("TR", "TA", "TC", "TB", "TE", "TF1", "KF1", "KA", "KE", "VRMAX", "VRMIN", "E1", "SE1", "E2", "SE2"),
    "IEEET1": ("TR", "KA", "TA", "VRMAX", "VRMIN", "KE", "TE", "KF", "TF", "Switch", "E1", "SE1", "E2", "SE2"),
    "EXAC1": ("TR", "TB", "TC", "KA", "TA", "VRMAX", "VRMIN", "TE", "KF", "TF", "KC", "KD", "KE",
              "E1", "SE1", "E2", "SE2"),
    "ESDC2A": ("TR", "KA", "TA", "TB", "TC", "VRMAX", "VRMIN", "KE", "TE", "KF", "TF1", "Switch",
               "E1", "SE1", "E2", "SE2"),
    "IEEEG1": ("Tn", "wref0", "K", "T1", "T2", "T3", "UO", "UC", "PMAX", "PMIN", "T4", "K1", "K2", "T5", "K3",
               "K4", "T6", "K5", "K6", "T7", "K7", "K8"),
    "IEESGO": ("Tn", "wref0", "T1", "T2", "T3", "T4", "T5", "T6", "K1", "K2", "K3", "PMAX", "PMIN"),
    "TG2": ("Tn", "wref0", "R", "pmax", "pmin", "dbl", "dbu", "dbc", "T1", "T2"),
    "TGOV1N": ("Tn", "wref0", "R", "VMAX", "VMIN", "T1", "T2", "T3", "Dt"),
    "ST2CUT": ("MODE", "MODE2", "K1", "K2", "T1", "T2", "T3", "T4", "T5", "T6", "T7", "T8", "T9", "T10",
               "LSMAX", "LSMIN", "VCU", "VCL"),
}


def _col(m, name):
    p = getattr(m, name)
    return list(p.v)


def _raw(m, name):
    """Raw (input-base) numeric values of parameter ``name`` of ANDES model ``m``."""
    p = getattr(m, name)
    v = getattr(p, "vin", None)
    if v is None:
        v = p.v
    return np.asarray(v, dtype=float)


def from_andes(ss, include_events: bool = True):
    """Build a weakgrid :class:`System` and its event list from an ANDES system.

    Parameters
    ----------
    ss : andes.System
        Loaded with ``setup=False`` (the raw device data are read).
    include_events : bool
        Convert ANDES ``Toggle`` (line) and ``Fault`` devices into weakgrid events.

    Returns
    -------
    system : System
        Not yet set up (call :meth:`System.setup`).
    events : list
        weakgrid events equivalent to the case's own timed events.
    """
    for name, mdl in ss.models.items():
        if mdl.n > 0 and name not in _SUPPORTED:
            raise DataError(f"ANDES model {name}", "n", mdl.n,
                            f"not supported by weakgrid.sim; supported: {sorted(_SUPPORTED)}")
    Sb = float(ss.config.mva)
    bus = ss.Bus
    nb = bus.n
    bidx = list(bus.idx.v)
    pos = {b: i for i, b in enumerate(bidx)}
    Vn_bus = _raw(bus, "Vn")
    B = np.zeros((nb, 13))
    B[:, 0] = np.arange(1, nb + 1)
    B[:, 1] = 1
    B[:, 6] = 1
    B[:, 7] = _raw(bus, "v0")
    B[:, 8] = np.degrees(_raw(bus, "a0"))
    B[:, 9] = Vn_bus
    B[:, 10] = 1
    B[:, 11] = _raw(bus, "vmax")
    B[:, 12] = _raw(bus, "vmin")
    pq = ss.PQ
    for k in range(pq.n):
        if _raw(pq, "u")[k] > 0:
            i = pos[pq.bus.v[k]]
            B[i, 2] += _raw(pq, "p0")[k] * Sb
            B[i, 3] += _raw(pq, "q0")[k] * Sb
    if "Shunt" in ss.models:
        sh = ss.Shunt
        for k in range(sh.n):
            if _raw(sh, "u")[k] > 0:
                i = pos[sh.bus.v[k]]
                Sn, Vn = _raw(sh, "Sn")[k], _raw(sh, "Vn")[k]
                c = (Sn / Sb) * (Vn_bus[i] / Vn) ** -2 if Vn > 0 else Sn / Sb
                B[i, 4] += _raw(sh, "g")[k] * c * Sb
                B[i, 5] += _raw(sh, "b")[k] * c * Sb
    G = []
    gen_row = {}
    for mname, btype in (("Slack", 3), ("PV", 2)):
        m = ss.models[mname]
        for k in range(m.n):
            i = pos[m.bus.v[k]]
            u = _raw(m, "u")[k]
            if u > 0:
                B[i, 1] = max(B[i, 1], btype) if btype == 2 else 3
            v0 = _raw(m, "v0")[k]
            B[i, 7] = v0
            if mname == "Slack":
                B[i, 8] = np.degrees(_raw(m, "a0")[k])
            row = np.zeros(21)
            row[0] = i + 1
            row[1] = _raw(m, "p0")[k] * Sb
            row[2] = _raw(m, "q0")[k] * Sb
            row[3], row[4] = 9999.0, -9999.0
            row[5] = v0
            row[6] = _raw(m, "Sn")[k]
            row[7] = 1 if u > 0 else 0
            row[8], row[9] = 9999.0, -9999.0
            gen_row[m.idx.v[k]] = len(G)
            G.append(row)
    line = ss.Line
    L = np.zeros((line.n, 13))
    for k in range(line.n):
        i, j = pos[line.bus1.v[k]], pos[line.bus2.v[k]]
        Sn, Vn1 = _raw(line, "Sn")[k], _raw(line, "Vn1")[k]
        zc = (Vn1 ** 2 / Sn) / (Vn_bus[i] ** 2 / Sb)
        g, g1, g2 = _raw(line, "g")[k], _raw(line, "g1")[k], _raw(line, "g2")[k]
        b, b1, b2 = _raw(line, "b")[k], _raw(line, "b1")[k], _raw(line, "b2")[k]
        if g or g1 or g2:
            raise DataError(f"ANDES Line {line.idx.v[k]}", "g", g, "line conductances are not supported; set g=g1=g2=0")
        if b1 != b2:
            raise DataError(f"ANDES Line {line.idx.v[k]}", "b1", b1, "asymmetric line charging (b1 != b2) unsupported")
        tap = _raw(line, "tap")[k]
        L[k, :] = [i + 1, j + 1, _raw(line, "r")[k] * zc, _raw(line, "x")[k] * zc, (b + b1 + b2) / zc,
                   0, 0, 0, 0 if tap == 1 else tap, np.degrees(_raw(line, "phi")[k]),
                   1 if _raw(line, "u")[k] > 0 else 0, -360, 360]
    case = {"baseMVA": Sb, "bus": B, "gen": np.array(G), "branch": L}
    fn = 60.0
    if "GENROU" in ss.models and ss.GENROU.n:
        fn = float(_raw(ss.GENROU, "fn")[0])
    elif "GENCLS" in ss.models and ss.GENCLS.n:
        fn = float(_raw(ss.GENCLS, "fn")[0])
    system = System(_network(case, fn))
    # machines
    syn_name = {}
    for mname, fields in _MACHINE_FIELDS.items():
        m = ss.models.get(mname)
        if m is None:
            continue
        for k in range(m.n):
            if _raw(m, "u")[k] <= 0:
                continue
            for fld in ("gammap", "gammaq"):
                if _raw(m, fld)[k] != 1:
                    raise DataError(f"ANDES {mname} {m.idx.v[k]}", fld, _raw(m, fld)[k],
                                    "only one machine per static generator (gamma = 1) is supported")
            params = {f: float(_raw(m, f)[k]) for f in fields}
            name = str(m.name.v[k]) if m.name.v[k] not in syn_name.values() else f"{mname}_{m.idx.v[k]}"
            name = f"{mname}_{m.idx.v[k]}"
            system.add_machine(mname, name, gen_row[m.gen.v[k]], **params)
            syn_name[m.idx.v[k]] = name
    avr_syn = {}
    # exciters first (PSSs are linked to them), then governors, then PSSs
    for mname, fields in sorted(_CONTROL_FIELDS.items(), key=lambda kv: (kv[0] in _PSS) - (kv[0] in _EXCITERS)):
        m = ss.models.get(mname)
        if m is None:
            continue
        for k in range(m.n):
            if _raw(m, "u")[k] <= 0:
                continue
            params = {f: float(_raw(m, f)[k]) for f in fields}
            if mname == "ST2CUT":
                params["MODE2"] = 0.0 if not np.isfinite(params["MODE2"]) else params["MODE2"]
                for fld in ("busr", "busr2"):
                    if getattr(m, fld).v[k] not in (None, ""):
                        raise DataError(f"ANDES ST2CUT {m.idx.v[k]}", fld, getattr(m, fld).v[k],
                                        "remote-bus inputs are not supported; leave it empty")
            name = f"{mname}_{m.idx.v[k]}"
            if mname in _PSS:
                syn = avr_syn[m.avr.v[k]]
                system.add_pss(mname, name, syn, **params)
            else:
                syn = syn_name[m.syn.v[k]]
                if mname in _EXCITERS:
                    avr_syn[m.idx.v[k]] = syn
                    system.add_exciter(mname, name, syn, **params)
                elif mname == "IEEEG1" and m.syn2.v[k] not in (None, ""):
                    system.add_governor(mname, name, syn, machine2=syn_name[m.syn2.v[k]], **params)
                else:
                    system.add_governor(mname, name, syn, **params)
    events = []
    if include_events:
        lpos = {ix: k for k, ix in enumerate(line.idx.v)}
        if "Toggle" in ss.models:
            tg = ss.Toggle
            for k in range(tg.n):
                if _raw(tg, "u")[k] <= 0:
                    continue
                if tg.model.v[k] != "Line":
                    raise DataError(f"ANDES Toggle {tg.idx.v[k]}", "model", tg.model.v[k], "only Line toggles supported")
                events.append(LineTrip(lpos[tg.dev.v[k]], float(_raw(tg, "t")[k])))
        if "Fault" in ss.models:
            fl = ss.Fault
            for k in range(fl.n):
                if _raw(fl, "u")[k] <= 0:
                    continue
                tc = float(_raw(fl, "tc")[k])
                events.append(Fault(pos[fl.bus.v[k]] + 1, float(_raw(fl, "tf")[k]), tc if tc > 0 else None,
                                    rf=float(_raw(fl, "rf")[k]), xf=float(_raw(fl, "xf")[k])))
    system.andes_bus_id = {b: pos[b] + 1 for b in bidx}
    system.andes_line_row = {ix: k for k, ix in enumerate(line.idx.v)}
    return system, events


def _network(case, fn):
    from ..network import Network

    return Network(case, f_hz=fn)
