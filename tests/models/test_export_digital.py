"""The exported digital controller (C step function, FMU) equals the Python controller along
closed-loop runs of shipped studies.

The runs, HJI controller, shipped ratings, the controller bypassed during the fault:

* case 2 (SG behind a UPQC, islanded LV microgrid), scenario c2-high-f200 (0.2-s fault at the
  UPQC bus, 3.0-3.2 s), to 3.5 s: the rating clip (0.1 pu) acts on ~1/3 of the post-fault
  samples, 200 samples are bypassed;
* case 1 (GTI with dc link behind a UPQC, weak grid), scenario c1-high-conv (fault 0.2-0.25 s),
  to 0.5 s: the GTI mapping (ϕs, Vc), clipped at 0.15 pu after the fault; and the same with
  the rating-aware HJI controller (the rating as its input bound: the bounded law's Newton
  iteration in C, inside the rating so the clip does not act).

The Python DigitalController's samples are recorded (measured signals, demanded and applied u);
the same measured signals are fed to the C step function and to the FMU.
"""

import ctypes
import shutil
import subprocess

import numpy as np
import pytest

from weakgrid.models.export_digital import generate_digital_c, spec_from_setup
from weakgrid.sim.upqc import rating_clip
from weakgrid.study.build import build_setup
from weakgrid.study.controllers import design_problem, train_hji
from weakgrid.study.runner import Run, run_scenario
from weakgrid.study.studyfile import load_study

# FMPy is in the extras 'fmu' and 'test': these tests need it; they are skipped only where gcc
# is missing (the C controller and the FMU are then not compiled)
CC = shutil.which("gcc")
needs_gcc = pytest.mark.skipif(CC is None, reason="gcc is not installed: the C controller and "
                                                  "the FMU cannot be compiled")
DP = ctypes.POINTER(ctypes.c_double)
TOL = 1e-9
# (study, scenario, t_end, HJI trained with the rating as its input bound)
CASES = {"c2": ("case2-lv-microgrid", "c2-high-f200", 3.5, False),
         "c1": ("case1-weak-grid", "c1-high-conv", 0.5, False),
         "c1-bounded": ("case1-weak-grid", "c1-high-conv", 0.5, True)}


@pytest.fixture(scope="module", params=sorted(CASES))
def closed_loop(request):
    """The recorded closed-loop run, the trained controller and its digital spec."""
    name, scenario, t_end, bounded = CASES[request.param]
    study = load_study(name)
    sc = next(s for s in study.scenarios() if s["id"] == scenario)
    run = Run.of(study, dict(sc, t_end=t_end), "hji")
    setup = build_setup(study, run.load, run.upqc)
    if bounded:     # the rating-aware controller (kind hji-bounded) in the hji slot
        ctl = design_problem(study, setup.design).with_rating(study.get("upqc.rating")).train()
    else:
        _, ctl = train_hji(study, setup.design)
    rec = run_scenario(study, run, trained={(run.load, run.upqc): ctl})
    assert not rec.metrics["failed"]
    spec = spec_from_setup(setup, bypass=run.bypass)
    return rec, ctl, spec


