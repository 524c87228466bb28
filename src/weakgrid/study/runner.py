"""Run one (scenario, controller) of a study on the detailed simulator and measure it."""

from __future__ import annotations

import fnmatch
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from ..game.errors import ParameterError
from ..sim.controllers import DigitalController, UPQCTarget
from ..sim.events import Fault, GeneratorTrip, LineTrip, LoadStep
from ..sim.integrate import simulate
from ..sim.network import F_BUS, T_BUS
from ..sim.upqc import rating_clip
from .build import build_setup
from .controllers import controller_variant, make_controller
from .device import power_metrics
from .failure import failure_text
from .law import StudyLaw
from .metrics import (SETTLING_BANDS, backswing, control_cost, definition_spread, itae,
                      running_cost, settling_time, stability_verdict)

__all__ = ["Run", "RunRecord", "Prepared", "run_scenario", "run_scenarios", "prepare_run",
           "simulate_prepared",
           "finish_run", "enable_windows", "make_events", "sim_settings", "derive_series",
           "flat_columns", "record_list", "metric_signals"]

Q_DESIGN = 0.01 * np.eye(2)  # the paper's state weight of (18), for the running cost metric
R_DESIGN = np.eye(2)


@dataclass(frozen=True)
class Run:
    """One run: a scenario of a study with one controller (``id = scenario-controller``)."""

    id: str
    case: str
    scenario: str
    load: str
    upqc: str
    controller: str
    t_end: float
    events: tuple
    bypass: tuple
    design_load: str | None = None   # load the controllers are designed at (None: own load)

    @classmethod
    def of(cls, study, sc: dict, controller: str) -> "Run":
        return cls(f"{sc['id']}-{controller}", study.name, sc["id"], sc["load"], sc["upqc"],
                   controller, float(sc["t_end"]), tuple(dict(e) for e in sc["events"]),
                   tuple(tuple(b) for b in sc["bypass"]), sc.get("design_load"))

    @property
    def design_key(self):
        """``(design load, UPQC structure)``: the operating point its controllers are for."""
        return (self.design_load or self.load, self.upqc)

    def to_dict(self):
        d = asdict(self)
        d["events"], d["bypass"] = [dict(e) for e in self.events], [list(b) for b in self.bypass]
        return d

    @property
    def fault_text(self) -> str:
        f = [e for e in self.events if e["kind"] == "fault"]
        return ", ".join(f"{e['t_on']:g}-{e['t_off']:g} s" for e in f) or "none"


class _MeasureOnly:
    """A controller target that applies nothing: samples the design states for the
    running cost when no UPQC is driven (PQ baseline)."""

    size = 2

    def bind(self, system):
        self._u = np.zeros(2)

    def get(self):
        return self._u

    def apply(self, u):
        self._u = np.asarray(u, float)


@dataclass
class RunRecord:
    """What a run produced: metrics (flat dict), the series the figures need and the
    simulator's full trajectories.

    Attributes
    ----------
    series : dict
        Per recorded instant (every array as long as ``series["t"]``, so
        ``pandas.DataFrame(series)`` works): ``t`` [s] and the figure keys, each an alias
        of a simulator signal (``aliases``) or derived from them (:func:`derive_series`).
    samples : dict
        Per controller sample (every array as long as ``samples["tk"]``): ``tk`` [s],
        ``running_cost`` and, for 2-D quantities (``x_design``, ``y_measured``,
        ``u_demanded``, ``u_applied``), one column ``key[j]`` each;
        :meth:`sample` stacks them back.
    results : weakgrid.sim.results.Results or None
        Every recorded signal of the simulation by name (None for a run read back from
        the cache: its run file holds them, :func:`weakgrid.read_run`).
    aliases : dict
        Figure key → simulator signal name (``sg_speed`` → ``G1.omega``).
    """

    scenario: Run
    metrics: dict
    series: dict
    info: dict = field(default_factory=dict)
    samples: dict = field(default_factory=dict)
    results: object = None
    aliases: dict = field(default_factory=dict)

    def sample(self, key) -> np.ndarray:
        """Per-sample quantity ``key``: 1-D, or 2-D (samples × columns ``key[j]``)."""
        if key in self.samples:
            return np.asarray(self.samples[key])
        cols = sorted((int(k[len(key) + 1:-1]), k) for k in self.samples
                      if k.startswith(key + "[") and k.endswith("]"))
        if not cols:
            raise KeyError(f"no per-sample '{key}' in this run; it has {sorted(self.samples)}")
        return np.column_stack([self.samples[k] for _, k in cols])


