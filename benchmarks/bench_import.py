"""Start-up latency: ``import weakgrid`` and ``weakgrid --help`` against ``import numpy``.

Not a test: prints medians (of ``--repeat`` fresh interpreters each) and the ratios to the
peer ``python -c "import numpy"`` measured in the same run (goal: ``--help`` within 1.5×).

Run:  python benchmarks/bench_import.py [--repeat 15]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

CASES = {
    "python -c 'import numpy' (peer)": [sys.executable, "-c", "import numpy"],
    "python -c 'import weakgrid'": [sys.executable, "-c", "import weakgrid"],
    "weakgrid --help": [sys.executable, "-c", "import sys; from weakgrid.cli.main import main; "
                        "sys.argv = ['weakgrid', '--help']; sys.exit(main())"],
    "python -c 'import weakgrid.sim'": [sys.executable, "-c", "import weakgrid.sim"],
}
#: the installed console script itself, where this interpreter has one (an install, not PYTHONPATH)
_SCRIPT = Path(sys.executable).with_name("weakgrid")
if _SCRIPT.is_file():
    CASES["weakgrid --help (console script)"] = [str(_SCRIPT), "--help"]


def wall(cmd) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=15)
    args = ap.parse_args()
    times = {k: [] for k in CASES}
    for _ in range(args.repeat):          # interleaved: drift hits every case alike
        for k, cmd in CASES.items():
            times[k].append(wall(cmd))
    peer = statistics.median(times[next(iter(CASES))])
    print(f"| command | median [s] | × import numpy |\n|---|---|---|")
    for k, v in times.items():
        m = statistics.median(v)
        print(f"| `{k}` | {m:.3f} | {m / peer:.2f} |")


if __name__ == "__main__":
    main()
