#!/usr/bin/env python3
"""Independent test records for platen's any-record identification (NumPy/SciPy only).

Nothing here uses platen's own generator or integrators: the motions, the forces and the
platen's response are made from scratch, and the records are written the way a lab's data
system writes them (its own channel names, mm and mm/s2, a pressure difference for the force,
time stamps rounded to 1e-5 s, offsets on every channel, noise, no velocity channel).

Model (identified form, Eq. 22/23 of Ozcelik et al. 2008, with parameters that are NOT the
paper's), optionally with a shear building of storeys fixed on the platen:

    Me*a = F(t) - Ke*u - s*D(|v|) + Vs,       D(w) = Fmu + Ce*w**alpha + A*exp(-B*w)
    Vs   = k1*x1 + c1*x1'                       (force of storey 1 on the platen)
    m1*(a + x1'') = -k1*x1 - c1*x1' + k2*(x2 - x1) + c2*(x2' - x1')
    m2*(a + x2'') = -k2*(x2 - x1) - c2*(x2' - x1')

x_i is storey i relative to the platen; the storeys' absolute accelerations a + x_i'' are the
floor accelerometers, and sum(m_i*(a + x_i'')) = -Vs, so the actuator force is
F = Me*a + Ke*u + s*D + sum(m_i*a_i): the base shear the identification must subtract.

Stick-slip is exact: in slip (s = +1 or -1 fixed) the smooth right-hand side is integrated
by SciPy's DOP853 with v = 0 as a terminal event; at v = 0 the platen sticks if
|F - Ke*u + Vs| <= Fmu + A, else reverses with s = sign(N); in stick (u fixed, a = 0, the
storeys still moving) breakaway is the terminal event |N| = Fmu + A. F(t) is the linear
interpolant of the force samples.

The force samples are the force a target motion needs (target: an earthquake-like or a
band-limited white-noise displacement made by FFT synthesis under a smooth envelope), so the
platen roughly follows the target; what it really does is the simulation's.

Outputs (tests/data/any-record/):
  truth.json                  the parameters, noise levels, offsets and units of every file
  eq-lab.csv                  earthquake-like, 30 s at 204.8 Hz, lab format
  wn-lab.csv                  white noise (0.3-15 Hz), 30 s, lab format
  wn-low-lab.csv              low-amplitude white noise (peak speed ~3 cm/s), 30 s
  eq-two-storey-lab.csv       earthquake-like with a two-storey specimen and floor accelerations
  coverage-K.csv (K = 0..4)   noise-free truth in SI (u_m, a_m_s2, force_n), 30 s each, for the
                              coverage study (the test adds seeded noise, offsets, rounding)

Usage (from the repository root):  python3 tools/record_reference/make_records.py
Deterministic: fixed seeds; the same NumPy/SciPy give the same bytes.
"""

import json
import math
import os

import numpy as np
from scipy.integrate import solve_ivp

FS_HZ = 204.8
DT_S = 1.0 / FS_HZ
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "data",
                   "any-record")

# A table that is not the paper's (paper: 144 t, 1.266 MN/m, 25.4 kN, 44.58 kN/(m/s)^0.5,
# 0.5, 12.04 kN, 78.5 s/m).
TABLE = dict(Me=118e3, Ke=0.95e6, Fmu=32e3, Ce=61e3, alpha=0.68, A=9e3, B=55.0)

# Two storeys: 14 t and 11 t, about 2.4 and 6.3 Hz fixed-base, 3 % damping-ish.
STOREYS = [dict(m=14e3, k=9.0e6, c=40e3), dict(m=11e3, k=7.0e6, c=25e3)]

# Lab channels: names, units (factor from SI to the file's unit), printed decimals.
AREA_M2 = 0.15                      # dP (MPa) x area = force
COLUMNS = {
    "t": ("Time", 1.0, 5),
    "u": ("Table Disp", 1e3, 4),    # mm
    "a": ("Table Acc", 1e3, 2),     # mm/s2
    "f": ("dP", 1e-6 / AREA_M2, 6),  # MPa
    "a1": ("Floor 1 Acc", 1e3, 2),
    "a2": ("Floor 2 Acc", 1e3, 2),
}

# Sensor noise and offsets, SI.
NOISE = dict(u_m=2e-5, a_m_s2=0.03, force_white_n=800.0, force_ar_n=1000.0, force_ar_rho=0.97)
OFFSETS = dict(u_m=2.5e-3, a_m_s2=0.012, force_n=3.0e3)


