"""Training problems: a design model with the game settings, from a preset or a TOML file.

A problem file has the tables ``[model]``, ``[cost]``, ``[mesh]``, ``[basis]``,
``[initial_policy]`` and optionally ``[solver]``, ``[preset]`` and ``[published]``;
see ``src/weakgrid/data/presets/case1-paper.toml`` for a complete example.

``[model]`` kinds:

* ``upqc-design`` — the calibrated form of (10): ``T, a, Vr_bar, phi_s0``;
* ``gti`` — a GTI with dc link from physical data: ``C, tau, Vs, B, Vr_bar, T``,
  ``chi`` and one of ``Pin`` / ``phi_s0`` (see :func:`gti_design_model`);
* ``sg`` — a classical SG: ``H, E_prime, B, Vr_bar, T``, ``f_nominal`` and one of
  ``Pm`` / ``delta0`` (see :func:`sg_design_model`);
* ``linear`` — ``A, B, E`` matrices (for checks against the LQ game).

``[cost]`` may bound the control (beyond the paper): ``u_bound = 0.15`` with
``u_bound_shape = "disk"`` (‖u‖ ≤ ū, the UPQC's ``|Vu| = √(Vup² + Vuq²) ≤ rating``, the
default) or ``"box"`` (``|u_i| ≤ ū_i``; one value or one per input). The penalty
``W(u)`` of :mod:`weakgrid.game.input_bound` then replaces ``u'Ru``. Studies set the
bound from the device rating with :meth:`TrainingProblem.with_input_bound`.

``[basis]`` may name, as ``bounded = { kind = …, … }``, the basis of the bounded
(rating-aware) problem: used whenever the cost has a bound (in the file or by
:meth:`TrainingProblem.with_input_bound`); without it the bounded problem keeps the
problem's basis. The shipped presets choose ``{ kind = "full", degree = 4 }``: with the
paper's 8-term basis the bounded value has a ridge at the edge of Ω (docs/beyond.md).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from ..game import (
    GameController,
    GameCost,
    GridMesh,
    LinearPolicy,
    LinearSystem,
    ParameterError,
    SolverSettings,
    even_monomials,
    full_monomials,
    from_generator,
    paper_basis,
    solve_hji,
)
from ..fileio import check_file_name, safe_name
from ..game.bases import PolynomialBasis
from ..game.errors import ShapeError
from .design import UPQCDesignModel, gti_design_model, sg_design_model
from .policies import NonlinearInitialPolicy, lqr_policy
from .presets import preset_names

__all__ = ["TrainingProblem", "preset_names", "load_preset", "load_problem", "problem_from_dict"]

_SECTIONS = {"preset", "model", "cost", "mesh", "basis", "initial_policy", "solver", "published"}




def _read_toml(path) -> dict:
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise FileNotFoundError(2, "problem file does not exist", str(path)) from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError("config", str(path), f"is not valid TOML ({exc})") from None
    except UnicodeDecodeError as exc:
        raise ParameterError("config", str(path), f"is not UTF-8 text (byte {exc.start}): give "
                             "a TOML problem file") from None


def load_preset(name: str) -> "TrainingProblem":
    """A shipped preset by name (``weakgrid train --preset NAME``)."""
    names = preset_names()
    if name not in names:
        raise ParameterError("preset", name, f"unknown preset; choose one of {names}")
    path = resources.files("weakgrid") / "data" / "presets" / f"{name}.toml"
    with resources.as_file(path) as p:
        return problem_from_dict(_read_toml(p), source=f"preset:{name}")


def load_problem(path) -> "TrainingProblem":
    """A user's problem from a TOML file (``weakgrid train --config FILE``)."""
    d = _read_toml(path)
    try:
        return problem_from_dict(d, source=str(Path(path)))
    except (ParameterError, ShapeError) as exc:  # name the file in front of the field
        exc.args = (f"{path}: {exc.args[0]}",) + exc.args[1:]
        raise exc from None


def _need(d: dict, key: str, section: str):
    if key not in d:
        raise ParameterError(f"{section}.{key}", None, f"missing: add `{key} = …` to [{section}]")
    return d[key]


def _num(d, key, section, default=None):
    v = d.get(key, default) if default is not None else _need(d, key, section)
    try:
        v = float(v)
    except (TypeError, ValueError):
        raise ParameterError(f"{section}.{key}", v, "must be a number") from None
    if not np.isfinite(v):
        raise ParameterError(f"{section}.{key}", v, "must be finite")
    return v


