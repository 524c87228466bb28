"""The catalogue of bad inputs of the study commands: design, modes, run, sweep and
simulate with a study file (see README.md for the counts).

Each entry: (id, category, argv builder, expected exit code, substrings stderr must
contain — the field/element and the value). Every entry fails before any simulation or
training starts; the checks are those of ``test_catalogue_cli.py``.
"""

from __future__ import annotations

import subprocess

import pytest
from catalogue import check_bad_input

RATING = "rating = 0.15"
AXIS = '"upqc.rating" = [0.1, 0.15, 0.3, 0.6, 1.0]'
FAULT = "events = [{ kind = \"fault\", bus = 3, t_on = 0.2, t_off = 0.25, rf = 0.0, xf = 0.1 }]"


def design(old, new):
    return lambda ws: ["design", ws.study_with(old, new), "--no-train"]


def sweep(old, new):
    return lambda ws: ["sweep", ws.study_with(old, new), "--workers", "0", "-o", ws.root / "sw"]


def run(old, new):
    return lambda ws: ["run", ws.study_with(old, new), "--workers", "0", "-o", ws.root / "r"]


def simulate(old, new):
    return lambda ws: ["simulate", ws.study_with(old, new)]


CATALOGUE = [
    # ---------------------------------------------------------------- design: study files
    ("design-rating-text", "study file", design(RATING, 'rating = "big"'), 2, ["upqc.rating", "big", "number"]),
    ("design-rating-negative", "study file", design(RATING, "rating = -0.15"), 2, ["upqc.rating", "-0.15", "> 0"]),
    ("design-rating-nan", "study file", design(RATING, "rating = nan"), 2, ["upqc.rating", "nan", "finite"]),
    ("design-upqc-unknown-field", "study file", design(RATING, "rating = 0.15\nratting = 0.2"), 2, ["upqc.ratting", "0.2", "unknown field"]),
    ("design-unknown-table", "study file", design("[machine]", "[machines]\nname = 1\n[machine]"), 2, ["machines", "unknown field"]),
    ("design-T-text", "study file", design("T = 8.100248e-4         # s, sampling", 'T = "fast" #'), 2, ["design.T", "fast"]),
    ("design-branch-x-nan", "study file", design("x = 0.253", "x = nan"), 2, ["grid.branch.2.x", "nan", "finite"]),
    ("design-bus-id-text", "study file", design("id = 4\n", 'id = "four"\n'), 2, ["grid.bus.3.id", "four", "whole number"]),
    ("design-load-text", "study file", design("4 = [36.0, 14.0]", '4 = ["a", 14.0]'), 2, ["grid.loads.high.4", "'a'"]),
    ("design-load-one-value", "study file", design("4 = [36.0, 14.0]", "4 = [36.0]"), 2, ["grid.loads.high.4", "[36.0]", "P_MW, Q_Mvar"]),
    ("design-load-unknown-bus", "study file", design("4 = [36.0, 14.0]", "4 = [36.0, 14.0]\n44 = [1.0, 0.0]"), 2, ["grid.loads.high.44", "no bus"]),
    ("design-f-hz-nan", "study file", design("f_hz = 60.0", "f_hz = nan"), 2, ["grid.f_hz", "nan"]),
    ("design-f-hz-zero", "study file", design("f_hz = 60.0", "f_hz = 0"), 2, ["grid.f_hz", "0", "> 0"]),
    ("design-sb-zero", "study file", design("Sb_mva = 100.0", "Sb_mva = 0"), 2, ["grid.Sb_mva", "0", "> 0"]),
    ("design-V-set-negative", "study file", design("V_set = 1.0", "V_set = -1.0"), 2, ["grid.gen.1.V_set", "-1.0", "> 0"]),
    ("design-gen-P-nan", "study file", design("P_mw = 24.0", "P_mw = nan"), 2, ["P_mw", "nan"]),
    ("design-bus-type", "study file", design("type = 3 ", "type = 7 "), 2, ["grid.bus.4.type", "7"]),
    ("design-branch-unknown-bus", "study file", design("from = 3\nto = 4", "from = 3\nto = 44"), 2, ["branch 2", "T_BUS", "44", "[1, 2, 3, 4, 5]"]),
    ("design-gti-C-negative", "study file", design("C = 0.05 ", "C = -0.05 "), 2, ["dynamics.gti.0.C", "-0.05"]),
    ("design-genrou-xd-text", "study file", design("xd = 1.8", 'xd = "x"'), 2, ["GENROU 'SG'", "xd", "'x'"]),
    ("design-genrou-M-negative", "study file", design("M = 6.0 ", "M = -6.0 "), 2, ["GENROU 'SG'", "'M'", "-6.0"]),
    ("design-genrou-unknown-parameter", "study file", design("xd = 1.8", "xd = 1.8\nxdd = 3"), 2, ["GENROU 'SG'", "xdd", "unknown parameter"]),
    ("design-exciter-unknown-model", "study file", design('model = "EXDC2"', 'model = "EXDC9"'), 2, ["dynamics.generator.0.exciter.model", "EXDC9"]),
    ("design-machine-unknown", "study file", design('name = "WF"             # the GTI', 'name = "WF2" #'), 2, ["machine.name", "WF2"]),
    ("design-upqc-branch-unknown", "study file", design('branch = "upqc"  ', 'branch = "upqq"  '), 2, ["upqc.branch", "upqq"]),
    ("design-settings-unknown", "study file", design('settings = "case1-paper"', 'settings = "case9"'), 2, ["design.settings", "case9"]),
    ("design-toml-syntax", "study file", design("rating = 0.15", "rating = "), 2, ["edited-study.toml", "TOML"]),
    # ---------------------------------------------------------------- design: arguments
    ("design-load-unknown", "study arguments", lambda ws: ["design", ws.study, "--load", "medium", "--no-train"], 2, ["load", "medium", "high"]),
    ("design-upqc-choice", "study arguments", lambda ws: ["design", ws.study, "--upqc", "partial"], 2, ["--upqc", "partial"]),
    ("design-output-extension", "study arguments", lambda ws: ["design", ws.study, "-o", "c.txt"], 2, ["--output", "c.txt", ".json"]),
    ("design-output-folder", "study arguments", lambda ws: ["design", ws.study, "-o", ws.root], 2, ["--output", "folder"]),
    ("design-output-under-file", "study arguments", lambda ws: ["design", ws.study, "-o", ws.precious / "c.json"], 2, ["--output", "precious.json", "not a folder"]),
    ("design-missing-study", "study arguments", lambda ws: ["design", ws.root / "none.toml"], 2, ["study", "none.toml", "no such file"]),
    # ---------------------------------------------------------------- modes
    ("modes-min-hz-nan", "study arguments", lambda ws: ["modes", ws.study, "--min-hz", "nan"], 2, ["--min-hz", "nan"]),
    ("modes-min-hz-text", "study arguments", lambda ws: ["modes", ws.study, "--min-hz", "low"], 2, ["--min-hz", "low"]),
    ("modes-min-hz-negative", "study arguments", lambda ws: ["modes", ws.study, "--min-hz", "-1"], 2, ["--min-hz", "-1"]),
    ("modes-plot-extension", "study arguments", lambda ws: ["modes", ws.study, "--plot", "p.pdfx"], 2, ["--plot", "p.pdfx", ".png"]),
    ("modes-plot-folder", "study arguments", lambda ws: ["modes", ws.study, "--plot", ws.root], 2, ["--plot", "folder"]),
    ("modes-plot-under-file", "study arguments", lambda ws: ["modes", ws.study, "--plot", ws.precious / "p.png"], 2, ["--plot", "precious.json", "not a folder"]),
    ("modes-load-unknown", "study arguments", lambda ws: ["modes", ws.study, "--load", "peak"], 2, ["load", "peak"]),
    ("modes-study-rating-negative", "study file", lambda ws: ["modes", ws.study_with(RATING, "rating = -1")], 2, ["upqc.rating", "-1"]),
    # ---------------------------------------------------------------- run
    ("run-no-study", "study arguments", lambda ws: ["run"], 2, ["STUDY", "--list"]),
    ("run-missing-study", "study arguments", lambda ws: ["run", "nope.toml"], 2, ["study", "nope.toml"]),
    ("run-workers-negative", "study arguments", lambda ws: ["run", ws.study, "--workers", "-1"], 2, ["--workers", "-1"]),
    ("run-workers-text", "study arguments", lambda ws: ["run", ws.study, "--workers", "two"], 2, ["--workers", "two"]),
    ("run-workers-too-many", "study arguments", lambda ws: ["run", ws.study, "--workers", "100000"], 2, ["--workers", "100000", "at most"]),
    ("run-workers-fraction", "study arguments", lambda ws: ["run", ws.study, "--workers", "1.5"], 2, ["--workers", "1.5"]),
    ("run-scheduler-malformed", "study arguments", lambda ws: ["run", ws.study, "--scheduler", "nonsense"], 2, ["--scheduler", "nonsense", "tcp://"]),
    ("run-scheduler-no-port", "study arguments", lambda ws: ["run", ws.study, "--scheduler", "tcp://localhost"], 2, ["--scheduler", "tcp://localhost"]),
    ("run-scheduler-unreachable", "study arguments", lambda ws: ["run", ws.study, "--scheduler", f"tcp://127.0.0.1:{ws.closed_port()}"], 2, ["--scheduler", "tcp://127.0.0.1:", "no Dask scheduler"]),
    ("run-output-is-file", "study arguments", lambda ws: ["run", ws.study, "-o", ws.precious], 2, ["--output", "precious.json", "not a folder"]),
    ("run-output-under-file", "study arguments", lambda ws: ["run", ws.study, "-o", ws.precious / "out"], 2, ["--output", "precious.json", "not a folder"]),
    ("run-controller-unknown", "study file", run('compare = ["hji", "nonlinear-29"', 'compare = ["mpc", "nonlinear-29"'), 2, ["controllers.compare", "mpc"]),
    ("run-scenario-t-end-negative", "study file", run("t_end = 6.0", "t_end = -6.0"), 2, ["scenarios.c1-high-conv.t_end", "-6.0"]),
    ("run-fault-after-end", "study file", run("t_off = 0.25", "t_off = 7.0"), 2, ["scenarios.c1-high-conv.events.0.t_off", "7.0", "t_end"]),
    ("run-scenario-load-unknown", "study file", run('load = "high"\nupqc', 'load = "peak"\nupqc'), 2, ["scenarios.c1-high-conv.load", "peak"]),
    ("run-scenario-id-duplicate", "study file", run('id = "c1-high-red"', 'id = "c1-high-conv"'), 2, ["scenarios.1.id", "c1-high-conv", "unique"]),
    ("run-event-kind-unknown", "study file", run('kind = "fault", bus = 3', 'kind = "meteor", bus = 3'), 2, ["events.0.kind", "meteor"]),
    ("run-fault-xf-negative", "study file", run("xf = 0.1 }", "xf = -0.1 }"), 2, ["events.0.xf", "-0.1"]),
    # ---------------------------------------------------------------- sweep
    ("sweep-axis-unknown-field", "sweep", sweep(AXIS, '"upqc.ratingg" = [0.1, 0.2]'), 2, ['sweep.axes."upqc.ratingg"', "no field 'ratingg'"]),
    ("sweep-axis-unknown-element", "sweep", sweep('"scenarios.c1-high-conv.events.0.t_off"', '"scenarios.c9.events.0.t_off"'), 2, ['sweep.axes."scenarios.c9.events.0.t_off"', "no element 'c9'"]),
    ("sweep-axis-empty", "sweep", sweep(AXIS, '"upqc.rating" = []'), 2, ['sweep.axes."upqc.rating"', "[]", "non-empty"]),
    ("sweep-axis-not-list", "sweep", sweep(AXIS, '"upqc.rating" = 0.1'), 2, ['sweep.axes."upqc.rating"', "0.1", "list"]),
    ("sweep-axis-text-value", "sweep", sweep(AXIS, '"upqc.rating" = [0.1, "big"]'), 2, ['sweep.axes."upqc.rating"', "'big'", "number"]),
    ("sweep-axis-negative-rating", "sweep", sweep(AXIS, '"upqc.rating" = [0.1, -1.0]'), 2, ['sweep.axes."upqc.rating"', "-1.0", "> 0"]),
    ("sweep-axis-nan", "sweep", sweep(AXIS, '"upqc.rating" = [0.1, nan]'), 2, ['sweep.axes."upqc.rating"', "nan", "finite"]),
    ("sweep-axis-unknown-load", "sweep", sweep('"scenarios.c1-high-conv.load" = ["high", "low"]\n\n', '"scenarios.c1-high-conv.load" = ["high", "peak"]\n\n'), 2, ['sweep.axes."scenarios.c1-high-conv.load"', "peak", "high"]),
    ("sweep-axis-fault-after-end", "sweep", sweep("[0.22, 0.25, 0.30]", "[0.25, 9.0]"), 2, ['"scenarios.c1-high-conv.events.0.t_off"', "9.0", "t_end"]),
    ("sweep-no-axes", "sweep", sweep("[sweep.axes]", "[sweep.axis]"), 2, ["sweep.axis", "unknown field"]),
    ("sweep-mode-unknown", "sweep", sweep('mode = "product"', 'mode = "zip"'), 2, ["sweep.mode", "zip"]),
    ("sweep-scenario-unknown", "sweep", sweep('scenarios = ["c1-high-conv"]', 'scenarios = ["c9"]'), 2, ["sweep.scenarios", "c9"]),
    ("sweep-controller-unknown", "sweep", sweep('controllers = ["hji", "nonlinear-29", "hji-bounded"]', 'controllers = ["mpc"]'), 2, ["sweep.controllers", "mpc"]),
    ("sweep-unknown-field", "sweep", sweep("t_end = 2.0\n", "t_end = 2.0\nrepeats = 3\n"), 2, ["sweep.repeats", "unknown field"]),
    ("sweep-t-end-negative", "sweep", sweep("t_end = 2.0\n", "t_end = -2.0\n"), 2, ["sweep.t_end", "-2.0", "> 0"]),
    ("sweep-t-end-text", "sweep", sweep("t_end = 2.0\n", 't_end = "2 s"\n'), 2, ["sweep.t_end", "2 s"]),
    ("sweep-quick-t-end-zero", "sweep", sweep("t_end = 1.0\naxes", "t_end = 0\naxes"), 2, ["sweep.quick.t_end", "0"]),
    ("sweep-design-load-unknown", "sweep", sweep('design_load = "high"\n\n[sweep.axes]', 'design_load = "peak"\n\n[sweep.axes]'), 2, ["sweep.design_load", "peak"]),
    ("sweep-dt-check-not-swept", "sweep", sweep('"upqc.rating" = [0.15]      #', '"upqc.x" = [0.15]      #'), 2, ['sweep.dt_check."upqc.x"', "[0.15]"]),
    ("sweep-no-sweep-table", "sweep", lambda ws: ["sweep", ws.study_with("[sweep]\n", "[sweeps]\n"), "-o", ws.root / "sw"], 2, ["sweeps", "unknown field"]),
    ("sweep-workers-negative", "study arguments", lambda ws: ["sweep", ws.study, "--workers", "-1"], 2, ["--workers", "-1"]),
    ("sweep-workers-too-many", "study arguments", lambda ws: ["sweep", ws.study, "--workers", "5000"], 2, ["--workers", "5000", "at most"]),
    ("sweep-scheduler-malformed", "study arguments", lambda ws: ["sweep", ws.study, "--scheduler", "http://x:80"], 2, ["--scheduler", "http://x:80"]),
    ("sweep-scheduler-unreachable", "study arguments", lambda ws: ["sweep", ws.study, "--scheduler", f"127.0.0.1:{ws.closed_port()}"], 2, ["--scheduler", "127.0.0.1:", "no Dask scheduler"]),
    ("sweep-output-is-file", "study arguments", lambda ws: ["sweep", ws.study, "-o", ws.precious], 2, ["--output", "precious.json", "not a folder"]),
    # ---------------------------------------------------------------- simulate STUDY
    ("simulate-study-rating-negative", "study file", simulate(RATING, "rating = -0.15"), 2, ["upqc.rating", "-0.15"]),
    ("simulate-study-unknown-scenario", "study arguments", lambda ws: ["simulate", ws.study, "--scenario", "c9"], 2, ["--scenario", "c9", "c1-high-conv"]),
    ("simulate-study-unknown-controller", "study arguments", lambda ws: ["simulate", ws.study, "--controller", "mpc"], 2, ["--controller", "mpc", "hji"]),
    ("simulate-study-event-kind", "study file", simulate('kind = "fault", bus = 3', 'kind = "meteor", bus = 3'), 2, ["events.0.kind", "meteor"]),
    ("simulate-study-fault-bus-unknown", "study file", simulate("bus = 3, t_on", "bus = 33, t_on"), 2, ["bus", "33"]),
]


