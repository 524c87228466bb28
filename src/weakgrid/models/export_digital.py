"""C99 of the complete digital UPQC controller: what a DSP calls once per sampling period T.

:class:`~weakgrid.sim.controllers.DigitalController` in a study run is, per sample::

    y  = measured signals            (GTI: [ϕs, Vc];  SG: [δ, θr, ω])
    x  = state_map(y)                (weakgrid.sim.design_states)
    u  = saddle-point law u*(x)      (weakgrid.game.export_c, the trained controller)
    u ← u·min(1, Vmax/|u|)           (the UPQC rating clip, weakgrid.sim.upqc.rating_clip)
    bypassed (fault windows, or an external disable): u = u_bypass

:func:`generate_digital_c` writes it as ``NAME.h``/``NAME.c`` (state struct, parameters,
``NAME_init``, ``NAME_step``) beside the law ``NAME_law.h``/``NAME_law.c``. The constants of
the measurement mapping, the rating and the bypass windows are a parameter struct (defaults
inlined by the export); T and the law are inlined. No allocation, C99, only ``<math.h>``.
:func:`fmu_block` describes the same controller to the FMU builder :mod:`weakgrid.fmu`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..game.errors import ParameterError
from ..game.export_c import c_literal, generate_c, valid_c_name
from ..sim.design_states import GTIStateMap, SGStateMap

__all__ = ["DigitalSpec", "MAX_BYPASS", "generate_digital_c", "fmu_block",
           "spec_from_setup", "spec_from_design", "check_exportable"]

#: Capacity of the bypass-window table in the parameter struct.
MAX_BYPASS = 8

# C of each measurement mapping: the same operations, in the same order, as its __call__
_MAP_C = {
    "gti": ["s->x[0] = meas[0] - p->phi_s0;",
            "s->x[1] = p->tau * (meas[1] * meas[1] - p->Vc0 * p->Vc0) / 2.0;"],
    "sg": ["s->x[0] = meas[0] - meas[1] - p->angle0;",
           "s->x[1] = (meas[2] - 1.0) * p->ws;"],
}


@dataclass
class DigitalSpec:
    """Everything of the digital controller besides the law.

    Attributes
    ----------
    state_map : GTIStateMap or SGStateMap
        Measured signals -> design state, with the operating point's constants.
    Vmax : float or None
        UPQC series-voltage rating, the largest ``|Vu|`` [pu]; None: no clip (``Vmax <= 0`` in C).
    bypass : list of (float, float)
        Windows ``[t_start, t_end)`` [s] of the sample clock ``t0 + k·T`` in which the output
        is ``u_bypass`` (the study's fault windows).
    t0 : float
        Time of the first sample [s].
    u_bypass : (float, float)
        Output while bypassed, ``[Vup, Vuq]`` [pu].
    origin : dict
        Where each value came from (name -> text), printed in the header.
    """

    state_map: object
    Vmax: float | None = None
    bypass: list = field(default_factory=list)
    t0: float = 0.0
    u_bypass: tuple = (0.0, 0.0)
    origin: dict = field(default_factory=dict)

    def __post_init__(self):
        self.bypass = [(float(a), float(b)) for a, b in self.bypass]
        if len(self.bypass) > MAX_BYPASS:
            raise ParameterError("bypass", len(self.bypass),
                                 f"at most {MAX_BYPASS} bypass windows fit the parameter struct")
        for a, b in self.bypass:
            if not (math.isfinite(a) and math.isfinite(b) and a < b):
                raise ParameterError("bypass", (a, b), "give windows t_start < t_end in s")
        if self.Vmax is not None and not (self.Vmax > 0 and math.isfinite(self.Vmax)):
            raise ParameterError("rating", self.Vmax, "give the series-voltage rating in pu "
                                 "(> 0), or none for no clip")

    def parameters(self) -> list:
        """``(C field, value, unit, meaning)`` of every scalar parameter, in struct order."""
        m = self.state_map
        out = [(k, v, u, d) for (k, u, d), v in zip(m.constants, m.values().values())]
        out.append(("Vmax", 0.0 if self.Vmax is None else float(self.Vmax), "pu",
                    "series-voltage rating |Vu|max: u is scaled down to it (<= 0: no clip)"))
        out += [("u_bypass[0]", float(self.u_bypass[0]), "pu", "Vup while bypassed"),
                ("u_bypass[1]", float(self.u_bypass[1]), "pu", "Vuq while bypassed"),
                ("t0", float(self.t0), "s", "time of the first sample")]
        return out


def spec_from_setup(setup, bypass=(), rating=None) -> DigitalSpec:
    """The digital controller of a study's grid (:class:`weakgrid.study.build.Setup`):
    its measurement mapping and the UPQC's rating (or ``rating``), bypassed in ``bypass``."""
    up = setup.system.components.get("UPQC")
    where = f"study {setup.study.name}, load {setup.load}"
    if rating is None and up is not None and setup.upqc_name in up.names:
        rating = float(up.p["Vmax"][up.names.index(setup.upqc_name)])
        r_from = f"{where}: upqc.rating"
    else:
        r_from = "given" if rating is not None else "none"
    origin = {k: f"{where}: {setup.machine.upper()} {setup.source} at its operating point"
              for k in setup.state_map.values()}
    origin.update(Vmax=r_from, bypass="given" if bypass else "none")
    return DigitalSpec(setup.state_map, rating, list(bypass), origin=origin)


def spec_from_design(model, values=None, bypass=(), rating=None) -> DigitalSpec:
    """The digital controller from a design model (10) alone, constants ``values`` given.

    GTI: ``phi_s0`` defaults to the model's ϕs0 and ``tau`` to its recorded source; ``Vc0``
    must be given. SG: ``angle0`` (δ0 − θr0) and ``ws`` default to the model's ϕs0 (exact for a
    classical machine, whose δ is the angle of E') and ``2π·f_nominal`` of its source.
    """
    values = dict(values or {})
    src = getattr(model, "source", {}) or {}
    origin = {k: "given" for k in values}
    if model.machine == "gti":
        defaults = {"phi_s0": (model.phi_s0, "design model phi_s0"),
                    "tau": (src.get("tau"), "design model source tau"),
                    "Vc0": (src.get("Vc0"), "design model source Vc0")}
        cls = GTIStateMap
    else:
        f = src.get("f_nominal")
        defaults = {"angle0": (model.phi_s0, "design model phi_s0 (classical machine: "
                               "delta = angle of E')"),
                    "ws": (None if f is None else 2 * math.pi * float(f),
                           "2 pi f_nominal of the design model source")}
        cls = SGStateMap
    unknown = set(values) - set(defaults)
    if unknown:
        raise ParameterError("--param", sorted(unknown)[0],
                             f"the {model.machine} measurement mapping has {sorted(defaults)}")
    for k, (v, why) in defaults.items():
        if k not in values:
            if v is None:
                raise ParameterError("--param", k, f"the controller file does not record {k}: "
                                     f"give --param {k}=VALUE or --study STUDY")
            values[k] = float(v)
            origin[k] = why
    origin.update(Vmax="given" if rating is not None else "none",
                  bypass="given" if bypass else "none")
    return DigitalSpec(cls(**{k: float(values[k]) for k in defaults}), rating, list(bypass),
                       origin=origin)


def check_exportable(controller, spec=None):
    """Refuse controllers that are not of the design model (10), or of another machine than
    ``spec``'s mapping."""
    system = controller.system
    if getattr(system, "kind", None) != "upqc-design":
        raise ParameterError("model.kind", getattr(system, "kind", None),
                             "the digital UPQC controller needs a controller of the design "
                             "model (10) ('upqc-design'); export the law alone with --format "
                             "c-law")
    if spec is not None and spec.state_map.machine != system.machine:
        raise ParameterError("machine", spec.state_map.machine,
                             f"the controller is designed for a {system.machine}")


def _signals(spec):
    m = spec.state_map
    return list(m.signals) + [("enable", "-", "1: controller enabled, 0: bypass (e.g. a "
                                                "protection's fault-detect); other finite "
                                                "values count as 1, non-finite as 0")]


def generate_digital_c(controller, spec: DigitalSpec, name: str,
                       provenance: str = "") -> dict:
    """The digital controller as C99 files ``{file name: text}``.

    ``NAME.h`` and ``NAME.c`` (the sampled controller), ``NAME_law.h`` and ``NAME_law.c``
    (the saddle point, :func:`weakgrid.game.export_c.generate_c`: ``NAME_saddle``,
    ``NAME_value``).
    """
    name = valid_c_name(name)
    check_exportable(controller, spec)
    law = f"{name}_law"
    law_c, law_h = generate_c(controller, name, provenance, file=law)
    T = controller.system.T
    up = name.upper()
    sig = _signals(spec)
    n_meas = len(sig)
    pars = spec.parameters()
    m = spec.state_map
    meas_doc = "\n".join(f" *   meas[{i}]  {n:<8} [{u}]  {d}" for i, (n, u, d) in enumerate(sig))
    par_doc = "\n".join(f"    double {k};{' ' * max(1, 12 - len(k))}/* [{u}] {d} */"
                        for k, _, u, d in pars if "[" not in k)
    origin = "\n".join(f" *   {k}: {v}" for k, v in spec.origin.items())
    h = f"""/* {name}.h — generated by weakgrid: the complete digital UPQC controller. {provenance}
 *
 * Call {name}_step once every sampling period T = {name.upper()}_T s (the period the law is
 * designed for), at t = t0 + k*T, k = 0, 1, ...: it reads the measured signals, maps them to
 * the design state x = [phi_hat (rad), upsilon (rad/s)], evaluates the saddle-point law
 * u*(x) ({law}.h), scales u down to the UPQC rating and outputs the series-voltage command
 * to hold (zero-order hold) until the next call. Bypassed (in a bypass window of the sample
 * clock, or with meas[{n_meas - 1}] = 0) it outputs u_bypass.
 *
 * Measured signals, meas[{up}_N_MEAS] ({m.machine.upper()} behind the UPQC; pu on the system base):
{meas_doc}
 * Output, u_out[{up}_N_OUT], the UPQC series voltage in the frame of the shunt-bus voltage [pu]:
 *   u_out[0]  Vup  in quadrature with the shunt-bus voltage
 *   u_out[1]  Vuq  in phase with the shunt-bus voltage
 * Measurement mapping ({m.machine}):
{chr(10).join(" *   " + ln.replace("s->", "").replace("p->", "") for ln in _MAP_C[m.machine])}
 *   (x[0] = phi_hat, x[1] = upsilon; see weakgrid.sim.design_states)
 * Default parameters ({name}_default_params) from:
{origin}
 *
 * C99, no allocation, no globals, only <math.h> (link with -lm); IEEE-754 64-bit double
 * (where double is 32-bit, e.g. TI C28x COFF, use a 64-bit-double ABI such as EABI). Do not
 * edit: regenerate with `weakgrid export FILE --format c`. */
#ifndef {up}_H
#define {up}_H

#ifdef __cplusplus
extern "C" {{
#endif

#define {up}_T {c_literal(T)}          /* sampling period [s] */
#define {up}_N_MEAS {n_meas}
#define {up}_N_OUT 2
#define {up}_MAX_BYPASS {MAX_BYPASS}

typedef struct {{
{par_doc}
    double u_bypass[2];   /* [pu] output [Vup, Vuq] while bypassed */
    int n_bypass;         /* number of bypass windows in use */
    double bypass[{up}_MAX_BYPASS][2];  /* [s] windows [t_start, t_end) of the sample clock */
}} {name}_params;

typedef struct {{
    {name}_params p;
    long long k;          /* samples taken (64-bit: no wrap in practice) */
    double t;             /* [s] time of the last sample, t0 + (k-1)*T */
    double x[2];          /* design state of the last sample [rad, rad/s] */
    double u_demand[2];   /* [pu] law output before the rating clip (last active sample) */
    double w[1];          /* [pu] worst-case disturbance w*(x) of the law */
    int active;           /* 1 if the last sample was not bypassed */
    int clipped;          /* 1 if the rating clip scaled the last output */
}} {name}_state;

/* The exported parameters (operating point, rating, bypass windows). */
void {name}_default_params({name}_params *p);

/* Reset the controller with parameters p (NULL: the defaults). Returns 0, or -1 if p is
 * invalid (a non-finite value, n_bypass outside 0..{up}_MAX_BYPASS). */
int {name}_init({name}_state *s, const {name}_params *p);

/* One sample: u_out = the command to hold for the next T. Returns 0 (controller active),
 * 1 (bypassed), or -1 (non-finite measurement or law: u_out = u_bypass, a fail-safe). */
int {name}_step({name}_state *s, const double meas[{up}_N_MEAS], double u_out[{up}_N_OUT]);

#ifdef __cplusplus
}}
#endif
#endif /* {up}_H */
"""
    defaults = "\n".join(f"    p->{k} = {c_literal(v)};" for k, v, _, _ in pars)
    wins = "\n".join(f"    p->bypass[{i}][0] = {c_literal(a)};\n    p->bypass[{i}][1] = "
                     f"{c_literal(b)};" for i, (a, b) in enumerate(spec.bypass))
    finite = " &&\n        ".join(f"isfinite(p->{k})" for k, _, _, _ in pars)
    mapc = "\n    ".join(_MAP_C[m.machine])
    c = f"""/* {name}.c — generated by weakgrid: the complete digital UPQC controller. {provenance} */
#include "{name}.h"
#include "{law}.h"
#include <math.h>

void {name}_default_params({name}_params *p)
{{
{defaults}
    p->n_bypass = {len(spec.bypass)};
    for (int i = 0; i < {up}_MAX_BYPASS; ++i) {{ p->bypass[i][0] = 0.0; p->bypass[i][1] = 0.0; }}
{wins}
}}

int {name}_init({name}_state *s, const {name}_params *p)
{{
    if (p == 0) {name}_default_params(&s->p);
    else s->p = *p;
    p = &s->p;
    if (!({finite})) return -1;
    if (p->n_bypass < 0 || p->n_bypass > {up}_MAX_BYPASS) return -1;
    for (int i = 0; i < p->n_bypass; ++i)
        if (!(isfinite(p->bypass[i][0]) && isfinite(p->bypass[i][1]))) return -1;
    s->k = 0;
    s->t = p->t0;
    s->x[0] = s->x[1] = 0.0;
    s->u_demand[0] = s->u_demand[1] = 0.0;
    s->w[0] = 0.0;
    s->active = 0;
    s->clipped = 0;
    return 0;
}}

int {name}_step({name}_state *s, const double meas[{up}_N_MEAS], double u_out[{up}_N_OUT])
{{
    const {name}_params *p = &s->p;
    const double t = p->t0 + (double)s->k * {up}_T;   /* this sample's time */
    int active = isfinite(meas[{n_meas - 1}]) && meas[{n_meas - 1}] != 0.0;
    for (int i = 0; i < p->n_bypass; ++i)
        if (p->bypass[i][0] <= t && t < p->bypass[i][1]) active = 0;
    s->t = t;
    s->k += 1;
    s->active = active;
    s->clipped = 0;
    /* measurement mapping: measured signals -> design state */
    {mapc}
    if (!active) {{
        u_out[0] = p->u_bypass[0];
        u_out[1] = p->u_bypass[1];
        return 1;
    }}
    double u[2];
    if (!isfinite(s->x[0]) || !isfinite(s->x[1]) || {name}_saddle(s->x, u, s->w) != 0 ||
        !isfinite(u[0]) || !isfinite(u[1])) {{
        s->active = 0;
        u_out[0] = p->u_bypass[0];
        u_out[1] = p->u_bypass[1];
        return -1;
    }}
    s->u_demand[0] = u[0];
    s->u_demand[1] = u[1];
    /* rating clip: u scaled down to |u| <= Vmax (as the UPQC applies it) */
    const double mag = hypot(u[0], u[1]);
    if (p->Vmax > 0.0 && mag > p->Vmax) {{
        const double scale = p->Vmax / mag;
        u[0] = u[0] * scale;
        u[1] = u[1] * scale;
        s->clipped = 1;
    }}
    u_out[0] = u[0];
    u_out[1] = u[1];
    return 0;
}}
"""
    return {f"{name}.h": h, f"{name}.c": c, f"{law}.h": law_h, f"{law}.c": law_c}


def fmu_block(controller, spec: DigitalSpec, name: str) -> dict:
    """The digital controller described for :func:`weakgrid.fmu.build_fmu`."""
    from ..fmu import FmuVar

    check_exportable(controller, spec)
    sig = _signals(spec)
    vars_ = []
    for i, (n, u, d) in enumerate(sig):
        vars_.append(FmuVar(n, "input", "continuous", f"c->meas[{i}]",
                            1.0 if n in ("enable", "omega") else 0.0, u, d))
    outs = [("Vup", "c->out[0]", "pu", "series voltage in quadrature with the shunt-bus voltage "
             "(applied: after the rating clip)"),
            ("Vuq", "c->out[1]", "pu", "series voltage in phase with the shunt-bus voltage "
             "(applied)"),
            ("Vup_demand", "c->st.u_demand[0]", "pu", "Vup of the law before the clip"),
            ("Vuq_demand", "c->st.u_demand[1]", "pu", "Vuq of the law before the clip"),
            ("phi_hat", "c->st.x[0]", "rad", "design state phi_hat of the last sample"),
            ("upsilon", "c->st.x[1]", "rad/s", "design state upsilon of the last sample"),
            ("active", "c->active_out", "-", "1 if the last sample was not bypassed")]
    for n, e, u, d in outs:
        vars_.append(FmuVar(n, "output", "discrete", e, 0.0, u, d))
    for k, v, u, d in spec.parameters():
        vars_.append(FmuVar(k.replace("[", "_").replace("]", ""), "parameter", "fixed",
                            f"c->par.{k}", v, u, d))
    vars_.append(FmuVar("n_bypass", "parameter", "fixed", "c->par.n_bypass", len(spec.bypass),
                        "-", "number of bypass windows in use", type="Integer"))
    for i in range(MAX_BYPASS):
        a, b = spec.bypass[i] if i < len(spec.bypass) else (0.0, 0.0)
        vars_.append(FmuVar(f"bypass_{i}_start", "parameter", "fixed", f"c->par.bypass[{i}][0]",
                            a, "s", f"bypass window {i}: start"))
        vars_.append(FmuVar(f"bypass_{i}_end", "parameter", "fixed", f"c->par.bypass[{i}][1]",
                            b, "s", f"bypass window {i}: end (excluded)"))
    return {"name": name, "header": f"{name}.h", "period": controller.system.T,
            "params_type": f"{name}_params", "state_type": f"{name}_state",
            "n_in": len(sig), "n_out": 2,
            "defaults": f"{name}_default_params(&c->par);",
            "init": f"{name}_init(&c->st, &c->par)",
            "sample": f"{name}_step(&c->st, c->meas, c->out)",
            "next_time": f"c->st.p.t0 + (double)c->st.k * {name.upper()}_T",
            "after_sample": "c->active_out = c->st.active ? 1.0 : 0.0;",
            "extra_fields": "double active_out;", "extra_reset": "c->active_out = 0.0;",
            "variables": vars_,
            "description": f"weakgrid digital UPQC controller {name} "
                           f"({spec.state_map.machine}, T = {controller.system.T:g} s)"}
