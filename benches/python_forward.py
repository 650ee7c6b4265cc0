"""How much a Python call costs over the Rust integrator: platen.forward on the standard
workload of `platen bench` against the integration time `platen bench` reports for it.

The workload (platen::bench, src/bench.rs): a 100 kN, 0.5 Hz sine force sampled at
1024 Hz for 600 s (614 401 samples), the lhpost-2008 identified model at 13.8 MPa, RK4 at
1/1024 s from rest, every output sample kept in memory. `platen bench --json` times that
run in Rust (`rk4_ns_per_step`, median of its round-robin runs); this script times
`platen.forward(t_s, force_n)` on the same record from Python — the whole call: reading the
arrays, validating the record, the run, the summary and the eight NumPy columns — and
reports the ratio of the medians. The two are measured alternately in the same run, so a
slow phase of the machine touches both.

    python benches/python_forward.py [--cli target/release/platen] [--rounds 3] [--repeats 5]

It needs a release build of the `platen` binary (`cargo build --release`; PLATEN_CLI or
--cli names it) and the installed package (`pip install .`, also a release build).
Target: ratio <= 1.5.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import platen

ROOT = Path(__file__).resolve().parents[1]
RATE_HZ = 1024
SECONDS = 600
AMPLITUDE_N = 100e3
FREQUENCY_HZ = 0.5
TARGET_RATIO = 1.5


def record():
    j = np.arange(SECONDS * RATE_HZ + 1)
    # The same doubles as bench.rs: j / 1024 is exact, sin(w·j/1024) with w = 2π·0.5.
    w = 2.0 * np.pi * FREQUENCY_HZ
    return j / RATE_HZ, AMPLITUDE_N * np.sin(w * j / RATE_HZ)


def cli_bench_s(cli: Path, repeats: int) -> float:
    """The integration time of the whole record that `platen bench` reports, s."""
    out = subprocess.run(
        [str(cli), "bench", "--json", "--seconds", str(SECONDS), "--repeats", str(repeats)],
        capture_output=True, text=True, check=True,
    )
    report = json.loads(out.stdout)
    if report.get("force_amplitude_n", AMPLITUDE_N) != AMPLITUDE_N:
        sys.exit(f"{cli} benches a {report['force_amplitude_n']} N force, this script {AMPLITUDE_N} N")
    return report["rk4_ns_per_step"] * 1e-9 * SECONDS * RATE_HZ


def python_s(t, f, repeats: int) -> float:
    """Median wall time of platen.forward(t, f), s."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run = platen.forward(t, f)
        times.append(time.perf_counter() - start)
        assert len(run) == len(t)
    return statistics.median(times)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", type=Path, default=Path(os.environ.get("PLATEN_CLI", ROOT / "target/release/platen")))
    parser.add_argument("--rounds", type=int, default=3, help="alternations of the two measurements")
    parser.add_argument("--repeats", type=int, default=5, help="runs per measurement (median)")
    args = parser.parse_args()
    if not args.cli.is_file():
        print(f"no platen binary at {args.cli}: run `cargo build --release` or pass --cli", file=sys.stderr)
        return 2

    t, f = record()
    run = platen.forward(t, f)  # warm-up; and the workload's shape, checked
    s = run.summary
    assert s["samples"] == 614_401 and s["solver"]["steps"] >= 614_400, s["solver"]
    rust, python = [], []
    for _ in range(args.rounds):
        rust.append(cli_bench_s(args.cli, args.repeats))
        python.append(python_s(t, f, args.repeats))
    r, p = statistics.median(rust), statistics.median(python)
    ratio = p / r
    print(f"record: {len(t)} samples ({SECONDS} s at {RATE_HZ} Hz), {s['solver']['steps']} RK4 steps")
    print(f"platen bench (Rust, rk4_ns_per_step x steps): {1e3 * r:8.1f} ms   rounds: {', '.join(f'{1e3 * x:.1f}' for x in rust)}")
    print(f"platen.forward (Python, the whole call):      {1e3 * p:8.1f} ms   rounds: {', '.join(f'{1e3 * x:.1f}' for x in python)}")
    print(f"ratio {ratio:.3f} (target <= {TARGET_RATIO})")
    return 0 if ratio <= TARGET_RATIO else 1


if __name__ == "__main__":
    sys.exit(main())
