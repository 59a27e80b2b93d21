"""IEEE 1788 conformance: the ITF1788 vectors (tests/itf1788/) against boundest.

One test per operation found in the files asserts that boundest's result is sound on every
bare vector (the tightest expected result lies inside boundest's, booleans and numbers equal);
operations boundest does not offer (yet) are skipped with the reason. ``+ - * / sqrt sqr`` must
moreover be tight or within 1 ulp. The harness itself (parser, number reading, classification)
is tested at the end. ``python benchmarks/itf1788_report.py`` prints the full tally.
"""

from __future__ import annotations

import functools
import math
from collections import defaultdict
from fractions import Fraction

import numpy as np
import pytest

from .itf1788_runner import (
    ERRATA,
    ITF_DIR,
    OPS,
    Ival,
    OpResult,
    Vector,
    _judge_interval,
    _judge_number,
    _judge_pair,
    _round,
    parse_all,
    parse_file,
    resolve,
    run_isolated,
    run_op,
    summarize,
)

VECTORS = parse_all()
BY_OP: dict[str, list[Vector]] = defaultdict(list)
for _v in VECTORS:
    BY_OP[_v.op].append(_v)
SHOWN = 12  # failing lines listed in a failure message


@functools.cache
def _results() -> dict[str, OpResult]:
    # in a worker process: a kernel that crashes the interpreter fails its own operation only
    return run_isolated()


def _result(op: str) -> OpResult:
    return _results()[op]


def _skip_if_not_run(r: OpResult) -> None:
    if not r.outcomes:
        why = r.reason or ("decorated vectors only" if r.vectors == r.skipped else "no vectors")
        pytest.skip(f"{r.op}: {r.unimplemented} bare vectors not run: {why}")


@pytest.mark.parametrize("op", sorted(BY_OP))
def test_itf1788_sound(op: str) -> None:
    r = _result(op)
    _skip_if_not_run(r)
    bad = r.failures
    lines = "\n".join(o.describe() for o in bad[:SHOWN])
    more = f"\n... and {len(bad) - SHOWN} more" if len(bad) > SHOWN else ""
    assert not bad, (f"{op} [{r.implementation}]: {len(bad)} of {len(r.outcomes)} vectors "
                     f"fail:\n{lines}{more}")


#: Operations whose every bare vector is the tightest result (no libm call involved): a
#: regression test of their exactness, on top of soundness.
TIGHTEST = ["abs", "absRev", "absRevBin", "add", "ceil", "cosRev", "div", "floor", "max", "min",
            "mul", "mulRev", "mulRevTen", "mulRevToPair", "neg", "pos", "pown", "pownRev",
            "pownRevBin", "recip", "sign", "sinRev", "sqr", "sqrRev", "sqrRevBin", "sqrt", "sub",
            "tanRev", "tanRevBin", "trunc", "convexHull", "intersection", "inf", "sup", "mid",
            "mag", "mig", "wid", "rad"]


@pytest.mark.parametrize("op", TIGHTEST)
def test_itf1788_exact_operations_are_tightest(op: str) -> None:
    r = _result(op)
    _skip_if_not_run(r)
    loose = [o for o in r.outcomes if o.status != "tight"]
    lines = "\n".join(o.describe() for o in loose[:SHOWN])
    assert not loose, f"{op}: {len(loose)} of {len(r.outcomes)} vectors not tightest:\n{lines}"


@pytest.mark.parametrize("op", ["add", "sub", "mul", "div", "sqrt", "sqr"])
def test_itf1788_basic_operations_tight(op: str) -> None:
    """Correctly rounded operations: each bound at most one float64 step from the tightest."""
    r = _result(op)
    _skip_if_not_run(r)
    loose = [o for o in r.outcomes if o.status not in ("tight", "within_1ulp")]
    lines = "\n".join(o.describe() for o in loose[:SHOWN])
    more = f"\n... and {len(loose) - SHOWN} more" if len(loose) > SHOWN else ""
    assert not loose, f"{op}: {len(loose)} of {len(r.outcomes)} not within 1 ulp:\n{lines}{more}"


# ---------------------------------------------------------------------------------------------
# the harness itself
# ---------------------------------------------------------------------------------------------

def test_vendored_files_and_licence_are_present() -> None:
    names = {p.name for p in ITF_DIR.iterdir()}
    assert {"LICENSE", "NOTICE", "AUTHORS", "ORIGIN.md"} <= names
    assert "Apache License" in (ITF_DIR / "LICENSE").read_text()
    assert len([n for n in names if n.endswith(".itl")]) == 12


def test_every_operation_in_the_files_is_mapped() -> None:
    assert set(BY_OP) <= set(OPS), sorted(set(BY_OP) - set(OPS))