def envelope(t, rise, hold, decay):
    """0 -> 1 over `rise` s (cosine), 1 for `hold` s, then exp decay to 0 at the end (tapered)."""
    e = np.ones_like(t)
    r = t < rise
    e[r] = 0.5 - 0.5 * np.cos(np.pi * t[r] / rise)
    late = t > rise + hold
    e[late] = np.exp(-(t[late] - rise - hold) / decay)
    end = t[-1]
    tail = t > end - 1.0
    e[tail] *= 0.5 + 0.5 * np.cos(np.pi * (t[tail] - (end - 1.0)) / 1.0)
    return e


def synth(n, rng, shape):
    """A random real signal of n samples at FS_HZ with amplitude spectrum `shape(f)`."""
    f = np.fft.rfftfreq(n, DT_S)
    spec = shape(f) * (rng.standard_normal(len(f)) + 1j * rng.standard_normal(len(f)))
    spec[0] = 0.0
    return np.fft.irfft(spec, n)


def spectral_derivatives(x):
    """First and second derivatives of a periodic signal (it is zero at both ends)."""
    n = len(x)
    w = 2j * np.pi * np.fft.rfftfreq(n, DT_S)
    X = np.fft.rfft(x)
    return np.fft.irfft(w * X, n), np.fft.irfft(w * w * X, n)


def target_motion(kind, duration_s, seed, scale):
    """Target displacement, velocity, acceleration: earthquake-like (Kanai-Tajimi-like
    spectrum of the acceleration, strong phase under an envelope) or band-limited white
    noise (flat acceleration 0.3-15 Hz, steady)."""
    n = int(round(duration_s * FS_HZ)) + 1
    rng = np.random.default_rng(seed)
    t = np.arange(n) * DT_S
    if kind == "eq":
        def shape(f):
            fg, zg = 1.8, 0.55
            r = (f / fg) ** 2
            kt = np.sqrt((1 + 4 * zg * zg * r) / ((1 - r) ** 2 + 4 * zg * zg * r))
            hp = (f / 0.25) ** 4 / (1 + (f / 0.25) ** 4)
            lp = 1.0 / (1 + (f / 18.0) ** 8)
            return kt * hp * lp / np.maximum(2 * np.pi * f, 1e-9) ** 2
        env = envelope(t, 2.0, 0.35 * duration_s, 0.2 * duration_s)
    else:
        def shape(f):
            band = (f > 0.3) & (f < 15.0)
            return band / np.maximum(2 * np.pi * f, 1e-9) ** 2
        env = envelope(t, 1.0, duration_s, 1e9)
    u = synth(n, rng, shape) * env
    u -= np.linspace(u[0], u[-1], n)  # exactly zero at both ends
    v, a = spectral_derivatives(u)
    k = scale / np.max(np.abs(v))
    return t, u * k, v * k, a * k