def flat_columns(d: dict) -> dict:
    """``d`` with every 2-D array split into 1-D columns ``key[j]``."""
    out = {}
    for k, v in d.items():
        a = np.asarray(v)
        if a.ndim == 2:
            for j in range(a.shape[1]):
                out[f"{k}[{j}]"] = a[:, j]
        else:
            out[k] = a
    return out


def derive_series(series: dict, Sb_mva: float) -> dict:
    """The figure keys computed from the aliased signals (a run read back from its file
    recomputes them identically): ``vu`` = √(vup² + vuq²) [pu], ``p_series_mw`` =
    ``p_series`` × Sb [MW]."""
    out = {}
    if "vup" in series and "vuq" in series:
        out["vu"] = np.hypot(series["vup"], series["vuq"])
    if "p_series" in series:
        out["p_series_mw"] = series["p_series"] * Sb_mva
    return out


def record_list(study, aliases: dict):
    """The simulator's ``record`` argument of a study's runs: ``None`` (every signal) unless
    ``[simulation] record`` selects some (names or fnmatch patterns); the signals the
    figures and metrics use (``aliases``) are always added."""
    rec = _sim(study).get("record")
    if rec is None:
        return None
    if isinstance(rec, str):
        rec = [rec]
    return list(dict.fromkeys([*rec, *aliases.values()]))


def metric_signals(setup) -> list:
    """The simulator signals a run's metrics read (:func:`finish_run`: the aliased signals of
    its grid, ``setup.signals``): what a sweep point that keeps no run file records
    (:func:`weakgrid.study.sweep.prepare_point`). Recorded alone, they cost a fraction of every
    signal's time and memory (case 2's maps: 10 of 237 columns), and the metrics are the same
    floats."""
    return list(dict.fromkeys(setup.signals.values()))


def enable_windows(bypass, t_end):
    """Windows the controller is active: the complement of the bypass windows in [0, t_end+1]."""
    out, t = [], 0.0
    for a, b in sorted(bypass):
        if a > t:
            out.append((t, a))
        t = max(t, b)
    out.append((t, t_end + 1.0))
    return out


def _branch_row(setup, ref, where):
    """Branch row of a study's branch reference: a source name (PSS/E ``"I-J-CKT"``, ANDES Line
    idx, pandapower element name or ``"line_3"``, a study's branch name), ``{from, to}`` buses,
    or a 0-based row of the network's branch table."""
    net = setup.system.network
    if isinstance(ref, str):
        if ref not in setup.branch_names:
            names = list(setup.branch_names)
            raise ParameterError(where, ref, f"no branch of that name; e.g. {names[:8]}"
                                 f"{' …' if len(names) > 8 else ''}, or {{from = BUS, to = BUS}}")
        return setup.branch_names[ref]
    if isinstance(ref, dict):
        f, t = setup.bus(ref.get("from"), f"{where}.from"), setup.bus(ref.get("to"), f"{where}.to")
        rows = [k for k, row in enumerate(net.branch) if {int(row[F_BUS]), int(row[T_BUS])}
                == {f, t}]
        if len(rows) != 1:
            raise ParameterError(where, ref, f"found {len(rows)} branches between these buses")
        return rows[0]
    if isinstance(ref, (int, np.integer)) and not isinstance(ref, bool) and 0 <= ref < net.nl:
        return int(ref)
    raise ParameterError(where, ref, f"give a branch name (e.g. {list(setup.branch_names)[:8]}), "
                         f"{{from = BUS, to = BUS}} or a row 0..{net.nl - 1}")


