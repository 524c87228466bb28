"""Code generation: a dependency-free C99 saddle point ``(u*, w*)`` of a trained controller.

The generated function evaluates, at one state ``x``, exactly what
:meth:`~weakgrid.game.controller.GameController.saddle_point` does (the joint block system of (23)–(24), docs/theory.md, "The saddle point")::

    ∇J, ∇²J  of  J = W'σ(x)            (polynomial, weights and exponents inlined)
    f, g, h  of the model               (model constants inlined)
    [[g'∇²J g + 2R,  g'∇²J h], [h'∇²J g,  h'∇²J h − 2γ²P]]·[u; w]
        = −[g'; h']·(∇J + ∇²J (f − x))   (Gaussian elimination, partial pivoting)

With an input bound in the cost (beyond the paper) the u-block carries no ``2R``:
the generated code eliminates w (``w(u) = −Yw⁻¹(h'r + h'∇²J g u)``) and minimizes
``½u'Mu + b'u + W(u)`` over the bound by the same damped Newton iteration in
``u = ū·tanh(v/ū)`` as :meth:`~weakgrid.game.input_bound.InputBound.minimize`
(see :func:`_bounded_c`), so that the result is inside the bound by construction.

No allocation, no globals, no library beyond ``<math.h>``. Models are emitted by
*emitters* registered per system kind (:func:`register_c_model`); the game layer
ships the ``linear`` one, :mod:`weakgrid.models` registers ``upqc-design``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .errors import ParameterError

__all__ = ["CModel", "register_c_model", "c_model_of", "generate_c", "c_literal",
           "valid_c_name"]


@dataclass
class CModel:
    """The model equations of a system as C99 expressions of ``x0, x1, …``.

    Attributes
    ----------
    prelude : list of str
        Statements computing shared temporaries (``const double s = sin(...);``).
    f : list of str
        ``f_i(x)``, n expressions.
    B : list of list of (str or None)
        ``[g h]`` (n × (m+q)) entries; ``None`` marks a structural zero.
    equations : dict
        Human-readable equations and parameters (for the JSON export).
    """

    prelude: list
    f: list
    B: list
    equations: dict = field(default_factory=dict)


_EMITTERS: dict[str, Callable] = {}


def register_c_model(kind: str, emitter: Callable) -> None:
    """Register ``emitter(system) -> CModel`` for systems of ``kind``."""
    _EMITTERS[kind] = emitter


def c_model_of(system) -> CModel:
    """The :class:`CModel` of a system; refuses kinds without an emitter."""
    kind = getattr(system, "kind", type(system).__name__)
    if kind not in _EMITTERS:
        raise ParameterError(
            "model.kind", kind,
            f"export supports the model kinds {sorted(_EMITTERS)}: retrain the controller on "
            "one of them (import weakgrid.models for 'upqc-design')")
    return _EMITTERS[kind](system)


def c_literal(v: float) -> str:
    """A C double literal that round-trips exactly."""
    v = float(v)
    if not np.isfinite(v):
        raise ParameterError("constant", v, "cannot export a non-finite constant")
    s = repr(v)
    if "e" not in s and "." not in s and "inf" not in s:
        s += ".0"
    return s if v >= 0 else f"({s})"


def valid_c_name(name: str) -> str:
    """Check a C identifier prefix."""
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name or ""):
        raise ParameterError("name", name, "use a C identifier: letters, digits and _, not "
                             "starting with a digit (e.g. case1_hji)")
    return name


def _linear_emitter(system) -> CModel:
    A, Bm, E = system.A, system.B, system.E
    n = A.shape[0]
    f = []
    for i in range(n):
        terms = [f"{c_literal(A[i, j])} * x{j}" for j in range(n) if A[i, j] != 0.0]
        f.append(" + ".join(terms) if terms else "0.0")
    BB = np.hstack([Bm, E])
    B = [[c_literal(BB[i, a]) if BB[i, a] != 0.0 else None for a in range(BB.shape[1])]
         for i in range(n)]
    eq = {"dynamics": "x+ = A x + B u + E w", "A": A.tolist(), "B": Bm.tolist(),
          "E": E.tolist()}
    return CModel([], f, B, eq)


register_c_model("linear", _linear_emitter)


def _poly_terms(basis, weights):
    """Gradient and Hessian of ``J = W'σ`` as lists of (coefficient, exponent) per entry."""
    E = basis.exponents
    n = basis.n_states
    grad = [[] for _ in range(n)]
    hess = {(i, j): [] for i in range(n) for j in range(i, n)}
    value = []
    for w, e in zip(weights, E):
        if w == 0.0:
            continue
        value.append((float(w), tuple(int(v) for v in e)))
        for i in range(n):
            if e[i] >= 1:
                ei = e.copy()
                ei[i] -= 1
                grad[i].append((float(w) * float(e[i]), tuple(int(v) for v in ei)))
        for (i, j) in hess:
            if i == j and e[i] >= 2:
                c = float(e[i] * (e[i] - 1))
                ee = e.copy()
                ee[i] -= 2
            elif i != j and e[i] >= 1 and e[j] >= 1:
                c = float(e[i] * e[j])
                ee = e.copy()
                ee[i] -= 1
                ee[j] -= 1
            else:
                continue
            hess[(i, j)].append((float(w) * c, tuple(int(v) for v in ee)))
    return value, grad, hess


