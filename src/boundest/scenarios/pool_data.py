"""The data of Jaulin's robust set-membership observer (pool robot): a small underwater robot in
a swimming pool, localised with a rotating sonar whose pings contain outliers.

State ``X = (x, y, theta, v)``: position [m], heading [rad, counter-clockwise from +x] and
forward speed [m/s]; inputs ``u = (u1, u2)``, the accelerations of the left and right
propellers [m/s^2]. The model is ``f(X, u) = (v cos theta, v sin theta, u2 - u1, u1 + u2 - v)``
and its explicit Euler discretisation ``X[k+1] = X[k] + dt f(X[k], u[k])`` is exact for the
data (:func:`euler_step`). The true input ``u[k]``, applied on ``[t_k, t_{k+1})``, lies in the
input box of row ``k``.

The sonar at the robot centre points along ``beta[k] = theta[k] + alpha[k]`` (``alpha`` relative
to the robot, exact as given) and measures the first-hit distance to the pool border
(:meth:`boundest.ctc.ObstacleMap.distance`). An inlier lies in ``[d_lo, d_hi]``; each ping is
independently an outlier with probability ``p_outlier``, whose box usually misses the truth.

The files (embedded: ``pool_setup.json``, ``pool_inputs.csv``, ``pool_sonar.csv``,
``pool_map.json``) are read with the validation of every loader (one error naming the file, the
line and the value); decimal bounds are enclosed one ulp outward.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..ctc.obstacles import ObstacleMap
from ..interval import Interval
from ._data import DataError, Table, check_index, outward, read_csv, read_text
from ._data import embedded as _embedded

__all__ = ["STATE", "PoolData", "binomial_bound", "euler_step", "load_pool"]

#: The state components, in order.
STATE = ("x", "y", "theta", "v")
_INPUT_COLUMNS = {"t": "finite", "u1_lo": "lo", "u1_hi": "hi", "u2_lo": "lo", "u2_hi": "hi"}
_SONAR_COLUMNS = {"t": "finite", "alpha": "finite", "d_lo": "lo", "d_hi": "hi"}


@dataclass(repr=False)
class PoolData:
    """Everything the observer knows about one mission (or a batch of simulated missions).

    Attributes
    ----------
    t0, dt : float
        The sample grid ``t_k = t0 + k dt``, ``k = 0 .. n - 1``.
    inputs : Interval, shape (n, 2) or (M, n, 2)
        Boxes of ``(u1, u2)`` applied on ``[t_k, t_{k+1})``.
    alpha : ndarray, shape (n,)
        Beam angle relative to the robot at sample ``k`` (exact as given).
    ranges : Interval, shape (n,) or (M, n)
        Sonar boxes ``[d_lo, d_hi]`` at sample ``k`` (outliers included, unmarked).
    x0 : Interval, shape (4,)
        Box of the initial state ``(x, y, theta, v)``.
    map : ObstacleMap
        The pool walls and pillars.
    p_outlier : float
        Probability that a ping is an outlier (independently of the others).
    max_range : float
        Largest range the sonar can measure [m].
    source : str
        Where the data came from.
    """

    t0: float
    dt: float
    inputs: Interval
    alpha: NDArray[np.float64]
    ranges: Interval
    x0: Interval
    map: ObstacleMap
    p_outlier: float = 0.05
    max_range: float = 30.0
    source: str = "<memory>"

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.alpha.shape[0])

    @property
    def n_missions(self) -> int | None:
        """Number of missions of a batch (leading axis of ``inputs``, ``ranges``), else None."""
        return int(self.ranges.shape[0]) if len(self.ranges.shape) == 2 else None

    @property
    def t(self) -> NDArray[np.float64]:
        """Sample times ``t0 + k dt`` (rounded to nearest; only for display and plots)."""
        return self.t0 + self.dt * np.arange(self.n)

    def mission(self, i: int) -> PoolData:
        """Mission ``i`` of a batch, as a single-mission :class:`PoolData`."""
        if self.n_missions is None:
            raise ValueError("not a batch: the data hold a single mission")
        return PoolData(self.t0, self.dt, self.inputs[i], self.alpha, self.ranges[i], self.x0,
                        self.map, self.p_outlier, self.max_range, f"{self.source}[{i}]")

    def __repr__(self) -> str:
        batch = "" if self.n_missions is None else f"missions={self.n_missions}, "
        return (f"PoolData({batch}samples={self.n}, dt={self.dt}, p_outlier={self.p_outlier}, "
                f"source={self.source!r})")


def euler_step(x: ArrayLike, u: ArrayLike, dt: float) -> NDArray[np.float64]:
    """One explicit Euler step ``X + dt f(X, u)`` of the pool robot, in float64.

    Parameters
    ----------
    x : array_like, shape (..., 4)
        States ``(x, y, theta, v)``.
    u : array_like, shape (..., 2)
        Inputs ``(u1, u2)``, broadcast with ``x`` over the leading axes.
    dt : float
        Sampling period.

    Returns
    -------
    ndarray, shape (..., 4)
        ``X + dt (v cos theta, v sin theta, u2 - u1, u1 + u2 - v)``.

    Examples
    --------
    >>> euler_step([0.0, 0.0, 0.0, 1.0], [0.5, 0.5], 0.1).tolist()
    [0.1, 0.0, 0.0, 1.0]
    """
    X = np.asarray(x, dtype=np.float64)
    U = np.asarray(u, dtype=np.float64)
    th, v, u1, u2 = X[..., 2], X[..., 3], U[..., 0], U[..., 1]
    f = np.stack(np.broadcast_arrays(v * np.cos(th), v * np.sin(th), u2 - u1, u1 + u2 - v),
                 axis=-1)
    return X + dt * f


def binomial_bound(m: int, q: int, p: float) -> float:
    """Probability that at most ``q`` of ``m`` independent pings are outliers.

    ``P = sum_{i=0..q} C(m, i) p^i (1 - p)^(m - i)``, summed exactly in rationals (``p`` is
    taken as the decimal it prints as) and rounded once to float.

    Parameters
    ----------
    m : int
        Window length (pings), ``m >= 0``.
    q : int
        Most outliers tolerated (the q-relaxed intersection); ``q >= m`` gives 1.
    p : float
        Outlier probability, in ``[0, 1]``.

    Returns
    -------
    float

    Examples
    --------
    >>> round(binomial_bound(80, 8, 0.05), 6)
    0.981597
    """
    if m < 0 or not 0.0 <= p <= 1.0:
        raise ValueError(f"need m >= 0 and 0 <= p <= 1, got m = {m!r}, p = {p!r}")
    if q < 0:
        return 0.0
    P = Fraction(repr(float(p)))
    total = sum((math.comb(m, i) * P**i * (1 - P) ** (m - i) for i in range(min(q, m) + 1)),
                Fraction(0))
    return float(total)


def _grid(table: Table, t0: float, dt: float, n: int, setup: Path) -> None:
    """Rows at ``t0, t0 + dt, ...`` in order (to 1e-6 dt), exactly ``n`` of them."""
    t = table["t"]
    kf = (t - t0) / dt
    k = np.rint(kf)
    off = np.flatnonzero(np.abs(kf - k) > 1e-6)
    if off.size:
        j = int(off[0])
        raise table.error(j, f"t = {float(t[j])!r} is not a sample time t0 + k dt "
                             f"(t0 = {t0!r}, dt = {dt!r})")
    table.columns["k"] = k
    check_index(table, "k", 0)
    if len(table) != n:
        j = n if len(table) > n else len(table) - 1  # the first extra row, or the last row
        raise table.error(j, f"{len(table)} rows, but {setup.name} says n_samples = {n}")


def _number(setup: dict[str, Any], key: str, path: Path) -> float:
    value: Any = setup
    for part in key.split("."):
        if not isinstance(value, dict) or part not in value:
            raise DataError(f"{path}: missing key {key}")
        value = value[part]
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise DataError(f"{path}: {key} must be a finite number, got {value!r}")
    return float(value)


def _initial_box(setup: dict[str, Any], path: Path) -> Interval:
    box = setup.get("initial_state_box")
    if not isinstance(box, dict):
        raise DataError(f"{path}: missing key initial_state_box (an object with keys "
                        f"{', '.join(STATE)})")
    lo, hi = np.empty(4), np.empty(4)
    for i, name in enumerate(STATE):
        b = box.get(name)
        ok = (isinstance(b, list) and len(b) == 2
              and all(isinstance(v, int | float) and not isinstance(v, bool)
                      and math.isfinite(v) for v in b) and b[0] <= b[1])
        if not ok:
            raise DataError(f"{path}: initial_state_box.{name} must be [lo, hi] with finite "
                            f"lo <= hi, got {b!r}")
        lo[i], hi[i] = b
    return outward(lo, hi)


def load_pool(folder: str | Path | None = None) -> PoolData:
    """Read a pool mission (default: the embedded one).

    Parameters
    ----------
    folder : str or Path, optional
        Holds ``pool_setup.json``, ``pool_map.json`` and the files the setup names
        (``input_file``, ``sonar_file``). Both files have ``n_samples`` rows at the sample
        times ``t0, t0 + dt, ...`` in order.

    Returns
    -------
    PoolData

    Raises
    ------
    DataError
        One line naming the file, the line and the value at fault.

    Examples
    --------
    >>> data = load_pool()
    >>> data
    PoolData(samples=406, dt=0.04, p_outlier=0.05, source='embedded')
    >>> data.inputs.shape, data.ranges.shape, data.x0.shape
    ((406, 2), (406,), (4,))
    """
    base = _embedded("") if folder is None else Path(folder)
    setup_path = base / "pool_setup.json"
    try:
        setup = json.loads(read_text(setup_path))
    except json.JSONDecodeError as exc:
        raise DataError(f"{setup_path}:{exc.lineno}: not JSON: {exc.msg}") from None
    if not isinstance(setup, dict):
        raise DataError(f"{setup_path}:1: the setup must be a JSON object")
    for key in ("input_file", "sonar_file"):
        if not isinstance(setup.get(key), str):
            raise DataError(f"{setup_path}: missing key {key} (a file name)")
    t0, dt = _number(setup, "t0", setup_path), _number(setup, "dt", setup_path)
    n_f = _number(setup, "n_samples", setup_path)
    p = _number(setup, "sonar.outlier_probability", setup_path)
    max_range = _number(setup, "sonar.max_range_m", setup_path)
    n = int(n_f)
    if not (dt > 0 and n == n_f and n >= 2 and 0 <= p < 1 and max_range > 0):
        raise DataError(f"{setup_path}: need dt > 0, an integer n_samples >= 2, "
                        f"0 <= outlier_probability < 1 and max_range_m > 0, got dt = {dt!r}, "
                        f"n_samples = {n_f!r}, outlier_probability = {p!r}, "
                        f"max_range_m = {max_range!r}")
    x0 = _initial_box(setup, setup_path)
    map_path = base / "pool_map.json"
    try:
        pool_map = ObstacleMap.from_json(map_path)
    except DataError:
        raise
    except ValueError as exc:
        raise DataError(str(exc)) from None

    inputs = read_csv(base / setup["input_file"], _INPUT_COLUMNS)
    _grid(inputs, t0, dt, n, setup_path)
    sonar = read_csv(base / setup["sonar_file"], _SONAR_COLUMNS)
    _grid(sonar, t0, dt, n, setup_path)
    # both files now hold the rows k = 0 .. n - 1 in order: the same times
    u = outward(np.stack([inputs["u1_lo"], inputs["u2_lo"]], axis=-1),
                 np.stack([inputs["u1_hi"], inputs["u2_hi"]], axis=-1))
    return PoolData(t0=t0, dt=dt, inputs=u, alpha=np.ascontiguousarray(sonar["alpha"]),
                    ranges=outward(sonar["d_lo"], sonar["d_hi"]), x0=x0, map=pool_map,
                    p_outlier=p, max_range=max_range,
                    source=str(base) if folder is not None else "embedded")
