"""``boundest solve MODEL``: propagate a model file, print a summary, optionally pave it.

The header options of the file (``Bisection none;``) are honoured or refused, never ignored:
``Bisection none;`` asks for propagation only (the default), ``Bisection EPS;`` (a number) for
a subpaving of precision ``EPS`` as ``--paving EPS`` does; any other option is an error naming
the file and line. ``--paving`` on the command line overrides the file's ``Bisection``.
"""

from __future__ import annotations

import argparse
import re
import statistics
from pathlib import Path
from typing import Any

from . import save_figure, subplots, write_json
from .options import (
    announce,
    check_input,
    check_outputs,
    check_size,
    fraction,
    positive_float,
    require_extra,
    whole,
)

#: ``boundest.csp.MODES``, spelt out here so that ``boundest --help`` does not import Numba
#: (``tests/test_solve_cli.py`` checks that the two agree)
PROPAGATION_MODES = ("hc4", "bc", "3b", "bc+3b", "lp", "centered", "3b+centered")

#: Subpavings are computed for models of at most this many variables (SIVIA bisects every
#: dimension; beyond a few the number of boxes explodes).
MAX_PAVING_VARIABLES = 12
DEFAULT_MAX_BOXES = 100_000


def paving_bytes(boxes: int, variables: int, json: bool) -> float:
    """The memory a subpaving of ``boxes`` boxes may take: each box's bounds (16 bytes a
    variable) about four times over (the frontier, its bisection, the kept boxes and their
    concatenation), and with ``--json`` its text and Python floats (about 150 bytes a
    variable), plus 0.3 GiB for the interpreter and the libraries."""
    return (300 << 20) + boxes * variables * (64 + (150 if json else 0))


def check(args: argparse.Namespace) -> None:
    """The checks before any work: the model file, the outputs, the extra --mode lp needs.
    Those that depend on the model (--paving, --max-boxes) follow its loading (:func:`run`)."""
    check_input("model file", args.file)
    check_outputs(args.out, args.json)
    if args.mode == "lp":
        require_extra("--mode lp", "scipy.optimize", "lp", "SciPy (linear programming)")
_FAMILY = re.compile(r"^(.*?)_?(\d+)$")


def _width(lo: float, hi: float) -> float:
    return hi - lo


def header_paving(model: Any, path: str) -> float | None:
    """The paving precision the model file's header asks for (``None``: propagation only).

    Raises
    ------
    ValueError
        Naming ``path`` and the line of an option boundest does not implement.
    """
    eps = None
    for key, value in model.options.items():
        line = model.option_lines.get(key, "?")
        if key.lower() == "bisection":
            if value.lower() == "none":
                continue
            try:
                eps = float(value)
            except ValueError:
                eps = None
            if eps is None or not eps > 0.0 or eps == float("inf"):
                raise ValueError(f"{path}:{line}: 'Bisection {value};' is not supported: "
                                 "boundest reads 'Bisection none;' (propagation only) or "
                                 "'Bisection EPS;' with a positive number EPS (a subpaving "
                                 "of that precision)")
            continue
        raise ValueError(f"{path}:{line}: header option '{key} {value};' is not supported by "
                         "boundest solve (only 'Bisection none;' and 'Bisection EPS;'); "
                         "remove it")
    return eps


def families(names: list[str]) -> dict[str, list[str]]:
    """Variables grouped by family: ``x1_0 ... x1_200`` are the family ``x1``; a name without
    a trailing index is a family of its own. In order of first appearance."""
    out: dict[str, list[str]] = {}
    for name in names:
        m = _FAMILY.match(name)
        key = m.group(1) if m and m.group(1) else name
        out.setdefault(key, []).append(name)
    return out