def _mono(e):
    parts = [f"p{i}_{k}" for i, k in enumerate(e) if k > 0]
    return " * ".join(parts) if parts else None


def _sum_expr(terms):
    if not terms:
        return "0.0"
    out = []
    for c, e in terms:
        m = _mono(e)
        out.append(c_literal(c) if m is None else f"{c_literal(c)} * {m}")
    return " + ".join(out)


def generate_c(controller, name: str, provenance: str = "", file: str | None = None
               ) -> tuple[str, str]:
    """C99 source and header computing ``(u*, w*)`` and ``J`` of a controller.

    Parameters
    ----------
    controller : GameController
    name : str
        Prefix of the generated symbols and files (a C identifier).
    provenance : str
        A line recorded in the generated comments (e.g. the source file and version).
    file : str, optional
        Stem of the files the caller writes (``FILE.c``, ``FILE.h``; default ``name``).

    Returns
    -------
    source, header : str
        Functions ``int NAME_saddle(const double x[n], double u[m], double w[q])``
        (0 on success, −1 if the block system is singular) and
        ``double NAME_value(const double x[n])``.
    """
    name = valid_c_name(name)
    file = valid_c_name(file or name)
    system, basis, cost = controller.system, controller.basis, controller.cost
    model = c_model_of(system)
    n, m, q = system.n_states, system.n_controls, system.n_disturbances
    K = m + q
    value, grad, hess = _poly_terms(basis, controller.weights)
    dmax = basis.degree
    up = name.upper()
    header = f"""/* {file}.h — generated by weakgrid: the saddle point (u*, w*) of a trained HJI
 * controller. {provenance}
 * Dependency-free C99; no allocation; thread-safe. Do not edit: regenerate with
 * `weakgrid export FILE --format c-law` (or --format c: the digital controller). */
#ifndef {file.upper()}_H
#define {file.upper()}_H

#ifdef __cplusplus
extern "C" {{
#endif

#define {up}_N_STATES {n}
#define {up}_N_CONTROLS {m}
#define {up}_N_DISTURBANCES {q}

/* Control u* and worst-case disturbance w* at state x (the paper's (23)-(24) solved jointly as one block system).
 * Returns 0, or -1 if the block system is singular at x (outputs then undefined). */
int {name}_saddle(const double x[{n}], double u[{m}], double w[{q}]);

/* The approximate cost J(x) = W'sigma(x). */
double {name}_value(const double x[{n}]);

#ifdef __cplusplus
}}
#endif
#endif /* {file.upper()}_H */
"""
    L = []
    L.append(f"/* {file}.c — generated by weakgrid. {provenance} */")
    L.append(f'#include "{file}.h"')
    L.append("#include <math.h>")
    L.append("")
    L.append(f"/* basis: {basis.name}; {basis.size} terms, degree {dmax}; "
             f"gamma = {cost.gamma!r} */")
    L.append("")

    def powers(lines, used, all_states=True):
        for i in range(n):
            if all_states or (i, 1) in used:
                lines.append(f"    const double x{i} = x[{i}];")
        for i in range(n):
            for k in range(1, dmax + 1):
                if (i, k) not in used:
                    continue
                lines.append(f"    const double p{i}_{k} = " +
                             (f"x{i};" if k == 1 else f"p{i}_{k - 1} * x{i};"))

    def used_powers(termlists):
        need = set()
        for terms in termlists:
            for _, e in terms:
                for i, k in enumerate(e):
                    need.update((i, j) for j in range(1, k + 1))
        return need

    # J(x)
    L.append(f"double {name}_value(const double x[{n}])")
    L.append("{")
    powers(L, used_powers([value]), all_states=False)
    L.append(f"    return {_sum_expr(value)};")
    L.append("}")
    L.append("")
    # saddle point: only the entries the block system needs (rows of B that are not zero)
    live = [i for i in range(n) if any(model.B[i][a] is not None for a in range(K))]
    need_h = [(i, j) for (i, j) in hess if i in live or j in live]
    L.append(f"int {name}_saddle(const double x[{n}], double u[{m}], double w[{q}])")
    L.append("{")
    powers(L, used_powers([grad[i] for i in live] + [hess[k] for k in need_h]))
    L.append("    /* gradient and Hessian of J */")
    for i in live:
        L.append(f"    const double gJ{i} = {_sum_expr(grad[i])};")
    for (i, j) in need_h:
        L.append(f"    const double H{i}{j} = {_sum_expr(hess[(i, j)])};")
    L.append("    /* model: f and B = [g h] */")
    for s in model.prelude:
        L.append(f"    {s}")
    for i in range(n):
        L.append(f"    const double d{i} = ({model.f[i]}) - x{i};  /* f - x */")
    for i in range(n):
        for a in range(K):
            if model.B[i][a] is not None:
                L.append(f"    const double B{i}_{a} = {model.B[i][a]};")

    def H(i, j):
        return f"H{min(i, j)}{max(i, j)}"

    L.append("    /* r = gJ + HJ (f - x) */")
    for i in live:
        L.append(f"    const double r{i} = gJ{i} + " + " + ".join(f"{H(i, j)} * d{j}"
                                                               for j in range(n)) + ";")
    L.append("    /* T = HJ B */")
    t_rows = set()
    for j in live:
        for b in range(K):
            terms = [f"{H(j, i)} * B{i}_{b}" for i in range(n) if model.B[i][b] is not None]
            if terms:
                t_rows.add((j, b))
                L.append(f"    const double T{j}_{b} = {' + '.join(terms)};")
    bound = getattr(cost, "bound", None)
    reg = np.zeros((K, K))
    if bound is None:
        reg[:m, :m] = 2.0 * cost.R
    reg[m:, m:] = -2.0 * cost.gamma**2 * cost.P
    L.append(f"    double M[{K}][{K + 1}];")
    L.append("    /* M = B' HJ B + blkdiag(2R, -2 gamma^2 P); last column -B' r */")
    for a in range(K):
        for b in range(K):
            terms = [f"B{j}_{a} * T{j}_{b}" for j in range(n)
                     if model.B[j][a] is not None and (j, b) in t_rows]
            if reg[a, b] != 0.0:
                terms.append(c_literal(reg[a, b]))
            L.append(f"    M[{a}][{b}] = {' + '.join(terms) if terms else '0.0'};")
        terms = [f"B{j}_{a} * r{j}" for j in range(n) if model.B[j][a] is not None]
        L.append(f"    M[{a}][{K}] = -({' + '.join(terms) if terms else '0.0'});")
    if bound is not None:
        helpers, body = _bounded_c(name, bound, cost.R, m, q)
        start = next(i for i, ln in enumerate(L) if ln.startswith(f"int {name}_saddle("))
        L[start:start] = helpers
        L.extend(body)
        L.append("}")
        header = header.replace(
            "/* Control u* and worst-case disturbance w* at state x (the paper's (23)-(24) solved "
            "jointly as one block system).",
            f"/* Control u* (inside the input bound {bound.describe()}) and worst-case "
            "disturbance w* at state x.")
        return "\n".join(L) + "\n", header
    L.append(f"""    /* Gaussian elimination with partial pivoting */
    for (int k = 0; k < {K}; ++k) {{
        int p = k;
        double best = fabs(M[k][k]);
        for (int i = k + 1; i < {K}; ++i) {{
            if (fabs(M[i][k]) > best) {{ best = fabs(M[i][k]); p = i; }}
        }}
        if (!(best > 0.0)) return -1;
        if (p != k) {{
            for (int j = k; j <= {K}; ++j) {{
                const double t = M[k][j]; M[k][j] = M[p][j]; M[p][j] = t;
            }}
        }}
        for (int i = k + 1; i < {K}; ++i) {{
            const double l = M[i][k] / M[k][k];
            for (int j = k; j <= {K}; ++j) M[i][j] -= l * M[k][j];
        }}
    }}
    double z[{K}];
    for (int i = {K - 1}; i >= 0; --i) {{
        double s = M[i][{K}];
        for (int j = i + 1; j < {K}; ++j) s -= M[i][j] * z[j];
        z[i] = s / M[i][i];
    }}""")
    for a in range(m):
        L.append(f"    u[{a}] = z[{a}];")
    for a in range(q):
        L.append(f"    w[{a}] = z[{m + a}];")
    L.append("    return 0;")
    L.append("}")
    return "\n".join(L) + "\n", header


