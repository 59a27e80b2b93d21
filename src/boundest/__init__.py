"""boundest: guaranteed nonlinear state estimation by interval constraint propagation.

The top level gathers what a user touches most: the interval type and its operators, elementary
functions that accept intervals and expressions alike (``sin(Interval)`` is an enclosure,
``sin(Var)`` an expression node), variables and models, contractors and propagation. ``abs``,
``min``, ``max`` and ``pow`` are reachable as ``boundest.abs`` etc. but are not exported by
``from boundest import *``.

The names are loaded on first access (PEP 562), so that ``import boundest.cli`` and
``boundest --help`` load neither NumPy nor Numba. Importing boundest changes no process-wide
state; the ``boundest`` command tunes glibc's allocator for its own process, and
``boundest.keep_freed_memory()`` does the same for a library user who asks (``_malloc``).

``dir(boundest)`` lists the public names only: ``__all__``, the four builtin-shadowing functions
above, the layers (``boundest.interval`` ... ``boundest.plot``) and the module's dunders.
"""

__version__ = "0.1.0"

#: name -> submodule that defines it (the interval names and the dispatching elementary
#: functions are looked up in ``interval`` and ``expr.functions``, see ``__getattr__``)
_NAMES: dict[str, str] = {
    **dict.fromkeys(("Arc", "BetaResult", "Centered", "Propagation", "Shaving", "TreeSCSP",
                     "beta_tuning", "propagate"), "csp"),
    **dict.fromkeys(("Contractor", "CtcCentered", "CtcFwdBwd", "CtcNewton", "CtcQInter",
                     "Fixpoint", "FunctionContractor", "Inflate", "Sequence", "Union",
                     "centered_form", "jacobian"), "ctc"),
    **dict.fromkeys(("ChainEstimate", "DiscreteSystem", "cse", "ncse", "rcse", "rcse_ncse"),
                    "estimation"),
    **dict.fromkeys(("Constraint", "Model", "ModelSyntaxError", "Var", "VarFamily",
                     "load_model", "parse_model"), "expr"),
    **dict.fromkeys(("Roots", "Subpaving", "image", "separators", "sivia", "solve_square"),
                    "paving"),
    **dict.fromkeys(("ContractorNetwork", "CtcDeriv", "CtcEval", "CtcSlices", "NetworkReport",
                     "Tube", "TubeVector"), "tube"),
    **dict.fromkeys(("abs", "min", "max", "pow"), "expr.functions"),
    "Box": "interval",
    "keep_freed_memory": "_malloc",
}
_ALIASES = {"Box": "IntervalVector", "centered_form": "centered"}
#: the layers, documented in the API reference (listed by ``dir``), then the command line's
_LAYERS = ("interval", "expr", "ctc", "csp", "paving", "tube", "estimation", "scenarios", "plot")
_SUBPACKAGES = (*_LAYERS, "commands", "cli")
#: public, but left out of ``__all__`` so that ``from boundest import *`` keeps the builtins
_NOT_STARRED = ("abs", "min", "max", "pow")


def _all() -> list[str]:
    from .expr import functions
    from .interval import __all__ as interval_all

    named = [n for n in _NAMES if n not in _NOT_STARRED]
    return list(dict.fromkeys([*interval_all, *functions.__all__, "__version__", *named]))


def __getattr__(name: str) -> object:
    from importlib import import_module

    value: object
    if name == "__all__":
        value = _all()
    elif name in _NAMES:
        module = import_module(f".{_NAMES[name]}", __name__)
        value = getattr(module, _ALIASES.get(name, name))
    elif name in _SUBPACKAGES:
        value = import_module(f".{name}", __name__)
    elif name.startswith("__"):
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    else:
        # the dispatching functions replace the interval-only ones of the same name
        from . import interval
        from .expr import functions

        if name in functions.__all__:
            value = getattr(functions, name)
        elif name in interval.__all__:
            value = getattr(interval, name)
        else:
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The public names: no helper, private table or command-line module (``__all__``, the
    builtin-shadowing functions, the layers and the dunders)."""
    dunders = [n for n in globals() if n.startswith("__") and n.endswith("__")]
    return sorted({*dunders, *_all(), *_NOT_STARRED, *_LAYERS})
