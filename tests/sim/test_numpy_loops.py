"""The NumPy the package runs on gives one result per input, wherever the output array lies.

Why NumPy 2.0 is the floor (pyproject.toml; docs/performance.md, "NumPy 1.26 itself"): NumPy
1.26 chooses between a SIMD loop and its scalar loop by a memory-overlap check that counts a
strided input's span one stride too far, so an output that the allocator places right behind
the input takes the scalar loop, which rounds otherwise. The same batch run twice then differed
in the last bits (the UPQC's ``np.abs`` of a strided view of the bus voltages). These checks
place the output there on purpose: they fail on NumPy 1.26.4 on an AVX-512 machine (measured)
and pass on 2.0.2 to 2.4.6.
"""

import numpy as np
import pytest

N = 44          # rows, as in the failing run: 2 members' Jacobian points (21 colours + base)


def _strided_and_behind(values, stride):
    """A strided column view of ``values`` (``stride`` elements apart, the second column) and
    an output array that starts where NumPy 1.26 counts the view's span to end."""
    dtype = values.dtype
    buf = np.zeros(N * stride + N + 2, dtype)
    view = buf[:N * stride].reshape(N, stride)[:, 1:2]
    view[:, 0] = values
    return view, buf, 1 + N * stride     # the view starts at element 1: its span ends there


@pytest.mark.parametrize("stride", [2, 3, 4])
def test_complex_magnitude_of_a_strided_view_does_not_depend_on_the_output_place(stride):
    rng = np.random.default_rng(stride)
    z = rng.uniform(0.05, 1.5, N) * np.exp(1j * rng.uniform(-np.pi, np.pi, N))
    view, buf, end = _strided_and_behind(z, stride)
    behind = buf.view(float)[2 * end:2 * end + N].reshape(N, 1)   # float64 output, 2 per complex
    np.abs(view, out=behind)
    assert np.array_equal(behind[:, 0], np.abs(z.copy()))


@pytest.mark.parametrize("name", ["exp", "log", "arctan", "tan", "expm1", "log1p", "cbrt"])
@pytest.mark.parametrize("stride", [2, 3])
def test_a_transcendental_function_of_a_strided_view_does_not_depend_on_the_output_place(name, stride):
    x = np.random.default_rng(7).uniform(0.05, 0.95, N)
    view, buf, end = _strided_and_behind(x, stride)
    behind = buf[end:end + N].reshape(N, 1)
    getattr(np, name)(view, out=behind)
    assert np.array_equal(behind[:, 0], getattr(np, name)(x.copy()))


@pytest.mark.parametrize("name", ["arctan2", "power"])
def test_a_binary_function_of_a_strided_view_does_not_depend_on_the_output_place(name):
    rng = np.random.default_rng(5)
    x, y = rng.uniform(0.1, 3.0, N), rng.uniform(0.1, 3.0, (N, 1))
    view, buf, end = _strided_and_behind(x, 3)
    behind = buf[end:end + N].reshape(N, 1)
    getattr(np, name)(view, y, out=behind)
    assert np.array_equal(behind, getattr(np, name)(x.copy()[:, None], y))


@pytest.mark.parametrize("stride", [2, 3])
def test_a_complex_product_of_a_strided_view_does_not_depend_on_the_output_place(stride):
    rng = np.random.default_rng(11)
    a = rng.standard_normal(N) + 1j * rng.standard_normal(N)
    b = rng.standard_normal((N, 1)) + 1j * rng.standard_normal((N, 1))
    view, buf, end = _strided_and_behind(a, stride)
    behind = buf[end:end + N].reshape(N, 1)
    np.multiply(view, b, out=behind)
    assert np.array_equal(behind, a.copy()[:, None] * b)
