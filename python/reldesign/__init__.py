"""reldesign for Python: actuator descriptions, hybrid simulation, fit,
diagnosis and controller design, with the command line's messages and numbers.

>>> import reldesign
>>> valve = reldesign.Actuator.from_toml("examples/perfect-tracking-valve.toml")
>>> run = reldesign.simulate(valve, t, v)          # a pandas DataFrame
>>> d = reldesign.diagnose(valve, "bench.csv")      # or a DataFrame with t, v, i[, z]
>>> d.causes, d.gain, d.parameters, d.to_dict()

Every long call releases the GIL; its own parallelism (rayon) stays inside
it. ``reldesign.batch.diagnose_many`` diagnoses many records, on the local
cores or on a Dask cluster.
"""

from __future__ import annotations

import os
from typing import Any, Dict, Iterable, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import pandas as pd

from ._reldesign import (
    Actuator,
    Design,
    DescriptionError,
    Diagnosis,
    RecordError,
    ReldesignError,
    __version__,
)
from . import _reldesign

__all__ = [
    "Actuator",
    "Design",
    "DescriptionError",
    "Diagnosis",
    "RecordError",
    "ReldesignError",
    "design",
    "diagnose",
    "fit",
    "loop",
    "pulses",
    "simulate",
    "sweep",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]
Record = Union[PathLike, pd.DataFrame, Mapping[str, Any]]

#: The measured-data columns a record may carry (``shared/spec/measured-data.md``).
RECORD_COLUMNS = ("t", "v", "i", "z", "phi", "lambda")


def _actuator_from_text(text: str, file_name: str) -> Actuator:
    """Rebuilds a pickled :class:`Actuator` from its text (``Actuator.__reduce__``)."""
    return Actuator.from_str(text, file_name)


def _actuator(actuator: Union[Actuator, PathLike]) -> Actuator:
    if isinstance(actuator, Actuator):
        return actuator
    return Actuator.from_toml(os.fspath(actuator))


def _column(values: Any) -> np.ndarray:
    # float64 and contiguous: the Rust side then reads the buffer in place
    return np.ascontiguousarray(np.asarray(values, dtype=np.float64))


def _record_args(record: Record, name: Optional[str]) -> Dict[str, Any]:
    """The keyword arguments naming a record for the extension module."""
    if isinstance(record, (str, os.PathLike)):
        return {"path": os.fspath(record)}
    if isinstance(record, (pd.DataFrame, Mapping)):
        columns = [(c, _column(record[c])) for c in RECORD_COLUMNS if c in record]
        return {"columns": columns, "name": name or "record.csv"}
    raise TypeError(
        f"a record is a CSV path, a DataFrame or a mapping of columns, not {type(record).__name__}"
    )


def simulate(
    actuator: Union[Actuator, PathLike],
    t: Any,
    v: Any = None,
    *,
    i: Any = None,
    rtol: float = 1e-9,
) -> pd.DataFrame:
    """Replays an input through the hybrid model from rest at z_max.

    ``t`` and ``v`` (or ``i`` for a current-driven description) are the
    input's samples, linear in between, as ``reldesign simulate --input``
    reads them. Returns a DataFrame with the columns ``t, v, i, z, vz, phi[,
    Hc], mode`` at the times ``t``: the command line's numbers.
    """
    actuator = _actuator(actuator)
    u = v if v is not None else i
    if u is None:
        raise TypeError("give the input: v=… (or i=… for a current-driven description)")
    columns = _reldesign.simulate(actuator, _column(t), _column(u), rtol)
    return pd.DataFrame(columns, copy=False)


def pulses(
    amplitudes: Sequence[Tuple[float, float, float]],
    t_end: float,
    dt: float = 1e-5,
) -> Tuple[np.ndarray, np.ndarray]:
    """A sampled input of rectangular pulses ``(amplitude, start, end)``, 0
    elsewhere, on a uniform grid of step ``dt`` up to ``t_end``: ``(t, v)``.
    Between samples the input is linear, so an edge takes one step ``dt``."""
    n = int(np.floor(t_end / dt * (1 + 1e-12)))
    t = np.minimum(np.arange(n + 1) * dt, t_end)
    v = np.zeros_like(t)
    for amplitude, start, end in amplitudes:
        v[(t >= start) & (t < end)] = amplitude
    return t, v


