"""Fixtures of the Python package's tests: the repository, the command
line's binary (to compare answers with), small generated records."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "semera-valve.toml"
#: The causes the tests try (every cause takes longer; the answers are the CLI's either way).
QUICK_CAUSES = ["eddy-currents", "saturation", "resistance-drift"]


def reldesign_binary() -> Path:
    """`RELDESIGN_BIN`, else the release (or debug) build under CARGO_TARGET_DIR or target/."""
    if os.environ.get("RELDESIGN_BIN"):
        return Path(os.environ["RELDESIGN_BIN"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for profile in ("release", "debug"):
        candidate = target / profile / "reldesign"
        if candidate.exists():
            return candidate
    found = shutil.which("reldesign")
    if found:
        return Path(found)
    pytest.skip("no reldesign binary: build it (cargo build --release -p reldesign) or set RELDESIGN_BIN")


@pytest.fixture(scope="session")
def cli() -> Path:
    return reldesign_binary()


def run_cli(binary: Path, *args: object) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(binary), *map(str, args)], capture_output=True, text=True, cwd=ROOT
    )


@pytest.fixture(scope="session")
def records(tmp_path_factory) -> Path:
    """Four small records of the SEMERA valve (2 000 samples each; eddy
    currents hidden in two) and a broken one."""
    from reldesign.synthetic import make_records

    directory = tmp_path_factory.mktemp("records")
    make_records(EXAMPLE, directory, 4, samples=2000, hidden={"eddy": 1500.0})
    lines = (directory / "unit-000.csv").read_text().splitlines()
    lines[4] = "x," + lines[4].split(",", 1)[1]
    (directory / "unit-broken.csv").write_text("\n".join(lines) + "\n")
    (directory / "notes.txt").write_text("not a record")
    return directory


def read_record(path) -> "pandas.DataFrame":
    """A CSV record read with correctly rounded floats (pandas 3's default;
    before it, `float_precision="round_trip"`), so a DataFrame holds the bits
    the Rust reader gets."""
    import pandas

    if int(pandas.__version__.split(".")[0]) >= 3:
        return pandas.read_csv(path)
    return pandas.read_csv(path, float_precision="round_trip")
