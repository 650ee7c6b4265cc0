"""Type stubs of the native module `platen._platen` (crates/platen-py). Use the `platen`
package: it checks Python values, converts arrays and re-raises `Failure` as its public
exceptions. Scenarios are passed as (path, JSON text, origin): one of the first two is None."""

from typing import List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class Failure(Exception):
    """args: (kind, message); kind is one of "input", "identification", "numerical",
    "output", "internal"; message is the CLI's."""

RunParts = Tuple[List[str], List[npt.NDArray[np.float64]], str]

def simulate(path: Optional[str], text: Optional[str], origin: str) -> RunParts: ...
def forward(
    text: str,
    origin: str,
    t_s: npt.NDArray[np.float64],
    force_n: npt.NDArray[np.float64],
) -> RunParts: ...
def inverse(
    text: str,
    origin: str,
    t_s: npt.NDArray[np.float64],
    u_m: npt.NDArray[np.float64],
    v_m_s: Optional[npt.NDArray[np.float64]],
    a_m_s2: Optional[npt.NDArray[np.float64]],
) -> RunParts: ...
def model(preset: str, pressure_mpa: Optional[float], full: bool) -> str: ...
def compare(
    path: Optional[str],
    text: Optional[str],
    origin: str,
    recorded: str,
    columns_path: Optional[str],
    columns_text: Optional[str],
    window: Optional[Tuple[float, float]],
    max_lag_s: float,
) -> str: ...
def identify(
    files: Sequence[str],
    pressures_mpa: Sequence[Optional[float]],
    columns_path: Optional[str],
    columns_text: Optional[str],
    viscous_exponent: Optional[float],
    low_velocity_term: bool,
    manifest: Optional[str] = None,
) -> str: ...
def sweep(
    path: Optional[str],
    text: Optional[str],
    origin: str,
    scales: Sequence[float],
    pressures_mpa: Sequence[float],
    sets: Sequence[Tuple[str, Sequence[float]]],
) -> Tuple[str, str]: ...
def schema() -> str: ...