def summary_lines(domains: dict[str, Any], widest: int = 5, max_rows: int = 30) -> list[str]:
    """The printed summary of the final domains: counts, one row per family (number of
    variables, min / median / max width, how many unbounded) and the widest variables."""
    bounds = {n: (float(d.lo), float(d.hi)) for n, d in domains.items()}
    empty = [n for n, (lo, hi) in bounds.items() if lo != lo]
    unbounded = [n for n, (lo, hi) in bounds.items() if lo == lo and _width(lo, hi) == float("inf")]
    lines = [f"domains: {len(bounds)} variables, {len(bounds) - len(empty) - len(unbounded)} "
             f"bounded, {len(unbounded)} unbounded, {len(empty)} empty"]
    if empty:
        return lines
    fams = families(list(bounds))
    name_w = max(len("family"), *(len(f) for f in fams)) if fams else len("family")
    lines.append(f"  {'family':<{name_w}} {'count':>6}  {'index range':<13} {'min width':>11} "
                 f"{'median':>11} {'max width':>11}  unbounded")
    for i, (fam, members) in enumerate(fams.items()):
        if i == max_rows:
            lines.append(f"  ... {len(fams) - max_rows} more families (--all prints every "
                         "variable)")
            break
        w = [_width(*bounds[n]) for n in members]
        idx = [m.group(2) for n in members if (m := _FAMILY.match(n))]
        span = f"{idx[0]}..{idx[-1]}" if len(members) > 1 and len(idx) == len(members) else ""
        n_unb = sum(x == float("inf") for x in w)
        lines.append(f"  {fam:<{name_w}} {len(members):>6}  {span:<13} {min(w):>11.4g} "
                     f"{statistics.median(w):>11.4g} {max(w):>11.4g}  {n_unb}")
    finite = sorted((n for n in bounds if n not in unbounded),
                    key=lambda n: -_width(*bounds[n]))[:widest]
    if finite:
        lines.append("widest bounded domains: " + ", ".join(
            f"{n} in [{bounds[n][0]:.6g}, {bounds[n][1]:.6g}]" for n in finite))
    if unbounded:
        lines.append(f"unbounded: {', '.join(unbounded[:widest])}"
                     + (f" and {len(unbounded) - widest} more" if len(unbounded) > widest
                        else ""))
    return lines


def pave(model: Any, domains: dict[str, Any], eps: float, max_boxes: int) -> Any:
    """SIVIA on the propagated domains with the model's forward-backward contractor: an
    outer subpaving (boundary boxes whose union contains every solution; no inner test)."""
    import numpy as np

    from ..ctc import CtcFwdBwd
    from ..interval import Interval
    from ..paving import sivia

    names = list(domains)
    if len(names) > MAX_PAVING_VARIABLES:
        raise ValueError(f"a subpaving is computed for at most {MAX_PAVING_VARIABLES} variables; "
                         f"the model has {len(names)} (propagation alone: 'Bisection none;' or "
                         "no --paving)")
    lo = np.array([float(domains[n].lo) for n in names])
    hi = np.array([float(domains[n].hi) for n in names])
    unb = [n for n, a, b in zip(names, lo, hi, strict=True) if not np.isfinite(b - a)]
    if unb:
        raise ValueError(f"a subpaving needs bounded domains; after propagation "
                         f"{', '.join(unb)} {'is' if len(unb) == 1 else 'are'} unbounded")
    ctc = CtcFwdBwd(model.constraints, names)
    return sivia(Interval.trusted(lo, hi), ctc_out=ctc, eps=eps, max_boxes=max_boxes)


_WHY = {"eps": "narrower than eps without a proof (a multiple or singular root, or no root "
               "that could be refuted)",
        "discontinuous": "where some function is undefined or discontinuous",
        "max_boxes": "left when --max-boxes ran out"}


def is_square(model: Any) -> bool:
    """Whether the model is a square system: as many equations as variables, and no other
    constraint (then ``--paving`` runs interval Newton and proves solutions)."""
    eqs = sum(c.rel == "==" for c in model.constraints)
    return eqs == len(model.constraints) and eqs == len(model.variable_names()) and eqs > 0


def pave_square(model: Any, domains: dict[str, Any], eps: float, max_boxes: int) -> Any:
    """Branch and prune with interval Newton on the propagated domains
    (``boundest.paving.roots.solve_square``): proved and undecided boxes."""
    import numpy as np

    from ..expr import Model
    from ..interval import Interval
    from ..paving.roots import solve_square

    names = list(domains)
    lo = np.array([float(domains[n].lo) for n in names])
    hi = np.array([float(domains[n].hi) for n in names])
    unb = [n for n, a, b in zip(names, lo, hi, strict=True) if not np.isfinite(b - a)]
    if unb:
        raise ValueError(f"solving a square system needs bounded domains; after propagation "
                         f"{', '.join(unb)} {'is' if len(unb) == 1 else 'are'} unbounded")
    square = Model(domains=dict(domains), constraints=list(model.constraints))
    return solve_square(square, Interval(lo, hi), eps=eps, max_boxes=max_boxes)


