"""The optional ``dpsimpy`` module (PyPI ``dpsim``), imported on first use."""

from __future__ import annotations

from ..errors import DataError

#: the engine names of the study layer → DPsim domain names
DOMAINS = {"dpsim-emt": "EMT", "dpsim-dp": "DP"}
#: every engine: weakgrid's phasor engine, then the DPsim ones
ENGINES = ("phasor", *DOMAINS)


def dpsimpy():
    """Return the ``dpsimpy`` module, or raise :class:`DataError` saying how to install it."""
    try:
        import dpsimpy as d
    except ImportError as exc:   # the optional extra is missing
        raise DataError("simulation", "engine", "dpsim",
                        "the DPsim engines need the optional extra: pip install 'weakgrid[emt]' "
                        f"(dpsim >= 1.4; import failed: {exc})") from None
    return d


def domain_of(engine: str) -> str:
    """DPsim domain (``"EMT"`` or ``"DP"``) of an engine name, refused with the valid names."""
    try:
        return DOMAINS[engine]
    except KeyError:
        raise DataError("simulation", "engine", engine,
                        f"use one of {sorted(DOMAINS)} for a DPsim run") from None


class Kit:
    """The DPsim classes of one domain: nodes, elements, switch event, and the three-phase lift.

    Parameters
    ----------
    domain : {"EMT", "DP"}
        DPsim domain.
    """

    def __init__(self, domain: str):
        import numpy as np

        d = dpsimpy()
        self.d, self.domain = d, domain
        self.three_phase = domain == "EMT"
        if self.three_phase:
            self.ns, self.ph = d.emt, d.emt.ph3
            self.phase_type = d.PhaseType.ABC
            self.event = d.event.SwitchEvent3Ph
            self.sim_domain = d.Domain.EMT
        else:
            self.ns, self.ph = d.dp, d.dp.ph1
            self.phase_type = d.PhaseType.Single
            self.event = d.event.SwitchEvent
            self.sim_domain = d.Domain.DP
        self._np = np

    def param(self, x: float):
        """A per-phase parameter in this domain's form: a scalar (DP), a diagonal 3×3 (EMT)."""
        return x * self._np.eye(3) if self.three_phase else float(x)

    def phasors(self, V: complex) -> list:
        """Initial node voltage(s) from the line-to-line RMS phasor ``V`` [V] (phases a, b, c in EMT)."""
        if not self.three_phase:
            return [complex(V)]
        a = complex(self._np.exp(-2j * self._np.pi / 3))
        return [complex(V), complex(V) * a, complex(V) * a * a]

    def set_source(self, src, name: str, X: complex, init: bool = False, f=None):
        """Set a DPsim source's phasor ``name`` (``V_ref``/``I_ref``) to ``X`` [line-to-line
        RMS phasor]: three phases (a, b, c) in EMT, one in DP; ``init``: through
        ``set_parameters``, with the source frequency ``f`` [Hz] in EMT."""
        if self.three_phase:
            X = self._np.array([[x] for x in self.phasors(X)], dtype=complex)
            if init:
                src.set_parameters(**{name: X, "f_src": f})
            else:
                src.attr(name).set(X)
        elif init:
            src.set_parameters(**{name: complex(X)})
        else:
            src.attr(name).set(complex(X))

    def node(self, name: str, V: complex):
        """A DPsim node initialized at the line-to-line RMS phasor ``V`` [V]."""
        return self.ns.SimNode(name, self.phase_type, self.phasors(V))

    @property
    def gnd(self):
        return self.ns.SimNode.gnd
