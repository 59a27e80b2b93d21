"""Propagation of a CSP to a fixed point: hull consistency on its primitive decomposition
(``mode="hc4"``, the fastest), and on top of it box consistency (``"bc"``), 3B consistency by
shaving (``"3b"``), both (``"bc+3b"``), LP contraction of the linear sub-networks (``"lp"``), or
the centered form of windows of constraints with optimal multipliers (``"centered"``, and
``"3b+centered"`` after shaving, the default: :data:`DEFAULT_MODE`)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .._progress import Progress
from ..expr.model import Model
from ..expr.nodes import Constraint, Var, VarFamily
from ..expr.tape import Tape, compile_model
from ..interval import Interval
from .engine import (
    BC_STATS,
    EMPTY,
    RUNNING,
    SHAVE_STATS,
    bc_closures,
    bc_kernel,
    family_flags,
    propagate_kernel,
    repropagate_kernel,
    shave_kernel,
)

__all__ = ["DEFAULT_MODE", "MODES", "BoxConsistency", "Centered", "LinearRelaxation", "Propagation",
           "Shaving", "arg_users", "bc_candidates", "domain_of", "propagate", "slot_users"]

#: The propagation modes: hull consistency alone, then box consistency, 3B shaving, box
#: consistency and shaving, LP contraction, the centered form of windows of constraints, or
#: shaving then the centered form (see ``propagate``).
MODES = ("hc4", "bc", "3b", "bc+3b", "lp", "centered", "3b+centered")

#: The mode ``propagate`` runs when none is given: chosen by measurement (benchmarks/README.md,
#: "Which mode by default"), the only mode within 1.5x of the best widths on every problem
#: measured, at 25-900 times the cost of ``"hc4"``, which stays one option away.
DEFAULT_MODE = "3b+centered"


@dataclass(frozen=True)
class Shaving:
    """Settings of 3B shaving (``propagate(mode="3b")``; ``engine.shave_kernel`` details them).

    Attributes
    ----------
    frac : float
        First slice of a bound, as a fraction of the domain's width (it doubles, up to 1/2,
        after each slice refuted).
    probe_eps : float
        Tolerance of a probe's propagation (coarser than the fixed point's ``rel_eps``: a probe
        only has to find an empty domain).
    probe_evals : int
        Node revisions a probe may spend before its slice counts as not refuted (what bounds
        the reach, and so the cost, of a probe).
    rounds : int
        Rounds over the candidates at most.
    reach : int
        A candidate is shaved again in the next round when it or one within ``reach``
        positions of it (in the candidate order) lost more than ``min_gain`` of its width
        (ACID-like: shave where it recently paid).
    min_gain : float
        Relative width a candidate must lose in a round for the round to count as paying.
    """

    frac: float = 0.1
    probe_eps: float = 1e-2
    probe_evals: int = 500
    rounds: int = 2
    reach: int = 12
    min_gain: float = 0.05

    def __post_init__(self) -> None:
        if not 0.0 < self.frac <= 0.5:
            raise ValueError(f"frac must lie in ]0, 1/2], got {self.frac}")
        if not 0.0 <= self.probe_eps < 1.0:
            raise ValueError(f"probe_eps must lie in [0, 1[, got {self.probe_eps}")
        for name in ("probe_evals", "rounds"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be at least 1, got {getattr(self, name)}")
        if self.reach < 0 or self.min_gain < 0:
            raise ValueError("reach and min_gain must be non-negative")


@dataclass(frozen=True)
class BoxConsistency:
    """Settings of box consistency (``propagate(mode="bc")``; ``engine.bc_kernel`` details
    them).

    Attributes
    ----------
    depth : int
        Bisections of a domain at most (1..52): a bound is narrowed to a slice
        ``2**-depth`` of its domain wide (a relative precision, like ``rel_eps``).
    max_steps : int
        Evaluations of the sub-network per bound at most; a search cut short keeps what it
        refuted.
    max_nodes : int
        Nodes of a variable's sub-network at most (the constraints it occurs in, up to the
        other variables narrowed, ``targets``; breadth first from the variable).
    rounds : int
        Rounds over the candidates at most.
    reach : int
        A candidate is narrowed again in the next round when it or one within ``reach``
        positions of it lost more than ``min_gain`` of its width.
    min_gain : float
        Relative width a candidate must lose in a round for the round to count as paying.
    """

    depth: int = 10
    max_steps: int = 60
    max_nodes: int = 64
    rounds: int = 3
    reach: int = 12
    min_gain: float = 0.05

    def __post_init__(self) -> None:
        if not 1 <= self.depth <= 52:
            raise ValueError(f"depth must lie in 1..52, got {self.depth}")
        for name in ("max_steps", "max_nodes", "rounds"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be at least 1, got {getattr(self, name)}")
        if self.reach < 0 or self.min_gain < 0:
            raise ValueError("reach and min_gain must be non-negative")


@dataclass(frozen=True)
class LinearRelaxation:
    """Settings of LP contraction (``propagate(mode="lp")``, ``ctc.linear.contract_slots``).

    Attributes
    ----------
    rounds : int
        LP contractions at most, each followed by propagation of what it narrowed.
    min_gain : float
        Stop when a round (LP and propagation) narrows the targets' total width by less than
        this fraction.
    radius : int, optional
        Each target's LPs use the rows within this many row-steps of it (default: the whole
        connected sub-network).
    log_linear : bool
        Also use the log-linear rows of multiplicative constraints (Jaulin 2002 eq. 19).
    relax : bool
        Also use a linear relaxation of the nonlinear nodes around the current box
        (``ctc.relax.relaxation``: McCormick rows of products and quotients, secants and
        tangents of convex or concave unary functions; the polytope hull of Trombettoni et
        al. 2011). Each round relaxes around the box the previous rounds reached.
    """

    rounds: int = 3
    min_gain: float = 0.01
    radius: int | None = None
    log_linear: bool = True
    relax: bool = False

    def __post_init__(self) -> None:
        if self.rounds < 1:
            raise ValueError(f"rounds must be at least 1, got {self.rounds}")
        if self.min_gain < 0:
            raise ValueError("min_gain must be non-negative")
        if self.radius is not None and self.radius < 1:
            raise ValueError(f"radius must be at least 1, got {self.radius}")


@dataclass(frozen=True)
class Centered:
    """Settings of the centered-form modes (``propagate(mode="centered")`` and
    ``"3b+centered"``; :mod:`boundest.ctc.windows` details the contraction).

    Attributes
    ----------
    window : int
        Consecutive constraints (in the model's order) linearised together: each target is
        contracted by the optimal aggregation of the constraints of one window (the one where
        it lies most central). Wider windows see further along a chain and cost more per
        target (a dense simplex over the window).
    stride : int, optional
        Constraints between the starts of two windows (default ``window // 2``).
    rounds : int
        Linearisations at most (each followed by hull consistency on what it narrowed).
    min_gain : float
        Stop when a round narrows the targets' total width by less than this fraction.
    """

    window: int = 42
    stride: int | None = None
    rounds: int = 2
    min_gain: float = 0.01

    def __post_init__(self) -> None:
        if self.window < 1:
            raise ValueError(f"window must be at least 1, got {self.window}")
        if self.stride is not None and not 1 <= self.stride <= self.window:
            raise ValueError(f"stride must lie in 1..window, got {self.stride}")
        if self.rounds < 1:
            raise ValueError(f"rounds must be at least 1, got {self.rounds}")
        if self.min_gain < 0:
            raise ValueError("min_gain must be non-negative")


@dataclass
class Propagation:
    """Result of ``propagate``.

    ``res[v]`` is the final domain of a variable ``v`` (a name or the ``Var`` itself), ``res[x]``
    that of a whole ``VarFamily`` as an interval array, and ``res.bounds(x)`` its lower and
    upper bounds as NumPy arrays in one call.

    Attributes
    ----------
    domains : dict of str -> Interval
        Final domain of every variable, by name (empty intervals when inconsistent).
    consistent : bool
        False when the CSP was *proven* to have no solution.
    evaluations : int
        Number of node revisions (forward image + backward projection of one primitive).
    iterations : float
        ``evaluations / n_nodes``: the work in units of full passes over the tape.
    time_s : float
        Wall time of the propagation (compilation of the model excluded).
    mode : str
        One of :data:`MODES` (see ``propagate``).
    shaving : dict
        With ``mode="3b"`` or ``"bc+3b"``: the counters of the shaving phase
        (``engine.SHAVE_STATS``: rounds, probes, slices refuted, revisions spent in probes,
        revisions in all) and its time ``time_s`` (included in the propagation's ``time_s``);
        empty otherwise.
    boxcons : dict
        With ``mode="bc"`` or ``"bc+3b"``: the counters of the box-consistency phase
        (``engine.BC_STATS``: rounds, BC3 searches, significant narrowings, node evaluations
        in the searches, revisions of the propagation), ``candidates`` (variables occurring
        several times in their constraints) and its time ``time_s``; empty otherwise.
    linear : dict
        With ``mode="lp"``: ``rounds`` (LP contractions), ``lp_time_s`` (extraction, solves,
        rigorous bounds), ``evaluations`` (revisions propagating what the LPs narrowed),
        ``widths`` (the targets' total width after hull consistency and after each round) and
        ``time_s``; empty otherwise.
    centered : dict
        With ``mode="centered"`` or ``"3b+centered"``: ``rounds``, the counters of the window
        contraction (``ctc.windows.WINDOW_STATS``: windows, linear programmes solved, not
        solved, bounds narrowed), ``evaluations`` (revisions propagating what it narrowed),
        ``widths`` (the targets' total width before and after each round), ``prepare_s``
        (differentiable form of the constraints, windows) and ``time_s``; empty otherwise.
    """

    domains: dict[str, Interval]
    consistent: bool
    evaluations: int
    iterations: float
    time_s: float
    n_nodes: int
    n_slots: int
    slots: Interval = field(repr=False)
    mode: str = "hc4"
    shaving: dict = field(default_factory=dict)
    boxcons: dict = field(default_factory=dict)
    linear: dict = field(default_factory=dict)
    centered: dict = field(default_factory=dict)

    def __getitem__(self, key: str | Var | VarFamily) -> Interval:
        """The final domain of a variable, by name or by the ``Var`` itself (``res["x_3"]``,
        ``res[x[3]]``); of a whole ``VarFamily``, an interval array (``res[x]``, see
        :meth:`bounds`)."""
        return domain_of(self.domains, key)

    def bounds(self, key: str | Var | VarFamily) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of a variable or of a whole family, as NumPy arrays.

        For a ``VarFamily`` ``x`` indexed ``x[k]``, both arrays have shape ``(K,)``, ``K - 1``
        the largest ``k`` in the model; indexed ``x[k, i]``, shape ``(K, I)``; entry ``[k, i]``
        is the domain of ``x[k, i]`` (NaN, NaN for an empty domain). Every index up to the
        largest must be a variable of the model, or ``KeyError`` names those missing. For one
        variable, 0-d arrays.

        >>> from boundest.expr import Model, VarFamily
        >>> x = VarFamily("x")
        >>> m = Model()
        >>> _ = m.declare(x[0], (0, 1))
        >>> res = propagate(m.add(x[1] == x[0] + 1, x[2] == 2 * x[1]), mode="hc4")
        >>> lo, hi = res.bounds(x)
        >>> lo, hi
        (array([0., 1., 2.]), array([1., 2., 4.]))
        """
        dom = domain_of(self.domains, key)
        return np.array(dom.lo, dtype=float), np.array(dom.hi, dtype=float)

    def __repr__(self) -> str:
        """Counts and summary numbers, never every domain (``domains`` holds them)."""
        doms = list(self.domains.values())
        empty = sum(int(np.count_nonzero(d.is_empty())) for d in doms)
        unbounded = sum(int(np.count_nonzero(~d.is_bounded())) for d in doms)
        return (f"Propagation(consistent={self.consistent}, variables={len(doms)}, "
                f"empty={empty}, unbounded={unbounded}, evaluations={self.evaluations}, "
                f"iterations={self.iterations:.3g}, time_s={self.time_s:.3g}, "
                f"n_nodes={self.n_nodes}, n_slots={self.n_slots}, mode={self.mode!r})")


def domain_of(domains: dict[str, Interval], key: str | Var | VarFamily) -> Interval:
    """``domains[key]`` for a name or a ``Var``; for a ``VarFamily``, the interval array of its
    members (``Propagation.bounds`` details the shape; ``KeyError`` names missing members)."""
    if isinstance(key, VarFamily):
        members = key.members(domains)
        if not members:
            raise KeyError(f"no variable of the family {key.name!r} ({key.name}_0 ...)")
        shape = tuple(max(k[j] for k in members) + 1 for j in range(len(next(iter(members)))))
        missing = [f"{key.name}_" + "_".join(map(str, k)) for k in np.ndindex(*shape)
                   if k not in members]
        if missing:
            raise KeyError(f"family {key.name!r} has {len(missing)} gaps below its largest "
                           f"index: {', '.join(missing[:5])}{' ...' if len(missing) > 5 else ''}")
        lo, hi = np.empty(shape), np.empty(shape)
        for k, name in members.items():
            lo[k], hi[k] = float(domains[name].lo), float(domains[name].hi)
        return Interval.trusted(lo, hi)
    name = key.name if isinstance(key, Var) else key
    if not isinstance(name, str):
        raise TypeError(f"a variable is named by a str, a Var or a VarFamily, not {key!r}")
    return domains[name]


def slot_users(tape: Tape) -> tuple[np.ndarray, np.ndarray]:
    """CSR lists of the nodes that use each slot (as output or argument)."""
    slots = np.concatenate([tape.out, tape.a, tape.b])
    nodes = np.tile(np.arange(tape.n_nodes, dtype=np.int64), 3)
    keep = slots >= 0
    slots, nodes = slots[keep], nodes[keep]
    order = np.lexsort((nodes, slots))
    slots, nodes = slots[order], nodes[order]
    pair = np.stack([slots, nodes])
    dedup = np.ones(slots.size, dtype=bool)
    dedup[1:] = np.any(pair[:, 1:] != pair[:, :-1], axis=0)
    slots, nodes = slots[dedup], nodes[dedup]
    ptr = np.zeros(tape.n_slots + 1, dtype=np.int64)
    np.add.at(ptr, slots + 1, 1)
    return np.cumsum(ptr), nodes


def arg_users(tape: Tape) -> tuple[np.ndarray, np.ndarray]:
    """CSR lists of the nodes that read each slot as an argument (each node once per slot)."""
    slots = np.concatenate([tape.a, tape.b]).astype(np.int64)
    nodes = np.tile(np.arange(tape.n_nodes, dtype=np.int64), 2)
    keep = (slots >= 0) & ~((np.arange(slots.size) >= tape.n_nodes)
                            & (slots == np.concatenate([tape.a, tape.a])))
    slots, nodes = slots[keep], nodes[keep]
    order = np.lexsort((nodes, slots))
    ptr = np.zeros(tape.n_slots + 1, dtype=np.int64)
    np.add.at(ptr, slots + 1, 1)
    return np.cumsum(ptr), nodes[order]


def bc_candidates(tape: Tape, slots: np.ndarray, max_nodes: int
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The slots among ``slots`` that occur several times in their constraints, with their
    sub-networks (``engine.bc_closures``, which stop at ``slots``: a variable's constraints
    reach up to the other variables narrowed, through any other named variable, such as a
    measured output that names a sub-expression): ``(cand, cptr, cnodes)``."""
    aptr, aadj = arg_users(tape)
    slots = np.asarray(slots, dtype=np.int64)
    stop = np.zeros(tape.n_slots, dtype=np.bool_)
    stop[slots] = True
    keep, cptr, cnodes = bc_closures(tape.out, tape.a, tape.b, aptr, aadj, stop, slots,
                                     int(max_nodes))
    return slots[keep], cptr, cnodes


def propagate(model: Model | list[Constraint] | Tape, *, rel_eps: float = 1e-3,
              max_evaluations: int | None = None,
              domains: dict[str | Var, Interval] | None = None,
              progress: bool | None = None, chunk: int = 2_000_000, window: int = 64,
              mode: str | None = None, shave: list[str | Var | VarFamily] | None = None,
              shaving: Shaving | None = None,
              targets: list[str | Var | VarFamily] | None = None,
              boxcons: BoxConsistency | None = None,
              linear: LinearRelaxation | None = None,
              centered: Centered | None = None) -> Propagation:
    """Contract all domains of a CSP to a fixed point.

    The default mode is ``"3b+centered"`` (shaving, then the centered form): the tightest on
    every model measured, at 25-900 times the cost of hull consistency alone (the record:
    ``benchmarks/results/modes.json``). For a large model or a quick look, ``mode="hc4"``
    costs one pass to the fixed point.

    ``mode="hc4"`` is hull consistency: every primitive node revised until nothing moves.
    ``mode="3b"`` then shaves (3B consistency, adaptive): for each variable of ``shave`` and
    each of its bounds, a slice at the bound is propagated alone, and removed when that proves
    it holds no solution (``engine.shave_kernel``). Each probe is local (it revises only what
    its slice reaches, within ``shaving.probe_evals`` revisions, and undoes itself from a
    trail), so the cost per variable does not grow with the size of the CSP. It is tighter
    where hull consistency suffers from the dependency problem or from the locality of its
    constraints (a variable that occurs several times, a sign that only the next steps decide).

    ``mode="bc"`` adds box consistency (BC3, Benhamou et al. 1999) after hull consistency:
    each variable of ``targets`` that occurs several times in its constraints has its bounds
    narrowed to the outermost slices whose image by the natural interval extension of those
    constraints (the sub-network of nodes it reaches, up to the other ``targets``) meets the
    domains; what it narrows is propagated by hull consistency, round after round while it
    pays (``engine.bc_kernel``). Each search is local and bounded (``boxcons``), so its cost
    per variable does not grow with the CSP. ``mode="bc+3b"`` runs box consistency, then
    shaving. ``mode="lp"`` contracts the linear and log-linear sub-networks by LPs at hull
    consistency's fixed point (``ctc.linear.contract_slots``, needs SciPy: ``pip install
    'boundest[lp]'``; with ``linear.relax``, also over a linear relaxation of the nonlinear
    nodes around the box) and propagates only what they narrowed (the users of the narrowed slots
    become dirty), up to ``linear.rounds`` times while it pays; unlike ``csp.linear.
    propagate_lp`` it never restarts propagation from scratch. The LPs are global: their cost
    grows faster than the CSP.

    ``mode="centered"`` linearises the constraints around the centre of the box (the
    mean-value form with the interval Jacobian, :mod:`boundest.ctc.derivatives`), which keeps
    the first-order correlation between variables that boxes lose, and contracts each variable
    of ``targets`` by the best aggregation of the constraints of a window of ``centered.window``
    consecutive constraints (:mod:`boundest.ctc.windows`: a compiled simplex chooses the
    multipliers, interval arithmetic makes the bound rigorous), then propagates what narrowed
    by hull consistency, round after round while it pays. The cost per target is one small
    dense simplex, so the cost per step of a chain stays flat. ``"3b+centered"`` shaves first
    (``shave``, ``shaving``): the linearisation pays most on boxes that are already narrow.

    Stopping rule: a node is revised again only when one of its slots shrank by more than
    ``rel_eps`` times its width (or lost an infinite bound); propagation stops when no such
    node is left (the fixed point at that tolerance), when a domain becomes empty (the CSP is
    proven inconsistent), or after ``max_evaluations`` node revisions.

    Parameters
    ----------
    model : Model, list of Constraint or Tape
    rel_eps : float
        Relative shrink below which a change is not propagated further.
    max_evaluations : int, optional
        Budget of node revisions (default: 10,000 per node).
    domains : dict, optional
        Domains narrowing the model's initial ones (keyed by variable name or ``Var``).
    progress : bool, optional
        Show a progress counter of node revisions and dirty nodes, on a terminal only
        (default: only when the run lasts more than 2 s).
    chunk : int
        Node revisions per call of the compiled kernel (between progress updates).
    window : int
        Consecutive tape nodes brought to their local fixed point together before a pass moves
        on (see ``engine.propagate_kernel``); 64 nodes is about three time steps of the
        satellite.
    mode : {"hc4", "bc", "3b", "bc+3b", "lp", "centered", "3b+centered"}, optional
        Hull consistency alone, or followed by box consistency, shaving, both, LPs, the
        centered form, or shaving and the centered form. Default :data:`DEFAULT_MODE`
        (``"3b+centered"``), or ``"3b"`` for a ``Tape`` built without its model (by
        ``expr.tape.instantiate``), which cannot be differentiated.
    shave : list of str, Var or VarFamily, optional
        With ``mode="3b"``: the variables to shave, in the order they are visited (for a time
        series, by time step; default: every variable of the model in its order). A
        ``VarFamily`` stands for its members, in index order; so in ``targets``.
    shaving : Shaving, optional
        With ``mode="3b"``: the shaving settings (default ``Shaving()``).
    targets : list of str, Var or VarFamily, optional
        With ``mode="bc"`` or ``"bc+3b"``: the variables box consistency narrows (those among
        them that occur several times; default: every variable); with ``mode="lp"``: the
        variables the LPs contract (default: every variable; each costs two LPs, four where it
        is sign-definite and in a log-linear row); with ``mode="centered"`` or
        ``"3b+centered"``: the variables the centered form contracts (default: every variable;
        each costs two small linear programmes per round).
    boxcons : BoxConsistency, optional
        With ``mode="bc"`` or ``"bc+3b"``: the settings (default ``BoxConsistency()``).
    linear : LinearRelaxation, optional
        With ``mode="lp"``: the settings (default ``LinearRelaxation()``).
    centered : Centered, optional
        With ``mode="centered"`` or ``"3b+centered"``: the settings (default ``Centered()``).
    """
    if mode is not None and mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if not 0.0 <= rel_eps < 1.0:
        raise ValueError(f"rel_eps must lie in [0, 1[, got {rel_eps}")
    if window < 1:
        raise ValueError(f"window must be a positive number of nodes, got {window}")
    tape = model if isinstance(model, Tape) else compile_model(model)
    shave, targets = _names(tape, shave), _names(tape, targets)
    if mode is None:
        mode = DEFAULT_MODE if tape.model is not None else "3b"
    if mode in ("centered", "3b+centered") and tape.model is None:
        raise ValueError(f"mode {mode!r} differentiates the model's constraints: pass the Model "
                         "(or a Tape from compile_model), not a Tape without its model")
    if mode == "lp":
        from ..ctc.linear import _linprog

        _linprog()  # fails before any work, naming the extra, when SciPy is missing
    lo, hi = tape.lo.copy(), tape.hi.copy()
    for key, dom in (domains or {}).items():
        name = key.name if isinstance(key, Var) else key
        if name not in tape.slot_of:
            raise ValueError(f"unknown variable {name!r}")
        s = tape.slot_of[name]
        if bool(dom.is_empty()):
            lo[s] = hi[s] = np.nan
        else:
            lo[s] = max(lo[s], float(dom.lo))
            hi[s] = min(hi[s], float(dom.hi))
    budget = 10_000 * max(tape.n_nodes, 1) if max_evaluations is None else max_evaluations
    ptr, adj = slot_users(tape)
    families = family_flags(tape.op)
    n = tape.n_nodes
    dirty = np.ones(n, dtype=np.bool_)
    state = np.array([0, n, RUNNING, 0, 1], dtype=np.int64)
    # a zero-budget call compiles (first use) or loads the kernel outside the timed part
    propagate_kernel(tape.op, tape.out, tape.a, tape.b, tape.param, lo, hi, ptr, adj, dirty,
                     state.copy(), rel_eps, 0, window, *families)
    e = slice(0, 0)
    if mode in ("bc", "bc+3b"):  # the same for the other kernels, on an empty tape
        bc_closures(tape.out[e], tape.a[e], tape.b[e], ptr[:1], adj[e], np.zeros(0, np.bool_),
                    adj[e], 1)
        bc_kernel(tape.op[e], tape.out[e], tape.a[e], tape.b[e], tape.param[e], lo[e], hi[e],
                  ptr[:1], adj[e], adj[e], ptr[:1], adj[e], rel_eps, 0.0, 1, 1, 1, 0, 0.0,
                  window, np.zeros(len(BC_STATS), dtype=np.int64), *families)
    if mode in ("lp", "centered", "3b+centered"):  # they repropagate what they narrowed
        repropagate_kernel(tape.op[e], tape.out[e], tape.a[e], tape.b[e], tape.param[e], lo[e],
                           hi[e], ptr[:1], adj[e], adj[e], rel_eps, window,
                           np.zeros(1, dtype=np.int64), *families)
    if mode in ("3b", "bc+3b", "3b+centered"):
        shave_kernel(tape.op[e], tape.out[e], tape.a[e], tape.b[e], tape.param[e], lo[e], hi[e],
                     ptr[:1], adj[e], np.zeros(0, dtype=np.int64), rel_eps, rel_eps, 1, 0.5, 1,
                     0, 0.0, window, np.zeros(len(SHAVE_STATS), dtype=np.int64), *families)
    t0 = time.perf_counter()
    status = EMPTY if np.isnan(lo).any() or (lo > hi).any() else RUNNING
    # no total: the budget is a cap, not a forecast of the revisions to the fixed point; the
    # bar counts revisions and shows how many nodes are still dirty
    with Progress(progress if n > 0 else False, desc="propagating", unit="rev",
                  unit_scale=True) as bar:
        while status == RUNNING and state[3] < budget and n > 0:
            status = propagate_kernel(tape.op, tape.out, tape.a, tape.b, tape.param, lo, hi,
                                      ptr, adj, dirty, state, rel_eps,
                                      min(chunk, budget - state[3]), window, *families)
            bar.update(int(state[3]) - bar.n)
            bar.set_postfix(dirty=int(state[1]))
        bar.stop("empty: the constraints are inconsistent" if status == EMPTY else
                 f"revision budget ({budget}) spent" if status == RUNNING else "fixed point")
    evaluations = int(state[3])
    shave_info: dict = {}
    bc_info: dict = {}
    lp_info: dict = {}
    if mode in ("bc", "bc+3b") and status != EMPTY and n > 0:
        opts_bc = boxcons or BoxConsistency()
        t1 = time.perf_counter()
        cand, cptr, cnodes = bc_candidates(tape, _shave_slots(tape, targets, "targets"),
                                           opts_bc.max_nodes)
        stats = np.zeros(len(BC_STATS), dtype=np.int64)
        status = bc_kernel(tape.op, tape.out, tape.a, tape.b, tape.param, lo, hi, ptr, adj,
                           cand, cptr, cnodes, rel_eps, 0.0, int(opts_bc.depth),
                           int(opts_bc.max_steps), int(opts_bc.rounds), int(opts_bc.reach),
                           float(opts_bc.min_gain), window, stats, *families)
        bc_info = {k: int(v) for k, v in zip(BC_STATS, stats, strict=True)}
        bc_info["candidates"] = int(cand.size)
        bc_info["time_s"] = time.perf_counter() - t1
        evaluations += int(stats[-1])
    if mode == "lp" and status != EMPTY and n > 0:
        status, lp_info = _lp_rounds(tape, lo, hi, ptr, adj, families, rel_eps, window,
                                     _shave_slots(tape, targets, "targets"),
                                     linear or LinearRelaxation())
        evaluations += lp_info["evaluations"]
    if mode in ("3b", "bc+3b", "3b+centered") and status != EMPTY and n > 0:
        cand = _shave_slots(tape, shave)
        opts = shaving or Shaving()
        stats = np.zeros(len(SHAVE_STATS), dtype=np.int64)
        t1 = time.perf_counter()
        status = shave_kernel(tape.op, tape.out, tape.a, tape.b, tape.param, lo, hi, ptr, adj,
                              cand, rel_eps, float(opts.probe_eps), int(opts.probe_evals),
                              float(opts.frac), int(opts.rounds), int(opts.reach),
                              float(opts.min_gain), window, stats, *families)
        shave_info = {k: int(v) for k, v in zip(SHAVE_STATS, stats, strict=True)}
        shave_info["time_s"] = time.perf_counter() - t1
        evaluations += int(stats[-1])
    ctr_info: dict = {}
    if mode in ("centered", "3b+centered") and status != EMPTY and n > 0:
        status, ctr_info = _centered_rounds(tape, lo, hi, ptr, adj, families, rel_eps, window,
                                            targets, centered or Centered())
        evaluations += ctr_info["evaluations"]
    elapsed = time.perf_counter() - t0
    consistent = status != EMPTY
    if not consistent:
        lo[:] = np.nan
        hi[:] = np.nan
    doms = {name: Interval.trusted(lo[s], hi[s]) for name, s in tape.slot_of.items()}
    return Propagation(domains=doms, consistent=consistent, evaluations=evaluations,
                       iterations=evaluations / max(n, 1), time_s=elapsed, n_nodes=n,
                       n_slots=tape.n_slots, slots=Interval.trusted(lo, hi), mode=mode,
                       shaving=shave_info, boxcons=bc_info, linear=lp_info,
                       centered=ctr_info)


def _lp_rounds(tape: Tape, lo: np.ndarray, hi: np.ndarray, ptr: np.ndarray, adj: np.ndarray,
               families: tuple, rel_eps: float, window: int, slots: np.ndarray,
               opts: LinearRelaxation) -> tuple[int, dict]:
    """LP contraction at the fixed point, then propagation of the slots it narrowed, in place
    on ``lo``/``hi``, while a round pays. Returns the status and the counters."""
    from ..ctc.linear import contract_slots

    t0 = time.perf_counter()
    lp_time, evals, done = 0.0, 0, 0
    widths = [float(np.sum(hi[slots] - lo[slots]))]
    status = RUNNING
    stats = np.zeros(1, dtype=np.int64)
    while done < opts.rounds:
        t1 = time.perf_counter()
        nlo, nhi, ok = contract_slots(tape, lo, hi, slots, opts.log_linear, opts.radius,
                                      opts.relax)
        lp_time += time.perf_counter() - t1
        done += 1
        if not ok:
            status = EMPTY
            break
        w0, w1 = hi - lo, nhi - nlo
        with np.errstate(invalid="ignore"):
            moved = (nlo != lo) | (nhi != hi)
            sig = moved & ((w0 == np.inf) | (w0 - w1 > rel_eps * w0))
        lo[:], hi[:] = nlo, nhi
        status = repropagate_kernel(tape.op, tape.out, tape.a, tape.b, tape.param, lo, hi, ptr,
                                    adj, np.flatnonzero(sig).astype(np.int64), rel_eps, window,
                                    stats, *families)
        evals += int(stats[0])
        if status == EMPTY:
            break
        widths.append(float(np.sum(hi[slots] - lo[slots])))
        if not widths[-1] < (1.0 - opts.min_gain) * widths[-2]:
            break
    info = {"rounds": done, "lp_time_s": lp_time, "evaluations": evals, "widths": widths,
            "settings": {"rounds": opts.rounds, "min_gain": opts.min_gain,
                         "radius": opts.radius, "log_linear": opts.log_linear,
                         "relax": opts.relax},
            "time_s": time.perf_counter() - t0}
    return status, info


def _centered_rounds(tape: Tape, lo: np.ndarray, hi: np.ndarray, ptr: np.ndarray,
                     adj: np.ndarray, families: tuple, rel_eps: float, window: int,
                     targets: list[str] | None, opts: Centered) -> tuple[int, dict]:
    """Window contraction of the centered form, then hull consistency on what it narrowed, in
    place on ``lo``/``hi``, while a round pays. Returns the status and the counters."""
    from ..ctc.windows import WINDOW_STATS, assign_targets, contract_windows
    from ..expr.function_tape import constraint_functions

    t0 = time.perf_counter()
    assert tape.model is not None
    ftape, _ = constraint_functions(tape.model)
    vslots = np.array([tape.slot_of[v] for v in ftape.names], dtype=np.int64)
    col = {v: j for j, v in enumerate(ftape.names)}
    if targets is None:
        tcols = np.arange(ftape.n_vars, dtype=np.int64)
    else:
        _shave_slots(tape, targets, "targets")  # the error for an unknown name
        tcols = np.array([col[v] for v in targets if v in col], dtype=np.int64)
    windows = assign_targets(ftape, tcols, opts.window, opts.stride or max(opts.window // 2, 1))
    tslots = vslots[tcols]
    prepare = time.perf_counter() - t0
    counts = np.zeros(len(WINDOW_STATS), dtype=np.int64)
    widths = [float(np.sum(hi[tslots] - lo[tslots]))]
    status, evals, done = RUNNING, 0, 0
    stats = np.zeros(1, dtype=np.int64)
    while done < opts.rounds:
        xl, xh = lo[vslots].copy(), hi[vslots].copy()
        ok, st = contract_windows(ftape, xl, xh, windows)
        counts += st
        done += 1
        if not ok:
            status = EMPTY
            break
        nlo, nhi = lo.copy(), hi.copy()
        np.maximum.at(nlo, vslots, xl)  # merged variables share a slot
        np.minimum.at(nhi, vslots, xh)
        w0, w1 = hi - lo, nhi - nlo
        with np.errstate(invalid="ignore"):
            sig = ((nlo != lo) | (nhi != hi)) & ((w0 == np.inf) | (w0 - w1 > rel_eps * w0))
        lo[:], hi[:] = nlo, nhi
        status = repropagate_kernel(tape.op, tape.out, tape.a, tape.b, tape.param, lo, hi, ptr,
                                    adj, np.flatnonzero(sig).astype(np.int64), rel_eps, window,
                                    stats, *families)
        evals += int(stats[0])
        if status == EMPTY:
            break
        widths.append(float(np.sum(hi[tslots] - lo[tslots])))
        if not widths[-1] < (1.0 - opts.min_gain) * widths[-2]:
            break
    info = {"rounds": done, **{k: int(v) for k, v in zip(WINDOW_STATS, counts, strict=True)},
            "evaluations": evals, "widths": widths, "prepare_s": prepare,
            "settings": {"window": opts.window, "stride": opts.stride, "rounds": opts.rounds,
                         "min_gain": opts.min_gain},
            "time_s": time.perf_counter() - t0}
    return status, info


def _names(tape: Tape, keys: list[str | Var | VarFamily] | None) -> list[str] | None:
    """The variable names of ``keys``: a ``Var`` by its name, a ``VarFamily`` by its members in
    the model, in index order."""
    if keys is None:
        return None
    names: list[str] = []
    for key in keys:
        if isinstance(key, VarFamily):
            members = key.members(tape.slot_of)
            names += [members[k] for k in sorted(members)]
        else:
            names.append(key.name if isinstance(key, Var) else key)
    return names


def _shave_slots(tape: Tape, names: list[str] | None, arg: str = "shave") -> np.ndarray:
    """The slots of the variables ``names`` (default: all), each once, in that order."""
    if names is None:
        names = list(tape.slot_of)
    unknown = [v for v in names if v not in tape.slot_of]
    if unknown:
        raise ValueError(f"unknown variable {unknown[0]!r} in {arg}")
    slots = np.array([tape.slot_of[v] for v in names], dtype=np.int64)
    _, first = np.unique(slots, return_index=True)
    return slots[np.sort(first)]