def _bounded_c(name, bound, R, m, q):
    """C of the bounded saddle point: static helpers and the tail of ``NAME_saddle``.

    Mirrors :meth:`InputBound.minimize` step by step (start ``v = −(M + 2R)⁻¹b``,
    Newton on ``2Rv + b + M·squash(v) = 0`` with Armijo backtracking on F, the
    fixed-point step where the direction is not one of descent, the same stopping
    rules, then ``u = squash(−(2R)⁻¹(b + M·squash(v)))``).
    """
    twoR = [2.0 * float(R[i, i]) for i in range(m)]
    lim = [float(v) for v in bound.limit]
    Lmax = max(lim)
    box = bound.shape == "box"
    cl = c_literal
    H = []
    H.append(f"/* input bound: {bound.describe()} ({bound.shape}); penalty W(u) = "
             "2 int_0^u (ubar atanh(v/ubar))' R dv */")
    H.append(f"static void {name}_lsolve(double A[{m}][{m}], double b[{m}], double x[{m}])")
    H.append("{")
    H.append(f"""    for (int k = 0; k < {m}; ++k) {{
        int p = k;
        double best = fabs(A[k][k]);
        for (int i = k + 1; i < {m}; ++i) {{
            if (fabs(A[i][k]) > best) {{ best = fabs(A[i][k]); p = i; }}
        }}
        if (p != k) {{
            for (int j = 0; j < {m}; ++j) {{
                const double t = A[k][j]; A[k][j] = A[p][j]; A[p][j] = t;
            }}
            const double t = b[k]; b[k] = b[p]; b[p] = t;
        }}
        for (int i = k + 1; i < {m}; ++i) {{
            const double l = A[i][k] / A[k][k];
            for (int j = k; j < {m}; ++j) A[i][j] -= l * A[k][j];
            b[i] -= l * b[k];
        }}
    }}
    for (int i = {m - 1}; i >= 0; --i) {{
        double s = b[i];
        for (int j = i + 1; j < {m}; ++j) s -= A[i][j] * x[j];
        x[i] = s / A[i][i];
    }}""")
    H.append("}")
    H.append("")
    # squash, its Jacobian and W(squash(v))
    H.append(f"static void {name}_squash(const double v[{m}], double u[{m}])")
    H.append("{")
    if box:
        for i in range(m):
            H.append(f"    u[{i}] = {cl(lim[i])} * tanh(v[{i}] / {cl(lim[i])});")
    else:
        H.append("    double s2 = 0.0;")
        H.append(f"    for (int i = 0; i < {m}; ++i) s2 += v[i] * v[i];")
        H.append(f"    const double t = sqrt(s2) / {cl(lim[0])};")
        H.append("    const double fac = t < 1e-8 ? 1.0 - t * t / 3.0 : tanh(t) / t;")
        H.append("    double n2 = 0.0;")
        H.append(f"    for (int i = 0; i < {m}; ++i) {{ u[i] = v[i] * fac; n2 += u[i] * u[i]; }}")
        H.append(f"    const double over = sqrt(n2) / {cl(lim[0])};")
        H.append("    if (over > 1.0) {")
        H.append(f"        for (int i = 0; i < {m}; ++i) u[i] = u[i] / over * "
                 f"{cl(1.0 - 2.0 ** -52)};")
        H.append("    }")
    H.append("}")
    H.append("")
    H.append(f"static void {name}_squash_jac(const double v[{m}], double S[{m}][{m}])")
    H.append("{")
    if box:
        for i in range(m):
            for j in range(m):
                if i != j:
                    H.append(f"    S[{i}][{j}] = 0.0;")
            H.append(f"    {{ const double t = fabs(v[{i}] / {cl(lim[i])}); "
                     f"const double ch = cosh(t < 350.0 ? t : 350.0); "
                     f"S[{i}][{i}] = 1.0 / (ch * ch); }}")
    else:
        L0 = cl(lim[0])
        H.append("    double s2 = 0.0;")
        H.append(f"    for (int i = 0; i < {m}; ++i) s2 += v[i] * v[i];")
        H.append(f"    const double t = sqrt(s2) / {L0};")
        H.append("    const double t2 = t * t;")
        H.append("    double fac, c;")
        H.append("    const double ch = cosh(t < 350.0 ? t : 350.0);")
        H.append("    const double sech2 = 1.0 / (ch * ch);")
        H.append("    if (t < 1e-3) {")
        H.append("        fac = 1.0 - t2 / 3.0 + 2.0 * t2 * t2 / 15.0;")
        H.append("        c = -2.0 / 3.0 + 8.0 * t2 / 15.0 - 34.0 * t2 * t2 / 105.0;")
        H.append("    } else {")
        H.append("        fac = tanh(t) / t;")
        H.append("        c = (sech2 - fac) / (t * t);")
        H.append("    }")
        H.append(f"    for (int i = 0; i < {m}; ++i)")
        H.append(f"        for (int j = 0; j < {m}; ++j)")
        H.append(f"            S[i][j] = (i == j ? fac : 0.0) + c * v[i] * v[j] / "
                 f"({L0} * {L0});")
    H.append("}")
    H.append("")
    H.append(f"static double {name}_lncosh_term(double t)  /* t tanh t - ln cosh t */")
    H.append("{")
    H.append("    const double lc = t > 20.0 ? t - log(2.0) : log1p(2.0 * sinh(0.5 * t) * "
             "sinh(0.5 * t));")
    H.append("    return t * tanh(t) - lc;")
    H.append("}")
    H.append("")
    H.append(f"static double {name}_F(const double M[{m}][{m}], const double b[{m}], "
             f"const double v[{m}])")
    H.append("{")
    H.append(f"    double u[{m}];")
    H.append(f"    {name}_squash(v, u);")
    H.append("    double f = 0.0;")
    H.append(f"    for (int i = 0; i < {m}; ++i) {{")
    H.append("        double Mu = 0.0;")
    H.append(f"        for (int j = 0; j < {m}; ++j) Mu += M[i][j] * u[j];")
    H.append("        f += 0.5 * u[i] * Mu + b[i] * u[i];")
    H.append("    }")
    if box:
        for i in range(m):
            H.append(f"    f += {cl(twoR[i] * lim[i] ** 2)} * "
                     f"{name}_lncosh_term(fabs(v[{i}]) / {cl(lim[i])});")
    else:
        H.append("    double s2 = 0.0;")
        H.append(f"    for (int i = 0; i < {m}; ++i) s2 += v[i] * v[i];")
        H.append(f"    f += {cl(twoR[0] * lim[0] ** 2)} * {name}_lncosh_term(sqrt(s2) / "
                 f"{cl(lim[0])});")
    H.append("    return f;")
    H.append("}")
    H.append("")
    H.append(f"static void {name}_G(const double M[{m}][{m}], const double b[{m}], "
             f"const double v[{m}], double g[{m}])")
    H.append("{")
    H.append(f"    static const double twoR[{m}] = {{{', '.join(cl(v) for v in twoR)}}};")
    H.append(f"    double u[{m}];")
    H.append(f"    {name}_squash(v, u);")
    H.append(f"    for (int i = 0; i < {m}; ++i) {{")
    H.append("        double Mu = 0.0;")
    H.append(f"        for (int j = 0; j < {m}; ++j) Mu += M[i][j] * u[j];")
    H.append("        g[i] = twoR[i] * v[i] + b[i] + Mu;")
    H.append("    }")
    H.append("}")
    H.append("")
    H.append("/* argmin_u 0.5 u'Mu + b'u + W(u) over the bound, u = squash(v) */")
    H.append(f"static void {name}_bounded_min(const double M[{m}][{m}], const double b[{m}], "
             f"double u[{m}])")
    H.append("{")
    H.append(f"    static const double twoR[{m}] = {{{', '.join(cl(v) for v in twoR)}}};")
    H.append(f"    double v[{m}], A[{m}][{m}], rhs[{m}], d[{m}], g[{m}], S[{m}][{m}], "
             f"vn[{m}];")
    H.append("    double scale = 0.0, Mmax = 0.0;")
    H.append(f"    for (int i = 0; i < {m}; ++i) {{")
    H.append("        if (fabs(b[i]) > scale) scale = fabs(b[i]);")
    H.append(f"        for (int j = 0; j < {m}; ++j) {{")
    H.append("            A[i][j] = M[i][j] + (i == j ? twoR[i] : 0.0);")
    H.append("            if (fabs(M[i][j]) > Mmax) Mmax = fabs(M[i][j]);")
    H.append("        }")
    H.append("        rhs[i] = -b[i];")
    H.append("    }")
    H.append("    double twoRmax = twoR[0];")
    H.append(f"    for (int i = 1; i < {m}; ++i) if (twoR[i] > twoRmax) twoRmax = twoR[i];")
    H.append(f"    scale += Mmax * {cl(Lmax)} + twoRmax * {cl(Lmax)};")
    H.append(f"    {name}_lsolve(A, rhs, v);  /* exact for M = 0 */")
    H.append("    for (int it = 0; it < 100; ++it) {")
    H.append(f"        {name}_G(M, b, v, g);")
    H.append(f"        {name}_squash_jac(v, S);")
    H.append(f"        for (int i = 0; i < {m}; ++i) {{")
    H.append(f"            for (int j = 0; j < {m}; ++j) {{")
    H.append("                double MS = 0.0;")
    H.append(f"                for (int k = 0; k < {m}; ++k) MS += M[i][k] * S[k][j];")
    H.append("                A[i][j] = (i == j ? twoR[i] : 0.0) + MS;")
    H.append("            }")
    H.append("            rhs[i] = -g[i];")
    H.append("        }")
    H.append(f"        {name}_lsolve(A, rhs, d);")
    H.append("        double slope = 0.0;")
    H.append("        int finite = 1;")
    H.append(f"        for (int i = 0; i < {m}; ++i) {{")
    H.append("            if (!isfinite(d[i])) finite = 0;")
    H.append(f"            for (int j = 0; j < {m}; ++j) slope += g[i] * S[i][j] * d[j];")
    H.append("        }")
    H.append("        if (!finite || !(slope < 0.0)) {  /* fixed-point step */")
    H.append(f"            for (int i = 0; i < {m}; ++i) d[i] = -g[i] / twoR[i];")
    H.append("            slope = 0.0;")
    H.append(f"            for (int i = 0; i < {m}; ++i)")
    H.append(f"                for (int j = 0; j < {m}; ++j) slope += g[i] * S[i][j] * d[j];")
    H.append("        }")
    H.append("        double alpha = 1.0;")
    H.append(f"        const double f0 = {name}_F(M, b, v);")
    H.append("        const double tol_f = 1e-15 * (fabs(f0) + 1.0);")
    H.append("        const double sl = slope < 0.0 ? slope : 0.0;")
    H.append("        for (int k = 0; k < 60; ++k) {")
    H.append(f"            for (int i = 0; i < {m}; ++i) vn[i] = v[i] + alpha * d[i];")
    H.append(f"            if (!({name}_F(M, b, vn) > f0 + 1e-4 * alpha * sl + tol_f)) break;")
    H.append("            alpha *= 0.5;")
    H.append("        }")
    H.append("        double gmax = 0.0, dv = 0.0, vmax = 0.0;")
    H.append(f"        for (int i = 0; i < {m}; ++i) {{")
    H.append("            vn[i] = v[i] + alpha * d[i];")
    H.append("            if (fabs(g[i]) > gmax) gmax = fabs(g[i]);")
    H.append("            if (fabs(vn[i] - v[i]) > dv) dv = fabs(vn[i] - v[i]);")
    H.append("            if (fabs(vn[i]) > vmax) vmax = fabs(vn[i]);")
    H.append("            v[i] = vn[i];")
    H.append("        }")
    H.append(f"        if (gmax <= 1e-14 * scale || dv <= 1e-15 * (vmax + {cl(Lmax)})) break;")
    H.append("    }")
    H.append("    /* u = squash(-(2R)^-1 (b + M squash(v))) */")
    H.append(f"    {name}_squash(v, u);")
    H.append(f"    for (int i = 0; i < {m}; ++i) {{")
    H.append("        double Mu = 0.0;")
    H.append(f"        for (int j = 0; j < {m}; ++j) Mu += M[i][j] * u[j];")
    H.append("        vn[i] = -(b[i] + Mu) / twoR[i];")
    H.append("    }")
    H.append(f"    {name}_squash(vn, u);")
    H.append("}")
    H.append("")
    K = m + q
    B_ = []
    B_.append(f"""    /* eliminate w: Yw X = [h'HJ g | h'r], Yw = M[m..][m..] (Gaussian elimination) */
    double Y[{q}][{q}], X[{q}][{m + 1}];
    for (int i = 0; i < {q}; ++i) {{
        for (int j = 0; j < {q}; ++j) Y[i][j] = M[{m} + i][{m} + j];
        for (int j = 0; j < {m}; ++j) X[i][j] = M[{m} + i][j];
        X[i][{m}] = -M[{m} + i][{K}];
    }}
    for (int k = 0; k < {q}; ++k) {{
        int p = k;
        double best = fabs(Y[k][k]);
        for (int i = k + 1; i < {q}; ++i) {{
            if (fabs(Y[i][k]) > best) {{ best = fabs(Y[i][k]); p = i; }}
        }}
        if (!(best > 0.0)) return -1;
        if (p != k) {{
            for (int j = 0; j < {q}; ++j) {{ const double t = Y[k][j]; Y[k][j] = Y[p][j]; Y[p][j] = t; }}
            for (int j = 0; j <= {m}; ++j) {{ const double t = X[k][j]; X[k][j] = X[p][j]; X[p][j] = t; }}
        }}
        for (int i = k + 1; i < {q}; ++i) {{
            const double l = Y[i][k] / Y[k][k];
            for (int j = k; j < {q}; ++j) Y[i][j] -= l * Y[k][j];
            for (int j = 0; j <= {m}; ++j) X[i][j] -= l * X[k][j];
        }}
    }}
    for (int i = {q - 1}; i >= 0; --i) {{
        for (int c = 0; c <= {m}; ++c) {{
            double s = X[i][c];
            for (int j = i + 1; j < {q}; ++j) s -= Y[i][j] * X[j][c];
            X[i][c] = s / Y[i][i];
        }}
    }}
    /* reduced problem in u: Meff = g'HJ g - g'HJ h X_g, beff = g'r - g'HJ h X_r */
    double Me[{m}][{m}], Ms[{m}][{m}], be[{m}];
    for (int a = 0; a < {m}; ++a) {{
        for (int b = 0; b < {m}; ++b) {{
            double s = M[a][b];
            for (int i = 0; i < {q}; ++i) s -= M[a][{m} + i] * X[i][b];
            Me[a][b] = s;
        }}
        double s = -M[a][{K}];
        for (int i = 0; i < {q}; ++i) s -= M[a][{m} + i] * X[i][{m}];
        be[a] = s;
    }}
    for (int a = 0; a < {m}; ++a)
        for (int b = 0; b < {m}; ++b) Ms[a][b] = 0.5 * (Me[a][b] + Me[b][a]);
    {name}_bounded_min((const double (*)[{m}])Ms, be, u);
    for (int i = 0; i < {q}; ++i) {{
        double s = X[i][{m}];
        for (int j = 0; j < {m}; ++j) s += X[i][j] * u[j];
        w[i] = -s;
    }}
    return 0;""")
    return H, B_
