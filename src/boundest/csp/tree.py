"""Tree-structured set CSPs: the FALL and CLIMB algorithms of Jaulin et al. 2001 (section 3.2).

A set constraint satisfaction problem (SCSP) has one *domain* per variable (any set
representation: a box, a subpaving, a finite set...) and binary constraints. When its graph is a
tree, one FALL (leaves to root) followed by one CLIMB (root to leaves) gives its optimal
contraction (Jaulin et al. 2001, Theorem 6), provided the local contraction operators are exact:

    rho_b(V_a) = {v_a in V_a | exists v_b in V_b, (v_a, v_b) in C_ab}      (Jaulin et al. 2001,
    eq. 9)

This module knows nothing about the domains: each ``Arc`` carries its two local operators as
callables, ``toward_a(V_a, V_b) -> V_a'`` and ``toward_b(V_b, V_a) -> V_b'``. With outer
approximations of the operators (interval images, SIVIA) the result is an outer approximation of
the optimal contraction: it never loses a solution.

Example (finite sets, the relation ``v2 = v1 + 1`` then ``v3 = 2 v2``):

>>> def arc(a, b, rel):
...     return Arc(a, b, lambda va, vb: {x for x in va if any((x, y) in rel for y in vb)},
...                lambda vb, va: {y for y in vb if any((x, y) in rel for x in va)})
>>> r12 = {(i, i + 1) for i in range(9)}
>>> r23 = {(i, 2 * i) for i in range(9)}
>>> tree = TreeSCSP(["v1", "v2", "v3"], [arc("v1", "v2", r12), arc("v2", "v3", r23)])
>>> out = tree.fall_climb({"v1": set(range(9)), "v2": {1, 2, 3}, "v3": {4, 6, 7}})
>>> sorted(out["v1"]), sorted(out["v2"]), sorted(out["v3"])
([1, 2], [2, 3], [4, 6])
"""

from __future__ import annotations

import random
from collections.abc import Callable, Hashable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

__all__ = ["Arc", "TreeSCSP"]

#: ``rho(V_target, V_other) -> V_target'``: contract the target domain w.r.t. the other one.
Rho = Callable[[Any, Any], Any]


@dataclass(frozen=True)
class Arc:
    """A binary constraint between the variables ``a`` and ``b`` with its local operators.

    ``toward_a(V_a, V_b)`` returns ``{v_a in V_a | exists v_b in V_b, (v_a, v_b) in C}`` (or an
    outer approximation of it inside ``V_a``); ``toward_b(V_b, V_a)`` symmetrically.
    """

    a: Hashable
    b: Hashable
    toward_a: Rho
    toward_b: Rho

    def contract(self, target: Hashable, domains: Mapping[Hashable, Any]) -> Any:
        """The local contraction of ``target``'s domain (``a`` or ``b``) by this constraint."""
        if target == self.a:
            return self.toward_a(domains[self.a], domains[self.b])
        if target == self.b:
            return self.toward_b(domains[self.b], domains[self.a])
        raise ValueError(f"variable {target!r} is not in the constraint {self.a!r}-{self.b!r}")


