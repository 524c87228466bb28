"""``weakgrid reproduce``: the shipped studies marked ``reproduce = true`` (the paper's two
cases), run through the study engine into one report."""

from __future__ import annotations

from .engine import run_studies
from .studyfile import load_study, shipped_studies

__all__ = ["reproduce", "paper_studies"]


def paper_studies():
    """The shipped studies that ``weakgrid reproduce`` runs."""
    out = []
    for name in shipped_studies():
        st = load_study(name)
        if st.data["study"]["reproduce"]:
            out.append(st)
    return out


def reproduce(output="reproduce-output", quick=False, log=None, scheduler=None,
              workers=None, progress=True, force=False, batched=True) -> dict:
    """Run the paper's case studies (and their sweeps, as maps) and write everything to
    ``output``; simulations run on a Dask cluster (see :func:`run_studies`; ``progress``:
    its progress bar on stderr; ``force``: overwrite files there that weakgrid did not
    write; ``batched``: the runs and the maps' sweep in batches of one grid (the default;
    ``False``: one by one), :mod:`weakgrid.study.batches`)."""
    return run_studies(paper_studies(), output, quick=quick, log=log,
                       title="reproduction of Nazaripouya & Mehraeen (2015)",
                       scheduler=scheduler, workers=workers, progress=progress, force=force,
                       batched=batched)