def make_events(setup, run: Run):
    """Simulator events of a run's scenario.

    Checked once the grid's identifiers are resolved (the study file's own check compares the
    references as written): no trip of the UPQC's own series branch however it is addressed
    (name, row or its buses), no two faults overlapping in time at one bus (``3`` and ``"3"``
    are one bus)."""
    out = []
    for j, e in enumerate(run.events):
        w = f"scenarios.{run.scenario}.events.{j}"
        if e["kind"] == "fault":
            f = Fault(bus=setup.bus(e["bus"], f"{w}.bus"), t_on=e["t_on"], t_off=e["t_off"],
                      rf=float(e["rf"]), xf=float(e["xf"]))
            for k, g in enumerate(out):
                if isinstance(g, Fault) and g.bus == f.bus and f.t_on < _end(g) and \
                        g.t_on < _end(f):
                    raise ParameterError(f"{w}.t_on", e["t_on"], f"overlaps the fault at the "
                                         f"same bus ({e['bus']}, {g.t_on:g}-{g.t_off:g} s) of "
                                         f"another event of this scenario; give one fault, or "
                                         "let the second start after the first is cleared")
            out.append(f)
        elif e["kind"] == "line_trip":
            row = _branch_row(setup, e["branch"], f"{w}.branch")
            if row == getattr(setup, "upqc_branch", None) and setup.upqc_name:
                raise ParameterError(f"{w}.branch", e["branch"], "is the UPQC's own series "
                                     "branch: tripping it disconnects the UPQC; trip another "
                                     "branch")
            out.append(LineTrip(row, e["t"], close=bool(e.get("close", False))))
        elif e["kind"] == "gen_trip":
            out.append(GeneratorTrip(unit_row(setup.system, e["machine"], f"{w}.machine"),
                                     e["t"]))
        else:
            _plausible_step(setup, e, w)
            out.append(LoadStep(setup.bus(e["bus"], f"{w}.bus"), e["t"], e["dP"], e["dQ"]))
    return out


def unit_row(system, name, where) -> int:
    """The gen-table row (0-based) of the machine or converter ``name`` of ``system`` (a
    study's ``[[dynamics.generator]]``/``[[dynamics.gti]]`` name, or an imported grid's:
    ANDES ``GENROU_3``, PSS/E ``GENROU_<bus>_<id>``); an unknown name is refused with the
    list."""
    rows = {c.names[i]: int(lk["gen"]) for c in system.components.values()
            if c.kind in ("machine", "device") for i, lk in enumerate(c.links)
            if lk.get("gen") is not None}
    if name not in rows:
        raise ParameterError(where, name, f"no machine or converter of that name in this grid; "
                             f"its units: {sorted(rows)}")
    return rows[name]


def _end(fault) -> float:
    """Clearing time of ``fault`` [s] (a permanent fault never clears)."""
    return float("inf") if fault.t_off is None else float(fault.t_off)


STEP_LIMIT = 10.0   # a load step beyond this many times the grid's size is refused


def _plausible_step(setup, e, w):
    """A load step no operating point of the grid could carry is refused with its size beside
    the grid's (the Newton iteration would fail with nothing to say)."""
    from ..sim.network import PD, PG, QD

    net = setup.system.network
    size = max(float(net.Sb), float(np.abs(net.bus[:, PD] + 1j * net.bus[:, QD]).sum()),
               float(np.abs(net.gen[:, PG]).sum()))
    step = abs(complex(e["dP"], e["dQ"]))
    if step > STEP_LIMIT * size:
        raise ParameterError(f"{w}.dP", e["dP"], f"a load step of {step:.4g} MVA is "
                             f"{step / size:.3g} times the grid's size ({size:.4g} MVA: the "
                             "largest of its base, total load and total generation); no "
                             "operating point carries it. Give dP, dQ in MW, Mvar, at most "
                             f"{STEP_LIMIT:g} × {size:.4g}")


def sim_engine(study) -> str:
    """The engine of ``study``'s runs: ``[simulation] engine`` (default ``"phasor"``)."""
    return _sim(study).get("engine") or "phasor"


def dpsim_measure(setup):
    """The DPsim twin of ``setup.measure_signals``: the same measured signals of the controlled
    machine read from DPsim's recorded signals (:mod:`weakgrid.sim.emt.controllers`)."""
    from ..sim.emt import gti_signals, sg_signals

    if setup.machine == "gti":
        return gti_signals(setup.source)
    return sg_signals(setup.source, setup.shunt_bus)


def _sim(study) -> dict:
    """The study's ``[simulation]`` table (empty if it has none)."""
    return study.data.get("simulation") or {}


