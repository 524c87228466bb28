"""Estimates of the memory and time of a training or a grid DP, before it starts.

The coefficients were measured on a 2-core development machine (peak resident
memory and wall time of ``solve_hji`` on meshes of 1e3–7e4 points with the
paper's 8-term basis, and of ``solve_game_dp`` on 31²–121² grids); they are
rough (±2× for time, which depends on the machine and its load) and meant to
stop a run that would take hours or exhaust the memory, not to predict it.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from .errors import ParameterError

__all__ = ["Estimate", "available_memory", "dp_estimate", "format_duration", "proc_kib", "training_estimate"]

# solve_hji: bytes per (mesh point × basis term), for 2 states (scaled by (2+n+n²)/8)
_HJI_BYTES = 176.0
# solve_hji: seconds per (mesh point × inner iteration) with 8 basis terms (∝ L²)
_HJI_SECONDS = 3e-6
_HJI_INNER = 200  # inner iterations assumed for a whole training (presets: 180–230)
# solve_game_dp: bytes per grid node and seconds ∝ nodes^1.5 (iterations grow with the grid)
_DP_BYTES, _DP_BASE = 13e3, 15e6
_DP_SECONDS = 5e-5

GiB = 1024.0**3


def proc_kib(path: str, key: str, default: float) -> float:
    """A ``key: <n> kB`` line of a /proc file (``/proc/meminfo``, ``/proc/self/status``) in
    bytes; ``default`` where the file or the line is missing."""
    try:
        with open(path) as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return float(line.split()[1]) * 1024
    except OSError:  # pragma: no cover
        pass
    return default


def available_memory() -> float:
    """MemAvailable of /proc/meminfo in bytes (inf where unknown)."""
    return proc_kib("/proc/meminfo", "MemAvailable", float("inf"))


@dataclass(frozen=True)
class Estimate:
    """What a run is expected to need."""

    what: str
    size: int
    bytes: float
    seconds: float

    def describe(self) -> str:
        return (f"estimate for {self.what}: ≈ {self.bytes / GiB:.2g} GiB of memory and "
                f"≈ {_duration(self.seconds)} (rough, measured on a 2-core machine)")

    def check(self, field: str, value, fix: str, force: bool = False,
              max_bytes: float | None = None, max_seconds: float = 1800.0):
        """Raise :class:`ParameterError` if beyond the limits (unless ``force``)."""
        if force:
            return
        if max_bytes is None:
            max_bytes = min(float(os.environ.get("WEAKGRID_MAX_GIB", 4.0)) * GiB,
                            0.5 * available_memory())
        if self.bytes > max_bytes or self.seconds > max_seconds:
            raise ParameterError(
                field, value,
                f"{self.what} needs ≈ {self.bytes / GiB:.2g} GiB and ≈ "
                f"{_duration(self.seconds)} (limits {max_bytes / GiB:.2g} GiB, "
                f"{_duration(max_seconds)}): {fix}, or pass --force to run it anyway")


def format_duration(s: float, cpu: bool = False) -> str:
    """``s`` seconds as "42 s", "17 min" or "2.5 h" ("CPU-s", "CPU-min", "CPU-h" with ``cpu``)."""
    p = "CPU-" if cpu else ""
    if s < 90:
        return f"{s:.0f} {p}s"
    if s < 5400:
        return f"{s / 60:.0f} {p}min"
    return f"{s / 3600:.1f} {p}h"


_duration = format_duration


def training_estimate(n_points: int, basis_size: int, n_states: int) -> Estimate:
    """Memory and time of ``solve_hji`` on ``n_points`` mesh points."""
    scale = (2 + n_states + n_states**2) / 8.0
    b = _HJI_BYTES * n_points * basis_size * scale + 50e6
    t = _HJI_SECONDS * n_points * (basis_size / 8.0) ** 2 * _HJI_INNER
    return Estimate(f"training on {n_points} mesh points × {basis_size} basis terms",
                    n_points, b, t)


def dp_estimate(n_nodes: int) -> Estimate:
    """Memory and time of ``solve_game_dp`` on a grid of ``n_nodes`` nodes."""
    return Estimate(f"the DP ground truth on {n_nodes} grid nodes", n_nodes,
                    _DP_BASE + _DP_BYTES * n_nodes, _DP_SECONDS * n_nodes**1.5)
