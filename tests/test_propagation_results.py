"""A propagation's result is read by the variables a model was written with: ``res[x[0]]``,
``res["x_0"]``, and a whole family as arrays of bounds (``res.bounds(x)``, ``res[x]``)."""

from __future__ import annotations

import numpy as np
import pytest

from boundest import Interval, parse_model
from boundest.csp import propagate
from boundest.expr import Model, Var, VarFamily


def _chain() -> tuple[Model, VarFamily]:
    x = VarFamily("x")
    m = Model()
    m.declare(x[0], (0, 1))
    m.add(x[k + 1] == x[k] + 1 for k in range(3))
    return m, x


def test_a_result_is_indexed_by_the_variable_itself():
    m, x = _chain()
    res = propagate(m, mode="hc4")
    assert res[x[2]] == res["x_2"] == Interval(2, 3)
    assert res[Var("x_3")] == Interval(3, 4)  # an equal name, another object
    with pytest.raises(KeyError, match="x_9"):
        res[x[9]]
    with pytest.raises(TypeError, match="str, a Var or a VarFamily"):
        res[3]


def test_a_family_comes_back_as_arrays_of_bounds_in_one_call():
    m, x = _chain()
    res = propagate(m, mode="hc4")
    lo, hi = res.bounds(x)
    assert lo.tolist() == [0, 1, 2, 3] and hi.tolist() == [1, 2, 3, 4]
    assert (res[x] == Interval(lo, hi)).all() and res[x].shape == (4,)
    one_lo, one_hi = res.bounds(x[1])
    assert (float(one_lo), float(one_hi)) == (1.0, 2.0)


def test_a_two_index_family_and_a_parsed_model():
    p = VarFamily("p")
    m = Model()
    for k in range(2):
        for i in range(3):
            m.declare(p[k, i], (k, k + i + 1))
    res = propagate(m.add(p[0, 0] + p[1, 2] <= 1.5), mode="hc4")
    lo, hi = res.bounds(p)
    assert lo.shape == hi.shape == (2, 3)
    assert hi[0].tolist() == [0.5, 2, 3] and hi[1].tolist() == [2, 3, 1.5]
    assert lo[1].tolist() == [1, 1, 1]
    # a model from text has no VarFamily object: the family is found by its members' names
    text = parse_model("y_0 in [0, 1], y_1 in [0, 5], y_2 in [0, 5], y in [0, 9];\n"
                       "Constraints\ny_1 = y_0 + 1, y_2 = y_1 + 1, y = y_2;")
    lo, hi = propagate(text, mode="hc4").bounds(VarFamily("y"))
    assert lo.tolist() == [0, 1, 2] and hi.tolist() == [1, 2, 3]  # y itself is no member


def test_a_family_with_gaps_or_mixed_indices_is_refused_by_name():
    x = VarFamily("x")
    m = Model()
    m.add(x[0] == 1, x[3] == 2)
    res = propagate(m, mode="hc4")
    with pytest.raises(KeyError, match=r"2 gaps.*x_1, x_2"):
        res.bounds(x)
    with pytest.raises(KeyError, match="no variable of the family 'z'"):
        res.bounds(VarFamily("z"))
    m.add(Var("x_1_0") == 3)  # x_1_0: a member of x with two indices, or of a family x_1
    with pytest.raises(ValueError, match=r"members with \[1, 2\] indices"):
        propagate(m, mode="hc4").bounds(x)
    assert propagate(m, mode="hc4").bounds(VarFamily("x_1"))[0].tolist() == [3]


def test_an_empty_result_gives_empty_domains_and_nan_bounds():
    m, x = _chain()
    m.add(x[3] >= 10)
    res = propagate(m, mode="hc4")
    assert not res.consistent and res[x].is_empty().all()
    assert np.isnan(res.bounds(x)[0]).all()


def test_domains_of_a_call_are_given_by_var_too():
    m, x = _chain()
    res = propagate(m, mode="hc4", domains={x[3]: Interval(3.5, 9)})
    assert res[x[0]] == Interval(0.5, 1)


def test_propagate_lp_results_are_indexed_the_same_way():
    pytest.importorskip("scipy")
    from boundest.csp.linear import propagate_lp

    m, x = _chain()
    res = propagate_lp(m)
    assert res[x[1]] == res["x_1"] == Interval(1, 2)
    assert res.bounds(x)[1].tolist() == [1, 2, 3, 4]


def test_shave_and_targets_take_vars_and_families():
    x = VarFamily("x")
    m = Model()
    m.declare(x[0], (-1, 1))
    m.add(x[k + 1] == x[k] * x[k] - 0.5 for k in range(3))
    m.add(x[3] >= 0)
    names = [f"x_{k}" for k in range(4)]
    by_name = propagate(m, mode="3b", shave=names)
    for shave in ([x], [x[0], "x_1", x[2], x[3]]):
        res = propagate(m, mode="3b", shave=shave)
        assert res.domains == by_name.domains and res.shaving == {**by_name.shaving,
                                                                 "time_s": res.shaving["time_s"]}
    assert by_name.shaving["probes"] > 0
    res = propagate(m, mode="centered", targets=[x[3]])
    assert res.domains == propagate(m, mode="centered", targets=["x_3"]).domains