def check_engine(study, setup, events) -> None:
    """Refuse, before any run, a model or event of ``setup`` that ``study``'s engine cannot
    run (the DPsim engines: :func:`weakgrid.sim.emt.check_supported`; the phasor engine runs
    everything)."""
    engine = sim_engine(study)
    if engine != "phasor":
        from ..sim.emt import check_supported

        sim = _sim(study)
        check_supported(setup.system, events, engine,
                        drop_saturation=sim.get("drop_saturation", False),
                        gti_power=sim.get("gti_power", "measured"))


def sim_settings(study, dt_factor: float = 1.0) -> tuple[float, float | None]:
    """``(dt, tol)``: integration step [s] and Newton tolerance [pu] of a run of ``study``.

    The step is the study's ``simulation.dt`` (default: the controller's sampling period
    ``design.T``; the integrator steps onto every sample anyway) times ``dt_factor``. The
    tolerance is ``simulation.tol`` for the study's own step and ``None`` (the simulator's
    default, scaled with the step like its local error:
    :func:`weakgrid.sim.integrate.default_tol`) otherwise. A reference run at half the step
    (``dt_factor = 0.5``, the sweeps' numerical-uncertainty check) is thus finer in both the
    step and the tolerance, and ``|m(T) − m(T/2)|`` measures the error of the study's
    setting, tolerance included.
    """
    sim = _sim(study)
    base = float(sim.get("dt") or study.data["design"]["T"])
    tol = sim.get("tol") if float(dt_factor) == 1.0 else None
    return base * float(dt_factor), (None if tol is None else float(tol))


@dataclass
class Prepared:
    """A run made ready to simulate (:func:`prepare_run`): its grid, events and controller.

    Attributes
    ----------
    setup : weakgrid.study.build.Setup
        The grid at the run's load, set up (``setup.system`` is what is simulated).
    events : list
        The simulator events of the run's scenario.
    dc : weakgrid.sim.controllers.DigitalController
        The run's digital controller (it logs its samples; ``xs``/``ys`` the design states and
        measured signals of its active samples).
    dt, tol : float
        Integration step [s] and Newton tolerance [pu] (``tol`` None: the simulator's default).
    record : list of str or None
        The simulator's ``record`` argument (:func:`record_list`).
    engine : str
        The study's engine (:func:`sim_engine`): ``"phasor"`` or a DPsim engine (its runs
        are simulated alone, at ``dt`` already divided by :func:`weakgrid.sim.emt.dpsim_step`).
    """

    study: object
    run: Run
    setup: object
    dload: str
    ctl: object
    choice: object
    dc: object
    events: list
    dt: float
    tol: float | None
    record: list | None
    xs: list
    ys: list
    engine: str = "phasor"

    def scenario(self) -> dict:
        """The run as a member of :func:`weakgrid.sim.batch.simulate_batch`."""
        return {"system": self.setup.system, "events": self.events, "controllers": [self.dc]}

    def sim_key(self) -> tuple:
        """Runs with equal keys can be simulated together (same final time, step, tolerance
        and recorded signals; their grids are compared by the batch simulator itself)."""
        return (self.run.t_end, self.dt, self.tol,
                None if self.record is None else tuple(self.record))


def run_scenario(study, run: Run, trained=None, dt=None, design_load=None,
                 design=None, tol=None) -> RunRecord:
    """Simulate ``run`` of ``study`` and compute its metrics: :func:`prepare_run`, the
    simulation, :func:`finish_run`.

    Parameters
    ----------
    trained : dict, optional
        ``(load, upqc) -> GameController`` cache of trained HJI controllers (keyed by the
        load the controller is designed at).
    dt, tol : float, optional
        Integration step [s] and Newton tolerance [pu]; default: the study's
        (:func:`sim_settings`: ``[simulation]``, else the controller's sampling period T and
        the simulator's default tolerance for it).
    design_load : str, optional
        Load level the controllers are designed at (default: the run's own load). The
        paper's low-load protocol applies the HIGH-load controllers at low load; the
        measured design states stay deviations from the run's own operating point.
    design : DesignModel, optional
        The design model (10) at ``design_load`` if already derived (a sweep caches it).
    """
    prep = prepare_run(study, run, trained, dt=dt, design_load=design_load, design=design,
                       tol=tol)
    res, wall = simulate_prepared([prep], batched=False)[0]
    return finish_run(prep, res, wall)


