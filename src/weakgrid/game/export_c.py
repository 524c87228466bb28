"""Code generation: a dependency-free C99 saddle point ``(u*, w*)`` of a trained controller.

The generated function evaluates, at one state ``x``, exactly what
:meth:`~weakgrid.game.controller.GameController.saddle_point` does (the joint block system of (23)–(24), docs/theory.md, "The saddle point")::

    ∇J, ∇²J  of  J = W'σ(x)            (polynomial, weights and exponents inlined)
    f, g, h  of the model               (model constants inlined)
    [[g'∇²J g + 2R,  g'∇²J h], [h'∇²J g,  h'∇²J h − 2γ²P]]·[u; w]
        = −[g'; h']·(∇J + ∇²J (f − x))   (Gaussian elimination, partial pivoting)

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


def generate_c(controller, name: str, provenance: str = "") -> tuple[str, str]:
    """C99 source and header computing ``(u*, w*)`` and ``J`` of a controller.

    Parameters
    ----------
    controller : GameController
    name : str
        Prefix of the generated symbols and files (a C identifier).
    provenance : str
        A line recorded in the generated comments (e.g. the source file and version).

    Returns
    -------
    source, header : str
        Functions ``int NAME_saddle(const double x[n], double u[m], double w[q])``
        (0 on success, −1 if the block system is singular) and
        ``double NAME_value(const double x[n])``.
    """
    name = valid_c_name(name)
    system, basis, cost = controller.system, controller.basis, controller.cost
    model = c_model_of(system)
    n, m, q = system.n_states, system.n_controls, system.n_disturbances
    K = m + q
    value, grad, hess = _poly_terms(basis, controller.weights)
    dmax = basis.degree
    up = name.upper()
    header = f"""/* {name}.h — generated by weakgrid: the saddle point (u*, w*) of a trained HJI
 * controller. {provenance}
 * Dependency-free C99; no allocation; thread-safe. Do not edit: regenerate with
 * `weakgrid export FILE --format c`. */
#ifndef {up}_H
#define {up}_H

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
#endif /* {up}_H */
"""
    L = []
    L.append(f"/* {name}.c — generated by weakgrid. {provenance} */")
    L.append(f'#include "{name}.h"')
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
    reg = np.zeros((K, K))
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