def _array(d, key, section, default=None):
    """A number or a (nested) list of finite numbers, as a float array."""
    v = d.get(key, default) if default is not None else _need(d, key, section)
    try:
        a = np.asarray(v, float)
    except (TypeError, ValueError):
        raise ParameterError(f"{section}.{key}", v, "must be a number or a list of numbers "
                             "(rows of equal length)") from None
    if not np.all(np.isfinite(a)):
        raise ParameterError(f"{section}.{key}", v, "must be finite numbers")
    return a


def _int(d, key, section):
    v = d[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or int(v) != v or v < 1:
        raise ParameterError(f"{section}.{key}", v, "must be a whole number ≥ 1")
    return int(v)


def _table(d, key):
    v = d.get(key, {})
    if not isinstance(v, dict):
        raise ParameterError(key, v, f"must be a table: write it as [{key}] with key = value lines")
    return v


def _check_keys(d: dict, allowed: set, section: str):
    extra = set(d) - allowed
    if extra:
        raise ParameterError(f"{section}.{sorted(extra)[0]}", d[sorted(extra)[0]],
                             f"unknown key; allowed in [{section}]: {sorted(allowed)}")


def _model(d: dict):
    kind = _need(d, "kind", "model")
    if kind == "upqc-design":
        _check_keys(d, {"kind", "T", "a", "Vr_bar", "phi_s0", "machine", "upqc", "source"},
                    "model")
        return UPQCDesignModel(_num(d, "T", "model"), _num(d, "a", "model"),
                               _num(d, "Vr_bar", "model"), _num(d, "phi_s0", "model"),
                               machine=d.get("machine", "gti"), upqc=d.get("upqc", "conventional"),
                               source=d.get("source"))
    if kind == "gti":
        keys = {"C", "tau", "Vs", "B", "Vr_bar", "T", "chi", "Pin", "phi_s0"}
        _check_keys(d, keys | {"kind", "upqc"}, "model")
        _required(d, ("C", "tau", "Vs", "B", "Vr_bar", "T"), "gti")
        kw = {k: _num(d, k, "model") for k in keys if k in d}
        return gti_design_model(upqc=d.get("upqc", "conventional"), **kw)
    if kind == "sg":
        keys = {"H", "E_prime", "B", "Vr_bar", "T", "f_nominal", "Pm", "delta0"}
        _check_keys(d, keys | {"kind"}, "model")
        _required(d, ("H", "E_prime", "B", "Vr_bar", "T"), "sg")
        kw = {k: _num(d, k, "model") for k in keys if k in d}
        return sg_design_model(**kw)
    if kind == "linear":
        _check_keys(d, {"kind", "A", "B", "E", "state_names"}, "model")
        return LinearSystem(_array(d, "A", "model"), _array(d, "B", "model"),
                            _array(d, "E", "model"), d.get("state_names"))
    raise ParameterError("model.kind", kind, "use 'upqc-design', 'gti', 'sg' or 'linear'")


def _required(d: dict, keys, kind):
    for k in keys:
        if k not in d:
            raise ParameterError(f"model.{k}", None, f"missing; a model of kind '{kind}' needs "
                                 f"{', '.join(keys)}")


def _bases(d: dict, n: int):
    """``(basis, bounded basis or None)`` of a ``[basis]`` table (its ``bounded`` sub-table)."""
    if "bounded" not in d:
        return _basis(d, n), None
    b = d["bounded"]
    if not isinstance(b, dict):
        raise ParameterError("basis.bounded", b, "give a table, e.g. bounded = { kind = "
                             "\"full\", degree = 4 }")
    if "bounded" in b:
        raise ParameterError("basis.bounded.bounded", b["bounded"], "the bounded basis has "
                             "no bounded basis of its own: remove it")
    try:
        bb = _basis(b, n)
    except ParameterError as exc:  # name the field where it is
        raise ParameterError(exc.field.replace("basis.", "basis.bounded.", 1), exc.value,
                             exc.fix) from None
    return _basis({k: v for k, v in d.items() if k != "bounded"}, n), bb


def _basis(d: dict, n: int) -> PolynomialBasis:
    kind = d.get("kind", "paper")
    if kind == "paper":
        if n != 2:
            raise ParameterError("basis.kind", kind, "the paper's basis is for 2 states; use "
                                 "'even' or 'generator'")
        return paper_basis()
    if kind == "even":
        return even_monomials(n, int(_num(d, "degree", "basis")))
    if kind == "full":
        return full_monomials(n, _num(d, "degree", "basis"))
    if kind == "generator":
        coef = d.get("coefficients")
        return from_generator(n, _array(d, "powers", "basis", [2, 4]),
                              None if coef is None else _array(d, "coefficients", "basis"))
    if kind == "custom":
        e = _array(d, "exponents", "basis")
        if np.any(e < 0) or np.any(e != np.round(e)):
            raise ParameterError("basis.exponents", e.tolist(), "exponents are whole numbers ≥ 0")
        return PolynomialBasis(e.astype(int), name="custom")
    raise ParameterError("basis.kind", kind, "use 'paper', 'even', 'full', 'generator' or "
                         "'custom'")


def _policy(d: dict, system):
    kind = _need(d, "kind", "initial_policy")
    if kind == "nonlinear-29":
        if not isinstance(system, UPQCDesignModel):
            raise ParameterError("initial_policy.kind", kind, "(29) needs a UPQC design model")
        chi = float(system.source.get("chi", 0.0) or 0.0)
        return NonlinearInitialPolicy.on_design_model(
            system, _num(d, "gain", "initial_policy"), _num(d, "phase", "initial_policy"), chi)
    if kind == "lqr":
        return lqr_policy(system, _weight(_array(d, "Q", "initial_policy", 0.01), system.n_states),
                          _weight(_array(d, "R", "initial_policy", 1.0), system.n_controls))
    if kind == "linear":
        K = np.atleast_2d(_array(d, "K", "initial_policy"))
        if K.shape != (system.n_controls, system.n_states):
            raise ParameterError("initial_policy.K", K.tolist(), f"has shape {K.shape}; give "
                                 f"{system.n_controls} × {system.n_states} (controls × states: "
                                 "u = −K x)")
        return LinearPolicy(K)
    raise ParameterError("initial_policy.kind", kind, "use 'nonlinear-29', 'lqr' or 'linear'")


def _weight(v, k):
    v = np.asarray(v, float)
    return v * np.eye(k) if v.ndim == 0 else v


@dataclass
class TrainingProblem:
    """Everything the solver needs, with its provenance.

    Attributes
    ----------
    name : str
    system : ControlAffineSystem
    basis : PolynomialBasis
    cost : GameCost
    mesh : GridMesh
    initial_policy : callable
    settings : SolverSettings
    published : dict
        The paper's weights and iteration counts, if any.
    raw : dict
        The problem file as read.
    """

    name: str
    system: object
    basis: PolynomialBasis
    cost: GameCost
    mesh: GridMesh
    initial_policy: object
    settings: SolverSettings
    published: dict = field(default_factory=dict)
    raw: dict = field(default_factory=dict)
    source: str = ""

    def train(self, settings: SolverSettings | None = None, progress=None, *, start=None,
              checkpoint=None) -> GameController:
        """Run the two-loop policy iteration (docs/theory.md, (25)–(28)); ``start`` and
        ``checkpoint`` resume and record it (see :func:`weakgrid.game.hji.solve_hji`)."""
        extra = {"name": self.name, "source": self.source}
        if self.published and self.cost.bound is None:
            extra["published"] = self.published
        return solve_hji(self.system, self.basis, self.cost, self.mesh, self.initial_policy,
                         settings or self.settings, problem=extra, progress=progress,
                         start=start, checkpoint=checkpoint)

    def with_gamma(self, gamma: float) -> "TrainingProblem":
        c = self.cost
        return TrainingProblem(self.name, self.system, self.basis,
                               GameCost.for_system(self.system, c.Q, c.R, c.P, gamma,
                                                   bound=c.bound), self.mesh,
                               self.initial_policy, self.settings, self.published, self.raw,
                               self.source)

    def with_rating(self, rating, shape: str | None = None) -> "TrainingProblem":
        """Bounded by the problem's own ``u_bound`` if it sets one, else by ``rating``.

        The hook for studies: ``problem.with_rating(upqc_rating)`` trains the bounded
        controller of a case with the device's rating unless the design settings
        choose another bound.
        """
        if self.cost.bound is not None:
            return self
        return self.with_input_bound(rating, shape)

    @property
    def input_bound(self):
        """The :class:`~weakgrid.game.input_bound.InputBound` of the cost, or None."""
        return self.cost.bound

    def with_input_bound(self, limit, shape: str | None = None) -> "TrainingProblem":
        """The same problem with the control bounded (e.g. by a device rating).

        Parameters
        ----------
        limit : float, sequence of float, or None
            ``ū`` in the units of u (per unit for the UPQC series voltage); None
            removes the bound (the paper's cost).
        shape : {"disk", "box"}, optional
            Default: the problem file's ``u_bound_shape``, else "disk".

        The published weights are dropped (they are for the unbounded cost). The basis
        is the problem file's ``[basis] bounded`` table while bounded (the shipped
        presets: every monomial of degree 2–4), its ``[basis]`` otherwise.
        See also :meth:`with_rating`.
        """
        if limit is None:
            cost = self.cost.with_bound(None)
        else:
            shape = shape or self.raw.get("cost", {}).get("u_bound_shape", "disk")
            c = self.cost
            cost = GameCost.for_system(self.system, c.Q, c.R, c.P, c.gamma, bound=limit,
                                       bound_shape=shape)
        name = self.name if cost.bound is None else f"{self.name}-bounded"
        basis = self.basis
        raw_basis = self.raw.get("basis", {}) if isinstance(self.raw, dict) else {}
        if isinstance(raw_basis, dict) and "bounded" in raw_basis:
            plain, bounded = _bases(raw_basis, self.system.n_states)
            if (self.cost.bound is None and self.basis == plain) or \
                    (self.cost.bound is not None and self.basis == bounded):
                basis = plain if cost.bound is None else bounded   # (a basis set apart stays)
        return TrainingProblem(name, self.system, basis, cost, self.mesh,
                               self.initial_policy, self.settings,
                               self.published if cost.bound is None else {}, self.raw,
                               self.source)


def problem_from_dict(d: dict, source: str = "") -> TrainingProblem:
    """Build a :class:`TrainingProblem` from the tables of a problem file."""
    extra = set(d) - _SECTIONS
    if extra:
        raise ParameterError(sorted(extra)[0], "…", f"unknown table; allowed: {sorted(_SECTIONS)}")
    for sec in ("model", "cost", "mesh", "initial_policy"):
        if sec not in d:
            raise ParameterError(sec, None, f"missing table [{sec}]")
    for sec in _SECTIONS:
        _table(d, sec)
    system = _model(d["model"])
    c = d["cost"]
    _check_keys(c, {"Q", "R", "P", "gamma", "u_bound", "u_bound_shape"}, "cost")
    gamma = _num(c, "gamma", "cost")
    if gamma <= 0:
        raise ParameterError("cost.gamma", gamma, "the attenuation level must be > 0")
    shape = c.get("u_bound_shape", "disk")
    if "u_bound_shape" in c and "u_bound" not in c:
        raise ParameterError("cost.u_bound", None, "u_bound_shape is given without a bound: "
                             "add `u_bound = …` (e.g. the device rating) or drop the shape")
    cost = GameCost.for_system(system, _array(c, "Q", "cost"), _array(c, "R", "cost"),
                               _array(c, "P", "cost"), gamma,
                               bound=c.get("u_bound"), bound_shape=shape)
    m = d["mesh"]
    _check_keys(m, {"lower", "upper", "step"}, "mesh")
    mesh = GridMesh(_array(m, "lower", "mesh"), _array(m, "upper", "mesh"),
                    _array(m, "step", "mesh"))
    if mesh.n_states != system.n_states:
        raise ParameterError("mesh.lower", list(mesh.lower),
                             f"give one bound per state ({system.n_states})")
    basis, bounded_basis = _bases(d.get("basis", {}), system.n_states)
    if cost.bound is not None and bounded_basis is not None:
        basis = bounded_basis
    policy = _policy(d["initial_policy"], system)
    s = d.get("solver", {})
    _check_keys(s, {"tol_u", "tol_w", "max_outer", "max_inner"}, "solver")
    s = {k: (_num(s, k, "solver") if k.startswith("tol") else _int(s, k, "solver")) for k in s}
    settings = SolverSettings(**s)
    # a name read from a file becomes part of output file names: keep it inside the folder
    pre = d.get("preset", {})
    name = check_file_name(pre["name"], "preset.name") if isinstance(pre, dict) and "name" in pre \
        else safe_name(Path(source).stem if source else "custom", "custom")
    return TrainingProblem(name, system, basis, cost, mesh, policy, settings,
                           d.get("published", {}), d, source)