def run_scenarios(study, runs, trained=None, batched: bool = True) -> list:
    """:func:`run_scenario` of every run of ``runs`` (one study, the study's step), their
    simulations together when ``batched`` (:func:`simulate_prepared`); the records in order,
    each equal to its run alone but the wall time."""
    preps = [prepare_run(study, r, trained) for r in runs]
    return [finish_run(p, *sim) for p, sim in zip(preps, simulate_prepared(preps, batched))]


def prepare_run(study, run: Run, trained=None, dt=None, design_load=None, design=None,
                tol=None) -> Prepared:
    """Build the grid, the events and the digital controller of ``run`` (the arguments of
    :func:`run_scenario`); nothing is simulated."""
    setup = build_setup(study, run.load, run.upqc, controller_variant(study, run.controller))
    events = make_events(setup, run)
    check_engine(study, setup, events)     # a model the engine lacks: refused before training
    dload = design_load or run.design_load or run.load
    if design is None:
        design = setup.design if dload == run.load else \
            build_setup(study, dload, run.upqc).design
    ctl = (trained or {}).get((dload, run.upqc))
    choice = make_controller(study, run.controller, design, ctl)
    T = setup.design.T
    # the digital controller: measured signals -> design state -> law (batched over the runs
    # of a batch whose policies have the same content: weakgrid.study.law)
    K = StudyLaw(choice.policy, setup.state_map)
    xs, ys = K.xs, K.ys
    engine = sim_engine(study)
    target = UPQCTarget(setup.upqc_name) if setup.upqc_name else _MeasureOnly()
    measure = setup.measure_signals if engine == "phasor" else dpsim_measure(setup)
    dc = DigitalController(K, T=T, measure=measure, target=target,
                           enable=enable_windows(run.bypass, run.t_end), name=run.controller,
                           batched=True)
    if dt is None:
        dt, tol = sim_settings(study)
    if engine != "phasor":       # DPsim: the run's step in parts of at most dpsim_dt_max
        from ..sim.emt import DT_MAX, dpsim_step

        dt = dpsim_step(dt, _sim(study).get("dpsim_dt_max", DT_MAX))
    return Prepared(study, run, setup, dload, ctl, choice, dc, events, float(dt), tol,
                    record_list(study, setup.signals), xs, ys, engine)


def simulate_prepared(preps, batched: bool = True, stats: dict | None = None) -> list:
    """Simulate prepared runs (:func:`prepare_run`); ``[(Results, wall [s])]`` in order.

    ``batched``: the runs with equal :meth:`Prepared.sim_key` go to one
    :func:`weakgrid.sim.batch.simulate_batch` call (members equal their one-by-one runs to
    round-off; a failed member keeps its own failure; the wall time of a batch is shared
    equally by its members); otherwise each is simulated alone. A run that fails returns its
    failure in ``Results.failure``. ``stats``: filled with the batches' statistics summed
    (:func:`weakgrid.sim.batch.simulate_batch`: ``batches``, ``rerun``, ``alone``, ``timing``).
    """
    from ..sim.batch import simulate_batch

    out = [None] * len(preps)
    groups: dict = {}
    for i, p in enumerate(preps):     # DPsim runs are simulated alone
        groups.setdefault(p.sim_key() if batched and p.engine == "phasor" else i, []).append(i)
    for rows in groups.values():
        p0 = preps[rows[0]]
        t0 = time.perf_counter()
        if len(rows) == 1:
            res = [_simulate_alone(p0)]
        else:
            st: dict = {}
            res = simulate_batch(p0.setup.system, [preps[i].scenario() for i in rows],
                                 p0.run.t_end, batch_size=len(rows), dt=p0.dt, tol=p0.tol,
                                 record=p0.record, on_failure="return", stats=st)
            if stats is not None:
                for k, v in st.items():
                    if isinstance(v, dict):
                        acc = stats.setdefault(k, {})
                        for kk, vv in v.items():
                            acc[kk] = acc.get(kk, 0.0) + vv
                    else:
                        stats[k] = stats.get(k, 0) + v
        wall = (time.perf_counter() - t0) / len(rows)
        for i, r in zip(rows, res):
            out[i] = (r, wall)
    return out