def _figure_roots(roots: Any, args: argparse.Namespace) -> None:
    """Proved boxes in green, undecided ones in yellow, projected on the first two variables."""
    from ..paving import Subpaving
    from ..plot.paving import plot_paving

    fig, ax = subplots(figsize=(6, 5.5))
    drawn = Subpaving(roots.boxes, roots.proved)  # 'inside' stands for 'proved' in the drawing
    plot_paving(drawn, ax=ax, dims=(0, 1), inside="tab:green", linewidth=0.8,
                labels=("proved: exactly one solution", "undecided", None))
    ax.set_xlabel(roots.variables[0])
    ax.set_ylabel(roots.variables[1])
    ax.legend(loc="best", fontsize=8)
    ax.set_title(f"{Path(args.file).name}: interval Newton, {int(roots.proved.sum())} proved, "
                 f"{int((~roots.proved).sum())} undecided", fontsize=9)
    save_figure(fig, args.out, f"{Path(args.file).stem}_paving")


def _phases(res: Any) -> str:
    """The cost of the phases after hull consistency, for the summary line."""
    parts = []
    if res.boxcons:
        b = res.boxcons
        parts.append(f"box consistency {b['time_s']:.3f} s ({b['candidates']} variables, "
                     f"{b['narrowed']} narrowed)")
    if res.shaving:
        s = res.shaving
        parts.append(f"shaving {s['time_s']:.3f} s ({s['probes']} probes, {s['refuted']} "
                     "slices refuted)")
    if res.linear:
        q = res.linear
        parts.append(f"LPs {q['lp_time_s']:.3f} s ({q['rounds']} rounds)")
    return "; of which " + ", ".join(parts) if parts else ""


def _paving_of(model: Any, args: argparse.Namespace) -> float | None:
    """The paving precision of this run (None: propagation only), after the checks that need
    the model: ``--max-boxes`` only with a paving, at most :data:`MAX_PAVING_VARIABLES`
    variables for SIVIA, the memory ``--max-boxes`` allows; ``--paving`` overriding the file's
    ``Bisection`` says so."""
    eps = header_paving(model, args.file)
    if args.paving is not None:
        if eps is not None:
            line = model.option_lines.get(next(k for k in model.options
                                               if k.lower() == "bisection"), "?")
            announce(f"--paving {args.paving:g} overrides 'Bisection {eps:g};' of "
                     f"{args.file}:{line}")
        eps = args.paving
    if eps is None:
        if args.max_boxes is not None:
            raise ValueError(f"--max-boxes {args.max_boxes} bounds a subpaving, and there is "
                             "none: give --paving EPS (or 'Bisection EPS;' in the file)")
        return None
    if args.max_boxes is None:
        args.max_boxes = DEFAULT_MAX_BOXES
    n = len(model.domains)
    if n > MAX_PAVING_VARIABLES and not is_square(model):
        raise ValueError(f"a subpaving is computed for at most {MAX_PAVING_VARIABLES} variables; "
                         f"the model has {n} (propagation alone: 'Bisection none;' or no "
                         "--paving)")
    check_size(paving_bytes(args.max_boxes, n, args.json is not None),
               f"a subpaving of up to {args.max_boxes:,} boxes of {n} variables",
               f"--max-boxes {args.max_boxes}")
    return eps


