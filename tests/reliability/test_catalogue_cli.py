"""The catalogue of bad inputs, command by command (see README.md for the counts).

Each entry: (id, category, argv builder, expected exit code, substrings stderr must
contain — the field/element and the value). Exit codes: 2 bad input, 3 failure
during a run (see ``weakgrid.cli.main``).
"""

from __future__ import annotations

import json

import pytest
from catalogue import check_bad_input


def sub(old, new):
    return lambda text: text.replace(old, new, 1)


def problem(old, new):
    return lambda ws: ["train", "--config", ws.problem_with(sub(old, new)), "-q",
                       "-o", ws.root / "new.controller.json"]


def ctl_edit(fn, cmd="export"):
    def build(ws):
        f = ws.controller_with(fn)
        if cmd == "export":
            return ["export", f, "-d", ws.root / "out"]
        return ["verify", "--preset", "case1-paper", "--controller", f]
    return build


def _set(path, value):
    def edit(d):
        *head, last = path
        x = d
        for k in head:
            x = x[k]
        x[last] = value
    return edit


def _del(path):
    def edit(d):
        *head, last = path
        x = d
        for k in head:
            x = x[k]
        del x[last]
    return edit


GAMMA = "gamma = 20.0"
STEP = "step = [0.06, 0.6]"

