"""The names of the shipped presets (standard library only: the CLI lists them in ``--help``)."""

from __future__ import annotations

from importlib import resources

__all__ = ["preset_names"]


def preset_names() -> list[str]:
    """Names of the shipped presets (``src/weakgrid/data/presets/*.toml``)."""
    folder = resources.files("weakgrid") / "data" / "presets"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))
