"""platen: the mechanics of a large servo-hydraulic shake-table platen, from Python.

The NEES-UCSD LHPOST model of Ozcelik, Luco, Conte, Trombetti and Restrepo (2008): effective
mass with the nonlinear strut terms, hold-down-strut stiffness, Coulomb friction with exact
stick-slip, fractional-power viscous damping and the low-velocity friction term. The
computation is the Rust library's (the same code as the ``platen`` command-line tool), run
with the GIL released.

>>> import numpy as np, platen
>>> t_s = np.arange(0, 10 * 1024 + 1) / 1024                  # 10 s at 1024 Hz
>>> run = platen.forward(t_s, 100e3 * np.sin(np.pi * t_s))     # 100 kN at 0.5 Hz, from rest
>>> run["u_m"].dtype, run.columns[:3]
(dtype('float64'), ('t_s', 'u_m', 'v_m_s'))
>>> round(run.summary["peak_u_m"], 3)                          # doctest: +SKIP
0.346

Conventions
-----------
* SI units everywhere, the unit in every name: ``t_s`` (s), ``u_m`` (m), ``v_m_s`` (m/s),
  ``a_m_s2`` (m/s²), ``force_n`` (N); displacement, velocity and acceleration are positive
  along the actuator force.
* Every function mirrors a verb of the CLI and returns what its ``--json`` prints (the same
  keys, the same numbers to the last bit), or a :class:`Run` with the columns of
  ``platen simulate --out``.
* Scenarios are a path to a scenario JSON file or a dict in the same format (README,
  "Scenario format"); paths inside a dict are relative to the working directory.
* Bad input raises :class:`ScenarioError` (a ``ValueError``) carrying the CLI's message:
  the file and line, the JSON path or the array index, the value and what was expected.
"""

from __future__ import annotations

import csv
import io
import json
import math
import numbers
import os
from collections.abc import Mapping
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _platen

__version__: str = _platen.__version__

__all__ = [
    "Run",
    "simulate",
    "forward",
    "inverse",
    "model",
    "compare",
    "identify",
    "sweep",
    "plan",
    "schema",
    "PlatenError",
    "ScenarioError",
    "IdentificationError",
    "SimulationError",
    "OutputError",
    "InternalError",
]

PathLike = Union[str, "os.PathLike[str]"]
Scenario = Union[PathLike, Mapping]
ArrayLike = Any

#: The preset every model starts from unless told otherwise.
DEFAULT_PRESET = "lhpost-2008"

# ----------------------------------------------------------------------------------------
# Errors


class PlatenError(Exception):
    """Base class of platen's errors. ``exit_code`` is the code the ``platen`` command-line
    tool exits with for the same problem."""

    exit_code = 1


class ScenarioError(PlatenError, ValueError):
    """Bad input: a scenario (file or dict), a record, an array or a parameter that cannot be
    used. The message is the CLI's: the file and line (records), the JSON path (scenarios) or
    the array and index (arrays), the value and what was expected. Nothing ran."""

    exit_code = 3


class IdentificationError(PlatenError, ValueError):
    """The test records cannot be identified (for example a record that is not a periodic
    test); the message says why, as ``platen identify`` does."""

    exit_code = 3


class SimulationError(PlatenError, RuntimeError):
    """A run failed numerically (the state became non-finite, the stick-slip event loop
    stalled, or the adaptive integrator gave up); the message names the time."""

    exit_code = 4


class OutputError(PlatenError, OSError):
    """An output could not be written."""

    exit_code = 5


class InternalError(PlatenError, RuntimeError):
    """A bug in platen (a panic in the Rust library, caught at the boundary): please report
    it with the message."""

    exit_code = 70


_KINDS = {
    "input": ScenarioError,
    "identification": IdentificationError,
    "numerical": SimulationError,
    "output": OutputError,
    "internal": InternalError,
}


def _native(function, *args):
    """Calls the native module, re-raising its failures as platen's public exceptions."""
    try:
        return function(*args)
    except _platen.Failure as failure:
        kind, message = failure.args
        raise _KINDS.get(kind, PlatenError)(message) from None


# ----------------------------------------------------------------------------------------
# Python values to the scenario format

_DICT_ORIGIN = "scenario dict"


