"""Type hints of the extension module ``reldesign._reldesign`` (PyO3)."""

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class DescriptionError(ValueError):
    """A description that does not parse or validate; ``str(e)`` is the
    command line's message (file:line:column, the key, a caret)."""

    file: str
    line: int
    column: int
    key: str
    reason: str

class RecordError(ValueError):
    """A measured record that cannot be read as ``measured-data.md`` asks."""

class ReldesignError(RuntimeError):
    """A simulation, diagnosis or design that failed."""

class Actuator:
    """A validated actuator description (``valve.toml``); pickled as its text."""

    @staticmethod
    def from_toml(path: str) -> Actuator: ...
    @staticmethod
    def from_str(text: str, file_name: str = "<string>") -> Actuator: ...
    @property
    def name(self) -> str: ...
    @property
    def file_name(self) -> str: ...
    @property
    def text(self) -> str: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def drive(self) -> str: ...

class Diagnosis:
    """One record's diagnosis (``reldesign diagnose``)."""

    @property
    def causes(self) -> List[str]: ...
    @property
    def gain(self) -> float: ...
    @property
    def parameters(self) -> Dict[str, Dict[str, Optional[float]]]: ...
    @property
    def extended(self) -> str: ...
    @property
    def file(self) -> str: ...
    @property
    def json(self) -> str: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def report(self) -> str: ...

class Design:
    """A description's design (``reldesign build``)."""

    @property
    def report_json(self) -> str: ...
    def report(self) -> Dict[str, Any]: ...
    def report_text(self) -> str: ...
    def emit(self) -> str: ...

_Columns = Sequence[Tuple[str, npt.NDArray[np.float64]]]

def simulate(
    actuator: Actuator,
    t: npt.NDArray[np.float64],
    u: npt.NDArray[np.float64],
    rtol: float = 1e-9,
) -> Dict[str, np.ndarray]: ...
def diagnose(
    actuator: Actuator,
    path: Optional[str] = None,
    columns: Optional[_Columns] = None,
    name: str = "record.csv",
    out_dir: Optional[str] = None,
    holdout: float = 0.25,
    causes: Optional[List[str]] = None,
    write: bool = False,
) -> Diagnosis: ...
def fit(
    actuator: Actuator,
    params: Sequence[Tuple[str, Optional[Tuple[float, float]]]],
    path: Optional[str] = None,
    columns: Optional[_Columns] = None,
    name: str = "record.csv",
    starts: int = 1,
    max_iterations: int = 50,
    use_flux: bool = True,
    seed: int = 1,
) -> Dict[str, Any]: ...
def design(actuator: Actuator) -> Design: ...
def closed_loop(
    actuator: Actuator,
    plant: Optional[Actuator] = None,
    sample_period: Optional[float] = None,
    duration: Optional[float] = None,
    seed: int = 0,
    noise: Optional[Tuple[float, float]] = None,
    initial_field: float = 0.0,
) -> Tuple[Dict[str, np.ndarray], List[Dict[str, Any]]]: ...
def sweep(
    actuator: Actuator,
    sample_periods: Optional[List[float]] = None,
    plant: Optional[Actuator] = None,
) -> Tuple[List[Dict[str, Any]], List[Dict[str, Any]]]: ...
