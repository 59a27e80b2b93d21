"""A 2-D map of obstacles (segments and circles) and the first-hit distance along a ray.

The map of Jaulin's robust set-membership observer (pool robot): vertical walls seen from above
as segments ``a -> b`` and vertical pillars as circles ``(centre, radius)``. A sonar at
``(x, y)`` pointing along ``beta`` (counter-clockwise from +x) measures the distance ``s > 0``
along the ray ``(x, y) + s (cos beta, sin beta)`` to the first obstacle it meets:

- segment ``a -> b``, with ``e = b - a``, ``w = a - (x, y)``,
  ``den = cos(beta) e_y - sin(beta) e_x``: ``s = (w_x e_y - w_y e_x) / den`` and
  ``tau = (w_x sin(beta) - w_y cos(beta)) / den``; a hit when ``s > 0`` and ``0 <= tau <= 1``;
- circle of centre ``c`` and radius ``rho``, with ``w = (x, y) - c``,
  ``b = cos(beta) w_x + sin(beta) w_y``, ``q = |w|^2 - rho^2``: ``s = -b - sqrt(b^2 - q)``, a hit
  when ``b^2 >= q`` and ``s > 0`` (the near side, seen from outside the disc).

:meth:`ObstacleMap.distance` evaluates these formulas in float64 (a point function, not an
enclosure); :class:`boundest.ctc.CtcRayCast` is the rigorous contractor of the same constraint.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._textfile import read_text

__all__ = ["ObstacleMap"]


class ObstacleMap:
    """Segments and circles in the plane.

    Parameters
    ----------
    segments : array_like, shape (n, 2, 2)
        Segment ``i`` runs from ``segments[i, 0]`` to ``segments[i, 1]`` (each ``(x, y)``); its
        two ends differ.
    circles : sequence of ((cx, cy), radius)
        Centres and radii (``radius > 0``).
    segment_ids, circle_ids : sequence of str, optional
        Names of the obstacles (default ``segment0``..., ``circle0``...).

    Examples
    --------
    >>> m = ObstacleMap([[(0, 0), (0, 10)]], [((5, 0), 1.0)])
    >>> m.distance(3.0, 0.0, [0.0, np.pi, np.pi / 2])
    array([ 1.,  3., inf])
    """

    def __init__(self, segments: ArrayLike = (), circles: Sequence[Any] = (),
                 segment_ids: Sequence[str] | None = None,
                 circle_ids: Sequence[str] | None = None) -> None:
        seg = np.array(segments, dtype=np.float64)
        if seg.size == 0:
            seg = np.zeros((0, 2, 2))
        if seg.ndim != 3 or seg.shape[1:] != (2, 2):
            raise ValueError(f"segments must have shape (n, 2, 2), got {seg.shape}")
        if not np.isfinite(seg).all():
            i = int(np.argwhere(~np.isfinite(seg))[0][0])
            raise ValueError(f"segment {i} has a non-finite end: {seg[i].tolist()}")
        flat = np.all(seg[:, 0] == seg[:, 1], axis=-1)
        if flat.any():
            i = int(np.argmax(flat))
            raise ValueError(f"segment {i} has equal ends {seg[i, 0].tolist()}")
        centers = np.zeros((len(circles), 2))
        radii = np.zeros(len(circles))
        for i, circle in enumerate(circles):
            try:
                (cx, cy), r = circle
                centers[i] = float(cx), float(cy)
                radii[i] = float(r)
            except (TypeError, ValueError):
                raise ValueError(f"circle {i} must be ((cx, cy), radius), got {circle!r}"
                                 ) from None
            if not (np.isfinite(centers[i]).all() and math.isfinite(radii[i]) and radii[i] > 0):
                raise ValueError(f"circle {i} needs a finite centre and a finite radius > 0, "
                                 f"got centre {centers[i].tolist()}, radius {radii[i]!r}")
        self.segments: NDArray[np.float64] = seg
        self.centers: NDArray[np.float64] = centers
        self.radii: NDArray[np.float64] = radii
        self.segment_ids = _ids(segment_ids, len(seg), "segment")
        self.circle_ids = _ids(circle_ids, len(radii), "circle")

    # -- construction ---------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "<map>") -> ObstacleMap:
        """Build from the ``pool_map.json`` layout.

        Parameters
        ----------
        data : mapping
            ``{"walls": [{"id": ..., "p1": [x, y], "p2": [x, y]}, ...],
            "cylinders": [{"id": ..., "center": [x, y], "radius": r}, ...]}``; both lists are
            optional (other keys are ignored) but the map needs one obstacle. ``id`` is
            optional.
        source : str
            Named in error messages (a file name).

        Raises
        ------
        ValueError
            One sentence naming ``source``, the key and the value at fault.
        """
        if not isinstance(data, Mapping):
            raise ValueError(f"{source}: a map must be a JSON object, got {type(data).__name__}")
        walls = _list(data, "walls", source)
        cylinders = _list(data, "cylinders", source)
        if not walls and not cylinders:
            raise ValueError(f"{source}: the map has no obstacle (no 'walls', no 'cylinders')")
        segs, seg_ids, circles, circ_ids = [], [], [], []
        for i, w in enumerate(walls):
            where = f"walls[{i}]"
            _need_object(w, where, source, ("p1", "p2"))
            p1 = _point(w["p1"], f"{where}.p1", source)
            p2 = _point(w["p2"], f"{where}.p2", source)
            if p1 == p2:
                raise ValueError(f"{source}: {where} has p1 == p2 = {list(p1)} (zero length)")
            segs.append((p1, p2))
            seg_ids.append(_id(w, where, source))
        for i, c in enumerate(cylinders):
            where = f"cylinders[{i}]"
            _need_object(c, where, source, ("center", "radius"))
            centre = _point(c["center"], f"{where}.center", source)
            r = c["radius"]
            if isinstance(r, bool) or not isinstance(r, int | float) or not (
                    math.isfinite(r) and r > 0):
                raise ValueError(f"{source}: {where}.radius must be a finite number > 0, "
                                 f"got {r!r}")
            circles.append((centre, float(r)))
            circ_ids.append(_id(c, where, source))
        return cls(segs, circles, seg_ids, circ_ids)

    @classmethod
    def from_json(cls, path: str | Path) -> ObstacleMap:
        """Read a map file in the ``pool_map.json`` layout (see :meth:`from_dict`)."""
        text = read_text(path)
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ValueError(f"{path}:{exc.lineno}: not JSON: {exc.msg}") from None
        return cls.from_dict(data, str(path))

    @classmethod
    def pool(cls) -> ObstacleMap:
        """The swimming pool of Jaulin's robust set-membership observer (pool robot): the
        rectangle ``[0, 20] x [0, 10]`` m (4 walls) and 2 pillars (the embedded
        ``pool_map.json``)."""
        return cls.from_json(Path(str(resources.files("boundest") / "data" / "pool_map.json")))

    # -- queries --------------------------------------------------------------------------
    @property
    def n_obstacles(self) -> int:
        return len(self.segments) + len(self.radii)

    def __repr__(self) -> str:
        return f"ObstacleMap({len(self.segments)} segments, {len(self.radii)} circles)"

    def distance(self, x: ArrayLike, y: ArrayLike, beta: ArrayLike) -> NDArray[np.float64]:
        """First-hit distance ``s > 0`` along the ray ``(x, y) + s (cos beta, sin beta)``.

        Parameters
        ----------
        x, y, beta : array_like
            Ray origins and directions (radians), broadcast together.

        Returns
        -------
        ndarray
            The smallest ``s`` over the obstacles hit (module docstring formulas, in float64:
            a close approximation, not an enclosure); ``inf`` where no obstacle is hit, NaN
            where an input is NaN.
        """
        x, y, beta = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64)
                                           for v in (x, y, beta)))
        c, s = np.cos(beta), np.sin(beta)
        best = np.full(x.shape, np.inf)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for (ax, ay), (bx, by) in self.segments:
                ex, ey = bx - ax, by - ay
                wx, wy = ax - x, ay - y
                den = c * ey - s * ex
                dist = (wx * ey - wy * ex) / den
                tau = (wx * s - wy * c) / den
                hit = (den != 0) & (dist > 0) & (tau >= 0) & (tau <= 1)
                best = np.where(hit & (dist < best), dist, best)
            for (cx, cy), r in zip(self.centers, self.radii, strict=True):
                wx, wy = x - cx, y - cy
                b = c * wx + s * wy
                q = wx * wx + wy * wy - r * r
                disc = b * b - q
                dist = -b - np.sqrt(disc)
                hit = (disc >= 0) & (dist > 0)
                best = np.where(hit & (dist < best), dist, best)
        return np.where(np.isnan(x) | np.isnan(y) | np.isnan(beta), np.nan, best)


def _ids(ids: Sequence[str] | None, n: int, kind: str) -> list[str]:
    if ids is None:
        return [f"{kind}{i}" for i in range(n)]
    ids = [str(i) for i in ids]
    if len(ids) != n:
        raise ValueError(f"{len(ids)} {kind} ids for {n} {kind}s")
    return ids


def _list(data: Mapping[str, Any], key: str, source: str) -> list[Any]:
    value = data.get(key, [])
    if not isinstance(value, list):
        raise ValueError(f"{source}: '{key}' must be a list, got {value!r}")
    return value


def _need_object(item: Any, where: str, source: str, keys: tuple[str, ...]) -> None:
    if not isinstance(item, Mapping):
        raise ValueError(f"{source}: {where} must be an object with keys "
                         f"{', '.join(keys)}, got {item!r}")
    missing = [k for k in keys if k not in item]
    if missing:
        raise ValueError(f"{source}: {where} lacks the key(s) {', '.join(missing)}")


def _point(value: Any, where: str, source: str) -> tuple[float, float]:
    ok = isinstance(value, list | tuple) and len(value) == 2 and all(
        isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
        for v in value)
    if not ok:
        raise ValueError(f"{source}: {where} must be two finite numbers [x, y], got {value!r}")
    return float(value[0]), float(value[1])


def _id(item: Mapping[str, Any], where: str, source: str) -> str:
    name = item.get("id", where)
    if not isinstance(name, str):
        raise ValueError(f"{source}: {where}.id must be a string, got {name!r}")
    return name