def _simulate_alone(p: Prepared):
    """One prepared run on its study's engine (phasor: :func:`weakgrid.sim.integrate.simulate`;
    DPsim: :func:`weakgrid.sim.emt.simulate_dpsim` at the step of :func:`prepare_run`)."""
    if p.engine == "phasor":
        return simulate(p.setup.system, p.run.t_end, dt=p.dt, tol=p.tol, events=p.events,
                        controllers=[p.dc], on_failure="return", record=p.record)
    from ..sim.emt import simulate_dpsim

    sim = _sim(p.study)
    res = simulate_dpsim(p.setup.system, p.run.t_end, engine=p.engine, dt=p.dt, events=p.events,
                         controllers=[p.dc], gti_power=sim.get("gti_power", "measured"),
                         drop_saturation=sim.get("drop_saturation", False))
    if p.record is not None:
        res = res.subset([n for n in res.names if any(fnmatch.fnmatchcase(n, q)
                                                      for q in p.record)])
    return res


def finish_run(prep: Prepared, res, wall: float) -> RunRecord:
    """The metrics, series and samples of a prepared run from its simulation ``res``
    (:class:`weakgrid.sim.results.Results`) that took ``wall`` seconds."""
    study, run, setup, dc = prep.study, prep.run, prep.setup, prep.dc
    dload, ctl, choice, xs, ys = prep.dload, prep.ctl, prep.choice, prep.xs, prep.ys
    dt, tol, T, engine = prep.dt, prep.tol, setup.design.T, prep.engine
    # controller samples: times and (bypass-aware) outputs actually applied
    tk = np.asarray(dc.log_t)
    uk = np.asarray(dc.log_u).reshape(-1, 2)
    xk = np.full((len(tk), 2), np.nan)
    # measurements were logged only when active; align them by the active mask (the last
    # ones: a batch member re-run alone logged its batched samples before, dc.log_* not)
    active = np.array([dc.active(t) for t in tk], bool)
    na = int(active.sum())
    xk[active] = np.asarray(xs[len(xs) - na:]).reshape(-1, 2)
    ny = len(setup.state_map.signals)
    yk = np.full((len(tk), ny), np.nan)
    yk[active] = np.asarray(ys[len(ys) - na:]).reshape(-1, ny)
    t = res.t
    series = {"t": t}
    aliases = {k: n for k, n in setup.signals.items() if n in res}
    for key_, name in aliases.items():
        series[key_] = res[name]
    derived = derive_series(series, setup.Sb_mva)
    series.update(derived)   # a derived key replaces a same-named alias (vu = |vup + j vuq|)
    aliases = {k: n for k, n in aliases.items() if k not in derived}
    metrics = {"id": run.id, "case": run.case, "load": run.load, "upqc": run.upqc,
               "controller": run.controller, "design_load": dload, "fault": run.fault_text,
               "failed": res.failure is not None,
               "failure": failure_text(res.failure, setup, dc.log_u[-1] if dc.log_u else None),
               "wall_s": wall}
    # metrics are taken after the last disturbance (fault clearing, bypass end, step, trip)
    after = max([b[1] for b in run.bypass] + [e["t_off"] for e in run.events if "t_off" in e]
                + [e["t"] for e in run.events if "t" in e], default=0.0)
    post = t >= after
    for key_, label in (("sg_speed", "speed"), ("dc_voltage", "vdc")):
        if key_ not in series:
            continue
        y = series[key_]
        ok = np.isfinite(y) & post
        if ok.sum() > 2:
            metrics[f"{label}_peak_dev_pu"] = float(np.max(np.abs(y[ok] - y[0])))
            metrics[f"{label}_backswing_pu"] = backswing(t[ok], y[ok], after, y_final=y[0])
            metrics[f"{label}_settling_s"] = settling_time(t[ok], y[ok], after, y_final=y[0])
            metrics[f"{label}_itae"] = itae(t[ok], y[ok], after, y_final=y[0])
            metrics[f"{label}_final_dev_pu"] = float(y[ok][-1] - y[0])  # back to set-point?
            metrics[f"{label}_verdict"] = stability_verdict(t[ok], y[ok], after, y_set=y[0]) \
                if res.failure is None else "unstable"
            metrics.update(_definition_spreads(label, t[ok], y[ok], after, y[0], metrics))
        else:
            metrics.update({f"{label}_peak_dev_pu": float("nan"),
                            f"{label}_backswing_pu": float("nan"),
                            f"{label}_settling_s": float("nan"),
                            f"{label}_itae": float("nan"), f"{label}_verdict": "unstable"})
    xa = np.nan_to_num(xk)
    # what the UPQC applied: |Vu| scaled down to its rating, as the simulator does
    up = setup.system.components.get("UPQC")
    vmax = float(up.p["Vmax"][up.names.index(setup.upqc_name)]) if up is not None and \
        setup.upqc_name in up.names else float("inf")
    ua = rating_clip(uk, vmax) if uk.size else uk
    metrics["control_cost"] = control_cost(ua, R_DESIGN, T)
    metrics["control_cost_demanded"] = control_cost(uk, R_DESIGN, T)
    rc = running_cost(xa, ua, Q_DESIGN, R_DESIGN)
    metrics["running_cost_18"] = float(rc[-1]) if rc.size else 0.0
    # the costs' sensitivity to their horizon: summed to the end less _HORIZON of the record
    early = tk <= (t[-1] - _HORIZON * (t[-1] - after)) if len(tk) else np.zeros(0, bool)
    metrics["control_cost_def_unc"] = definition_spread(
        metrics["control_cost"], [control_cost(ua[early], R_DESIGN, T)] if early.any() else [])
    metrics["running_cost_18_def_unc"] = definition_spread(
        metrics["running_cost_18"], [float(rc[early][-1])] if early.any() else [])
    # per sample: the measured signals (NaN while bypassed), design states, demanded and
    # applied u, the running cost (and J, below)
    samples = {"tk": tk, "running_cost": rc, "x_design": xk, "y_measured": yk,
               "u_demanded": uk, "u_applied": ua}
    if "vu" in series:
        vu = series["vu"]
        metrics["vu_peak_pu"] = float(np.nanmax(vu)) if vu.size else 0.0
        metrics["vu_rms_pu"] = float(np.sqrt(np.nanmean(vu[post] ** 2))) if post.any() else 0.0
        metrics["vu_rating_pu"] = vmax
        metrics["vu_rating_reached"] = bool(metrics["vu_peak_pu"] >= vmax * (1 - 1e-6))
    if "p_series_mw" in series:
        pmw = series["p_series_mw"]
        pk = float(np.nanmax(np.abs(pmw[post]))) if post.any() else float("nan")
        metrics["p_series_peak_mw"] = pk
        metrics["p_series_peak_pct_line"] = 100 * pk / abs(setup.line_power_mw) \
            if setup.line_power_mw else float("nan")
    metrics["line_power_mw"] = setup.line_power_mw
    if setup.upqc_name:
        metrics.update(power_metrics(series, post, setup.Sb_mva, setup.s_rating_mva,
                                     setup.line_mva))
    metrics.update(_protocol_metrics(study, tk, uk, xk, vmax, after))
    if ctl is not None and len(tk):   # Fig. 10/13: J(x(t)) of (30), running cost with -γ²w'Pw
        J, rcw = value_along(ctl, xa, ua)
        samples["value_J"], samples["running_cost_w"] = J, rcw
    info = {"design": setup.design.to_dict(), "derivation": setup.derivation.to_dict(),
            "controller": choice.info, "Sb_mva": setup.Sb_mva,
            "sim": {"dt": float(dt), "tol": None if tol is None else float(tol),
                    "engine": engine,
                    **({k: _sim(study)[k] for k in ("gti_power", "drop_saturation")
                        if k in _sim(study)} if engine != "phasor" else {})}}
    return RunRecord(run, metrics, series, info, samples=flat_columns(samples), results=res,
                     aliases=aliases)


