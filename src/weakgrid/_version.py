"""The package version, static (read by ``pyproject.toml`` at build time; no metadata look-up at import)."""

__version__ = "0.1.0"