def _plain(value: Any, at: str, origin: str) -> Any:
    """``value`` as plain JSON data (dicts, lists, str, int, float, bool, None): NumPy scalars
    and arrays and ``os.PathLike`` are converted; a non-finite number or an object that JSON
    cannot hold is reported with its JSON path ``at``."""
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        x = float(value)
        if not math.isfinite(x):
            raise ScenarioError(f"`{origin}`: {at or '(top level)'} = {x}: expected a finite number")
        return x
    if isinstance(value, os.PathLike):
        return os.fsdecode(os.fspath(value))
    if isinstance(value, Mapping):
        out = {}
        for key, item in value.items():
            if not isinstance(key, str):
                raise ScenarioError(f"`{origin}`: {at or '(top level)'}: key {key!r}: expected a string")
            out[key] = _plain(item, f"{at}.{key}" if at else key, origin)
        return out
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [_plain(item, f"{at}[{i}]", origin) for i, item in enumerate(value)]
    raise ScenarioError(
        f"`{origin}`: {at or '(top level)'} = {type(value).__name__}: expected a number, a string, "
        "True/False, None, a list or a dict"
    )


def _json(value: Mapping, origin: str) -> str:
    return json.dumps(_plain(value, "", origin))


def _path(value: PathLike, what: str) -> str:
    if isinstance(value, (str, os.PathLike)):
        return os.fsdecode(os.fspath(value))
    raise ScenarioError(f"{what}: expected a path (str or os.PathLike), got {type(value).__name__}")


def _scenario(scenario: Scenario) -> Tuple[Optional[str], Optional[str], str]:
    """(path, JSON text, origin) of a scenario given as a path or a dict."""
    if isinstance(scenario, Mapping):
        return None, _json(scenario, _DICT_ORIGIN), _DICT_ORIGIN
    if isinstance(scenario, (str, os.PathLike)):
        return _path(scenario, "scenario"), None, ""
    raise ScenarioError(
        "scenario: expected a path to a scenario JSON file or a dict in the scenario format, "
        f"got {type(scenario).__name__}"
    )


def _columns(columns: Union[None, PathLike, Mapping]) -> Tuple[Optional[str], Optional[str]]:
    """(path, JSON text) of a column map given as a JSON file or a dict."""
    if columns is None:
        return None, None
    if isinstance(columns, Mapping):
        return None, _json(columns, "columns=")
    return _path(columns, "columns"), None