class Plant:
    def __init__(self, table, storeys, force):
        self.p = table
        self.st = storeys
        self.F = force
        self.fs = table["Fmu"] + table["A"]

    def force(self, t):
        x = t * FS_HZ
        j = min(int(math.floor(x)), len(self.F) - 2)
        w = x - j
        return self.F[j] * (1.0 - w) + self.F[j + 1] * w

    def D(self, w):
        p = self.p
        return p["Fmu"] + p["Ce"] * w ** p["alpha"] + p["A"] * math.exp(-p["B"] * w)

    def specimen_force(self, y):
        """Force of storey 1 on the platen, k1*x1 + c1*x1' (0 without storeys): minus the
        base shear sum(m_i*a_i)."""
        if not self.st:
            return 0.0
        return self.st[0]["k"] * y[2] + self.st[0]["c"] * y[3]

    def storey_acc(self, y, a):
        """Relative accelerations x_i'' given the platen acceleration a."""
        out = []
        ns = len(self.st)
        for i in range(ns):
            x, xd = y[2 + 2 * i], y[3 + 2 * i]
            xm, xmd = (y[2 * i], y[1 + 2 * i]) if i > 0 else (0.0, 0.0)
            f = -self.st[i]["k"] * (x - xm) - self.st[i]["c"] * (xd - xmd)
            if i + 1 < ns:
                xn, xnd = y[2 + 2 * (i + 1)], y[3 + 2 * (i + 1)]
                f += self.st[i + 1]["k"] * (xn - x) + self.st[i + 1]["c"] * (xnd - xd)
            out.append(f / self.st[i]["m"] - a)
        return out

    def platen_acc(self, t, y, mode):
        if mode == 0:
            return 0.0
        p = self.p
        w = max(mode * y[1], 0.0)
        return (self.force(t) - p["Ke"] * y[0] - mode * self.D(w) + self.specimen_force(y)) / p["Me"]

    def rhs(self, t, y, mode):
        a = self.platen_acc(t, y, mode)
        d = [y[1] if mode != 0 else 0.0, a]
        for i, xdd in enumerate(self.storey_acc(y, a)):
            d += [y[3 + 2 * i], xdd]
        return d

    def net(self, t, y):
        return self.force(t) - self.p["Ke"] * y[0] + self.specimen_force(y)

    def simulate(self, n):
        """Exact stick-slip from rest; the state at every sample time, and the mode."""
        t_end = (n - 1) * DT_S
        ts = np.arange(n) * DT_S
        dim = 2 + 2 * len(self.st)
        Y = np.zeros((n, dim))
        MODE = np.zeros(n, dtype=int)
        t, y = 0.0, np.zeros(dim)
        mode = 0
        N0 = self.net(0.0, y)
        if abs(N0) > self.fs:
            mode = 1 if N0 > 0 else -1
        k = 0  # next sample to fill
        events = 0
        while t < t_end:
            if mode == 0:
                def ev(tt, yy):
                    return abs(self.net(tt, yy)) - self.fs
            else:
                def ev(tt, yy, s=mode):
                    return s * yy[1]
            ev.terminal = True
            ev.direction = 1 if mode == 0 else -1
            sol = solve_ivp(lambda tt, yy: self.rhs(tt, yy, mode), (t, t_end), y,
                            method="DOP853", rtol=1e-10, atol=1e-12, max_step=DT_S,
                            events=ev, dense_output=True)
            if sol.status < 0:
                raise RuntimeError(sol.message)
            t_stop = float(sol.t[-1])
            while k < n and ts[k] <= t_stop:
                Y[k] = sol.sol(ts[k])
                MODE[k] = mode
                k += 1
            if sol.status != 1:
                break
            events += 1
            t = float(sol.t_events[0][0])
            y = np.array(sol.y_events[0][0], dtype=float)
            if mode != 0:
                y[1] = 0.0
                N = self.net(t, y)
                mode = 0 if abs(N) <= self.fs else (1 if N > 0 else -1)
            else:
                N = self.net(t, y)
                mode = 1 if N > 0 else -1
        while k < n:  # the last sample, if the loop ended on it
            Y[k] = y
            MODE[k] = mode
            k += 1
        if mode == 0:
            pass
        for j in range(n):
            if MODE[j] == 0:
                Y[j, 1] = 0.0
        return Y, MODE, events

    def outputs(self, Y, MODE):
        """Platen a, storeys' absolute accelerations, force at every sample."""
        n = len(Y)
        a = np.zeros(n)
        floors = np.zeros((n, len(self.st)))
        for j in range(n):
            t = j * DT_S
            a[j] = self.platen_acc(t, Y[j], MODE[j])
            rel = self.storey_acc(Y[j], a[j])
            for i, x in enumerate(rel):
                floors[j, i] = a[j] + x
        return a, floors


def target_force(table, storeys, u, v, a):
    """The force the target motion needs (sign(0) = 0), with the storeys as rigid masses."""
    p = table
    w = np.abs(v)
    D = p["Fmu"] + p["Ce"] * w ** p["alpha"] + p["A"] * np.exp(-p["B"] * w)
    rigid = sum(s["m"] for s in storeys)
    return (p["Me"] + rigid) * a + p["Ke"] * u + np.sign(v) * D


def make(kind, duration_s, seed, peak_speed, storeys=()):
    storeys = list(storeys)
    t, u_t, v_t, a_t = target_motion(kind, duration_s, seed, peak_speed)
    force = target_force(TABLE, storeys, u_t, v_t, a_t)
    plant = Plant(TABLE, storeys, force)
    Y, MODE, events = plant.simulate(len(t))
    a, floors = plant.outputs(Y, MODE)
    return dict(t=t, u=Y[:, 0], v=Y[:, 1], a=a, f=force, floors=floors, stuck=MODE == 0,
                events=events)


def ar1(n, rng, sigma, rho):
    e = rng.standard_normal(n) * sigma * math.sqrt(1 - rho * rho)
    x = np.zeros(n)
    x[0] = rng.standard_normal() * sigma
    for j in range(1, n):
        x[j] = rho * x[j - 1] + e[j]
    return x


def fmt(x, decimals):
    s = f"{x:.{decimals}f}"
    return "0" + s[2:] if s.startswith("-0") and float(s) == 0.0 else s


