"""A portable JSON description of a trained controller (``weakgrid export --format json``).

Everything needed to re-implement the controller elsewhere: the model equations
and their parameters, the basis exponents and weights, the cost, and the formula
of the saddle point.
"""

from __future__ import annotations

from .export_c import c_model_of

__all__ = ["EXPORT_FORMAT", "describe_controller", "SADDLE_FORMULA", "BOUNDED_SADDLE_FORMULA"]

EXPORT_FORMAT = "weakgrid-export/1"

SADDLE_FORMULA = {
    "value": "J(x) = sum_l W[l] * prod_i x[i]**exponents[l][i]",
    "saddle_point": (
        "[[g'HJ g + 2R, g'HJ h], [h'HJ g, h'HJ h - 2 gamma^2 P]] [u; w] = "
        "-[g'; h'] (gJ + HJ (f(x) - x)), with gJ = grad J(x), HJ = Hessian of J at x"),
    "conditions": "g'HJ g + 2R positive definite, h'HJ h - 2 gamma^2 P negative definite",
    "reference": "Nazaripouya & Mehraeen, IEEE TCST 2015, eqs. (22)-(24)",
}

BOUNDED_SADDLE_FORMULA = {
    "value": SADDLE_FORMULA["value"],
    "penalty": (
        "u'Ru is replaced by W(u) = 2 int_0^u (ubar*atanh(v/ubar))' R dv: box (R diagonal) "
        "W = sum_i 2 R[i][i] ubar_i^2 psi(|u_i|/ubar_i); disk (R = r I) "
        "W = 2 r ubar^2 psi(|u|/ubar); psi(p) = ((1+p) ln(1+p) + (1-p) ln(1-p))/2"),
    "saddle_point": (
        "r = gJ + HJ (f(x) - x); Yw = h'HJ h - 2 gamma^2 P; "
        "w(u) = -Yw^-1 (h'r + h'HJ g u); u* = argmin over the bound of "
        "0.5 u'M u + b'u + W(u) with M = g'HJ g - g'HJ h Yw^-1 h'HJ g, "
        "b = g'r - g'HJ h Yw^-1 h'r; w* = w(u*). Stationarity: u* = -ubar*tanh((2R)^-1 "
        "(b + M u*)/ubar) per component (box) or along b + M u* (disk)"),
    "conditions": "g'HJ g + 2R positive definite, h'HJ h - 2 gamma^2 P negative definite",
    "reference": ("constrained-input penalty of Abu-Khalaf & Lewis on the approximate HJI "
                  "(22) of Nazaripouya & Mehraeen, IEEE TCST 2015"),
}


def describe_controller(controller, version: str, source: str = "") -> dict:
    """The portable description (refuses model kinds without an emitter)."""
    model = c_model_of(controller.system)
    sysd = controller.system.to_dict()
    basis = controller.basis
    names = getattr(controller.system, "state_names", None)
    return {
        "format": EXPORT_FORMAT,
        "weakgrid_version": version,
        "source_file": source,
        "model": {"kind": sysd.get("kind"), "record": sysd, "equations": model.equations,
                  "n_states": controller.system.n_states,
                  "n_controls": controller.system.n_controls,
                  "n_disturbances": controller.system.n_disturbances},
        "basis": {"name": basis.name, "exponents": basis.exponents.tolist(),
                  "labels": basis.labels(names)},
        "weights": controller.weights.tolist(),
        "cost": controller.cost.to_dict(),
        "formula": SADDLE_FORMULA if controller.cost.bound is None else BOUNDED_SADDLE_FORMULA,
    }