def test_parser_counts_and_decorations() -> None:
    assert len(VECTORS) > 6000
    bare = [v for v in VECTORS if not v.decorated]
    assert len(bare) > 5000
    # nothing with a decoration suffix or NaI is ever run as a bare vector
    assert not any("_com" in v.text or "_dac" in v.text or "_def" in v.text or "_trv" in v.text
                   or "[nai]" in v.text.lower() for v in bare)
    for v in bare:
        assert all(isinstance(e, (Ival, float, int, bool, str)) for e in (*v.args, *v.expected))


def test_parser_reads_literals(tmp_path) -> None:
    f = tmp_path / "x.itl"
    f.write_text("/* header\n  comment */\ntestcase t {\n"
                 "    // a comment = 1;\n"
                 "    add [1.0,2.0] [-infinity, +0X1.8P+1] = [-infinity,0x1.4p2];\n"
                 "    sqrRev [0.1, 0.1] = [empty];\n"
                 "    pown [entire] -2 = [0.0, infinity];\n"
                 "    inf [empty] = +infinity;\n"
                 "    isEmpty [1.0,2.0]_com = false;\n"
                 "    mulRevToPair [1.0, 2.0] [empty] = [empty] [entire];\n"
                 "}\ntestcase t_dec_test {\n    neg [1.0, 2.0] = [-2.0, -1.0];\n}\n")
    vs = parse_file(f)
    assert [v.line for v in vs] == [5, 6, 7, 8, 9, 10, 13]
    add, sqr_rev, pown, inf, is_empty, pair, neg = vs
    assert add.args == (Ival(1.0, 2.0), Ival(-math.inf, 3.0))
    assert add.expected == (Ival(-math.inf, 5.0),)
    assert add.exact and not add.decorated
    assert sqr_rev.args[0] == Ival(0.1, 0.1) and not sqr_rev.exact  # nearest double of 0.1
    assert sqr_rev.expected[0].is_empty
    assert pown.args[1] == -2 and type(pown.args[1]) is int
    assert inf.expected == (math.inf,)
    assert is_empty.decorated and is_empty.expected == (False,)
    assert pair.expected[0].is_empty and pair.expected[1] == Ival(-math.inf, math.inf)
    assert neg.decorated  # a _dec testcase: decorated even without a suffix
    out = parse_file(f, decimal_mode="outward")[1].args[0]
    assert Fraction(out.lo) < Fraction("0.1") < Fraction(out.hi)
    assert out.hi == np.nextafter(out.lo, np.inf)


def test_rounding_of_decimal_literals() -> None:
    tenth = Fraction(1, 10)
    dn, up, near = _round(tenth, "down"), _round(tenth, "up"), _round(tenth, "nearest")
    assert Fraction(dn) < tenth < Fraction(up) and up == np.nextafter(dn, np.inf)
    assert near == 0.1
    assert _round(Fraction(3, 4), "down") == _round(Fraction(3, 4), "up") == 0.75
    big = Fraction(2) ** 1024
    assert _round(big, "down") == np.finfo(np.float64).max and _round(big, "up") == math.inf
    assert _round(-big, "up") == -np.finfo(np.float64).max


def test_decimal_literals_denote_the_nearest_double() -> None:
    """Why decimals are read as nearest doubles: exact rational hulls of c / b agree with the
    expected mulRev results for nearest-rounded inputs, not for outward-rounded ones."""
    def agree(mode: str) -> tuple[int, int]:
        ok = total = 0
        for v in parse_all(decimal_mode=mode):
            if v.op != "mulRev" or v.decorated or v.exact:
                continue
            b, c = v.args
            bounds = (b.lo, b.hi, c.lo, c.hi)
            if not all(math.isfinite(t) for t in bounds) or b.lo <= 0 <= b.hi:
                continue
            q = [Fraction(cc) / Fraction(bb) for bb in (b.lo, b.hi) for cc in (c.lo, c.hi)]
            total += 1
            ok += (_round(min(q), "down"), _round(max(q), "up")) == (v.expected[0].lo,
                                                                      v.expected[0].hi)
        return ok, total

    ok, total = agree("nearest")
    assert total >= 10 and ok == total
    ok, total = agree("outward")
    assert ok < total / 2


