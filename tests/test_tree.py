"""FALL/CLIMB on tree SCSPs (Jaulin et al. 2001, section 3.2): optimality against brute force and
against
every other order of local contractions (Waltz), on finite-set and interval domains."""

from __future__ import annotations

import itertools
import random
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from boundest import Interval
from boundest.csp.tree import Arc, TreeSCSP

U = range(6)  # the universe of the finite-set domains


def relation_arc(a, b, rel: frozenset) -> Arc:
    """The exact local operators of a finite relation ``rel`` of pairs (v_a, v_b)."""
    return Arc(a, b,
               lambda va, vb: frozenset(x for x in va if any((x, y) in rel for y in vb)),
               lambda vb, va: frozenset(y for y in vb if any((x, y) in rel for x in va)))


@st.composite
def finite_trees(draw):
    n = draw(st.integers(1, 6))
    parents = [draw(st.integers(0, i - 1)) for i in range(1, n)]
    pairs = list(itertools.product(U, U))
    rels = [frozenset(p for p in pairs if draw(st.integers(0, 99)) < 35) for _ in parents]
    doms = [frozenset(u for u in U if draw(st.integers(0, 99)) < 70) for _ in range(n)]
    arcs, names = [], [f"v{i}" for i in range(n)]
    for i, (p, rel) in enumerate(zip(parents, rels, strict=True), start=1):
        # random orientation: the relation reads (a, b) either way round
        arcs.append(relation_arc(names[p], names[i], rel) if draw(st.booleans())
                    else relation_arc(names[i], names[p], frozenset((y, x) for x, y in rel)))
    draw(st.randoms()).shuffle(arcs)
    root = draw(st.sampled_from(names))
    return TreeSCSP(names, arcs), dict(zip(names, doms, strict=True)), root


def projections(tree: TreeSCSP, doms: dict) -> dict:
    """The exact projected domains, by enumerating every assignment."""
    names = tree.variables
    proj = {v: set() for v in names}
    for values in itertools.product(*(sorted(doms[v]) for v in names)):
        point = dict(zip(names, values, strict=True))
        if all(arc.contract(arc.a, {arc.a: frozenset([point[arc.a]]),
                                    arc.b: frozenset([point[arc.b]])}) for arc in tree.arcs):
            for v in names:
                proj[v].add(point[v])
    return {v: frozenset(s) for v, s in proj.items()}


@settings(max_examples=150)
@given(finite_trees(), st.integers(0, 2**32 - 1))
def test_fall_climb_is_the_optimal_contraction_on_finite_sets(case, seed):
    tree, doms, root = case
    exact = projections(tree, doms)
    fc = tree.fall_climb(doms, root)
    assert fc == exact  # Theorem 6: the projections, exactly
    # FALL alone already makes the root consistent (Theorem 4 / Example 4)
    assert tree.fall(doms, root)[root] == exact[root]
    # another order of local contractions (Waltz to its fixed point) neither beats it nor
    # stays above it, and no local contraction applied after it removes anything
    waltz, _ = tree.waltz(doms, lambda x, y: x == y, seed=seed)
    assert waltz == fc
    again, rounds = tree.waltz(fc, lambda x, y: x == y, seed=seed + 1)
    assert again == fc and rounds == 1
    assert fc == tree.fall_climb(doms, random.Random(seed).choice(tree.variables))


def test_an_inconsistent_tree_empties_every_domain():
    r = frozenset({(0, 1)})
    tree = TreeSCSP("abc", [relation_arc("a", "b", r), relation_arc("b", "c", r)])
    out = tree.fall_climb({"a": frozenset({0}), "b": frozenset({1}), "c": frozenset(U)})
    assert out == {"a": frozenset(), "b": frozenset(), "c": frozenset()}


def test_the_arguments_are_not_modified_and_a_single_variable_is_a_tree():
    tree = TreeSCSP(["x"], [])
    doms = {"x": frozenset({1, 2})}
    assert tree.fall_climb(doms) == doms
    r = frozenset({(1, 2)})
    t2 = TreeSCSP("ab", [relation_arc("a", "b", r)])
    d2 = {"a": frozenset({1, 3}), "b": frozenset({2, 5})}
    out = t2.fall_climb(d2, "b")
    assert d2 == {"a": frozenset({1, 3}), "b": frozenset({2, 5})}
    assert out == {"a": frozenset({1}), "b": frozenset({2})}


