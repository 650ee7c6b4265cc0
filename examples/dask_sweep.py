"""A platen sweep scaled out with dask.distributed: how to spread a large grid of cases over
the workers of a cluster without platen having a scheduler of its own.

platen.sweep already runs a grid in parallel on every core of one machine (and releases the
GIL while it does). To go beyond one machine, split the grid into chunks along one axis,
send each chunk to a dask worker as one platen.sweep call, and gather the rows: the rows
are the same, number for number, as those of one platen.sweep over the whole grid (this
script checks it). Here the cluster is a LocalCluster; point a dask Client at a real
scheduler (dask-jobqueue, dask-kubernetes, …) to use a cluster.

    pip install "dask[distributed]"
    python examples/dask_sweep.py [--workers 2] [--scenario scenarios/sr9-like-sine-force.json]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from dask.distributed import Client, LocalCluster

import platen

ROOT = Path(__file__).resolve().parents[1]


def run_chunk(scenario: str, scales, pressures_mpa, sets):
    """One dask task: a platen.sweep over part of the grid, on the worker's cores."""
    # One rayon thread per dask worker process (each worker is one task at a time), set
    # before platen's thread pool starts in this process: the workers share the machine.
    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    return platen.sweep(scenario, scale=scales, pressure_mpa=pressures_mpa, set=sets, as_frame=False)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2, help="dask worker processes")
    parser.add_argument("--scenario", type=Path, default=ROOT / "scenarios" / "sr9-like-sine-force.json")
    args = parser.parse_args()

    scenario = str(args.scenario)
    scales = [0.5, 0.75, 1.0, 1.25, 1.5, 1.75]  # chunked: one task per scale
    pressures_mpa = [6.9, 10.35, 13.8]
    sets = {"identified.coulomb_force_n": [20e3, 25e3, 30e3]}
    cases = len(scales) * len(pressures_mpa) * len(sets["identified.coulomb_force_n"])

    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True) as cluster, Client(cluster) as client:
        start = time.perf_counter()
        futures = [client.submit(run_chunk, scenario, [s], pressures_mpa, sets, pure=False) for s in scales]
        chunks = client.gather(futures)
        wall_s = time.perf_counter() - start

    # Scale varies slowest, so the chunks in order are the grid in case order.
    rows = [row for chunk in chunks for row in chunk]
    for case, row in enumerate(rows):
        row["case"] = case

    print(f"{cases} cases of `{args.scenario.name}` on {args.workers} dask workers in {wall_s:.2f} s")
    print(f"{'case':>4} {'scale':>6} {'MPa':>6} {'F_mu kN':>8} {'peak u m':>10} {'peak F kN':>10} {'stick s':>8}  limits")
    for r in rows:
        print(
            f"{r['case']:>4} {r['scale']:>6} {r['hold_down_pressure_mpa']:>6} "
            f"{r['identified.coulomb_force_n'] / 1e3:>8.1f} {r['peak_u_m']:>+10.4f} "
            f"{r['peak_force_n'] / 1e3:>+10.1f} {r['stick_time_s']:>8.3f}  {r['limits_exceeded']}"
        )

    # The same grid in one call on this machine: the same rows, bit for bit.
    whole = platen.sweep(scenario, scale=scales, pressure_mpa=pressures_mpa, set=sets, as_frame=False)
    if rows != whole:
        raise SystemExit("the dask rows differ from one platen.sweep over the whole grid")
    print(f"the {len(rows)} rows equal one platen.sweep over the whole grid")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
