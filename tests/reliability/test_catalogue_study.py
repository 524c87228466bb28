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


NAME = 'name = "case1-weak-grid"'
COMPARE = 'compare = ["hji", "nonlinear-29"'


def _machine_sg(d):
    """A controller record trained for a synchronous generator (another machine kind)."""
    d["problem"]["model"]["machine"] = "sg"


def _binary(ws):
    p = ws.root / "binary-study.toml"
    p.write_bytes(b"[study]\nname = \"x\xff\xfe\"\n")
    return p


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
    # ---------------------------------------------------------------- names read from a file that become paths
    ("run-study-name-parent", "names from files", run(NAME, 'name = "../escaped"'), 2, ["study.name", "'../escaped'", "output file name", "'_escaped'"]),
    ("run-study-name-absolute", "names from files", lambda ws: ["run", ws.study_with(NAME, f'name = "{ws.root.parent}/abs"'), "--workers", "0", "-o", ws.root / "r"], 2, ["study.name", "/abs'", "no path separator"]),
    ("design-study-name-separator", "names from files", design(NAME, 'name = "a/b"'), 2, ["study.name", "'a/b'"]),
    ("sweep-study-name-dotdot", "names from files", sweep(NAME, 'name = ".."'), 2, ["study.name", "'..'"]),
    ("run-study-name-hidden", "names from files", run(NAME, 'name = ".hidden"'), 2, ["study.name", "'.hidden'", "not starting with '.'"]),
    ("run-study-name-empty", "names from files", run(NAME, 'name = ""'), 2, ["study.name", "''"]),
    ("run-study-name-backslash", "names from files", run(NAME, 'name = "a\\\\b"'), 2, ["study.name", "a\\\\b"]),
    ("run-scenario-id-parent", "names from files", run('id = "c1-low-conv-redesign"', 'id = "../redesign"'), 2, ["scenarios.4.id", "'../redesign'"]),
    ("sweep-scenario-id-separator", "names from files", sweep('id = "c1-low-red"', 'id = "low/red"'), 2, ["scenarios.3.id", "'low/red'"]),
    ("simulate-scenario-id-absolute", "names from files", lambda ws: ["simulate", ws.study_with('id = "c1-low-red"', f'id = "{ws.root.parent}/sc"')], 2, ["scenarios.3.id", "/sc'"]),
    ("run-controller-name-parent", "names from files", lambda ws: ["run", ws.study_with(COMPARE, 'compare = ["hji", "../lqr2", "nonlinear-29"', "[controllers.lqr]", '[controllers."../lqr2"]\nkind = "lqr"\n\n[controllers.lqr]'), "--workers", "0", "-o", ws.root / "r"], 2, ["controllers.compare", "'../lqr2'", "output file name"]),
    ("run-figure-id-parent", "names from files", run('id = "fig07"', 'id = "../fig07"'), 2, ["figures.0.id", "'../fig07'"]),
    ("run-figure-id-absolute", "names from files", lambda ws: ["run", ws.study_with('id = "fig08"', f'id = "{ws.root.parent}/fig"'), "--workers", "0", "-o", ws.root / "r"], 2, ["figures.1.id", "/fig'"]),
    ("sweep-map-id-parent", "names from files", sweep('claim = "C1-cost"\ntitle', 'claim = "C1-cost"\nid = "../map"\ntitle'), 2, ["sweep.maps.0.id", "'../map'"]),
    ("sweep-map-claim-as-name", "names from files", sweep('claim = "C1-power"\ntitle', 'claim = "C1/power"\ntitle'), 2, ["sweep.maps.2.claim", "'C1/power'"]),
    ("design-load-level-parent", "names from files", design("[grid.loads.high]", '[grid.loads."../high"]'), 2, ["grid.loads.../high", "'../high'"]),
    # ---------------------------------------------------------------- unknown keys and cross-references
    ("run-figure-unknown-key", "cross-references", run('id = "fig07"', 'id = "fig07"\ncolour = "red"'), 2, ["figures.0.colour", "unknown field"]),
    ("run-figure-run-unknown", "cross-references", run('[["c1-high-conv-hji", "HJI (optimal, (24))"], ["c1-high-conv-nonlinear-29"', '[["c1-high-conv-mpc", "HJI (optimal, (24))"], ["c1-high-conv-nonlinear-29"'), 2, ["figures.0.runs.0", "c1-high-conv-mpc", "no run of that id"]),
    ("run-figure-panel-unknown", "cross-references", run('panels = ["sg_speed", "dc_voltage"]', 'panels = ["sg_sped", "dc_voltage"]'), 2, ["figures.0.panels", "sg_sped"]),
    ("run-figure-run-not-pair", "cross-references", run('runs = [["c1-high-conv-hji", "HJI (optimal, (24))"], ["c1-high-conv-nonlinear-29", "nonlinear (29)"], ["c1-high-conv-pq"', 'runs = ["c1-high-conv-hji", ["c1-high-conv-nonlinear-29", "nonlinear (29)"], ["c1-high-conv-pq"'), 2, ["figures.0.runs.0", "c1-high-conv-hji", "[run id, legend label]"]),
    ("run-figure-id-duplicate", "cross-references", run('id = "fig08"', 'id = "fig07"'), 2, ["figures.1.id", "fig07", "unique"]),
    ("run-figure-id-missing", "cross-references", run('id = "fig07"\n', ''), 2, ["figures.0.id", "missing"]),
    ("run-claim-unknown-key", "cross-references", run("reduction = 0.2\nsettling_tol = 0.25", "reduction = 0.2\nsettling_tol = 0.25\ntreshold = 3"), 2, ["claims.0.treshold", "unknown field"]),
    ("run-claim-judge-parameter-missing", "cross-references", run('judge = "power_share"\nruns', 'judge = "power_share"\nrunz'), 2, ["claims.3.runz", "unknown field"]),
    ("run-claim-judge-unknown", "cross-references", run('judge = "cost_less"', 'judge = "cost_more"'), 2, ["claims.0.judge", "cost_more"]),
    ("sweep-map-unknown-key", "cross-references", sweep('claim = "C1-cost"\ntitle', 'claim = "C1-cost"\ncolour = "red"\ntitle'), 2, ["sweep.maps.0.colour", "unknown field"]),
    ("sweep-map-kind-unknown", "cross-references", sweep('kind = "ratio"\nmetric = "running_cost_18"', 'kind = "pie"\nmetric = "running_cost_18"'), 2, ["sweep.maps.0.kind", "pie"]),
    ("sweep-map-controller-unknown", "cross-references", sweep('a = "hji"\nb = "nonlinear-29"', 'a = "hji"\nb = "mpc"'), 2, ["sweep.maps.0.b", "mpc", "controllers.compare"]),
    ("sweep-map-axis-not-swept", "cross-references", sweep('claim = "C1-cost"\ntitle', 'claim = "C1-cost"\nx = "upqc.x"\ntitle'), 2, ["sweep.maps.0.x", "upqc.x", "not a swept field"]),
    ("sweep-map-id-duplicate", "cross-references", sweep('claim = "C1-power"\ntitle', 'claim = "C1-cost"\ntitle'), 2, ["sweep.maps.2.id", "C1-cost", "unique"]),
    ("run-speed-of-unknown", "cross-references", run('speed_of = "SG"', 'speed_of = "G9"'), 2, ["report.speed_of", "G9", "['SG']"]),
    ("run-quick-controller-unknown", "cross-references", run('quick = { t_end = 3.0, controllers = ["hji", "nonlinear-29", "pq"] }', 'quick = { t_end = 3.0, controllers = ["hji", "mpc"] }'), 2, ["scenarios.c1-high-conv.quick.controllers", "mpc"]),
    ("run-controller-file-missing", "cross-references", lambda ws: ["run", ws.study_with("[controllers.lqr]", '[controllers.mine]\nkind = "file"\npath = "gone.controller.json"\n\n[controllers.lqr]', COMPARE, 'compare = ["mine", "hji", "nonlinear-29"'), "--workers", "0", "-o", ws.root / "r"], 2, ["controllers.mine.path", "gone.controller.json", "no such file"]),
    # ---------------------------------------------------------------- physical plausibility
    ("run-rating-beyond-line", "physical plausibility", run(RATING, "rating = 1e9"), 2, ["upqc.rating", "1000000000.0", "at most 1.0"]),
    ("design-rating-above-1", "physical plausibility", design(RATING, "rating = 1.5"), 2, ["upqc.rating", "1.5", "series transformer"]),
    ("sweep-axis-rating-above-1", "physical plausibility", sweep(AXIS, '"upqc.rating" = [0.1, 2.0]'), 2, ['sweep.axes."upqc.rating"', "2.0", "at most 1.0"]),
    ("run-dt-longer-than-T", "physical plausibility", run("tol = 1e-8  ", "dt = 10.0\ntol = 1e-8  "), 2, ["simulation.dt", "10.0", "design.T"]),
    ("run-t-end-within-one-step", "physical plausibility", run("t_end = 6.0\ncontrollers = [\"hji\", \"nonlinear-29\", \"lqr\"", "t_end = 5e-4\ncontrollers = [\"hji\", \"nonlinear-29\", \"lqr\""), 2, ["scenarios.c1-high-conv.t_end", "0.0005", "integration step"]),
    ("run-t-off-and-duration", "physical plausibility", run(FAULT, FAULT.replace("t_off = 0.25", "t_off = 0.25, duration = 0.1")), 2, ["events.0.duration", "0.1", "not both"]),
    ("run-faults-overlap", "physical plausibility", run(FAULT, FAULT[:-1] + ', { kind = "fault", bus = 3, t_on = 0.22, t_off = 0.3, xf = 0.2 }]'), 2, ["events.1.t_on", "0.22", "overlaps", "bus 3"]),
    ("simulate-faults-overlap", "physical plausibility", simulate(FAULT, FAULT[:-1] + ', { kind = "fault", bus = 3, t_on = 0.1, duration = 0.2 }]'), 2, ["t_on", "overlaps", "bus 3"]),
    ("run-trip-upqc-branch", "physical plausibility", run(FAULT, FAULT[:-1] + ', { kind = "line_trip", branch = "upqc", t = 1.0 }]'), 2, ["events.1.branch", "upqc", "UPQC's own"]),
    ("run-trip-after-end", "physical plausibility", run(FAULT, FAULT[:-1] + ', { kind = "line_trip", branch = "line", t = 9.0 }]'), 2, ["events.1.t", "9.0", "t_end"]),
    ("run-load-step-after-end", "physical plausibility", run(FAULT, FAULT[:-1] + ', { kind = "load_step", bus = 4, t = 7.0, dP = 5.0 }]'), 2, ["events.1.t", "7.0", "t_end"]),
    ("simulate-load-step-1e6-MW", "physical plausibility", lambda ws: ["simulate", ws.study_with(FAULT, FAULT[:-1] + ', { kind = "load_step", bus = 4, t = 0.3, dP = 1e6 }]'), "--controller", "lqr", "--t-end", "0.5"], 2, ["events.1.dP", "1000000.0", "times the grid's size"]),
    ("run-controller-file-other-machine", "physical plausibility", lambda ws: ["run", ws.study_with("[controllers.lqr]", f'[controllers.mine]\nkind = "file"\npath = "{ws.controller_with(_machine_sg)}"\n\n[controllers.lqr]', COMPARE, 'compare = ["mine", "hji", "nonlinear-29"'), "--workers", "0", "-o", ws.root / "r"], 2, ["controllers.mine.path", "trained for a SG", "'WF' is a GTI"]),
    ("design-study-not-utf8", "study file", lambda ws: ["design", _binary(ws), "--no-train"], 2, ["binary-study.toml", "UTF-8"]),
    ("run-study-not-utf8", "study file", lambda ws: ["run", _binary(ws), "--workers", "0", "-o", ws.root / "r"], 2, ["binary-study.toml", "UTF-8"]),
]


