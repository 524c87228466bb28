"""Importers: MATPOWER cases (:mod:`.matpower`), ANDES systems (:mod:`.andes`) and PSS/E
``.raw`` + ``.dyr`` files read natively (:mod:`.psse`).

``from weakgrid.sim.io import from_psse, from_andes`` (imported on first use).
"""

__all__ = ["from_psse", "from_andes", "load_matpower"]


def __getattr__(name):
    if name == "from_psse":
        from .psse import from_psse

        return from_psse
    if name == "from_andes":
        from .andes import from_andes

        return from_andes
    if name == "load_matpower":
        from .matpower import load_matpower

        return load_matpower
    raise AttributeError(name)