CATALOGUE = [
    # ---------------------------------------------------------------- CLI arguments
    ("train-tol-negative", "arguments", lambda ws: ["train", "--preset", "case1-paper", "--tol", "-1"], 2, ["--tol", "-1"]),
    ("train-tol-nan", "arguments", lambda ws: ["train", "--preset", "case1-paper", "--tol", "nan"], 2, ["--tol", "nan"]),
    ("train-tol-text", "arguments", lambda ws: ["train", "--preset", "case1-paper", "--tol", "small"], 2, ["--tol", "small"]),
    ("train-output-extension", "arguments", lambda ws: ["train", "--preset", "case1-paper", "-o", "ctl.txt"], 2, ["--output", "ctl.txt", ".json"]),
    ("train-output-folder", "arguments", lambda ws: ["train", "--preset", "case1-paper", "-o", ws.root], 2, ["--output", "folder"]),
    ("train-output-under-file", "arguments", lambda ws: ["train", "--preset", "case1-paper", "-o", ws.precious / "c.json"], 2, ["--output", "precious.json", "not a folder"]),
    ("train-unknown-preset", "arguments", lambda ws: ["train", "--preset", "case9"], 2, ["--preset", "case9"]),
    ("train-missing-config", "arguments", lambda ws: ["train", "--config", "nope.toml"], 2, ["--config", "nope.toml", "does not exist"]),
    ("train-config-folder", "arguments", lambda ws: ["train", "--config", ws.root], 2, ["--config", "folder"]),
    ("train-preset-and-config", "arguments", lambda ws: ["train", "--preset", "case1-paper", "--config", ws.problem], 2, ["--config", "not allowed"]),
    ("train-no-problem", "arguments", lambda ws: ["train"], 2, ["--preset", "--config", "required"]),
    ("gamma-rtol-zero", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--rtol", "0"], 2, ["--rtol", "'0'"]),
    ("gamma-rtol-text", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--rtol", "tight"], 2, ["--rtol", "tight"]),
    ("gamma-rtol-above-1", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--rtol", "2"], 2, ["rtol", "2"]),
    ("gamma-max-trials-zero", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--max-trials", "0"], 2, ["--max-trials", "'0'"]),
    ("gamma-max-trials-fraction", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--max-trials", "2.5"], 2, ["--max-trials", "2.5"]),
    ("gamma-rollout-negative", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--rollout-steps", "-3"], 2, ["--rollout-steps", "-3"]),
    ("gamma-escape-inf", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--escape-factor", "inf"], 2, ["--escape-factor", "inf"]),
    ("gamma-return-nan", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--return-fraction", "nan"], 2, ["--return-fraction", "nan"]),
    ("gamma-report-extension", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--report", "r.csv"], 2, ["--report", "r.csv"]),
    ("gamma-unknown-start", "arguments", lambda ws: ["gamma", "--preset", "case1-paper", "--starts", "random"], 2, ["--starts", "random"]),
    ("verify-points-zero", "arguments", lambda ws: ["verify", "--preset", "case1-paper", "--points", "0"], 2, ["--points", "'0'"]),
    ("verify-points-text", "arguments", lambda ws: ["verify", "--preset", "case1-paper", "--points", "many"], 2, ["--points", "many"]),
    ("verify-margin-negative", "arguments", lambda ws: ["verify", "--preset", "case1-paper", "--margin", "-1"], 2, ["--margin", "-1"]),
    ("verify-steps-nan", "arguments", lambda ws: ["verify", "--preset", "case1-paper", "--steps", "nan"], 2, ["--steps", "nan"]),
    ("verify-start-fraction-2", "arguments", lambda ws: ["verify", "--preset", "case1-paper", "--controller", ws.controller, "--start-fraction", "2"], 2, ["--start-fraction", "2"]),
    ("verify-controller-missing", "arguments", lambda ws: ["verify", "--preset", "case1-paper", "--controller", "gone.json"], 2, ["--controller", "gone.json"]),
    ("verify-report-extension", "arguments", lambda ws: ["verify", "--preset", "case1-paper", "--report", "r.html"], 2, ["--report", "r.html"]),
    ("verify-grid-too-large", "arguments", lambda ws: ["verify", "--preset", "case1-paper", "--points", "1001"], 2, ["--points", "1001", "GiB", "--force"]),
    ("export-missing-file", "arguments", lambda ws: ["export", "gone.json"], 2, ["gone.json", "does not exist"]),
    ("export-file-is-folder", "arguments", lambda ws: ["export", ws.root], 2, ["folder"]),
    ("export-format-xml", "arguments", lambda ws: ["export", ws.controller, "--format", "xml"], 2, ["--format", "xml"]),
    ("export-name-digit", "arguments", lambda ws: ["export", ws.controller, "--name", "1bad"], 2, ["name", "1bad", "C identifier"]),
    ("export-name-path", "arguments", lambda ws: ["export", ws.controller, "--name", "../../evil"], 2, ["name", "../../evil"]),
    ("export-dir-is-file", "arguments", lambda ws: ["export", ws.controller, "-d", ws.precious], 2, ["--output-dir", "precious.json", "not a folder"]),
    ("simulate-t-end-negative", "arguments", lambda ws: ["simulate", "case1-weak-grid", "--t-end", "-1"], 2, ["--t-end", "-1"]),
    ("simulate-t-end-nan", "arguments", lambda ws: ["simulate", "case1-weak-grid", "--t-end", "nan"], 2, ["--t-end", "nan"]),
    ("simulate-t-end-zero", "arguments", lambda ws: ["simulate", "case1-weak-grid", "--t-end", "0"], 2, ["--t-end", "'0'"]),
    ("simulate-t-end-overflow", "arguments", lambda ws: ["simulate", "case1-weak-grid", "--t-end", "1e400"], 2, ["--t-end", "1e400"]),
    ("simulate-t-end-text", "arguments", lambda ws: ["simulate", "case1-weak-grid", "--t-end", "long"], 2, ["--t-end", "long"]),
("simulate-t-end-before-fault", "arguments", lambda ws: ["simulate", "case1-weak-grid", "--t-end", "0.1"], 2, ["--t-end", "0.1", "last event"]),
    ("simulate-unknown-scenario", "arguments", lambda ws: ["simulate", "case1-weak-grid", "--scenario", "c9-nope"], 2, ["--scenario", "c9-nope"]),
    ("simulate-missing-study-file", "arguments", lambda ws: ["simulate", str(ws.root / "no" / "study.toml")], 2, ["study", "study.toml"]),
    ("simulate-t-end-inf", "arguments", lambda ws: ["simulate", "case1-weak-grid", "--t-end", "inf"], 2, ["--t-end", "inf"]),
    ("simulate-output-xlsx", "arguments", lambda ws: ["simulate", "case1-weak-grid", "-o", "run.xlsx"], 2, ["--output", "run.xlsx", ".csv or .parquet"]),
    ("simulate-output-folder", "arguments", lambda ws: ["simulate", "case1-weak-grid", "-o", str(ws.root) + "/"], 2, ["--output", "folder"]),
    ("simulate-unknown-case", "arguments", lambda ws: ["simulate", "case3"], 2, ["case3"]),
    ("simulate-unknown-controller", "arguments", lambda ws: ["simulate", "case1-weak-grid", "-c", "mpc"], 2, ["--controller", "mpc"]),
    ("reproduce-output-is-file", "arguments", lambda ws: ["reproduce", "-o", ws.precious], 2, ["--output", "precious.json", "not a folder"]),
    ("reproduce-output-under-file", "arguments", lambda ws: ["reproduce", "-o", ws.precious / "sub"], 2, ["--output", "precious.json"]),
    ("reproduce-scheduler-unreachable", "arguments", lambda ws: ["reproduce", "--quick", "-o", ws.root / "rep", "--scheduler", f"tcp://127.0.0.1:{ws.closed_port()}"], 2, ["--scheduler", "127.0.0.1", "no Dask scheduler"]),
    ("reproduce-workers-too-many", "arguments", lambda ws: ["reproduce", "--workers", "99999"], 2, ["--workers", "99999", "at most"]),
    ("unknown-command", "arguments", lambda ws: ["bake"], 2, ["bake"]),
    # ---------------------------------------------------------------- problem files
    ("problem-Q-text", "problem file", problem("Q = 0.01", 'Q = "abc"'), 2, ["cost.Q", "abc", "edited.toml"]),
    ("problem-max-outer-text", "problem file", problem("max_outer = 500", 'max_outer = "many"'), 2, ["solver.max_outer", "many"]),
    ("problem-max-outer-zero", "problem file", problem("max_outer = 500", "max_outer = 0"), 2, ["solver.max_outer", "0"]),
    ("problem-tol-negative", "problem file", problem("tol_u = 1e-7", "tol_u = -1e-7"), 2, ["tol_u", "-1e-07"]),
    ("problem-step-text", "problem file", problem(STEP, 'step = "fine"'), 2, ["mesh.step", "fine"]),
    ("problem-step-zero", "problem file", problem(STEP, "step = [0.0, 0.6]"), 2, ["mesh.step", "0.0"]),
    ("problem-step-one-value", "problem file", problem(STEP, "step = [0.06]"), 2, ["mesh.step", "(1,)"]),
    ("problem-upper-below-lower", "problem file", problem("upper = [1.0, 10.0]", "upper = [-2.0, 10.0]"), 2, ["mesh.upper", "-2.0"]),
    ("problem-lower-inf", "problem file", problem("lower = [-1.0, -10.0]", "lower = [-inf, -10.0]"), 2, ["mesh.lower", "inf"]),
    ("problem-gamma-nan", "problem file", problem(GAMMA, "gamma = nan"), 2, ["cost.gamma", "nan"]),
    ("problem-gamma-negative", "problem file", problem(GAMMA, "gamma = -5"), 2, ["cost.gamma", "-5"]),
    ("problem-gamma-text", "problem file", problem(GAMMA, 'gamma = "big"'), 2, ["cost.gamma", "big"]),
    ("problem-R-zero", "problem file", problem("R = 1.0 ", "R = 0.0 "), 2, ["cost.R", "positive definite"]),
    ("problem-P-negative", "problem file", problem("P = 1.0", "P = -1.0"), 2, ["cost.P", "-1.0"]),
    ("problem-Q-shape", "problem file", problem("Q = 0.01", "Q = [1, 2, 3]"), 2, ["cost.Q", "(1, 3)"]),
    ("problem-model-kind", "problem file", problem('kind = "upqc-design"', 'kind = "foo"'), 2, ["model.kind", "foo"]),
    ("problem-model-T-negative", "problem file", problem("T = 8.100248e-4", "T = -1.0"), 2, ["T", "-1.0"]),
    ("problem-model-a-inf", "problem file", problem("a = 896.8810", "a = inf"), 2, ["model.a", "inf"]),
    ("problem-model-unknown-key", "problem file", problem("a = 896.8810", "a = 896.8810\nfoo = 1"), 2, ["model.foo", "unknown key"]),
    ("problem-basis-kind", "problem file", problem('kind = "paper"', 'kind = "fourier"'), 2, ["basis.kind", "fourier"]),
    ("problem-basis-degree-text", "problem file", problem('kind = "paper"', 'kind = "even"\ndegree = "four"'), 2, ["basis.degree", "four"]),
    ("problem-policy-kind", "problem file", problem('kind = "nonlinear-29"', 'kind = "mpc"'), 2, ["initial_policy.kind", "mpc"]),
    ("problem-policy-gain-text", "problem file", problem("gain = 125.0", 'gain = "big"'), 2, ["initial_policy.gain", "big"]),
    ("problem-unknown-table", "problem file", problem("[cost]", "[costs]\n[cost]"), 2, ["costs", "unknown table"]),
    ("problem-missing-table", "problem file", problem("[cost]", "[c0st]"), 2, ["c0st"]),
    ("problem-cost-not-table", "problem file", lambda ws: ["train", "--config", ws.problem_with(lambda t: "solver = 3\n" + t.replace("[solver]", "[solverx]"))], 2, ["solver"]),
    ("problem-toml-syntax", "problem file", problem(GAMMA, "gamma = "), 2, ["edited.toml", "TOML", "line"]),
    ("problem-mesh-3x3", "diagnosis", problem(STEP, "step = [1.0, 10.0]"), 2, ["mesh.step", "[1.0, 10.0]", "too few mesh points for the basis", "underdetermined"]),
    ("problem-mesh-too-large", "long work", problem(STEP, "step = [0.001, 0.01]"), 2, ["mesh.step", "GiB", "--force"]),
    ("gamma-problem-Q-text", "problem file", lambda ws: ["gamma", "--config", ws.problem_with(sub("Q = 0.01", 'Q = "abc"'))], 2, ["cost.Q", "abc"]),
    ("verify-problem-step-text", "problem file", lambda ws: ["verify", "--config", ws.problem_with(sub(STEP, 'step = "fine"'))], 2, ["mesh.step", "fine"]),
    # ---------------------------------------------------------------- controller files
    ("ctl-weight-nan", "controller file", ctl_edit(_set(["weights", 0], float("nan"))), 2, ["weights", "NaN", "edited.controller.json"]),
    ("ctl-weight-inf", "controller file", ctl_edit(_set(["weights", 3], float("inf"))), 2, ["weights", "inf"]),
    ("ctl-weight-text", "controller file", ctl_edit(_set(["weights", 1], "x")), 2, ["weights", "'x'"]),
    ("ctl-weights-short", "controller file", ctl_edit(lambda d: d["weights"].pop()), 2, ["weights", "(7,)", "(8,)"]),
    ("ctl-gamma-negative", "controller file", ctl_edit(_set(["problem", "cost", "gamma"], -5)), 2, ["problem.cost.gamma", "-5"]),
    ("ctl-gamma-zero", "controller file", ctl_edit(_set(["problem", "cost", "gamma"], 0)), 2, ["problem.cost.gamma", "0"]),
    ("ctl-Q-infinity", "controller file", ctl_edit(_set(["problem", "cost", "Q"], [[float("inf"), 0], [0, 1]])), 2, ["problem.cost.Q", "inf"]),
    ("ctl-json-list", "controller file", ctl_edit(lambda d: [1, 2, 3]), 2, ["controller file", "list"]),
    ("ctl-missing-problem", "controller file", ctl_edit(_del(["problem"])), 2, ["problem", "missing"]),
    ("ctl-missing-weights", "controller file", ctl_edit(_del(["weights"])), 2, ["weights", "missing"]),
    ("ctl-missing-basis", "controller file", ctl_edit(_del(["problem", "basis"])), 2, ["problem.basis", "missing"]),
    ("ctl-model-kind", "controller file", ctl_edit(_set(["problem", "model", "kind"], "rocket")), 2, ["model.kind", "rocket"]),
    ("ctl-model-not-object", "controller file", ctl_edit(_set(["problem", "model"], "upqc")), 2, ["problem.model", "upqc"]),
    ("ctl-exponents-negative", "controller file", ctl_edit(_set(["problem", "basis", "exponents", 0], [-1, 0])), 2, ["problem.basis.exponents", "-1"]),
    ("ctl-format-tag", "controller file", ctl_edit(_set(["format"], "other/9")), 2, ["format", "other/9"]),
    ("ctl-not-json", "controller file", ctl_edit(lambda d: "{not json"), 2, ["edited.controller.json", "JSON"]),
    ("ctl-empty", "controller file", ctl_edit(lambda d: " "), 2, ["edited.controller.json", "JSON"]),
    ("verify-ctl-weight-nan", "controller file", ctl_edit(_set(["weights", 0], float("nan")), "verify"), 2, ["weights", "NaN"]),
    ("verify-ctl-json-list", "controller file", ctl_edit(lambda d: [], "verify"), 2, ["controller file", "list"]),
]


def test_catalogue_size():
    assert len(CATALOGUE) >= 80
    assert len({c[0] for c in CATALOGUE}) == len(CATALOGUE)


@pytest.mark.parametrize("case", CATALOGUE, ids=[c[0] for c in CATALOGUE])
def test_bad_input(case, ws, cli):
    check_bad_input(case, ws, cli)


def test_binary_problem_file(ws, cli):
    f = ws.root / "binary.toml"
    f.write_bytes(b"\x80\x81\xff[model]\n")
    ws.snapshot()
    code, _, err = cli(["train", "--config", f])
    assert code == 2 and "binary.toml" in err and "UTF-8" in err
    ws.check_untouched()


def test_binary_controller_file(ws, cli):
    f = ws.root / "binary.controller.json"
    f.write_bytes(b"\xff\xfe\x00{")
    ws.snapshot()
    code, _, err = cli(["export", f])
    assert code == 2 and "binary.controller.json" in err and "UTF-8" in err
    ws.check_untouched()


def test_export_json_never_writes_nan(ws, cli):
    """Strict JSON out, even where a record holds NaN (train_seconds of a hand-made file)."""
    f = ws.controller_with(_set(["train_seconds"], float("nan")))
    code, _, err = cli(["export", f, "--format", "json", "-d", ws.root / "o"])
    assert code == 0, err
    text = (ws.root / "o" / "edited.export.json").read_text()
    json.loads(text, parse_constant=lambda c: pytest.fail(f"{c} written into JSON"))