def write_lab(name, rec, seed):
    """The record as a data system writes it: noise, offsets, lab units, rounded stamps."""
    rng = np.random.default_rng(seed)
    n = len(rec["t"])
    u = rec["u"] + OFFSETS["u_m"] + rng.standard_normal(n) * NOISE["u_m"]
    a = rec["a"] + OFFSETS["a_m_s2"] + rng.standard_normal(n) * NOISE["a_m_s2"]
    f = (rec["f"] + OFFSETS["force_n"] + rng.standard_normal(n) * NOISE["force_white_n"]
         + ar1(n, rng, NOISE["force_ar_n"], NOISE["force_ar_rho"]))
    cols = [("t", rec["t"]), ("u", u), ("a", a), ("f", f)]
    for i in range(rec["floors"].shape[1]):
        cols.append((f"a{i + 1}", rec["floors"][:, i]
                     + rng.standard_normal(n) * NOISE["a_m_s2"]))
    header = ",".join(f"{COLUMNS[c][0]}" for c, _ in cols)
    lines = [header]
    for j in range(n):
        lines.append(",".join(fmt(x[j] * COLUMNS[c][1], COLUMNS[c][2]) for c, x in cols))
    with open(os.path.join(OUT, name), "w") as fh:
        fh.write("\n".join(lines) + "\n")


def write_truth_si(name, rec):
    lines = ["u_m,a_m_s2,force_n"]
    for j in range(len(rec["t"])):
        lines.append(f"{rec['u'][j]:.12g},{rec['a'][j]:.12g},{rec['f'][j]:.12g}")
    with open(os.path.join(OUT, name), "w") as fh:
        fh.write("\n".join(lines) + "\n")


def summary(rec):
    moving = ~rec["stuck"]
    w = np.abs(rec["v"][moving])
    return dict(samples=len(rec["t"]), events=int(rec["events"]),
                stuck_fraction=float(np.mean(rec["stuck"])),
                peak_u_m=float(np.max(np.abs(rec["u"]))),
                peak_v_m_s=float(np.max(np.abs(rec["v"]))),
                peak_a_m_s2=float(np.max(np.abs(rec["a"]))),
                speed_p05_p99_m_s=[float(np.quantile(w, 0.05)), float(np.quantile(w, 0.99))])


def main():
    os.makedirs(OUT, exist_ok=True)
    lab = [
        ("eq-lab.csv", "eq", 30.0, 11, 0.45, (), 101),
        ("wn-lab.csv", "wn", 30.0, 12, 0.30, (), 102),
        ("wn-low-lab.csv", "wn", 30.0, 13, 0.03, (), 103),
        ("eq-two-storey-lab.csv", "eq", 30.0, 14, 0.45, STOREYS, 104),
    ]
    files = {}
    for name, kind, dur, seed, speed, storeys, noise_seed in lab:
        rec = make(kind, dur, seed, speed, storeys)
        write_lab(name, rec, noise_seed)
        files[name] = dict(kind=kind, storeys=len(storeys), **summary(rec))
        print(name, files[name])
    coverage = {}
    for k in range(5):
        kind = "eq" if k % 2 == 0 else "wn"
        rec = make(kind, 30.0, 200 + k, 0.35, ())
        name = f"coverage-{k}.csv"
        write_truth_si(name, rec)
        coverage[name] = dict(kind=kind, **summary(rec))
        print(name, coverage[name])
    truth = dict(
        sample_rate_hz=FS_HZ,
        identified=dict(effective_mass_kg=TABLE["Me"], stiffness_n_per_m=TABLE["Ke"],
                        coulomb_force_n=TABLE["Fmu"], viscous_coefficient=TABLE["Ce"],
                        viscous_exponent=TABLE["alpha"], low_velocity_force_n=TABLE["A"],
                        low_velocity_decay_s_per_m=TABLE["B"]),
        storeys=[dict(mass_kg=s["m"], stiffness_n_per_m=s["k"], damping_n_s_per_m=s["c"])
                 for s in STOREYS],
        noise_si=NOISE,
        offsets_si=OFFSETS,
        area_m2=AREA_M2,
        lab_columns={c: dict(name=v[0], factor_from_si=v[1], decimals=v[2])
                     for c, v in COLUMNS.items()},
        lab_files=files,
        coverage_files=coverage,
    )
    with open(os.path.join(OUT, "truth.json"), "w") as fh:
        json.dump(truth, fh, indent=2, sort_keys=True)
        fh.write("\n")


if __name__ == "__main__":
    main()