class TreeSCSP:
    """An SCSP whose graph is a tree: variables (hashable names) and binary constraints.

    Parameters
    ----------
    variables : iterable of hashable
        The variable names.
    arcs : sequence of Arc
        The constraints; the graph they form must be a tree over all the variables (connected,
        ``len(variables) - 1`` arcs, no cycle), else ValueError.

    Notes
    -----
    The methods take the domains as a mapping ``variable -> domain`` and return a new dict; the
    argument is not modified.
    """

    def __init__(self, variables: Iterable[Hashable], arcs: Sequence[Arc]) -> None:
        self.variables = list(variables)
        if len(set(self.variables)) != len(self.variables):
            raise ValueError(f"duplicate variable names in {self.variables!r}")
        if not self.variables:
            raise ValueError("a tree SCSP needs at least one variable")
        self.arcs = list(arcs)
        known = set(self.variables)
        self._adj: dict[Hashable, list[tuple[Hashable, Arc]]] = {v: [] for v in self.variables}
        for arc in self.arcs:
            for v in (arc.a, arc.b):
                if v not in known:
                    raise ValueError(f"constraint {arc.a!r}-{arc.b!r}: unknown variable {v!r}")
            if arc.a == arc.b:
                raise ValueError(f"constraint {arc.a!r}-{arc.b!r} is not binary (a loop)")
            self._adj[arc.a].append((arc.b, arc))
            self._adj[arc.b].append((arc.a, arc))
        if len(self.arcs) != len(self.variables) - 1:
            raise ValueError(f"not a tree: {len(self.variables)} variables need "
                             f"{len(self.variables) - 1} constraints, got {len(self.arcs)} "
                             "(group the variables of a cycle into one vector variable)")
        reached = self.rooted(self.variables[0])
        if len(reached) != len(self.variables) - 1:
            seen = {self.variables[0], *(c for _, c, _ in reached)}
            missing = [v for v in self.variables if v not in seen]
            raise ValueError(f"not a tree: variables {missing!r} are not connected to "
                             f"{self.variables[0]!r}")

    def rooted(self, root: Hashable) -> list[tuple[Hashable, Hashable, Arc]]:
        """The arcs as ``(parent, child, arc)`` in breadth-first order from ``root``."""
        if root not in self._adj:
            raise ValueError(f"unknown root variable {root!r}")
        order, seen, frontier = [], {root}, [root]
        while frontier:
            nxt = []
            for p in frontier:
                for c, arc in self._adj[p]:
                    if c not in seen:
                        seen.add(c)
                        order.append((p, c, arc))
                        nxt.append(c)
            frontier = nxt
        return order

    def _check(self, domains: Mapping[Hashable, Any]) -> dict[Hashable, Any]:
        missing = [v for v in self.variables if v not in domains]
        if missing:
            raise ValueError(f"no domain given for the variables {missing!r}")
        return {v: domains[v] for v in self.variables}

    def fall(self, domains: Mapping[Hashable, Any], root: Hashable) -> dict[Hashable, Any]:
        """FALL (Jaulin et al. 2001, section 3.2.2): contract every domain by its sons, from the
        leaves
        down to ``root``. The result is up-consistent; the root's domain is its projection."""
        out = self._check(domains)
        for p, _, arc in reversed(self.rooted(root)):  # all sons of c are done before c -> p
            out[p] = arc.contract(p, out)
        return out

    def climb(self, domains: Mapping[Hashable, Any], root: Hashable) -> dict[Hashable, Any]:
        """CLIMB (Jaulin et al. 2001, section 3.2.3): contract every son by its father, from
        ``root`` up
        to the leaves. On an up-consistent SCSP this gives the optimal contraction."""
        out = self._check(domains)
        for _, c, arc in self.rooted(root):
            out[c] = arc.contract(c, out)
        return out

    def fall_climb(self, domains: Mapping[Hashable, Any], root: Hashable | None = None
                   ) -> dict[Hashable, Any]:
        """FALL then CLIMB from ``root`` (default: the first variable): the optimal contraction
        (Jaulin et al. 2001, Theorem 6) when the local operators are exact, an outer one
        otherwise."""
        root = self.variables[0] if root is None else root
        return self.climb(self.fall(domains, root), root)

    def waltz(self, domains: Mapping[Hashable, Any], equal: Callable[[Any, Any], bool], *,
              seed: int | None = None, max_rounds: int = 10_000
              ) -> tuple[dict[Hashable, Any], int]:
        """The Waltz algorithm (Jaulin et al. 2001, section 2): apply the local operators in a
        random
        order (``seed``) until a whole round changes no domain (``equal(old, new)``).

        Returns the domains and the number of rounds. On a tree with exact operators it reaches
        the same optimal contraction as ``fall_climb``, with more operator calls.
        """
        rng = random.Random(seed)
        out = self._check(domains)
        moves = [(v, arc) for arc in self.arcs for v in (arc.a, arc.b)]
        for rounds in range(1, max_rounds + 1):
            rng.shuffle(moves)
            changed = False
            for v, arc in moves:
                new = arc.contract(v, out)
                if not equal(out[v], new):
                    out[v] = new
                    changed = True
            if not changed:
                return out, rounds
        raise RuntimeError(f"waltz: no fixed point after {max_rounds} rounds")