def run(args: argparse.Namespace) -> int:
    """``boundest solve``: propagate, print the summary (every domain with ``--all``), pave."""
    from ..csp import propagate
    from ..expr import load_model

    model = load_model(args.file)
    eps = _paving_of(model, args)
    res = propagate(model, rel_eps=args.rel_eps, mode=args.mode)
    status = "consistent" if res.consistent else "INCONSISTENT (no solution)"
    print(f"{args.file}: {len(model.domains)} variables, {len(model.constraints)} constraints: "
          f"{status}; mode {res.mode}: {res.evaluations} node revisions in {res.time_s:.3f} s"
          + _phases(res))
    if args.all:
        width = max((len(n) for n in res.domains), default=0)
        for name, dom in res.domains.items():
            text = ("[empty]" if bool(dom.is_empty())
                    else f"[{float(dom.lo)!r}, {float(dom.hi)!r}]")
            print(f"  {name:<{width}} in {text}")
    else:
        for line in summary_lines(res.domains):
            print(line)
        print("(--all prints every domain; --json writes them)")
    data: dict[str, Any] = {"file": str(args.file), "consistent": res.consistent,
                            "mode": res.mode,
                            "evaluations": res.evaluations, "time_s": res.time_s,
                            "domains": res.domains}
    paving = None
    if eps is not None and res.consistent and is_square(model):
        roots = pave_square(model, res.domains, eps, args.max_boxes)
        n_proved, n_und = int(roots.proved.sum()), int((~roots.proved).sum())
        why = ", ".join(f"{v} {_WHY[k]}" for k, v in roots.stats["undecided_why"].items() if v)
        print(f"square system, interval Newton (eps = {eps:g}): {n_proved} solutions proved "
              f"(each box holds exactly one), {n_und} undecided boxes"
              + (f" ({why})" if why else "")
              + f"; {roots.stats['processed']} boxes contracted in "
                f"{roots.stats['time_s']:.3f} s; stopped by {roots.stats['stopped']}")
        for i, b in enumerate(roots.solutions[:10]):
            print(f"  solution {i + 1}: " + ", ".join(
                f"{v} in [{float(a)!r}, {float(c)!r}]"
                for v, a, c in zip(roots.variables, b.lo, b.hi, strict=True)))
        if n_proved > 10:
            print(f"  ... and {n_proved - 10} more (--json writes them all)")
        data["paving"] = {"eps": eps, "method": "newton", "variables": roots.variables,
                          "boxes": roots.boxes, "proved": roots.proved.tolist(),
                          "stopped": roots.stats["stopped"],
                          "undecided_why": roots.stats["undecided_why"]}
        if len(roots) and len(roots.variables) >= 2:
            _figure_roots(roots, args)
        if not len(roots):
            write_json(data, args.json)
            return 1
    elif eps is not None and res.consistent:
        paving = pave(model, res.domains, eps, args.max_boxes)
        st = paving.stats
        empty = len(paving) == 0
        print(f"subpaving (SIVIA, eps = {eps:g}): {len(paving)} boundary boxes"
              + (" (empty: no solution)" if empty else "")
              + f", {st.get('processed', '?')} boxes classified, stopped by "
              f"{st.get('stopped', '?')}; their union contains every solution (no inner test)")
        if not empty:
            hull = paving.hull()
            print("  hull: " + ", ".join(f"{n} in [{float(a):.6g}, {float(b):.6g}]" for n, a, b
                                         in zip(res.domains, hull.lo, hull.hi, strict=True)))
        data["paving"] = {"eps": eps, "method": "sivia", "variables": list(res.domains),
                          "boxes": paving.boxes, "stopped": st.get("stopped")}
        if paving.dim >= 2 and not empty:
            from ..plot.paving import plot_paving

            names = list(res.domains)
            fig, ax = subplots(figsize=(6, 5.5))
            plot_paving(paving, ax=ax, dims=(0, 1))
            ax.set_xlabel(names[0])
            ax.set_ylabel(names[1])
            ax.set_title(f"{Path(args.file).name}: subpaving projected on ({names[0]}, "
                         f"{names[1]})\nyellow: boundary boxes (may hold solutions)",
                         fontsize=9)
            save_figure(fig, args.out, f"{Path(args.file).stem}_paving")
        if empty:
            write_json(data, args.json)
            return 1
    write_json(data, args.json)
    return 0 if res.consistent else 1


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``boundest solve`` and its options."""
    p = sub.add_parser("solve", help="propagate a model file; print a summary of the domains "
                                     "(and a subpaving with --paving)")
    p.add_argument("file", help="model in the text format (docs/model-format.md)")
    p.add_argument("--rel-eps", type=fraction, default=1e-3,
                   help="propagation stops when no domain shrinks by more than this fraction "
                        "of its width, in [0, 1[ (default 1e-3)")
    p.add_argument("--mode", choices=PROPAGATION_MODES, default="3b+centered",
                   help="shaving then the centered form of windows of constraints "
                        "(3b+centered, default: the tightest), hull consistency alone (hc4: "
                        "the fastest, 25-900 times cheaper), then box consistency (bc), 3B "
                        "shaving (3b), both (bc+3b), LP contraction (lp, needs the lp extra) "
                        "or the centered form alone (centered); see boundest.csp.propagate "
                        "and docs/derivatives.md; without the lp extra, --mode lp is refused "
                        "before any work")
    p.add_argument("--all", action="store_true",
                   help="print every variable's domain instead of the summary")
    p.add_argument("--paving", type=positive_float, metavar="EPS",
                   help="after propagation, bisect with SIVIA to boxes narrower than EPS > 0: "
                        f"an outer subpaving (for models of at most {MAX_PAVING_VARIABLES} "
                        "bounded variables; overrides the file's 'Bisection' option, and says "
                        "so); a square system (as many equations as variables, nothing else) "
                        "is solved by interval Newton instead, which proves solutions")
    p.add_argument("--max-boxes", type=whole(1), default=None,
                   help="with a paving: it stops before exceeding this many boxes, >= 1 "
                        "(default 100000); a bound whose subpaving could not fit in memory is "
                        "refused")
    p.add_argument("--out", default="out", help="folder for the subpaving figure, created if "
                                                "missing (default: out)")
    p.add_argument("--json", help="write every domain (and the subpaving's boxes) as JSON to "
                                  "this file, in an existing folder (strict JSON: docs/json.md)")
    p.set_defaults(func=run, check=check)
