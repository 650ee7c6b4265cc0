"""NumPy arrays in and out: dtypes, shapes, strides, ownership, pandas, and the GIL."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

import platen

RATE_HZ = 1024


def record(seconds=8.0):
    t = np.arange(0, int(seconds * RATE_HZ) + 1) / RATE_HZ
    return t, 90e3 * np.sin(2 * np.pi * 0.5 * t)


def test_outputs_are_owned_contiguous_float64_columns_of_the_input_length():
    t, f = record()
    run = platen.forward(t, f)
    assert len(run) == len(t)
    for name in run.columns:
        a = run[name]
        assert a.dtype == np.float64 and a.shape == t.shape and a.flags.c_contiguous
        assert a.flags.owndata or a.base is not None
        assert a.flags.writeable
    assert np.array_equal(run["t_s"], t)
    # Writing to one run's array changes neither the input nor another run.
    again = platen.forward(t, f)
    run["u_m"][:] = 0
    assert np.any(again["u_m"] != 0)
    assert np.array_equal(t, record()[0]) and np.array_equal(f, record()[1])


def test_float32_integer_big_endian_strided_lists_and_series_give_the_float64_result():
    t, f = record()
    expected = platen.forward(t, np.round(f))
    base = expected["u_m"]
    variants = {
        "int64": (t, np.round(f).astype(np.int64)),
        "int32": (t, np.round(f).astype(np.int32)),
        "big-endian": (t.astype(">f8"), np.round(f).astype(">f8")),
        "strided": (np.repeat(t, 2)[::2], np.repeat(np.round(f), 2)[::2]),
        "column of a 2-D array": (np.stack([t, np.round(f)], axis=1)[:, 0], np.stack([t, np.round(f)], axis=1)[:, 1]),
        "Fortran 2-D column": (np.asfortranarray(np.stack([t, np.round(f)]))[0], np.asfortranarray(np.stack([t, np.round(f)]))[1]),
        "lists": (t.tolist(), np.round(f).tolist()),
    }
    for name, (tt, ff) in variants.items():
        assert not (name == "strided" and ff.flags.c_contiguous)
        run = platen.forward(tt, ff)
        assert np.array_equal(run["u_m"], base), name
    # float32 is widened exactly; the result is that of the widened values.
    f32 = np.round(f).astype(np.float32)
    assert np.array_equal(platen.forward(t, f32)["u_m"], platen.forward(t, f32.astype(np.float64))["u_m"])
    # Integer times: 1 Hz samples.
    ti = np.arange(0, 60)
    fi = (60e3 * np.sin(2 * np.pi * 0.05 * ti)).astype(np.int64)
    assert np.array_equal(platen.forward(ti, fi)["u_m"], platen.forward(ti.astype(float), fi.astype(float))["u_m"])


def test_pandas_series_in_and_a_dataframe_out():
    pd = pytest.importorskip("pandas", reason="SKIPPED: pandas is not installed")
    t, f = record()
    frame = pd.DataFrame({"t_s": t, "force_n": f})
    run = platen.forward(frame["t_s"], frame["force_n"])
    out = run.to_pandas()
    assert list(out.columns) == list(run.columns)
    assert len(out) == len(t)
    assert np.array_equal(out["u_m"].to_numpy(), run["u_m"])


def test_run_behaves_like_a_table_of_columns():
    t, f = record(2)
    run = platen.forward(t, f)
    assert list(run) == list(run.columns) == list(dict(run))
    assert "u_m" in run and "x" not in run
    with pytest.raises(KeyError, match="'x' is not a column of this run"):
        run["x"]
    assert "forward" in repr(run) and str(len(t)) in repr(run)


def test_the_gil_is_released_during_a_run():
    """While a 600 s forward run (614 401 samples, tens of ms) executes in one thread, a
    Python thread keeps running: it could not if the run held the GIL."""
    t, f = record(600)
    ticks = []
    during = []

    def run():
        start = time.perf_counter()
        platen.forward(t, f)
        during.append((start, time.perf_counter()))

    worker = threading.Thread(target=run)
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    worker.join()
    (start, end) = during[0]
    inside = [x for x in ticks if start + 0.005 < x < end - 0.005]
    assert end - start > 0.02, "the run is long enough to tell"
    assert len(inside) >= 3, f"{len(inside)} ticks of the Python thread during a {end - start:.3f} s run"
