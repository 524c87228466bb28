"""A portable JSON description of a trained controller (``weakgrid export --format json``).

Everything needed to re-implement the controller elsewhere: the model equations
and their parameters, the basis exponents and weights, the cost, and the formula
of the saddle point.
"""

from __future__ import annotations

from .export_c import c_model_of

__all__ = ["EXPORT_FORMAT", "describe_controller", "SADDLE_FORMULA"]

EXPORT_FORMAT = "weakgrid-export/1"

SADDLE_FORMULA = {
    "value": "J(x) = sum_l W[l] * prod_i x[i]**exponents[l][i]",
    "saddle_point": (
        "[[g'HJ g + 2R, g'HJ h], [h'HJ g, h'HJ h - 2 gamma^2 P]] [u; w] = "
        "-[g'; h'] (gJ + HJ (f(x) - x)), with gJ = grad J(x), HJ = Hessian of J at x"),
    "conditions": "g'HJ g + 2R positive definite, h'HJ h - 2 gamma^2 P negative definite",
    "reference": "Nazaripouya & Mehraeen, IEEE TCST 2015, eqs. (22)-(24)",
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
        "formula": SADDLE_FORMULA,
    }
