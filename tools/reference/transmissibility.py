#!/usr/bin/env python3
"""The roof's transmissibility of recorded table records, model-free (numpy only, no platen code).

Reads CSV records with the columns of `tests/data/real_table` (table, storey 1 and storey 2
accelerations in g), pools Welch cross-spectra over them and writes the peaks that
`platen identify --system` must report (issue 51):

    python3 tools/reference/transmissibility.py tests/data/real_table/r0[1-4]*.csv \
        > tests/data/real_table/transmissibility.json

Welch as `scipy.signal.csd(x, y, fs, nperseg=L)` with its defaults: periodic Hann window, 50 %
overlap, each segment's mean removed, one-sided density; every segment of every record
weighs alike. The segment L is the largest power of two no longer than two thirds of the
shortest record and than fs/0.0125 Hz. H1 = P_xy/P_xx from the table's acceleration x to the
roof's y; its local maxima between 0.5 Hz and min(40 Hz, 0.4 fs), the two tallest distinct
ones (a two-storey frame; a maximum is distinct from a taller one kept when |H| falls below
half the lower of the two somewhere between them), lowest first.
"""

import json
import sys

import numpy as np

TABLE = "Table acceleration (g)"
ROOF = "Storey 2 acceleration (g)"
TIME = "Time (s)"


def read(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    col = {name: data[:, i] for i, name in enumerate(header)}
    return col[TIME], col[TABLE] * 9.80665, col[ROOF] * 9.80665


def segments(x, length):
    step = length - length // 2
    count = (len(x) - length) // step + 1
    return [x[s * step : s * step + length] for s in range(count)]


def main(paths):
    records = [read(p) for p in paths]
    fs = 1.0 / (records[0][0][1] - records[0][0][0])
    shortest = min(len(r[0]) for r in records)
    cap = min(2 * shortest // 3, int(fs / 0.0125))
    length = 1 << (cap.bit_length() - 1)
    window = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(length) / length)
    sxx = np.zeros(length // 2 + 1)
    sxy = np.zeros(length // 2 + 1, dtype=complex)
    count = 0
    for _, x, y in records:
        for sx, sy in zip(segments(x, length), segments(y, length)):
            fx = np.fft.rfft((sx - sx.mean()) * window)
            fy = np.fft.rfft((sy - sy.mean()) * window)
            sxx += np.abs(fx) ** 2
            sxy += np.conj(fx) * fy
            count += 1
    gain = np.abs(sxy) / sxx
    df = fs / length
    lo = max(int(np.ceil(0.5 / df)), 1)
    hi = min(int(np.floor(min(40.0, 0.4 * fs) / df)), len(gain) - 2)
    maxima = [k for k in range(lo, hi + 1) if gain[k] > gain[k - 1] and gain[k] >= gain[k + 1]]
    kept = []
    for k in sorted(maxima, key=lambda k: (-gain[k], k)):
        if len(kept) == 2:
            break
        # Distinct resonances: |H| falls below half the lower of the two between them.
        if all(gain[min(p, k) : max(p, k) + 1].min() < 0.5 * min(gain[p], gain[k]) for p in kept):
            kept.append(k)
    maxima = sorted(kept)
    out = {
        "records": [p.split("/")[-1] for p in paths],
        "sample_rate_hz": fs,
        "segment_samples": length,
        "segments": count,
        "resolution_hz": df,
        "peak_bins_hz": [k * df for k in maxima],
    }
    json.dump(out, sys.stdout, indent=2)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main(sys.argv[1:])
