"""Controllers of one family (the same design model, basis and cost but for their weights and
input bounds, e.g. one trained at each UPQC rating) evaluated in one call
(``GameController.rows_of``): each row's floats are those of its own controller alone."""

import numpy as np
import pytest

from weakgrid.game import FunctionSystem, GameCost, even_monomials
from weakgrid.game.controller import GameController
from weakgrid.game.errors import ParameterError


def _system():
    """A nonlinear design model written elementwise (as weakgrid's own): a row's floats do
    not depend on the rows evaluated with it (``LinearSystem``'s matrix products do)."""
    G = np.array([[0.1, 0.0], [0.0, 0.2], [0.05, 0.1]])
    H = np.array([[0.02, 0.0], [0.0, 0.03], [0.01, 0.0]])

    def f(x):
        x0, x1, x2 = x[..., 0], x[..., 1], x[..., 2]
        return np.stack([0.9 * x0 + 0.1 * x1, 0.95 * x1 - 0.05 * x0 * x2,
                         0.8 * x2 + 0.1 * x0 * x1], axis=-1)

    def g(x):
        return np.broadcast_to(G, np.shape(x)[:-1] + G.shape)

    def h(x):
        return np.broadcast_to(H, np.shape(x)[:-1] + H.shape)

    return FunctionSystem(f, g, h, 3, 2, 2)


def _controller(system, weights, bound=None, shape="disk", R=(2.0, 2.0), gamma=6.0):
    cost = GameCost.for_system(system, np.eye(3), np.diag(R), np.eye(2), gamma, bound=bound,
                               bound_shape=shape)
    return GameController(system, even_monomials(3, 4), weights, cost)


def _weights(basis_size, seed):
    """A convex quadratic part plus small higher-order terms (a J such training gives)."""
    rng = np.random.default_rng(seed)
    w = rng.normal(size=basis_size) * 0.02
    w[:6] = np.abs(w[:6]) + 0.5
    return w


def _family(bounded):
    s = _system()
    L = even_monomials(3, 4).size
    specs = ([(0.02, "disk"), (0.06, "disk"), ([0.03, 0.06], "box"), ([0.08, 0.01], "box")]
             if bounded else [(None, "disk")] * 4)
    return [_controller(s, _weights(L, k), bound=b, shape=sh) for k, (b, sh) in enumerate(specs)]


@pytest.mark.parametrize("bounded", [True, False])
def test_rows_of_gives_each_row_its_own_controller_bit_for_bit(bounded):
    ctls = _family(bounded)
    assert len({c.family_key() for c in ctls}) == 1
    rng = np.random.default_rng(11)
    for n in (2, 7, 25):
        ks = [ctls[i] for i in rng.integers(0, len(ctls), n)]
        X = rng.uniform(-1.5, 1.5, (n, 3))
        U = GameController.rows_of(ks, X)
        assert U.shape == (n, 2)
        for i, c in enumerate(ks):
            np.testing.assert_array_equal(U[i], c.control(X[i]))
            np.testing.assert_array_equal(U[i], c.rows(X[i:i + 1])[0])
        if bounded:        # the bounds did act: rows away from the unbounded saddle point
            assert any(np.abs(U[i] - c.unbounded_control(X[i])).max() > 1e-3
                       for i, c in enumerate(ks))


def test_rows_of_one_controller_is_its_rows():
    c = _family(True)[0]
    X = np.random.default_rng(2).uniform(-1, 1, (5, 3))
    np.testing.assert_array_equal(GameController.rows_of([c] * 5, X), c.rows(X))


def test_rows_of_refuses_controllers_of_another_family():
    s = _system()
    L = even_monomials(3, 4).size
    a = _controller(s, _weights(L, 0), bound=0.2)
    others = {"another R": _controller(s, _weights(L, 1), bound=0.2, R=(3.0, 3.0)),
              "another gamma": _controller(s, _weights(L, 1), bound=0.2, gamma=5.0),
              "no bound": _controller(s, _weights(L, 1)),
              "another design model": _controller(_system_scaled(s), _weights(L, 1), bound=0.2)}
    X = np.zeros((2, 3))
    for why, b in others.items():
        assert b.family_key() != a.family_key(), why
        with pytest.raises(ParameterError, match="more than its weights"):
            GameController.rows_of([a, b], X)


def _system_scaled(s):
    return FunctionSystem(lambda x: 0.5 * s.open_loop_dynamics(x), s.control_directions,
                          s.disturbance_directions, 3, 2, 2)


def test_rows_of_three_bounded_inputs_calls_each_controller_on_its_rows():
    """Beyond 2 inputs the bound's minimization is vectorized (not point by point): each
    controller of the family is then called on its own rows, as separate calls were."""
    G = np.array([[0.1, 0.0, 0.02], [0.0, 0.2, 0.0], [0.05, 0.1, 0.1]])

    def f(x):
        return np.stack([0.9 * x[..., 0] + 0.1 * x[..., 1], 0.95 * x[..., 1],
                         0.8 * x[..., 2] + 0.1 * x[..., 0] * x[..., 1]], axis=-1)

    s = FunctionSystem(f, lambda x: np.broadcast_to(G, np.shape(x)[:-1] + G.shape),
                       lambda x: np.broadcast_to(G[:, :1] * 0.2, np.shape(x)[:-1] + (3, 1)),
                       3, 3, 1)
    L = even_monomials(3, 4).size
    ctls = []
    for k, lim in enumerate(([0.02, 0.03, 0.04], [0.05, 0.01, 0.02])):
        cost = GameCost.for_system(s, np.eye(3), np.eye(3), np.eye(1), 6.0, bound=lim,
                                   bound_shape="box")
        ctls.append(GameController(s, even_monomials(3, 4), _weights(L, k), cost))
    assert ctls[0].family_key() == ctls[1].family_key()
    X = np.random.default_rng(4).uniform(-1.5, 1.5, (6, 3))
    ks = [ctls[i] for i in (0, 1, 1, 0, 1, 0)]
    U = GameController.rows_of(ks, X)
    for c in ctls:
        idx = [i for i, k in enumerate(ks) if k is c]
        np.testing.assert_array_equal(U[idx], c.rows(X[idx]))
