"""Synthetic bench records for tests, benchmarks and the guide: a bundled
description replayed (``reldesign.simulate``, the command line's numbers)
under a pulse train, with a per-record coil resistance and Gaussian
measurement noise on the voltage and the current, written as the
measured-data CSV (``t,v,i``) a DAQ would give.
"""

from __future__ import annotations

import os
import re
from typing import List, Optional, Sequence, Union

import numpy as np
import pandas as pd

from . import Actuator, PathLike, _actuator, pulses, simulate

__all__ = ["make_record", "make_records", "with_values"]


def with_values(text: str, values: dict) -> str:
    """The description's text with ``key = value`` lines replaced (the first
    line of each key, e.g. ``{"resistance": 78.0, "eddy": 1500.0}``)."""
    for key, value in values.items():
        text, n = re.subn(
            rf"(?m)^(\s*{re.escape(key)}\s*=\s*)[-+0-9.eE]+", rf"\g<1>{value!r}", text, count=1
        )
        if n == 0:
            raise KeyError(f"no `{key} = …` line in the description")
    return text


def make_record(
    actuator: Union[Actuator, PathLike],
    *,
    samples: int = 3000,
    dt: float = 40e-6,
    amplitude: float = 24.0,
    period: float = 10e-3,
    width: float = 5e-3,
    start: float = 1e-3,
    noise: Sequence[float] = (15e-3, 1e-3),
    seed: int = 0,
    values: Optional[dict] = None,
) -> pd.DataFrame:
    """One record ``t, v, i``: pulses of ``amplitude`` volts, ``width`` long,
    every ``period`` from ``start``, replayed through the description (its
    ``values`` replaced first: the hidden truth), σ_v, σ_i = ``noise`` added."""
    actuator = _actuator(actuator)
    if values:
        actuator = Actuator.from_str(with_values(actuator.text, values), actuator.file_name)
    t_end = (samples - 1) * dt
    edges = [(amplitude, s, s + width) for s in np.arange(start, t_end, period)]
    t, v = pulses(edges, t_end, dt)
    run = simulate(actuator, t, v)
    rng = np.random.default_rng(seed)
    return pd.DataFrame(
        {
            "t": run["t"].to_numpy(),
            "v": run["v"].to_numpy() + noise[0] * rng.standard_normal(len(t)),
            "i": run["i"].to_numpy() + noise[1] * rng.standard_normal(len(t)),
        }
    )


def make_records(
    actuator: Union[Actuator, PathLike],
    out_dir: PathLike,
    n: int,
    *,
    seed: int = 1,
    samples: int = 3000,
    resistance: float = 75.0,
    spread: float = 0.04,
    hidden: Optional[dict] = None,
) -> List[str]:
    """``n`` records ``unit-000.csv``… in ``out_dir``: record k's coil
    resistance drawn within ±``spread`` of ``resistance``, its pulse width
    and amplitude varied, its noise seeded by ``seed + k``; ``hidden``
    values (e.g. ``{"eddy": 1500.0}``) on every other record. Returns the paths."""
    os.makedirs(out_dir, exist_ok=True)
    rng = np.random.default_rng(seed)
    paths = []
    for k in range(n):
        values = {"resistance": round(resistance * (1 + spread * rng.uniform(-1, 1)), 3)}
        if hidden and k % 2 == 1:
            values.update(hidden)
        record = make_record(
            actuator,
            samples=samples,
            amplitude=float(rng.choice([18.0, 24.0, 30.0])),
            width=float(rng.uniform(3e-3, 6e-3)),
            seed=seed + k,
            values=values,
        )
        path = os.path.join(os.fspath(out_dir), f"unit-{k:03d}.csv")
        record.to_csv(path, index=False, float_format="%.10g")
        paths.append(path)
    return paths
