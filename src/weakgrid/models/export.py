"""C and JSON emitters of the design model (10) for ``weakgrid export``.

Registers the ``upqc-design`` kind with :func:`weakgrid.game.export_c.register_c_model`:
the expressions mirror :class:`~weakgrid.models.design.UPQCDesignModel` operation by
operation so that the generated C matches the Python model to rounding.
"""

from __future__ import annotations

import numpy as np

from ..game.export_c import CModel, c_literal, register_c_model
from .design import UPQCDesignModel

__all__ = ["upqc_c_model"]


def upqc_c_model(model: UPQCDesignModel) -> CModel:
    """f, g, h of (10) as C expressions of ``x0 = ϕ̂``, ``x1 = υ``."""
    T, a, Vr, p0 = model.T, model.a, model.Vr_bar, model.phi_s0
    Ta = T * a
    TaVr = Ta * Vr
    prelude = [f"const double ang = x0 + {c_literal(p0)};",
               "const double s = sin(ang);",
               "const double c = cos(ang);"]
    f = [f"x0 + {c_literal(T)} * x1",
         f"x1 + {c_literal(TaVr)} * ({c_literal(np.sin(p0))} - s)"]
    # B = [g h]: row 0 is zero; row 1 = T·a·[cos, −sin, −sin]
    B = [[None, None, None],
         [f"{c_literal(Ta)} * c", f"-({c_literal(Ta)} * s)", f"-({c_literal(Ta)} * s)"]]
    eq = {
        "states": ["phi_hat", "upsilon"], "controls": ["u1 = Vup", "u2 = Vuq"],
        "disturbances": ["w = Vr - Vr_bar"],
        "dynamics": "x+ = f(x) + g(x) u + h(x) w (paper (10), forward Euler of (9))",
        "f": ["phi_hat + T*upsilon",
              "upsilon + T*a*Vr_bar*(sin(phi_s0) - sin(phi_hat + phi_s0))"],
        "g": [["0", "0"], ["T*a*cos(phi_hat + phi_s0)", "-T*a*sin(phi_hat + phi_s0)"]],
        "h": [["0"], ["-T*a*sin(phi_hat + phi_s0)"]],
        "parameters": {"T": T, "a": a, "Vr_bar": Vr, "phi_s0": p0,
                       "machine": model.machine, "upqc": model.upqc},
    }
    return CModel(prelude, f, B, eq)


register_c_model(UPQCDesignModel.kind, upqc_c_model)