_TAIL = 0.5          # s: the final value's window (the metrics' default tail)
_HORIZON = 0.1       # the horizon's move for the definition check: this fraction of the record
                     # after the last disturbance is left out of ITAE and the costs


def _definition_spreads(label, t, y, after, y0, metrics) -> dict:
    """``<metric>_def_unc`` of a signal's metrics: each re-measured on the same trajectory with
    its definition's parameter moved (:func:`weakgrid.study.metrics.definition_spread`).

    ``t``, ``y``: the signal from ``after`` (the last disturbance) on; ``y0``: its set-point
    (the pre-disturbance value the metrics are measured against)."""
    out = {}
    ts = metrics[f"{label}_settling_s"]
    # a band at which the signal does not settle inside the record: at least the record's end
    longest = max(float(t[-1] - _TAIL - after), ts if np.isfinite(ts) else 0.0)
    alts = [settling_time(t, y, after, band=b, y_final=y0, tail=_TAIL) for b in SETTLING_BANDS]
    out[f"{label}_settling_s_def_unc"] = definition_spread(
        ts, [a if np.isfinite(a) else longest for a in alts])
    # backswing past the final value (the mean over the last _TAIL s), not the set-point
    out[f"{label}_backswing_pu_def_unc"] = definition_spread(
        metrics[f"{label}_backswing_pu"], [backswing(t, y, after, tail=_TAIL)])
    early = t <= t[-1] - _HORIZON * (t[-1] - after)
    out[f"{label}_itae_def_unc"] = definition_spread(
        metrics[f"{label}_itae"],
        [itae(t[early], y[early], after, y_final=y0)] if (early & (t >= after)).sum() > 2
        else [])
    return out