def compile_digital(ctl, spec, tmp_path, name="c2"):
    files = generate_digital_c(ctl, spec, name, "test")
    for f, text in files.items():
        (tmp_path / f).write_text(text)
    lib = tmp_path / f"lib{name}.so"
    r = subprocess.run([CC, "-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror",
                        "-fPIC", "-shared", "-o", str(lib), str(tmp_path / f"{name}.c"),
                        str(tmp_path / f"{name}_law.c"), "-lm"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return ctypes.CDLL(str(lib))


class CController:
    """ctypes driver of NAME_init/NAME_step (the state struct in an opaque buffer)."""

    def __init__(self, lib, name):
        self.init, self.step_fn = getattr(lib, f"{name}_init"), getattr(lib, f"{name}_step")
        self.s = ctypes.create_string_buffer(4096)
        assert self.init(self.s, None) == 0

    def step(self, meas):
        m = np.ascontiguousarray(meas, float)
        u = np.zeros(2)
        rc = self.step_fn(self.s, m.ctypes.data_as(DP), u.ctypes.data_as(DP))
        return rc, u


def recorded(rec, spec):
    """Per sample: measured signals (arbitrary while bypassed: the controller ignores them),
    enable = 1, Python's active flag, demanded and applied u."""
    y = rec.sample("y_measured")
    active = np.all(np.isfinite(y), axis=1)
    y = np.where(np.isfinite(y), y, 0.0)
    meas = np.hstack([y, np.ones((len(y), 1))])
    assert meas.shape[1] == len(spec.state_map.signals) + 1
    return rec.samples["tk"], meas, active, rec.sample("u_demanded"), rec.sample("u_applied")


def inputs(spec):
    return [n for n, _, _ in spec.state_map.signals] + ["enable"]


def test_the_run_exercises_the_clip_and_the_bypass(closed_loop):
    rec, ctl, spec = closed_loop
    tk, _, active, ud, ua = recorded(rec, spec)
    (a, b), = spec.bypass
    assert abs((~active).sum() - (b - a) / ctl.system.T) <= 1     # the fault bypassed
    mag = np.hypot(ud[:, 0], ud[:, 1])
    clipped = mag > spec.Vmax * (1 + 1e-6)
    if getattr(ctl.cost, "bound", None) is None:
        assert clipped.sum() >= 20 and np.abs(ua - ud)[clipped].max() > 1e-2
    else:           # the rating-aware law stays inside its bound: the clip has nothing to do
        assert mag.max() < spec.Vmax and mag.max() > 0.9 * spec.Vmax
    np.testing.assert_array_equal(ua, rating_clip(ud, spec.Vmax))


@needs_gcc
def test_c_step_equals_the_python_controller_in_closed_loop(closed_loop, tmp_path):
    rec, ctl, spec = closed_loop
    tk, meas, active, ud, ua = recorded(rec, spec)
    c = CController(compile_digital(ctl, spec, tmp_path), "c2")
    assert c.init(c.s, None) == 0
    U = np.zeros_like(ua)
    rc = np.zeros(len(tk), int)
    for k in range(len(tk)):
        rc[k], U[k] = c.step(meas[k])
    np.testing.assert_array_equal(rc == 0, active)      # same samples bypassed
    err = np.abs(U - ua).max()
    print(f"C vs Python, {rec.scenario.id}, {len(tk)} samples: max |u_C - u_Python| = {err:.3g} pu")
    assert err <= TOL
    # without the clip the C law equals the demanded u (clip off: Vmax <= 0)
    spec0 = type(spec)(spec.state_map, None, spec.bypass)
    c0 = CController(compile_digital(ctl, spec0, tmp_path, "c2n"), "c2n")
    U0 = np.array([c0.step(m)[1] for m in meas])
    assert np.abs(U0[active] - ud[active]).max() <= TOL


@needs_gcc
def test_c_step_enable_input_and_fail_safe(closed_loop, tmp_path):
    rec, ctl, spec = closed_loop
    tk, meas, active, ud, ua = recorded(rec, spec)
    c = CController(compile_digital(ctl, spec, tmp_path), "c2")
    k = int(np.nonzero(active & (np.hypot(ud[:, 0], ud[:, 1]) > 0.05))[0][0])
    for j in range(k):
        c.step(meas[j])
    off = meas[k].copy()
    off[-1] = 0.0                                      # external disable: bypass output
    assert c.step(off) == (1, pytest.approx([0.0, 0.0]))
    bad = meas[k + 1].copy()
    bad[0] = np.nan                                    # a lost measurement: fail-safe
    rc, u = c.step(bad)
    assert rc == -1 and np.all(u == 0.0)
    rc, u = c.step(meas[k + 2])                        # the clock kept counting
    assert rc == 0 and np.abs(u - ua[k + 2]).max() <= TOL


@pytest.fixture(scope="module")
def fmu_file(closed_loop, tmp_path_factory):
    if CC is None:
        pytest.skip("gcc is not installed: the FMU cannot be compiled")
    from weakgrid.fmu import build_fmu
    from weakgrid.models.export_digital import fmu_block

    rec, ctl, spec = closed_loop
    files = generate_digital_c(ctl, spec, "c2hji", "test")
    return build_fmu(fmu_block(ctl, spec, "c2hji"), files,
                     tmp_path_factory.mktemp("fmu") / "c2hji.fmu")


def test_fmu_model_description_validates(closed_loop, fmu_file):
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(fmu_file)) == []
    md = read_model_description(str(fmu_file))
    assert md.fmiVersion == "2.0" and md.coSimulation.modelIdentifier == "c2hji"
    causal = {v.name: v.causality for v in md.modelVariables}
    rec, ctl, spec = closed_loop
    assert [n for n, c in causal.items() if c == "input"] == inputs(spec)
    assert {"Vup", "Vuq"} <= {n for n, c in causal.items() if c == "output"}
    assert {causal[k] for k in ["Vmax", "bypass_0_start", *spec.state_map.values()]} == \
        {"parameter"}
    assert float(md.defaultExperiment.stepSize) == ctl.system.T


def test_fmu_equals_the_python_controller_in_closed_loop(closed_loop, fmu_file):
    """FMPy's FMU2Slave, set inputs -> get outputs -> doStep every T (direct feedthrough)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    rec, ctl, spec = closed_loop
    tk, meas, active, ud, ua = recorded(rec, spec)
    md = read_model_description(str(fmu_file))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    ins = [vr[n] for n in inputs(spec)]
    outs = [vr[n] for n in ("Vup", "Vuq", "Vup_demand", "Vuq_demand", "active")]
    d = extract(str(fmu_file))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier="c2hji", instanceName="c")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    T = ctl.system.T
    got = np.zeros((len(tk), 5))
    for k in range(len(tk)):
        fmu.setReal(ins, list(meas[k]))
        got[k] = fmu.getReal(outs)
        fmu.doStep(currentCommunicationPoint=k * T, communicationStepSize=T)
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(d, ignore_errors=True)
    np.testing.assert_array_equal(got[:, 4] == 1.0, active)
    err = np.abs(got[:, :2] - ua).max()
    print(f"FMU vs Python, {rec.scenario.id}, {len(tk)} samples: "
          f"max |u_FMU - u_Python| = {err:.3g} pu")
    assert err <= TOL
    assert np.abs(got[active, 2:4] - ud[active]).max() <= TOL


def test_fmu_simulated_by_fmpy_with_input_signals(closed_loop, fmu_file):
    """fmpy.simulate_fmu: inputs applied at t, doStep, outputs recorded at t + T — the
    controller's output of sample k is recorded at t_(k+1) (the master's one-step delay)."""
    from fmpy import simulate_fmu

    rec, ctl, spec = closed_loop
    tk, meas, active, ud, ua = recorded(rec, spec)
    T = ctl.system.T
    t = np.arange(len(tk)) * T
    sig = np.zeros(len(tk), dtype=[("time", float)] + [(n, float) for n in inputs(spec)])
    sig["time"] = t
    for n, col in zip(inputs(spec), meas.T):
        sig[n] = col
    res = simulate_fmu(str(fmu_file), start_time=0.0, stop_time=t[-1], step_size=T,
                       output_interval=T, input=sig, output=["Vup", "Vuq"])
    got = np.column_stack([res["Vup"], res["Vuq"]])
    assert len(got) == len(tk)
    np.testing.assert_allclose(res["time"], t, rtol=0, atol=1e-12)
    err = np.abs(got[1:] - ua[:-1]).max()
    print(f"fmpy.simulate_fmu vs Python, {rec.scenario.id}: max |u_FMU - u_Python| = {err:.3g} pu")
    assert err <= TOL and np.abs(got[0] - ua[0]).max() <= TOL
    # a parameter set at start: rating 0.05 pu clips harder
    res = simulate_fmu(str(fmu_file), start_time=0.0, stop_time=t[-1], step_size=T,
                       output_interval=T, input=sig, output=["Vup", "Vuq"],
                       start_values={"Vmax": 0.05})
    got = np.column_stack([res["Vup"], res["Vuq"]])
    assert np.abs(got[1:] - rating_clip(ud[:-1], 0.05)).max() <= TOL


@needs_gcc
def test_cli_writes_the_validated_controller(closed_loop, tmp_path, capsys):
    """`weakgrid export --study --scenario` writes the C checked above, and its FMU."""
    from weakgrid.cli.main import main

    rec, ctl, spec = closed_loop
    f = tmp_path / "c2hji.controller.json"
    ctl.save(f)
    args = ["export", str(f), "--study", rec.scenario.case, "--scenario", rec.scenario.scenario]
    assert main(args + ["--format", "c"]) == 0
    from weakgrid import __version__

    prov = f"From {f.name} (weakgrid {__version__}; model kind upqc-design)."
    from weakgrid.hashing import stamp_c

    for k, text in generate_digital_c(ctl, spec, "c2hji", prov).items():
        assert (tmp_path / k).read_text() == stamp_c(text), k   # + its checksum line
    out = capsys.readouterr().out
    assert f"|u| <= {spec.Vmax:g} pu" in out and str(spec.bypass[0]) in out
    assert all(k in out for k in spec.state_map.values())
    from fmpy.validation import validate_fmu

    assert main(args + ["--format", "fmu", "-d", str(tmp_path / "fmu")]) == 0
    assert validate_fmu(str(tmp_path / "fmu" / "c2hji.fmu")) == []


def test_cli_refuses_incomplete_constants(trained_presets, tmp_path, capsys):
    from weakgrid.cli.main import main

    _, ctl = trained_presets["case2-paper"]
    f = tmp_path / "p.controller.json"
    ctl.save(f)
    assert main(["export", str(f)]) == 2
    assert "ws" in capsys.readouterr().err
    assert main(["export", str(f), "--param", "ws=314.1592653589793", "--rating", "0.1",
                 "--bypass", "3.0:3.1"]) == 0
    h = (tmp_path / "p.h").read_text()
    assert "p_step" in h and "meas[2]  omega" in h
    assert "p->bypass[0][1] = 3.1;" in (tmp_path / "p.c").read_text()
    assert main(["export", str(f), "--param", "ws=1", "--bypass", "3.1"]) == 2
    assert main(["export", str(f), "--param", "tau=1", "--param", "ws=1"]) == 2
    assert main(["export", str(f), "--param", "ws=1", "--load", "high"]) == 2   # needs --study
    capsys.readouterr()


def test_cli_refuses_a_model_without_a_digital_upqc_controller(tmp_path, capsys):
    from weakgrid.cli.main import main
    from weakgrid.game import (GameCost, GridMesh, LinearPolicy, LinearSystem, dlqr,
                               even_monomials, solve_hji)

    A, B, E = np.array([[1.0, 0.01], [-0.1, 0.99]]), np.eye(2), 0.1 * np.ones((2, 1))
    s = LinearSystem(A, B, E)
    K, _, _ = dlqr(A, B, np.eye(2), np.eye(2))
    ctl = solve_hji(s, even_monomials(2, 2), GameCost.for_system(s, np.eye(2), np.eye(2),
                                                                 np.eye(1), 5.0),
                    GridMesh([-1] * 2, [1] * 2, [0.5] * 2), LinearPolicy(K))
    f = tmp_path / "lin.controller.json"
    ctl.save(f)
    assert main(["export", str(f), "--format", "c"]) == 2
    assert "c-law" in capsys.readouterr().err
    assert main(["export", str(f), "--format", "c-law"]) == 0
