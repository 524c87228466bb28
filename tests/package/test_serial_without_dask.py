"""Serial runs need no Dask: ``dask.distributed`` is imported only to open a cluster.

Dask stays a base dependency (the README's main job, ``weakgrid reproduce``, runs its sweeps
on a local cluster by default), but a serial run (``workers=0``) — and importing any module
of the package — must work where ``dask`` and ``distributed`` cannot be imported.
"""

import json
import subprocess
import sys
import textwrap


def test_a_serial_sweep_runs_where_dask_cannot_be_imported(tmp_path):
    code = textwrap.dedent(f"""
        import json, sys
        sys.modules["dask"] = None          # import dask -> ImportError
        sys.modules["distributed"] = None
        from weakgrid.sweep import expand, run_sweep
        from weakgrid.study.engine import run_studies  # noqa: F401  (imports without Dask)

        def run(inputs):
            return {{"v": inputs["x"] * 2.0}}

        table = run_sweep(expand({{"x": 1.0}}, {{"x": [1.0, 2.0, 3.0]}}), run,
                          cache_dir={str(tmp_path / "c")!r}, workers=0, progress=False)
        print("OUT" + json.dumps(sorted(table["v"].tolist())))
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    out = [ln for ln in r.stdout.splitlines() if ln.startswith("OUT")][-1]
    assert json.loads(out[3:]) == [2.0, 4.0, 6.0]
