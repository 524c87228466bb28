"""The linearized grid as a state-space model for a control designer (python-control).

At the operating point ``z`` of a set-up simulator system, with the UPQC's series-voltage
commands ``u = (Vup, Vuq)`` [pu] as inputs and named states as outputs::

    dx/dt = A x + B u,      y = C x
    A = fx − fy · gy⁻¹ · gx           (as :func:`weakgrid.design.modes.linearize`)
    B = fu − fy · gy⁻¹ · gu           (fu, gu: central differences of the residual in u)

``x``, ``u`` and ``y`` are deviations from the operating point. The eigenvalues of ``A`` are
those of :func:`weakgrid.design.modes.modes`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["state_space", "input_matrix"]

_H = 1e-6   # [pu] the step of the central differences in u (the residual is smooth in u)


def _upqc(system, upqc):
    comp = system.components.get("UPQC")
    if comp is None or not comp.names:
        from ..sim.errors import DataError

        raise DataError("state_space", "upqc", upqc, "the system has no UPQC: there is no input")
    if upqc is None:
        if len(comp.names) != 1:
            from ..sim.errors import DataError

            raise DataError("state_space", "upqc", None,
                            f"the system has several UPQCs {comp.names}: name one")
        upqc = comp.names[0]
    if upqc not in comp.names:
        from ..sim.errors import DataError

        raise DataError("state_space", "upqc", upqc, f"no such UPQC; the system has {comp.names}")
    return comp, upqc


def input_matrix(system, upqc=None, t: float = 0.0, z=None) -> np.ndarray:
    """``B`` (nx × 2): the state derivatives' response to the UPQC's ``(Vup, Vuq)`` [1/s per pu],
    the bus voltages following algebraically."""
    comp, name = _upqc(system, upqc)
    z = system.z0 if z is None else np.asarray(z, float)
    i = comp.names.index(name)
    u0 = (float(comp.u_p[i]), float(comp.u_q[i]))
    Fu = np.zeros((system.N, 2))
    try:
        for k in range(2):
            du = np.zeros(2)
            du[k] = _H
            comp.set_input(name, u0[0] + du[0], u0[1] + du[1])
            Fp = np.array(system.residual(t, z)[0], float)
            comp.set_input(name, u0[0] - du[0], u0[1] - du[1])
            Fm = np.array(system.residual(t, z)[0], float)
            Fu[:, k] = (Fp - Fm) / (2 * _H)
    finally:
        comp.set_input(name, *u0)
    J = system.jacobian(t, z)
    nx = system.nx
    fy, gy = J[:nx, nx:], J[nx:, nx:]
    return Fu[:nx] - fy @ np.linalg.solve(gy, Fu[nx:])


def state_space(system, outputs=(), upqc=None, t: float = 0.0, z=None):
    """A :class:`control.StateSpace` of the linearized grid.

    Parameters
    ----------
    system : weakgrid.sim.system.System
        Set up (its initial point ``z0`` is the default operating point).
    outputs : sequence of str
        State names for ``y`` (e.g. ``"GENROU_2.omega"``, see ``system.state_names()``);
        empty: every state (``C = I``).
    upqc : str, optional
        The UPQC whose ``(Vup, Vuq)`` are the inputs (default: the system's only one).

    Returns
    -------
    control.StateSpace
        With ``A`` (nx × nx), ``B`` (nx × 2), ``C``, ``D = 0``; state, input and output names
        as weakgrid's with ``_`` for ``.`` (python-control's rule: ``G1.omega`` → ``G1_omega``;
        inputs ``<upqc>_Vup``, ``<upqc>_Vuq``).
    """
    import control

    from .modes import linearize

    names = system.state_names()
    A = linearize(system, t, z)
    B = input_matrix(system, upqc, t, z)
    outs = list(outputs) or names
    unknown = [o for o in outs if o not in names]
    if unknown:
        import difflib

        from ..sim.errors import DataError

        close = sorted({c for o in unknown for c in difflib.get_close_matches(o, names, 5)})
        raise DataError("state_space", "outputs", unknown,
                        f"not states of the system; close names: {close or names[:8]}")
    C = np.zeros((len(outs), len(names)))
    for r, o in enumerate(outs):
        C[r, names.index(o)] = 1.0
    comp, name = _upqc(system, upqc)

    def label(n):   # python-control's signal names take no '.': "G1.omega" -> "G1_omega"
        return n.replace(".", "_")

    return control.ss(A, B, C, np.zeros((len(outs), 2)), states=[label(n) for n in names],
                      inputs=[label(f"{name}.Vup"), label(f"{name}.Vuq")],
                      outputs=[label(o) for o in outs])