def omega_of(study):
    """Lower and upper corners of the training region Ω of the study's design settings."""
    from ..models import load_preset

    mesh = study.data["design"].get("mesh") or load_preset(study.data["design"]["settings"]).raw[
        "mesh"]
    return np.asarray(mesh["lower"], float), np.asarray(mesh["upper"], float)


def _protocol_metrics(study, tk, uk, xk, vmax, after) -> dict:
    """Per run: how much the rating clips u, demanded vs applied, how far x leaves Ω.

    * ``clip_fraction``: fraction of the post-fault controller samples at which the demanded
      |u| exceeds the rating (the applied u is then scaled down to it);
    * ``u_demanded_peak_pu``: the largest demanded |u| (what a C2-voltage claim is judged on);
    * ``omega_reach``: max over samples and states of x_i / (Ω's bound on that side): ≤ 1
      inside the training region, > 1 = the controller extrapolates its value function;
      ``extrapolation`` flags it.
    """
    out = {}
    mag = np.hypot(uk[:, 0], uk[:, 1]) if uk.size else np.zeros(0)
    post = tk >= after if len(tk) else np.zeros(0, bool)
    act = post & (mag > 0) if mag.size else post
    out["u_demanded_peak_pu"] = float(mag.max()) if mag.size else 0.0
    out["u_applied_peak_pu"] = float(np.minimum(mag, vmax).max()) if mag.size else 0.0
    out["clip_fraction"] = float(np.mean(mag[post] > vmax * (1 + 1e-9))) \
        if post.any() and np.isfinite(vmax) else 0.0
    out["clip_fraction_active"] = float(np.mean(mag[act] > vmax * (1 + 1e-9))) \
        if act.any() and np.isfinite(vmax) else 0.0
    lo, hi = omega_of(study)
    x = xk[np.all(np.isfinite(xk), axis=1)] if xk.size else xk
    if x.size:
        reach = np.where(x >= 0, x / hi, x / lo)
        out["omega_reach"] = float(np.max(reach))
        out["omega_reach_phi"] = float(np.max(reach[:, 0]))
        out["omega_reach_2"] = float(np.max(reach[:, 1]))
    else:
        out["omega_reach"] = out["omega_reach_phi"] = out["omega_reach_2"] = 0.0
    out["extrapolation"] = bool(out["omega_reach"] > 1.0)
    return out


def value_along(ctl, x, u):
    """``J(x_k)`` of (30) and the accumulated running cost of the discrete-time game (18),
    ``Σ_{j≤k} x_j'Qx_j + u_j'Ru_j − γ²w_j'Pw_j`` with w the worst-case disturbance w*(x_j)
    and Q, R, P, γ the controller's own cost, per controller sample."""
    x = np.asarray(x, float)
    J = np.asarray(ctl.value(x), float)
    w = np.asarray(ctl.disturbance(x), float)
    c = ctl.cost
    Q, R, P = (np.atleast_2d(np.asarray(m, float)) for m in (c.Q, c.R, c.P))
    q = np.einsum("ki,ij,kj->k", x, Q, x) + np.einsum("ki,ij,kj->k", u, R, u)
    wpw = np.einsum("ki,ij,kj->k", w, P, w)
    return J, np.cumsum(q - c.gamma ** 2 * wpw)