def test_classification() -> None:
    up = lambda x, k=1: float(x if k == 0 else up(np.nextafter(x, np.inf), k - 1))  # noqa: E731
    dn = lambda x, k=1: float(x if k == 0 else dn(np.nextafter(x, -np.inf), k - 1))  # noqa: E731
    e = Ival(1.0, 2.0)
    assert _judge_interval(e, 1.0, 2.0)[0] == "tight"
    assert _judge_interval(e, dn(1.0), 2.0)[0] == "within_1ulp"
    assert _judge_interval(e, dn(1.0), up(2.0, 4))[0] == "within_4ulp"
    assert _judge_interval(e, dn(1.0, 5), 2.0)[0] == "looser"
    assert _judge_interval(e, -math.inf, 2.0)[0] == "looser"
    assert _judge_interval(e, up(1.0), 2.0)[0] == "unsound"
    assert _judge_interval(e, math.nan, math.nan)[0] == "unsound"
    assert _judge_interval(e, 2.0, 1.0)[0] == "invalid"
    assert _judge_interval(e, math.nan, 2.0)[0] == "invalid"
    assert _judge_interval(e, math.inf, math.inf)[0] == "invalid"
    empty = Ival(math.nan, math.nan)
    assert _judge_interval(empty, math.nan, math.nan)[0] == "tight"
    assert _judge_interval(empty, 0.0, 1.0)[0] == "looser"  # sound, not tight
    assert _judge_interval(Ival(0.0, 0.0), -0.0, 0.0)[0] == "tight"  # signed zeros alike
    assert _judge_interval(Ival(-1.0, 0.0), -1.0, 5e-324)[0] == "within_1ulp"
    # pairs: either order, and a part may be covered by the union of the two results
    a, b = Ival(-math.inf, -1.0), Ival(1.0, math.inf)
    assert _judge_pair((a, b), ((1.0, math.inf), (-math.inf, -1.0)))[0] == "tight"
    assert _judge_pair((a, b), ((-math.inf, math.inf), (math.nan, math.nan)))[0] == "looser"
    assert _judge_pair((a, b), ((-math.inf, -1.0), (math.nan, math.nan)))[0] == "unsound"
    assert _judge_pair((Ival(0.0, 4.0), empty), ((0.0, 2.0), (2.0, 4.0)))[0] == "looser"
    # numbers: exact, or an upper bound
    assert _judge_number(1.0, 1.0, "exact")[0] == "tight"
    assert _judge_number(1.0, up(1.0), "exact")[0] == "mismatch"
    assert _judge_number(1.0, up(1.0), "upper")[0] == "within_1ulp"
    assert _judge_number(1.0, dn(1.0), "upper")[0] == "mismatch"
    assert _judge_number(math.nan, math.nan, "exact")[0] == "tight"


def test_unimplemented_is_reported_not_failed() -> None:
    assert resolve("no_such_function_in_boundest") is None
    assert resolve("add") is not None
    v = BY_OP["cancelPlus"]
    r = run_op("cancelPlus", v)
    assert r.unimplemented == sum(not x.decorated for x in v) and not r.outcomes
    assert r.reason
    report = summarize({"cancelPlus": r})
    assert report["total"]["sound_failures"] == 0
    assert report["unimplemented"] == ["cancelPlus"]


def test_errata_apply_and_are_justified() -> None:
    """Each erratum matches one vector, and its corrected result is the tightest one.

    powRev2 with a in [0.25, 0.5] or [0.25, 1] and a**y in [2, inf]: y = -0.5 is reached
    (0.25**-0.5 = 2) and nothing above it is (a**y <= 0.25**y < 2 for -0.5 < y < 0, and
    a**y <= 1 for y >= 0). cosRevBin [-1, -1] [3.14, 3.15]: the only solution is pi.
    """
    fixed = {(v.file, v.text): v for v in VECTORS if v.erratum}
    assert set(fixed) == set(ERRATA)
    mpmath = pytest.importorskip("mpmath")
    with mpmath.workprec(200):
        pow_rev = [v for v in fixed.values() if v.op == "powRev2"]
        assert len(pow_rev) == 2
        for v in pow_rev:
            assert v.expected == (Ival(-math.inf, -0.5),)
        assert mpmath.power(mpmath.mpf(0.25), -0.5) == 2
        for y in (-0.5 + 2.0**-40, -0.25, -1e-9, 0.0, 3.0):
            for a in (0.25, 0.5, 0.75, 1.0):
                assert mpmath.power(mpmath.mpf(a), y) < 2
        (cos_rev,) = [v for v in fixed.values() if v.op == "cosRevBin"]
        lo, hi = cos_rev.expected[0].lo, cos_rev.expected[0].hi
        assert hi == np.nextafter(lo, np.inf)
        assert mpmath.mpf(lo) < mpmath.pi < mpmath.mpf(hi)
        assert cos_rev.args[1].lo < lo and hi < cos_rev.args[1].hi  # pi inside X = [3.14, 3.15]