def _array(value: ArrayLike, name: str, origin: str) -> np.ndarray:
    """A 1-D C-contiguous float64 copy-free view of ``value`` where possible: float and
    integer arrays (any width, any strides, lists, pandas Series) are accepted; anything
    else is reported naming the argument."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError) as e:
        raise ScenarioError(f"`{origin}`: {name}: cannot be read as an array: {e}") from None
    if a.dtype.kind not in "fiu":
        raise ScenarioError(
            f"`{origin}`: {name}: expected real numbers (a float or integer array), got dtype {a.dtype}"
        )
    if a.ndim != 1:
        raise ScenarioError(f"`{origin}`: {name}: expected a 1-D array, got shape {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def _model_spec(model: Union[None, str, Mapping], origin: str) -> Dict[str, Any]:
    """The scenario format's ``model`` object: None is the preset, a string names a preset,
    a dict without ``preset`` gets the default one."""
    if model is None:
        return {"preset": DEFAULT_PRESET}
    if isinstance(model, str):
        return {"preset": model}
    if isinstance(model, Mapping):
        spec = dict(model)
        spec.setdefault("preset", DEFAULT_PRESET)
        return spec
    raise ScenarioError(
        f"`{origin}`: model = {type(model).__name__}: expected None, a preset name or a dict in "
        'the scenario format ({"preset": …, "identified": {…}} or {"full": {…}})'
    )


def _specimen_spec(specimen: Any, origin: str) -> Optional[Dict[str, Any]]:
    """The scenario format's ``specimen`` object from ``specimen=``: ``None``, the object
    itself (``{"storeys": [...]}``) or the list of storeys, bottom first."""
    if specimen is None:
        return None
    if isinstance(specimen, Mapping):
        return dict(specimen)
    if isinstance(specimen, (list, tuple)):
        return {"storeys": [dict(s) if isinstance(s, Mapping) else s for s in specimen]}
    raise ScenarioError(
        f"`{origin}`: specimen = {type(specimen).__name__}: expected None, "
        '{"storeys": [{"mass_kg": …, "stiffness_n_per_m": …, "damping_n_s_per_m": …}, …]} '
        "or the list of storeys, bottom first"
    )


def _settings(name: str, model: Any, origin: str, **rest: Any) -> str:
    """The scenario format without an excitation source, as JSON text."""
    settings: Dict[str, Any] = {"name": name, "model": _model_spec(model, origin)}
    excitation = {k: rest.pop(k) for k in ("lowpass_hz", "lowpass_filter") if rest.get(k) is not None}
    rest = {k: v for k, v in rest.items() if v is not None}
    settings.update(excitation=excitation, **rest)
    return _json(settings, origin)


# ----------------------------------------------------------------------------------------
# Results


class Run:
    """A finished run held in memory.

    ``run["u_m"]`` is one output column as a 1-D NumPy float64 array (SI units, one value
    per input sample); ``run.columns`` names them in CSV order (``t_s``, ``u_m``, ``v_m_s``,
    ``a_m_s2``, ``force_n``, ``inertial_force_n``, ``elastic_force_n``,
    ``dissipative_force_n``, then with a specimen ``base_shear_n``, ``storey{i}_u_m``,
    ``storey{i}_a_m_s2``, then for a closed loop (a scenario with a ``table_system``)
    ``command_u_m``, ``drive``, ``spool_opening``, ``delta_p_pa``, ``flow_m3_s``,
    ``supply_pressure_pa``, ``cap_pressure_pa``, ``rod_pressure_pa``); ``run.summary`` is the dict ``platen simulate --json`` prints
    (peaks and their times, stick-slip counts, solver statistics, energy balance, limits).
    ``len(run)`` is the number of samples; ``run.to_pandas()`` makes a DataFrame.
    """

    __slots__ = ("_data", "columns", "summary")

    def __init__(self, names: Sequence[str], arrays: Sequence[np.ndarray], summary_json: str):
        #: The output columns, in CSV order.
        self.columns: Tuple[str, ...] = tuple(names)
        self._data: Dict[str, np.ndarray] = dict(zip(self.columns, arrays))
        #: The summary, as ``platen simulate --json`` prints it.
        self.summary: Dict[str, Any] = json.loads(summary_json)

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self._data[name]
        except KeyError:
            raise KeyError(f"{name!r} is not a column of this run (columns: {', '.join(self.columns)})") from None

    def __contains__(self, name: object) -> bool:
        return name in self._data

    def __iter__(self) -> Iterator[str]:
        return iter(self.columns)

    def __len__(self) -> int:
        return len(self._data[self.columns[0]]) if self.columns else 0

    def keys(self) -> Tuple[str, ...]:
        """The column names (so that ``dict(run)`` holds every column)."""
        return self.columns

    def to_dict(self) -> Dict[str, np.ndarray]:
        """Every column by name."""
        return dict(self._data)

    def to_pandas(self):
        """The columns as a ``pandas.DataFrame`` (one row per sample). Needs pandas."""
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("Run.to_pandas() needs pandas: pip install pandas") from None
        return pd.DataFrame({c: self._data[c] for c in self.columns}, columns=list(self.columns))

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"<platen.Run {s.get('direction')} ({s.get('model_form')} model): {len(self)} samples "
            f"over {s.get('duration_s')} s; peak u {s.get('peak_u_m'):+.4g} m, "
            f"peak force {s.get('peak_force_n'):+.4g} N>"
        )


def _run(parts) -> Run:
    return Run(*parts)


# ----------------------------------------------------------------------------------------
# The verbs


def simulate(scenario: Scenario) -> Run:
    """Runs a scenario, as ``platen simulate SCENARIO --json --out OUT.csv`` does.

    ``scenario`` is a path to a scenario JSON file or a dict in the scenario format (the
    README's "Scenario format"; paths inside a dict are relative to the working directory).
    Returns a :class:`Run`: its columns hold the samples ``--out`` writes (the same numbers
    to the last bit) and its ``summary`` the object ``--json`` prints.

    Raises :class:`ScenarioError` for a scenario or record that cannot be used and
    :class:`SimulationError` for a run that fails numerically.
    """
    return _run(_native(_platen.simulate, *_scenario(scenario)))


def forward(
    t_s: ArrayLike,
    force_n: ArrayLike,
    model: Union[None, str, Mapping] = None,
    integrator: Optional[Mapping] = None,
    initial: Optional[Mapping] = None,
    specimen: Optional[Mapping] = None,
    *,
    duration_s: Optional[float] = None,
    lowpass_hz: Optional[float] = None,
    lowpass_filter: Optional[str] = None,
    name: str = "forward",
) -> Run:
    """The motion an actuator force produces: a forward run, with exact stick-slip.

    * ``t_s``: sample times, s, on a uniform grid (stamps may be rounded: within 10 % of the fitted interval), strictly increasing.
    * ``force_n``: actuator force at those times, N (linear between samples).
    * ``model``: ``None`` (the ``lhpost-2008`` preset's identified model, Eq. 22/23, at
      13.8 MPa), a preset name, or the scenario format's ``model`` object, e.g.
      ``{"identified": {"coulomb_force_n": 20e3}}`` or ``{"full": {},
      "hold_down_pressure_mpa": 6.9}`` (``preset`` defaults to ``lhpost-2008``).
    * ``integrator``: ``{"method": "rk4", "step_s": Δt/k}`` (default: RK4 at the sample
      interval) or ``{"method": "dopri5", "rtol": 1e-8, "atol": 1e-11}``.
    * ``initial``: ``{"u_m": …, "v_m_s": …}``, m and m/s (default: at rest at 0).
    * ``specimen``: a shear building on the platen, bottom storey first: the scenario
      format's ``{"storeys": [{"mass_kg", "stiffness_n_per_m", "damping_n_s_per_m"}, …]}``
      or just the list of storeys. Its base shear enters the platen's equation and the run
      gains the columns ``base_shear_n``, ``storey{i}_u_m``, ``storey{i}_a_m_s2``
      (``docs/specimen.md``). RK4 only.
    * ``duration_s`` (s, default the record's span), ``lowpass_hz`` (Hz) and
      ``lowpass_filter`` (``"brickwall"``, ``"fir"``, ``"butterworth"``): as in a scenario.

    Arrays may be float or integer, of any strides; they are read as float64. Returns a
    :class:`Run` with one sample per input sample.
    """
    origin = "platen.forward()"
    t = _array(t_s, "t_s", origin)
    f = _array(force_n, "force_n", origin)
    text = _settings(
        name,
        model,
        origin,
        integrator=integrator,
        initial=initial,
        specimen=_specimen_spec(specimen, origin),
        duration_s=duration_s,
        lowpass_hz=lowpass_hz,
        lowpass_filter=lowpass_filter,
    )
    return _run(_native(_platen.forward, text, origin, t, f))


def inverse(
    t_s: ArrayLike,
    u_m: ArrayLike,
    v_m_s: Optional[ArrayLike] = None,
    a_m_s2: Optional[ArrayLike] = None,
    model: Union[None, str, Mapping] = None,
    specimen: Optional[Mapping] = None,
    *,
    duration_s: Optional[float] = None,
    name: str = "inverse",
) -> Run:
    """The actuator force a prescribed motion needs, and its decomposition (Eq. 1/23).

    * ``t_s``: sample times, s, strictly increasing.
    * ``u_m``: displacement, m; ``v_m_s`` (m/s) and ``a_m_s2`` (m/s²) where known — a
      missing one is derived from the displacement by second-order finite differences.
    * ``model``: as for :func:`forward`.
    * ``specimen``: as for :func:`forward`; the prescribed motion drives it and the force
      adds its base shear.

    Returns a :class:`Run`: ``force_n`` = ``inertial_force_n`` + ``elastic_force_n`` +
    ``dissipative_force_n`` (+ ``base_shear_n`` with a specimen).
    """
    origin = "platen.inverse()"
    t = _array(t_s, "t_s", origin)
    u = _array(u_m, "u_m", origin)
    v = None if v_m_s is None else _array(v_m_s, "v_m_s", origin)
    a = None if a_m_s2 is None else _array(a_m_s2, "a_m_s2", origin)
    text = _settings(
        name, model, origin, specimen=_specimen_spec(specimen, origin), duration_s=duration_s
    )
    return _run(_native(_platen.inverse, text, origin, t, u, v, a))


def model(
    preset: str = DEFAULT_PRESET,
    pressure_mpa: Optional[float] = 13.8,
    form: str = "identified",
) -> Dict[str, Any]:
    """A preset's parameters, as ``platen model --json`` prints them.

    The seven identified keys of the selected ``form`` (``"identified"``: Eq. 22/23;
    ``"full"``: the full Lagrangian model's equivalent) — ``effective_mass_kg``,
    ``stiffness_n_per_m``, ``coulomb_force_n``, ``viscous_coefficient`` (N/(m/s)^α),
    ``viscous_exponent``, ``low_velocity_force_n``, ``low_velocity_decay_s_per_m`` — the
    derived quantities of Eq. 5–8, the table ``limits`` and the ``physical`` parameters, at
    the hold-down pressure ``pressure_mpa`` (MPa; ``None``: the preset's nominal one).
    """
    if form not in ("identified", "full"):
        raise ScenarioError(f"form = {form!r}: expected 'identified' or 'full'")
    if pressure_mpa is not None and not isinstance(pressure_mpa, numbers.Real):
        raise ScenarioError(f"pressure_mpa = {pressure_mpa!r}: expected a pressure in MPa")
    p = None if pressure_mpa is None else float(pressure_mpa)
    return json.loads(_native(_platen.model, str(preset), p, form == "full"))


def compare(
    scenario: Scenario,
    recorded: PathLike,
    columns: Union[None, PathLike, Mapping] = None,
    *,
    window: Optional[Tuple[float, float]] = None,
    max_lag_s: float = 0.25,
) -> Dict[str, Any]:
    """Runs a scenario and compares it with a recorded test, as ``platen compare --json``.

    A forward scenario's ``u_m`` and ``v_m_s`` are compared, an inverse one's ``force_n``,
    on the recorded time base. Per channel: ``rms_error``, ``nrmse`` (a fraction),
    the signed peaks and their times, ``peak_ratio``, ``correlation`` and ``lag_s``
    (positive: the simulation is late). ``recorded`` is a CSV file; ``columns`` maps its
    channel names and units to platen's (a JSON file or a dict: ``{"u_m": {"name": "Table
    disp", "unit": "mm"}, …}``); ``window=(t0_s, t1_s)`` restricts the metrics;
    ``max_lag_s`` bounds the lag search, s.
    """
    path, text, origin = _scenario(scenario)
    win = None
    if window is not None:
        try:
            t0, t1 = (float(x) for x in window)
        except (TypeError, ValueError):
            raise ScenarioError(f"window = {window!r}: expected two times in seconds, (t0_s, t1_s)") from None
        if not (math.isfinite(t0) and math.isfinite(t1) and t0 < t1):
            raise ScenarioError(f"window = {window!r}: expected finite times with t0_s < t1_s")
        win = (t0, t1)
    lag = float(max_lag_s)
    if not (math.isfinite(lag) and lag >= 0):
        raise ScenarioError(f"max_lag_s = {max_lag_s!r}: expected a duration in seconds, >= 0")
    cpath, ctext = _columns(columns)
    recorded_path = _path(recorded, "recorded")
    return json.loads(_native(_platen.compare, path, text, origin, recorded_path, cpath, ctext, win, lag))


def identify(
    files: Union[PathLike, Sequence[PathLike]] = (),
    columns: Union[None, PathLike, Mapping] = None,
    *,
    manifest: Optional[PathLike] = None,
    pressure_mpa: Union[None, float, Sequence[Optional[float]]] = None,
    viscous_exponent: Optional[float] = None,
    low_velocity_term: bool = True,
) -> Dict[str, Any]:
    """Identifies the platen's parameters from recorded tests, as ``platen identify FILE…
    [--manifest M] --json``: periodic tests by the paper's hysteresis-loop method (§3), any
    other record (earthquake, white noise) by the any-record method, each file by its data;
    ``records`` lists every file with the method that took it, whether it was used and why.

    ``files``: recorded CSVs with ``t_s``, ``u_m``, ``a_m_s2``, ``force_n`` and optionally
    ``v_m_s`` (``columns`` maps a lab's own names and units, as for :func:`compare`,
    including a channel's known ``delay_s``). ``manifest``: an identification manifest
    (``{"tests": [{"file": …, "kind": …, "pressure_mpa": …}], "columns": …, "floors": …}``,
    see docs/identification.md) whose entries are read after ``files``, as the CLI reads it:
    per-entry kinds, pressures and column maps, a specimen's ``floors`` (their base shear is
    taken off the force) and ``scenario`` entries (recorded-like data made in memory).
    ``pressure_mpa``: the hold-down pressure, MPa, for every file (and every manifest entry
    without one) or one per file. ``viscous_exponent`` holds α instead of fitting it;
    ``low_velocity_term=False`` drops a·e^(−b|v|). Returns the seven identified keys at the
    top level, with the per-test tables (or the any-record fits), standard errors, the
    records' accounts and warnings.
    """
    if isinstance(files, (str, os.PathLike)):
        files = [files]
    paths = [_path(f, "files") for f in files]
    if pressure_mpa is None:
        pressures: List[Optional[float]] = []
    elif isinstance(pressure_mpa, numbers.Real):
        pressures = [float(pressure_mpa)]
    else:
        pressures = [None if p is None else float(p) for p in pressure_mpa]
        if len(pressures) != len(paths):
            raise ScenarioError(
                f"pressure_mpa has {len(pressures)} values for {len(paths)} files: give one value "
                "for all files, or one per file in order"
            )
    exponent = None if viscous_exponent is None else float(viscous_exponent)
    cpath, ctext = _columns(columns)
    manifest_path = None if manifest is None else _path(manifest, "manifest")
    return json.loads(
        _native(
            _platen.identify,
            paths,
            pressures,
            cpath,
            ctext,
            exponent,
            bool(low_velocity_term),
            manifest_path,
        )
    )


def _sweep_rows(csv_text: str) -> Tuple[List[str], List[Dict[str, Any]]]:
    """The rows of the sweep CSV with typed cells (int case and events, float numbers,
    None for an empty cell)."""
    reader = csv.reader(io.StringIO(csv_text))
    header = next(reader)
    rows = []
    for fields in reader:
        row: Dict[str, Any] = {}
        for column, cell in zip(header, fields):
            if cell == "":
                row[column] = None
            elif column in ("limits_exceeded", "status"):
                row[column] = cell
            elif column in ("case", "events"):
                row[column] = int(cell)
            else:
                row[column] = float(cell)
        rows.append(row)
    return header, rows


def sweep(
    scenario: Scenario,
    scale: Optional[Sequence[float]] = None,
    pressure_mpa: Optional[Sequence[float]] = None,
    set: Optional[Mapping[str, Sequence[float]]] = None,  # noqa: A002 (the CLI's --set)
    *,
    as_frame: Optional[bool] = None,
):
    """Runs a grid of variants of a scenario in parallel on every core, as ``platen sweep``.

    The cases are the Cartesian product of ``scale`` (factors on the excitation),
    ``pressure_mpa`` (hold-down pressures, MPa) and each ``set`` axis
    (``{"identified.coulomb_force_n": [20e3, 25e3]}`` or ``{"full.platen_mass_kg": […]}``,
    the scenario's form), scale varying slowest; an axis not given holds the scenario's value.
    One row per case with the columns of ``platen sweep --out``: ``case``, ``scale``,
    ``hold_down_pressure_mpa``, one per ``set`` axis, ``peak_u_m``, ``peak_v_m_s``,
    ``peak_a_m_s2``, ``peak_force_n`` (signed peaks), ``stick_time_s``, ``events``,
    ``limits_exceeded``, ``status`` (``"ok"`` or ``"failed: …"``: a case that fails
    numerically does not stop the others).

    Returns a pandas DataFrame when pandas is installed (``as_frame=None``) or asked for
    (``True``), else a list of dicts (``False``, or no pandas).
    """
    path, text, origin = _scenario(scenario)

    def numbers_of(values, what) -> List[float]:
        if values is None:
            return []
        if isinstance(values, numbers.Real):
            values = [values]
        out = [float(v) for v in values]
        bad = [v for v in out if not math.isfinite(v)]
        if bad:
            raise ScenarioError(f"{what}: {bad[0]} is not a finite number")
        return out

    scales = numbers_of(scale, "scale")
    pressures = numbers_of(pressure_mpa, "pressure_mpa")
    if any(p < 0 for p in pressures):
        raise ScenarioError(f"pressure_mpa: {min(pressures)} MPa: expected a pressure >= 0")
    axes = [(str(k), numbers_of(v, f"set: `{k}`")) for k, v in (set or {}).items()]
    csv_text, _summary = _native(_platen.sweep, path, text, origin, scales, pressures, axes)
    header, rows = _sweep_rows(csv_text)
    if as_frame is False:
        return rows
    try:
        import pandas as pd
    except ImportError:
        if as_frame:
            raise ImportError("sweep(as_frame=True) needs pandas: pip install pandas") from None
        return rows
    return pd.DataFrame(rows, columns=header)


def plan(
    scenario: Scenario,
    target_t_s: ArrayLike,
    target_a_m_s2: Optional[ArrayLike] = None,
    target_u_m: Optional[ArrayLike] = None,
    iterations: int = 10,
    gain: Optional[float] = None,
    *,
    target_nrmse: float = 0.02,
    frf: str = "auto",
    band_hz: Optional[Tuple[float, float]] = None,
    max_scale: bool = True,
    per_axis_scale: bool = False,
    rrs: Optional[Union[str, "os.PathLike[str]"]] = None,
    rrs_damping: float = 0.05,
    iterate_at: Optional[float] = None,
) -> Dict[str, Any]:
    """Plans a test as ``platen plan`` does: can the scenario's table run the target, what
    limits it, the largest scale that fits, and the drive (displacement command) that makes
    the simulated table reproduce it. See docs/planning.md.

    ``scenario`` is a path or a dict in the scenario format with a ``table_system`` (its
    excitation, if any, is ignored: the target takes its place). The target is
    ``target_a_m_s2`` (an acceleration record, m/s²) or ``target_u_m`` (a displacement, m) at
    the uniformly spaced time stamps ``target_t_s`` (s); a target faster than the controller
    is put on its rate, anti-aliased, with a notice in the summary's ``warnings``.
    ``iterations`` is the most drive corrections (0: the target's own command only),
    ``gain`` the iteration's gain in (0, 2) (None: the CLI's default, 0.7), ``target_nrmse``
    the acceleration NRMSE (a fraction) that stops it, ``frf`` where the loop's response comes
    from (``"auto"``, ``"linearised"`` or ``"measured"``), ``band_hz`` the correction band
    ``(lo, hi)``, and ``max_scale=False`` skips the search of the largest scale that fits.
    ``rrs`` is a required response spectrum CSV (``period_s`` or ``frequency_hz``, and
    ``psa_m_s2`` or ``psa_g``; per axis ``x_psa_m_s2`` … on a multi-axis table) the drive's
    run is accepted against (band −10/+30 %, ``summary["drive"]["spectrum_acceptance"]``),
    of damping ratio ``rrs_damping``; None: the target's own spectrum. ``iterate_at`` (a
    fraction in (0, 1], say 0.25) iterates the drive at that level of the target, then scales
    it up and runs it once at full level: the drive returned is the scaled-up one, and
    ``summary["drive"]["achieved"]`` its full-level run (the predicted full-level error;
    ``summary["drive"]["at_iteration_level"]`` what it achieved at the level).

    Returns a dict: ``drive_t_s`` and ``drive_u_m`` (float64 arrays: the drive at the
    controller's rate, what ``--out`` writes; None when there is no drive, for a target whose
    command reaches the end of the actuators) and ``summary`` (the object of
    ``platen plan --json``: feasibility, margins, ``max_scale``, the iterations' errors, the
    drive's; the target's ``file`` is ``"target"`` and the drive's ``out`` is None).
    An infeasible target is an answer (``summary["feasible"]`` is False), not an error.

    **A multi-axis table** (a scenario with a ``table`` and its ``controller``): give the
    target per axis, ``target_a_m_s2={"x": ..., "y": ..., "z": ...}`` (any of them; absent
    axes are held at zero; ``target_u_m`` likewise for displacements, for axes without an
    acceleration). The plan is the three-component one (feasibility per axis and per
    actuator, the largest common scale, and with ``per_axis_scale=True`` each axis's, the
    drives iterated through the transfer matrix; ``frf`` must be ``"auto"`` or
    ``"linearised"``). Returns ``drive_t_s``, ``drive`` (a dict of float64 arrays ``x_m`` …
    ``yaw_rad``: the six-DOF ``motion_csv`` that ``--out`` writes) and ``summary``.

    Raises ScenarioError (a ValueError) for bad input, with the CLI's message;
    SimulationError if a closed-loop run fails.
    """
    path, text, origin = _scenario(scenario)
    if isinstance(target_a_m_s2, dict) or isinstance(target_u_m, dict):
        return _plan_table(
            path, text, origin, target_t_s, target_a_m_s2 or {}, target_u_m or {},
            iterations, gain, target_nrmse, frf, band_hz, max_scale, per_axis_scale,
            rrs, rrs_damping, iterate_at,
        )
    if (target_a_m_s2 is None) == (target_u_m is None):
        raise ScenarioError("target: give exactly one of target_a_m_s2 and target_u_m")
    t = _array(target_t_s, "target_t_s", "target")
    a = None if target_a_m_s2 is None else _array(target_a_m_s2, "target_a_m_s2", "target")
    u = None if target_u_m is None else _array(target_u_m, "target_u_m", "target")
    values = a if a is not None else u
    if len(values) != len(t):
        raise ScenarioError(
            f"`target`: target_t_s has {len(t)} samples, the target's values {len(values)}: "
            "expected the same number"
        )
    iterations, gain, target_nrmse, band = _plan_checks(iterations, gain, target_nrmse, band_hz)
    drive_t, drive_u, summary = _native(
        _platen.plan,
        path,
        text,
        origin,
        t,
        a,
        u,
        iterations,
        gain,
        target_nrmse,
        str(frf),
        band,
        bool(max_scale),
        *_rrs_args(rrs, rrs_damping),
        _level(iterate_at),
    )
    return {"drive_t_s": drive_t, "drive_u_m": drive_u, "summary": json.loads(summary)}


def _level(iterate_at):
    """``iterate_at`` checked as ``plan`` checks it: None or a fraction in (0, 1]."""
    if iterate_at is None:
        return None
    level = float(iterate_at)
    if not (0.0 < level <= 1.0):
        raise ScenarioError(
            f"iterate_at = {iterate_at!r}: expected a fraction of the target in (0, 1] "
            "(0.25 for 25 %)"
        )
    return level


def _rrs_args(rrs, rrs_damping):
    """``rrs`` as a path (or None) and its damping ratio, checked as ``plan`` checks them."""
    damping = float(rrs_damping)
    if not (0.0 <= damping < 1.0):
        raise ScenarioError(
            f"rrs_damping = {rrs_damping!r}: expected a damping ratio in [0, 1) (0.05 for 5 %)"
        )
    return (None if rrs is None else os.fspath(rrs)), damping


def _plan_checks(iterations, gain, target_nrmse, band_hz):
    """The iteration's settings, checked as ``plan`` checks them."""
    if isinstance(iterations, bool) or not isinstance(iterations, numbers.Integral) or not (
        0 <= int(iterations) <= 200
    ):
        raise ScenarioError(f"iterations = {iterations!r}: expected a whole number from 0 to 200")
    gain = 0.7 if gain is None else float(gain)
    if not (0.0 < gain < 2.0):
        raise ScenarioError(f"gain = {gain}: expected a gain in (0, 2)")
    target_nrmse = float(target_nrmse)
    if not (math.isfinite(target_nrmse) and target_nrmse >= 0.0):
        raise ScenarioError(f"target_nrmse = {target_nrmse}: expected an NRMSE >= 0 (a fraction)")
    band = None
    if band_hz is not None:
        lo, hi = (float(x) for x in band_hz)
        if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
            raise ScenarioError(f"band_hz = {band_hz!r}: expected (lo, hi) with 0 < lo < hi, Hz")
        band = (lo, hi)
    return int(iterations), gain, target_nrmse, band


def _plan_table(path, text, origin, target_t_s, accelerations, displacements, iterations,
                gain, target_nrmse, frf, band_hz, max_scale, per_axis_scale, rrs, rrs_damping,
                iterate_at):
    """``plan`` with per-axis targets: the three-component plan of a multi-axis table."""
    if str(frf) not in ("auto", "linearised"):
        raise ScenarioError(
            f"frf = {frf!r}: a multi-axis table's drives are iterated through its linearised "
            "transfer matrix: expected \"auto\" or \"linearised\""
        )
    t = _array(target_t_s, "target_t_s", "target")
    axes = []
    for kind, given, name in (("acceleration", accelerations, "target_a_m_s2"),
                              ("displacement", displacements, "target_u_m")):
        if not isinstance(given, dict):
            raise ScenarioError(f"{name}: per axis, a dict {{\"x\": ..., \"y\": ..., \"z\": ...}}")
        for axis, values in given.items():
            if axis not in ("x", "y", "z"):
                raise ScenarioError(f"{name}[{axis!r}]: expected an axis among x, y, z")
            if kind == "displacement" and axis in accelerations:
                raise ScenarioError(f"{name}[{axis!r}]: axis {axis} has an acceleration already")
            v = _array(values, f"{name}[{axis!r}]", "target")
            if len(v) != len(t):
                raise ScenarioError(
                    f"`target`: target_t_s has {len(t)} samples, {name}[{axis!r}] {len(v)}: "
                    "expected the same number"
                )
            axes.append((axis, kind, v))
    if not axes:
        raise ScenarioError("target: give at least one axis (x, y, z)")
    iterations, gain, target_nrmse, band = _plan_checks(iterations, gain, target_nrmse, band_hz)
    drive_t, columns, summary = _native(
        _platen.plan_table, path, text, origin, t, axes, iterations, gain, target_nrmse, band,
        bool(max_scale), bool(per_axis_scale), *_rrs_args(rrs, rrs_damping),
        _level(iterate_at),
    )
    names = ["x_m", "y_m", "z_m", "roll_rad", "pitch_rad", "yaw_rad"]
    return {
        "drive_t_s": drive_t,
        "drive": dict(zip(names, columns)),
        "summary": json.loads(summary),
    }


def schema() -> Dict[str, Any]:
    """The JSON Schema of the scenario format (``platen schema``)."""
    return json.loads(_platen.schema())


def __dir__() -> List[str]:
    """``dir(platen)``: the public API (``__all__``) and ``__version__``, not the modules and
    typing names this file imports for its own use (PEP 562)."""
    return sorted(__all__ + ["__version__"])
