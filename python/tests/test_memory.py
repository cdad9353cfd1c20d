"""No call leaks: the resident set after many calls of simulate, diagnose,
from_str and the error path stays where the first calls left it.

CI runs a short version; the figure of the documentation (10 000 calls of
each) comes from running this file as a script:

    python python/tests/test_memory.py 10000
"""

from __future__ import annotations

import gc
import sys
import time

import numpy as np

import reldesign
import reldesign.synthetic
from conftest import EXAMPLE

try:
    import psutil

    def rss_mb() -> float:
        return psutil.Process().memory_info().rss / 2**20

except ImportError:  # pragma: no cover
    import resource

    def rss_mb() -> float:  # the peak, in KiB on Linux
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def growth(call, n: int, warmup: int = 50) -> tuple:
    """RSS growth [MB] over ``n`` calls after ``warmup`` calls, and the seconds per call."""
    for _ in range(warmup):
        call()
    gc.collect()
    before = rss_mb()
    start = time.perf_counter()
    for _ in range(n):
        call()
    seconds = (time.perf_counter() - start) / n
    gc.collect()
    return rss_mb() - before, seconds


def calls():
    valve = reldesign.Actuator.from_toml(str(EXAMPLE))
    text = EXAMPLE.read_text()
    t, v = reldesign.pulses([(24.0, 1e-3, 4e-3)], 6e-3, 20e-6)
    record = reldesign.synthetic.make_record(valve, samples=300, seed=3)
    bad = text.replace("turns = 1200", "turns = -3")

    def error():
        try:
            reldesign.Actuator.from_str(bad, "bad.toml")
        except reldesign.DescriptionError:
            pass

    return {
        "simulate (301 samples)": lambda: reldesign.simulate(valve, t, v),
        "Actuator.from_str": lambda: reldesign.Actuator.from_str(text, "valve.toml"),
        "DescriptionError": error,
        "diagnose (300 samples, resistance-drift)": lambda: reldesign.diagnose(
            valve, record, causes=["resistance-drift"]
        ).to_dict(),
    }


def test_no_leak():
    for name, call in calls().items():
        n = 100 if name.startswith("diagnose") else 1000
        grown, _ = growth(call, n)
        # allocator noise is a few MB; a leak of 1 kB per call would show 1 MB per 1000 calls
        assert grown < 8.0, f"{name}: RSS grew {grown:.1f} MB over {n} calls"


if __name__ == "__main__":
    import reldesign.synthetic  # noqa: F401

    n = int(sys.argv[1]) if len(sys.argv) > 1 else 10_000
    print(f"RSS at start {rss_mb():.1f} MB; {n} calls each after 50 warm-up calls")
    for name, call in calls().items():
        grown, seconds = growth(call, n)
        print(f"{name:<42} RSS {grown:+7.2f} MB over {n} calls ({1e3 * seconds:.2f} ms per call)")