def diagnose(
    actuator: Union[Actuator, PathLike],
    record: Record,
    *,
    out_dir: Optional[PathLike] = None,
    holdout: float = 0.25,
    causes: Optional[Iterable[str]] = None,
    name: Optional[str] = None,
    write: Optional[bool] = None,
) -> Diagnosis:
    """Diagnoses a record against the description: ``reldesign diagnose``.

    ``record`` is a CSV path or a DataFrame (mapping) with columns ``t, v,
    i[, z, phi, lambda]``; ``name`` names a DataFrame in messages and in its
    files (default ``record.csv``). The result's ``to_dict()`` is the
    command line's ``--json`` object (its paths named as ``--out out_dir``
    names them), ``report()`` its text, ``extended`` the extended
    description. With ``out_dir`` (or ``write=True``) the extended model,
    the report and the JSON are written there (or next to the record).
    """
    actuator = _actuator(actuator)
    kwargs = _record_args(record, name)
    return _reldesign.diagnose(
        actuator,
        out_dir=None if out_dir is None else os.fspath(out_dir),
        holdout=holdout,
        causes=None if causes is None else list(causes),
        write=(out_dir is not None) if write is None else write,
        **kwargs,
    )


def fit(
    actuator: Union[Actuator, PathLike],
    record: Record,
    params: Union[Sequence[str], Mapping[str, Optional[Tuple[float, float]]]],
    *,
    starts: int = 1,
    max_iterations: int = 50,
    use_flux: bool = True,
    seed: int = 1,
    name: Optional[str] = None,
) -> Dict[str, Any]:
    """Fits description parameters to a record: ``reldesign fit --param``.

    ``params`` lists key paths (``"coil.resistance"``: a decade either side
    of its value) or maps them to bounds ``(lo, hi)``. Returns a dict with
    ``values``, ``initial``, ``relative_std_errors``, the current's wNRMSE
    before and after, ``status`` and ``description`` (the fitted TOML text).
    """
    actuator = _actuator(actuator)
    if isinstance(params, Mapping):
        pairs = [(p, None if b is None else (float(b[0]), float(b[1]))) for p, b in params.items()]
    else:
        pairs = [(p, None) for p in params]
    return _reldesign.fit(
        actuator,
        pairs,
        starts=starts,
        max_iterations=max_iterations,
        use_flux=use_flux,
        seed=seed,
        **_record_args(record, name),
    )


def design(actuator: Union[Actuator, PathLike]) -> Design:
    """Designs the controller and observers (``reldesign build``): the
    result's ``report()`` is ``--report-json``'s dict, ``emit()`` the Rust code."""
    return _reldesign.design(_actuator(actuator))


def loop(
    actuator: Union[Actuator, PathLike],
    *,
    plant: Union[Actuator, PathLike, None] = None,
    sample_period: Optional[float] = None,
    duration: Optional[float] = None,
    seed: int = 0,
    noise: Optional[Tuple[float, float]] = None,
    initial_field: float = 0.0,
) -> pd.DataFrame:
    """The designed controller in a sampled loop on the hybrid model of
    ``plant`` (default: the description): ``reldesign loop``.

    Returns the command line's columns ``t, u, i, z, vz, phi[, Hc], mode,
    z_ref[, z_hat, v_hat, phi_hat[, Hc_hat]]``; ``.attrs["outcomes"]`` holds
    per operation the first impact velocity, RMSE_z, bounces, the highest
    bounce, its arrival time, ``late`` (the runtime pushed it to its stop
    after t_f + the arrival margin) and ``flagged_late`` (the controller's
    own verdict), or the position hold's settling. With an estimator or
    another ``plant`` each operation's window leaves room for that push. The
    backstepping law's loop is the command line's only.
    """
    columns, outcomes = _reldesign.closed_loop(
        _actuator(actuator),
        plant=None if plant is None else _actuator(plant),
        sample_period=sample_period,
        duration=duration,
        seed=seed,
        noise=noise,
        initial_field=initial_field,
    )
    frame = pd.DataFrame(columns, copy=False)
    frame.attrs["outcomes"] = outcomes
    return frame


def sweep(
    actuator: Union[Actuator, PathLike],
    sample_periods: Optional[Sequence[float]] = None,
    *,
    plant: Union[Actuator, PathLike, None] = None,
) -> pd.DataFrame:
    """The design redone at each sample period and run in closed loop:
    ``reldesign sweep --json``'s rows (law, design, sample_period,
    operation, impact_velocity, rmse_z, bounces) as a DataFrame;
    ``.attrs["switching"]`` holds the uncontrolled switching's impact
    velocity per operation."""
    rows, switching = _reldesign.sweep(
        _actuator(actuator),
        None if sample_periods is None else [float(ts) for ts in sample_periods],
        None if plant is None else _actuator(plant),
    )
    frame = pd.DataFrame(rows)
    frame.attrs["switching"] = switching
    return frame