def test_graphs_that_are_not_trees_are_refused():
    r = frozenset({(0, 0)})
    cycle = [relation_arc("a", "b", r), relation_arc("b", "c", r), relation_arc("c", "a", r)]
    with pytest.raises(ValueError, match="not a tree"):
        TreeSCSP("abc", cycle)
    with pytest.raises(ValueError, match="not connected"):
        TreeSCSP("abcd", [relation_arc("a", "b", r), relation_arc("b", "a", r),
                          relation_arc("c", "d", r)])
    with pytest.raises(ValueError, match="unknown variable 'z'"):
        TreeSCSP("ab", [relation_arc("a", "z", r)])
    with pytest.raises(ValueError, match="no domain given"):
        TreeSCSP("ab", [relation_arc("a", "b", r)]).fall_climb({"a": frozenset()})
    with pytest.raises(ValueError, match="unknown root"):
        TreeSCSP("ab", [relation_arc("a", "b", r)]).fall({"a": 1, "b": 2}, "q")


def test_waltz_deadlocks_on_the_cycle_of_seed_example_2():
    """Jaulin et al. 2001 Example 2: v2 = -v1, v3 = -v2, v1 = -v3 on [-1, 1]^3; only 0 is a
    solution but
    local contractions remove nothing. (FALL/CLIMB needs a tree, which is why it is refused.)"""
    neg = Arc("p", "q", lambda vp, vq: vp & -vq, lambda vq, vp: vq & -vp)
    doms = Interval(-1.0, 1.0)
    assert neg.contract("p", {"p": doms, "q": doms}) == doms


# --- interval domains: affine constraints v_b = s * v_a + t (monotone, so projections are
# intervals, computed exactly with Fractions)

def affine_arc(a, b, s: int, t: int) -> Arc:
    return Arc(a, b, lambda va, vb: va & ((vb - t) / s), lambda vb, va: vb & (s * va + t))


def exact_affine(tree: TreeSCSP, coefs: dict, doms: dict) -> dict:
    """Exact projections: every variable is an affine function of the root's value, so the
    solution set is one segment of the root variable; intersect all constraints on it."""
    root = tree.variables[0]
    slope = {root: Fraction(1)}
    shift = {root: Fraction(0)}
    for p, c, arc in tree.rooted(root):
        s, t = coefs[(arc.a, arc.b)]
        if arc.a == p:  # v_c = s v_p + t
            slope[c], shift[c] = s * slope[p], s * shift[p] + t
        else:  # v_p = s v_c + t
            slope[c], shift[c] = slope[p] / s, (shift[p] - t) / s
    lo, hi = Fraction(-10**9), Fraction(10**9)
    for v in tree.variables:
        a, b = (Fraction(doms[v][0]) - shift[v]) / slope[v], (Fraction(doms[v][1]) - shift[v]) \
            / slope[v]
        lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
    if lo > hi:
        return {v: None for v in tree.variables}
    return {v: sorted([slope[v] * lo + shift[v], slope[v] * hi + shift[v]])
            for v in tree.variables}


@settings(max_examples=150)
@given(st.integers(1, 7), st.integers(0, 2**32 - 1))
def test_fall_climb_on_interval_domains_is_sound_and_optimal_to_rounding(n, seed):
    rng = random.Random(seed)
    names = [f"v{i}" for i in range(n)]
    arcs, coefs = [], {}
    for i in range(1, n):
        p = rng.randrange(i)
        a, b = (names[p], names[i]) if rng.random() < 0.5 else (names[i], names[p])
        s, t = rng.choice([-3, -2, -1, 1, 2, 3]), rng.randint(-5, 5)
        coefs[(a, b)] = (Fraction(s), Fraction(t))
        arcs.append(affine_arc(a, b, s, t))
    doms = {}
    for v in names:
        lo, hi = sorted([rng.randint(-40, 40) / 4, rng.randint(-40, 40) / 4])
        doms[v] = (lo, hi)
    tree = TreeSCSP(names, arcs)
    exact = exact_affine(tree, coefs, doms)
    start = {v: Interval(*doms[v]) for v in names}
    root = rng.choice(names)
    fc = tree.fall_climb(start, root)
    waltz, _ = tree.waltz(start, lambda x, y: bool(np.all(x == y)), seed=seed)
    for v in names:
        if exact[v] is None:  # inconsistent: the root at least is proven empty
            assert bool(fc[root].is_empty())
            continue
        lo, hi = exact[v]
        assert not bool(fc[v].is_empty())
        assert Fraction(float(fc[v].lo)) <= lo and hi <= Fraction(float(fc[v].hi))  # sound
        # optimal up to the outward rounding of a few operations
        assert float(fc[v].lo) >= float(lo) - 1e-12 * (1 + abs(float(lo)))
        assert float(fc[v].hi) <= float(hi) + 1e-12 * (1 + abs(float(hi)))
        # Waltz never goes below FALL-CLIMB's result by more than rounding, nor loses the truth
        assert Fraction(float(waltz[v].lo)) <= lo and hi <= Fraction(float(waltz[v].hi))
        assert float(waltz[v].lo) <= float(fc[v].lo) + 1e-12 * (1 + abs(float(lo)))
        assert float(waltz[v].hi) >= float(fc[v].hi) - 1e-12 * (1 + abs(float(hi)))
