"""The data of an AUV mine survey (Jaulin, Bertholom, Dabe 2007, the Redermor AUV): sensor boxes
of every sample, GPS and surface boxes at both ends, side-scan detections of unknown mines.

Frames: world North-East-Down ``p = (north, east, depth)`` in metres; body x forward, y
starboard, z down; attitude roll ``phi``, pitch ``theta``, heading ``psi`` (unwrapped), body to
world ``R = R_psi R_theta R_phi``. Kinematics with the attitude and the body velocity held over
each sample (zero-order hold, exact for the data): ``p[k+1] = p[k] + dt R[k] v[k]``.

The files (embedded: ``auv_sensors.csv.gz``, ``auv_gps.csv``, ``auv_detections.csv``,
``auv_setup.json``) are read with the validation of every loader (one error naming the file,
the line and the value); decimal bounds are enclosed one ulp outward.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..interval import Interval
from ._data import (
    DataError,
    check_index,
    check_sorted,
    embedded,
    outward,
    read_csv,
    read_text,
    sample_index,
)

__all__ = ["AuvData", "load_auv"]

#: The sensor columns: time, then a ``_lo``/``_hi`` pair per quantity.
SENSORS = ("phi", "theta", "psi", "vx", "vy", "vz", "a", "depth")
_SENSOR_COLUMNS = {"t": "finite", **{f"{q}_{s}": s for q in SENSORS for s in ("lo", "hi")}}
_GPS_COLUMNS = {"t": "finite", **{f"{q}_{s}": s for q in ("north", "east", "depth")
                                  for s in ("lo", "hi")}}
_DETECTION_COLUMNS = {"t": "finite", "mine_id": "finite", "r_lo": "lo", "r_hi": "hi"}


@dataclass(repr=False)
class AuvData:
    """Everything the estimator knows about one survey.

    Attributes
    ----------
    t0, dt : float
        The sample grid ``t_k = t0 + k dt``, ``k = 0 .. n - 1``.
    attitude : Interval, shape (n, 3)
        Boxes of ``(phi, theta, psi)`` held over ``[t_k, t_{k+1})``.
    velocity : Interval, shape (n, 3)
        Boxes of the body velocity over the ground ``(vx, vy, vz)``, held likewise.
    altitude : Interval, shape (n,)
        Altitude above the seabed at sample ``k``.
    depth : Interval, shape (n,)
        Depth ``p_z`` of the vehicle at sample ``k`` (pressure sensor).
    fix_k : ndarray of int, shape (f,)
        Samples of the GPS fixes (the first and the last sample).
    fix : Interval, shape (f, 3)
        The position box at each fix (north, east from GPS; depth from the surface condition).
    det_k, det_mine : ndarray of int, shape (m,)
        Sample and mine of each side-scan detection.
    det_range : Interval, shape (m,)
        Slant range of each detection.
    n_mines : int
        Number of mines (ids ``0 .. n_mines - 1``).
    seabed_tol : float
        ``m_z - p_z - a`` lies in ``[-seabed_tol, seabed_tol]`` at a detection.
    source : str
        Where the data came from.
    """

    t0: float
    dt: float
    attitude: Interval
    velocity: Interval
    altitude: Interval
    depth: Interval
    fix_k: NDArray[np.intp]
    fix: Interval
    det_k: NDArray[np.intp]
    det_mine: NDArray[np.intp]
    det_range: Interval
    n_mines: int
    seabed_tol: float = 0.5
    source: str = "<memory>"

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.attitude.shape[0])

    @property
    def t(self) -> NDArray[np.float64]:
        """Sample times ``t0 + k dt`` (rounded to nearest; only for display and plots)."""
        return self.t0 + self.dt * np.arange(self.n)

    def __repr__(self) -> str:
        return (f"AuvData(samples={self.n}, dt={self.dt}, fixes={self.fix_k.size}, "
                f"detections={self.det_k.size}, mines={self.n_mines}, source={self.source!r})")


def _pairs(table, names: tuple[str, ...]) -> Interval:
    lo = np.stack([table[f"{q}_lo"] for q in names], axis=-1)
    hi = np.stack([table[f"{q}_hi"] for q in names], axis=-1)
    return outward(lo, hi)


def load_auv(folder: str | Path | None = None) -> AuvData:
    """Read a survey (default: the embedded one).

    ``folder`` holds ``auv_setup.json`` and the files it names (``sensor_file``, ``gps_file``,
    ``detection_file``; a sensor file may be gzip-compressed, ``.csv.gz``). Sample times must
    run ``t0, t0 + dt, ...`` in order; GPS and detection times must be sample times.
    """
    base = embedded("") if folder is None else Path(folder)
    setup_path = base / "auv_setup.json"
    try:
        setup = json.loads(read_text(setup_path))
    except json.JSONDecodeError as exc:
        raise DataError(f"{setup_path}:{exc.lineno}: not JSON: {exc.msg}") from None
    need = ("t0", "dt", "n_samples", "sensor_file", "gps_file", "detection_file", "n_mines")
    missing = [key for key in need if key not in setup]
    if missing:
        raise DataError(f"{setup_path}: missing key(s) {', '.join(missing)}")
    t0, dt, n = float(setup["t0"]), float(setup["dt"]), int(setup["n_samples"])
    if not (np.isfinite(t0) and np.isfinite(dt) and dt > 0 and n >= 2):
        raise DataError(f"{setup_path}: need finite t0, dt > 0 and n_samples >= 2, got "
                        f"t0 = {t0!r}, dt = {dt!r}, n_samples = {n!r}")
    sensor_file = base / setup["sensor_file"]
    if folder is None or (not sensor_file.exists()
                          and sensor_file.with_suffix(".csv.gz").exists()):
        sensor_file = sensor_file.with_suffix(".csv.gz")
    sensors = read_csv(sensor_file, _SENSOR_COLUMNS)
    check_sorted(sensors, "t", strict=True)
    if len(sensors) != n:
        raise sensors.error(len(sensors) - 1, f"{len(sensors)} samples, but {setup_path.name} "
                                              f"says n_samples = {n}")
    k = sample_index(sensors, t0, dt, n)
    sensors.columns["k"] = k.astype(np.float64)
    check_index(sensors, "k", 0)

    gps = read_csv(base / setup["gps_file"], _GPS_COLUMNS)
    check_sorted(gps, "t", strict=True)
    fix_k = sample_index(gps, t0, dt, n)

    det = read_csv(base / setup["detection_file"], _DETECTION_COLUMNS)
    check_sorted(det, "t", strict=False)
    det_k = sample_index(det, t0, dt, n)
    n_mines = int(setup["n_mines"])
    mine = det["mine_id"]
    bad = np.flatnonzero((mine != np.rint(mine)) | (mine < 0) | (mine >= n_mines))
    if bad.size:
        raise det.error(int(bad[0]), f"mine_id = {float(mine[bad[0]])!r} is not one of "
                                     f"0..{n_mines - 1}")
    return AuvData(
        t0=t0, dt=dt,
        attitude=_pairs(sensors, ("phi", "theta", "psi")),
        velocity=_pairs(sensors, ("vx", "vy", "vz")),
        altitude=_pairs(sensors, ("a",)).reshape(n),
        depth=_pairs(sensors, ("depth",)).reshape(n),
        fix_k=fix_k, fix=_pairs(gps, ("north", "east", "depth")),
        det_k=det_k, det_mine=mine.astype(np.intp),
        det_range=_pairs(det, ("r",)).reshape(det_k.size),
        n_mines=n_mines, seabed_tol=float(setup.get("seabed_tolerance_m", 0.5)),
        source=str(base if folder is not None else "embedded"))