def test_catalogue_size():
    assert len({c[0] for c in CATALOGUE}) == len(CATALOGUE)
    assert {c[1] for c in CATALOGUE} == {"study file", "study arguments", "sweep"}


@pytest.mark.parametrize("case", CATALOGUE, ids=[c[0] for c in CATALOGUE])
def test_bad_input(case, ws, cli):
    check_bad_input(case, ws, cli)


# ---------------------------------------------------------------- a read-only output folder
@pytest.fixture
def readonly_dir(tmp_path):
    """A read-only file system (a tmpfs remounted read-only) holding an earlier result."""
    mnt = tmp_path / "ro"
    mnt.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mnt)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here (needs root): {r.stderr.strip()}")
    (mnt / "earlier.json").write_text('{"earlier": "result"}\n')
    subprocess.run(["mount", "-o", "remount,ro", str(mnt)], check=True)
    yield mnt
    subprocess.run(["umount", str(mnt)], check=False)


READONLY = [
    ("train", lambda ws, ro: ["train", "--preset", "case1-paper", "-o", ro / "c.json"]),
    ("design", lambda ws, ro: ["design", ws.study, "-o", ro / "c.controller.json"]),
    ("modes", lambda ws, ro: ["modes", ws.study, "--plot", ro / "modes.png"]),
    ("run", lambda ws, ro: ["run", ws.study, "-o", ro / "out"]),
    ("sweep", lambda ws, ro: ["sweep", ws.study, "-o", ro / "out"]),
    ("simulate", lambda ws, ro: ["simulate", ws.study, "-o", ro / "run.csv"]),
]


@pytest.mark.parametrize("case", READONLY, ids=[c[0] for c in READONLY])
def test_readonly_output_folder(case, ws, cli, readonly_dir):
    _, build = case
    ws.snapshot()
    before = sorted(p.name for p in readonly_dir.iterdir())
    code, out, err = cli(build(ws, readonly_dir))
    assert code == 2, err
    body = err.strip().splitlines()
    assert len(body) == 1 and "read-only file system" in body[0] and str(readonly_dir) in body[0]
    assert sorted(p.name for p in readonly_dir.iterdir()) == before
    ws.check_untouched()


def test_a_missing_output_folder_is_created(ws, cli):
    """Not an error: the folders of an output path are made (only where the user said)."""
    ws.snapshot()
    plot = ws.root / "new" / "sub" / "modes.svg"
    code, out, err = cli(["modes", ws.study, "--plot", plot])
    assert code == 0, err
    assert plot.read_text().lstrip().startswith(("<?xml", "<svg"))
    assert sorted(p.name for p in (ws.root / "new").rglob("*")) == ["modes.svg", "sub"]
    ws.check_untouched()