def test_catalogue_size():
    assert len({c[0] for c in CATALOGUE}) == len(CATALOGUE)
    assert {c[1] for c in CATALOGUE} == {"study file", "study arguments", "sweep",
                                         "names from files", "cross-references",
                                         "physical plausibility"}


@pytest.mark.parametrize("case", CATALOGUE, ids=[c[0] for c in CATALOGUE])
def test_bad_input(case, ws, cli, monkeypatch):
    import weakgrid.study.engine as engine

    def passed(*a, **k):    # a `run` entry must be refused before any work: fail fast
        raise AssertionError("the study passed validation and the engine started its work")

    import weakgrid.study.runner as runner
    import weakgrid.study.sweep_estimate as sweep_estimate

    monkeypatch.setattr(engine, "build_setup", passed)
    monkeypatch.setattr(sweep_estimate, "estimate_sweep", passed)
    monkeypatch.setattr(runner, "simulate", passed)
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


# ------------------------------------------------- events checked on the grid while planning
# Events that only the built grid can judge (a load step beside the grid's size, the UPQC's
# own branch given by its buses, a bus the grid does not have, faults overlapping at one bus
# named two ways) stop `run` while it plans, before any training: the engine's training,
# simulation and sweep estimate are patched to fail, and nothing may be written.
_STEP = FAULT[:-1] + ', { kind = "load_step", bus = 4, t = 0.3, dP = 1e6 }]'
_LOW_RED = 'protocol: the high-load controllers applied at low load\nupqc = "reduced"\nt_end = 6.0\ncontrollers = ["hji", "nonlinear-29"]\n'
PLANNING = [
    ("run-load-step-1e6-MW", "physical plausibility", run(FAULT, _STEP), 2, ["scenarios.c1-high-conv.events.1.dP", "1000000.0", "times the grid's size"]),
    ("run-load-step-1e6-MW-last-scenario", "physical plausibility", run(_LOW_RED + FAULT, _LOW_RED + _STEP), 2, ["scenarios.c1-low-red.events.1.dP", "1000000.0", "times the grid's size"]),
    ("run-trip-upqc-branch-by-buses", "physical plausibility", run(FAULT, FAULT[:-1] + ', { kind = "line_trip", branch = { from = 2, to = 3 }, t = 1.0 }]'), 2, ["events.1.branch", "'from': 2", "UPQC's own"]),
    ("run-fault-unknown-bus", "physical plausibility", run(FAULT, FAULT.replace("bus = 3", "bus = 99")), 2, ["events.0.bus", "99"]),
    ("run-faults-overlap-bus-named-two-ways", "physical plausibility", run(FAULT, FAULT[:-1] + ', { kind = "fault", bus = "UPQC shunt bus r", t_on = 0.22, t_off = 0.3, xf = 0.2 }]'), 2, ["events.1.t_on", "0.22", "overlaps"]),
]


@pytest.mark.parametrize("case", PLANNING, ids=[c[0] for c in PLANNING])
def test_bad_event_stops_run_before_training(case, ws, cli, monkeypatch):
    import weakgrid.study.engine as engine
    import weakgrid.study.runner as runner

    def passed(*a, **k):
        raise AssertionError("a bad event passed planning and the engine started its work")

    monkeypatch.setattr(engine, "train_hji", passed)
    monkeypatch.setattr(engine, "estimate_sweep", passed)
    monkeypatch.setattr(runner, "simulate", passed)
    check_bad_input(case, ws, cli)
