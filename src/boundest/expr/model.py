"""A model: variables with their initial domains and a list of constraints."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from ..interval import Interval
from .nodes import Constraint, Var, _decode, _encode, variables

__all__ = ["Model"]


@dataclass
class Model:
    """Variables (name -> scalar interval domain) and constraints over them.

    Variables used by a constraint but not declared get the entire line as domain; a variable
    declared twice gets the intersection of its domains (``declare``).
    ``options`` keeps header lines of a model file (e.g. RealPaver's ``Bisection none;``),
    ``option_lines`` the line of each in the file.
    """

    domains: dict[str, Interval] = field(default_factory=dict)
    constraints: list[Constraint] = field(default_factory=list)
    options: dict[str, str] = field(default_factory=dict)
    option_lines: dict[str, int] = field(default_factory=dict)

    def declare(self, var: Var | str, domain: Interval | tuple[float, float] | None = None
                ) -> Var:
        """Declare a variable with a domain (entire line by default); returns the ``Var``.

        Declaring a variable again intersects its domains: each declaration is one more
        statement that the variable lies in its domain, as a bound from a second sensor
        would be (``declare(x)`` alone adds nothing). An empty intersection is refused with a
        ``ValueError`` naming both domains, the model being left as it was: the model would
        have no solution. To replace a domain, assign ``model.domains[name]``.
        """
        v = var if isinstance(var, Var) else Var(var)
        dom = Interval.entire() if domain is None else (
            domain if isinstance(domain, Interval) else Interval(*domain))
        if dom.shape != ():
            raise ValueError(f"domain of {v.name} must be a scalar interval, got {dom}")
        old = self.domains.get(v.name)
        if old is not None:
            both = old & dom
            if bool(both.is_empty()) and not (bool(old.is_empty()) or bool(dom.is_empty())):
                raise ValueError(f"{v.name} declared in {dom} after {old}: the domains do not "
                                 "meet, so the model would have no solution")
            dom = both
        self.domains[v.name] = dom
        return v

    def add(self, *constraints: Constraint | Iterable[Constraint]) -> Model:
        """Add constraints (or iterables of them); returns the model for chaining."""
        for c in constraints:
            if isinstance(c, Constraint):
                self.constraints.append(c)
            else:
                for ci in c:
                    if not isinstance(ci, Constraint):
                        raise TypeError(f"not a constraint: {ci!r}")
                    self.constraints.append(ci)
        return self

    def variable_names(self) -> list[str]:
        """Declared variables first (in declaration order), then undeclared ones."""
        names = list(self.domains)
        known = set(names)
        names += [v.name for v in variables(self.constraints) if v.name not in known]
        return names

    def __getstate__(self) -> dict:
        # the expressions of all constraints as one flat table: pickling (a model sent to a
        # worker process) and deepcopy would otherwise recurse once per level of an expression,
        # and a sub-expression shared by two constraints stays one object
        state = dict(self.__dict__)
        cons = state.pop("constraints")
        table, roots = _encode(e for c in cons for e in (c.lhs, c.rhs))
        state["_constraints"] = ([c.rel for c in cons], table, roots)
        return state

    def __setstate__(self, state: dict) -> None:
        state = dict(state)
        rels, table, roots = state.pop("_constraints")
        exprs = _decode(table, roots)
        state["constraints"] = [Constraint(exprs[2 * i], rel, exprs[2 * i + 1])
                                for i, rel in enumerate(rels)]
        self.__dict__.update(state)

    def __repr__(self) -> str:
        return (f"Model({len(self.variable_names())} variables, "
                f"{len(self.constraints)} constraints)")
