#!/usr/bin/env python3
"""Is the slow roll and pitch moment that no logged signal predicts an artefact of how the
motor commands were logged? A Crazyflie log block takes each motor command as it is at the
instant of its 100 Hz tick, while the rate loop changes the command at 500 Hz (the firmware's
stabilizer_types.h: ATTITUDE_RATE). What the command holds above 50 Hz, which the rotors
never follow (they lag by 40-70 ms), folds into the logged samples at every frequency, the
slow band included, and a model that reads the log turns it into a moment the vehicle never
felt.

Measured on the differential commands, roll (-m1 - m2 + m3 + m4) / (4 mean) and pitch
(-m1 + m2 + m3 - m4) / (4 mean), fractions of the mean command, in the slow band 0.4-2 Hz
(Welch, 2.56 s Hann windows at 100 Hz: the bins from 0.39 Hz; the residual's correlation
time is 0.3-1 s). Every slow band is taken from 100 Hz values (10 ms means of faster ones).

  1. ARPL log 10 (1 kHz on one clock: the one log here that holds what a 100 Hz log leaves
     out; a system-identification flight with some twenty motor cuts, whose airborne rows
     between them are used). Its band RMS at full rate; what a sample every 10 ms adds to the
     slow band against the mean of the 10 ms around it (all ten phases a tick could have), as
     a ratio to the samples' own top band (25-50 Hz), the one trace of folding a 100 Hz log
     keeps; that ratio piece by piece; and the estimate it gives through NanoBench's pipeline
     (a sample every 10 ms, a fifth of them lost, the rest interpolated linearly onto a grid
     at another phase), against the folded part it should find. Then the consequence: a
     moment model (the log authors' thrust curve, a first-order lag of 0.062 s, gain and
     offset fitted by least squares to the gyro's angular acceleration) fed the 1 kHz
     commands and the commands held from each tick, with the 1 kHz fit's gain and refitted;
     and how far the moment error the holding makes would carry a rollout in 1 s.
  2. Each NanoBench flight (100 Hz, interpolated onto the Vicon grid; B6 saturates motor 4
     and is marked): the slow band of the logged commands (what a model turns into its slow
     moment), their top band, and the folded part estimated from it with the ARPL ratio.

Fractions are said as angular acceleration with thrust ~ command^2 about hover: a fraction d
moves roll by 2 * arm * m * g * d / J (arm 0.0325 m, m 0.0271 kg, J 1.395e-5 / 1.436e-5
kg m^2, vehicles/crazyflie21.yaml and Foerster 2015), before the 0.62-0.75 answer to the
commands the diagnoses measure. Given DIAGNOSIS_DIRs (single-flight diagnoses of the
NanoBench flights, residuals.csv unthinned), the slow band of the extended model's own roll
and pitch residual is printed beside each flight, and the correlation across the flights
between it and the folded estimate. Last, the folded estimates as the model's slow moment
(the pipeline's share undone, the answer applied) and as a 1 s rollout error (the ARPL log's
drift per rad/s^2 of slow band, scaled by the 0.50-0.59 ratio of measured rollouts to the
linearised drift, docs/history.md's twenty-seventh session, remeasured with the corrected
held-out part in the fifty-fifth).

Usage: command_aliasing.py [--data DIR] [DIAGNOSIS_DIR ...]
  DIR holds arpl/log10.csv and nanobench/B*.csv (default: ../shared/data/crazyflie)"""
import cmath
import csv
import glob
import math
import os
import random
import sys

import disturbance_floor
from markdown_cell import terminal_text  # file names printed as text
import moment_residuals

SLOW = (0.35, 2.0)  # Hz: at 2.56 s windows the bins 0.39-1.95 Hz
TOP = (25.0, 50.0)  # Hz: the top band of a 100 Hz log
FAST_BANDS = [(2, 10), (10, 25), TOP, (50, 100), (100, 250), (250, 500)]
AIRBORNE = 15000  # command: from the first row with every motor above it to the last
G, MASS, ARM = 9.80665, 0.0271, 0.0325
INERTIA = {"roll": 1.395e-5, "pitch": 1.436e-5}
AXES = ("roll", "pitch")
MOTOR_LAG = 0.062  # s: quadgen's fit of the ARPL log (the authors give 0.072 s)
ANSWER = (0.62, 0.75)  # NanoBench: roll/pitch answer to the commands against the stock file (README)
ROLLOUT_RATIO = (0.50, 0.59)  # a measured rollout over the linearised drift (docs/history.md, 27th and 55th sessions)
SATURATED = {"B6_linear_ramp_rep1"}  # motor 4 at full command on most airborne rows
LOST = 0.2  # the share of motor samples lost over the radio on NanoBench (about 18 %)


# ---- spectra ----

def fft(x):
    n = len(x)
    if n == 1:
        return [complex(x[0])]
    even, odd = fft(x[0::2]), fft(x[1::2])
    out = [0j] * n
    for k in range(n // 2):
        twiddled = cmath.exp(-2j * math.pi * k / n) * odd[k]
        out[k], out[k + n // 2] = even[k] + twiddled, even[k] - twiddled
    return out


def band_rms(pieces, rate, bands):
    """RMS in each band of a signal given as contiguous pieces (Welch: Hann windows of 2.56 s
    at 100 Hz, 2.048 s at 1 kHz, half overlapping, within each piece)."""
    n = 256 if rate <= 100 else 2048
    window = [0.5 - 0.5 * math.cos(2 * math.pi * i / n) for i in range(n)]
    power, segments = [0.0] * (n // 2 + 1), 0
    for x in pieces:
        for start in range(0, len(x) - n + 1, n // 2):
            seg = x[start:start + n]
            mean = sum(seg) / n
            spectrum = fft([(s - mean) * w for s, w in zip(seg, window)])
            for i in range(n // 2 + 1):
                power[i] += abs(spectrum[i]) ** 2
            segments += 1
    if not segments:
        sys.exit(f"too few samples for a spectrum at {rate:g} Hz")
    scale = 1.0 / (segments * sum(w * w for w in window) * rate)
    df = rate / n
    density = [p * scale * (1 if i in (0, n // 2) else 2) for i, p in enumerate(power)]
    return [math.sqrt(sum(d * df for i, d in enumerate(density) if lo <= i * df < hi)) for lo, hi in bands]


def slow(pieces_at_100_hz):
    return band_rms(pieces_at_100_hz, 100, [SLOW])[0]


def top(pieces_at_100_hz):
    return band_rms(pieces_at_100_hz, 100, [TOP])[0]


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values))


def correlation(x, y):
    mx, my = sum(x) / len(x), sum(y) / len(y)
    sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    return sxy / math.sqrt(sum((a - mx) ** 2 for a in x) * sum((b - my) ** 2 for b in y))


# ---- commands ----

def differential(commands):
    out = {"roll": [], "pitch": []}
    for m1, m2, m3, m4 in commands:
        mean = (m1 + m2 + m3 + m4) / 4
        out["roll"].append((-m1 - m2 + m3 + m4) / (4 * mean))
        out["pitch"].append((-m1 + m2 + m3 - m4) / (4 * mean))
    return out


def rad_s2(fraction, axis):
    return 2 * ARM * MASS * G * fraction / INERTIA[axis]


def airborne_stretch(commands, margin):
    """(first, last): the rows from take-off to landing, less a margin at either end."""
    airborne = [i for i, c in enumerate(commands) if min(c) > AIRBORNE]
    if len(airborne) < 2 * margin + 100:
        sys.exit("the log has too few airborne rows")
    return airborne[0] + margin, airborne[-1] - margin


def on_a_grid(times, rows, rate):
    """rows held from the latest one at each tick of a uniform grid."""
    out, j, tick = [], 0, times[0]
    while tick < times[-1]:
        while j + 1 < len(times) and times[j + 1] <= tick:
            j += 1
        out.append(rows[j])
        tick += 1.0 / rate
    return out


def ticks(piece, phase):
    """The 10 ms ticks of a 1 kHz piece at a phase (0-9), each with 5 ms on either side."""
    return range(5 + phase, len(piece) - 5, 10)


def held(piece, phase):
    """The piece as a replay of its 10 ms samples holds it: each row the latest tick's."""
    first = 5 + phase
    return [piece[max(first, first + (i - first) // 10 * 10)] for i in range(len(piece))]


def means_around(piece, phase):
    return [[sum(c[k] for c in piece[i - 5:i + 5]) / 10 for k in range(4)] for i in ticks(piece, phase)]


def block_means(x):
    """1 kHz values as 100 Hz ones (10 ms means), the first 0.2 s left out (a lag's start)."""
    return [sum(x[i:i + 10]) / 10 for i in range(200, len(x) - 9, 10)]


# ---- 1. the ARPL log ----

def arpl_pieces(path):
    """The airborne rows on a 1 kHz grid as (commands, gyro rad/s) pieces of at least 3 s (a
    spectral window of 2.56 s after the 0.2 s a lag needs to start),
    split where a motor's command is below 5 % (as quadgen's flight loader drops them: the
    log holds some twenty cuts of up to 0.3 s mid-flight, in which the accelerometer falls
    to about 0.2 g)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    times = [float(r["timestamp_ms"]) / 1000 for r in rows]
    commands = [[float(r[f"motor.m{i}"]) for i in range(1, 5)] for r in rows]
    gyro = [[math.radians(float(r[f"gyro.{a}"])) for a in "xy"] for r in rows]
    first, last = airborne_stretch(commands, 500)
    grid = on_a_grid(times[first:last], list(zip(commands, gyro))[first:last], 1000)
    pieces, current = [], []
    for row in grid + [([0, 0, 0, 0], [0, 0])]:
        if min(row[0]) < 0.05 * 65535:
            if len(current) >= 3000:
                pieces.append(current)
            current = []
        else:
            current.append(row)
    return [[c for c, _ in p] for p in pieces], [[w for _, w in p] for p in pieces]


def folding(pieces):
    """Per axis and phase: what a sample every 10 ms adds to the slow band against the mean
    of the 10 ms around it, and the samples' top band; per axis and piece, the ratio of the
    two over the phases."""
    added, tops = {a: [] for a in AXES}, {a: [] for a in AXES}
    by_piece = {a: [[] for _ in pieces] for a in AXES}
    for phase in range(10):
        sampled = [differential([p[i] for i in ticks(p, phase)]) for p in pieces]
        means = [differential(means_around(p, phase)) for p in pieces]
        for axis in AXES:
            errors = [[s - m for s, m in zip(d[axis], e[axis])] for d, e in zip(sampled, means)]
            added[axis].append(slow(errors))
            tops[axis].append(top([d[axis] for d in sampled]))
            for k, (e, d) in enumerate(zip(errors, sampled)):
                by_piece[axis][k].append((slow([e]), top([d[axis]])))
    piece_ratio = {a: [rms([x for x, _ in v]) / rms([t for _, t in v]) for v in by_piece[a]] for a in AXES}
    return added, tops, piece_ratio


def through_nanobench_pipeline(piece, phase, rng):
    """A 1 kHz piece as NanoBench's columns hold a signal: a sample every 10 ms, a share of
    them lost, the rest interpolated linearly onto a 100 Hz grid at another phase."""
    kept = [(i, piece[i]) for i in ticks(piece, phase) if rng.random() > LOST]
    shift = rng.random() * 10
    out, j = [], 0
    for k in range(int((kept[-1][0] - kept[0][0] - shift) // 10)):
        at = kept[0][0] + shift + 10 * k
        while kept[j + 1][0] < at:
            j += 1
        (i0, v0), (i1, v1) = kept[j], kept[j + 1]
        w = (at - i0) / (i1 - i0)
        out.append([a + w * (b - a) for a, b in zip(v0, v1)])
    return out


def estimator_check(pieces, ratio):
    """The folded part the ARPL ratio finds in NanoBench-like columns of the ARPL commands,
    as a share of the folded part there is (both over the ten phases)."""
    rng = random.Random(1)
    found, there = {a: [] for a in AXES}, {a: [] for a in AXES}
    for phase in range(10):
        columns = [differential(through_nanobench_pipeline(p, phase, rng)) for p in pieces]
        sampled = [differential([p[i] for i in ticks(p, phase)]) for p in pieces]
        means = [differential(means_around(p, phase)) for p in pieces]
        for axis in AXES:
            found[axis].append(ratio[axis] * top([c[axis] for c in columns]))
            there[axis].append(slow([[s - m for s, m in zip(d[axis], e[axis])] for d, e in zip(sampled, means)]))
    return {a: rms(found[a]) / rms(there[a]) for a in AXES}


def lagged_differential_thrust(commands):
    alpha = 0.001 / (MOTOR_LAG + 0.001)
    T = [thrust(c) for c in commands[0]]
    out = {"roll": [], "pitch": []}
    for c in commands:
        T = [t + alpha * (thrust(x) - t) for t, x in zip(T, c)]
        out["roll"].append(-T[0] - T[1] + T[2] + T[3])
        out["pitch"].append(-T[0] + T[1] + T[2] - T[3])
    return out


def thrust(command):
    u = command / 65536.0
    return 0.02127 - 0.01118 * u + 0.12013 * u * u  # N, the log authors' curve


def angular_acceleration(gyro, axis):
    """Centred difference of the gyro averaged over 20 ms, rad/s^2."""
    k = AXES.index(axis)
    w = [sum(g[k] for g in gyro[max(0, i - 10):i + 10]) / len(gyro[max(0, i - 10):i + 10]) for i in range(len(gyro))]
    return [(w[min(i + 1, len(w) - 1)] - w[max(i - 1, 0)]) * 500 for i in range(len(w))]


def fitted_gain(model, measured):
    """Least squares of measured = gain * model + offset over every piece, the first 0.2 s of
    each left out: (gain, offset)."""
    x = [v for p in model for v in p[200:]]
    y = [v for p in measured for v in p[200:]]
    mx, my = sum(x) / len(x), sum(y) / len(y)
    gain = sum((a - mx) * (b - my) for a, b in zip(x, y)) / sum((a - mx) ** 2 for a in x)
    return gain, my - gain * mx


def residual(model, measured, gain_offset):
    gain, offset = gain_offset
    return [block_means([b - offset - gain * a for a, b in zip(pm, py)]) for pm, py in zip(model, measured)]


def one_second_drift(roll, pitch):
    """Mean position error [m] that an angular-acceleration error (100 Hz pieces) makes over
    1 s, linearised about hover as scripts/disturbance_floor.py integrates it (rate, tilt,
    g times tilt, position; trapezoids; no damping), from a start every 0.05 s."""
    t = [0.01 * k for k in range(101)]
    errors = []
    for p, q in zip(roll, pitch):
        for start in range(0, len(p) - 100, 5):
            errors.append(G * math.hypot(disturbance_floor.integrate_four_times(t, p[start:start + 101]),
                                         disturbance_floor.integrate_four_times(t, q[start:start + 101])))
    return sum(errors) / len(errors)


def consequence(commands, gyro):
    """Per axis the slow residual with the 1 kHz commands and, over the phases, with the
    commands held from a tick (the 1 kHz gain kept, and refitted); the slow band of the moment
    error the holding makes and its 1 s drift."""
    measured = {axis: [angular_acceleration(g, axis) for g in gyro] for axis in AXES}
    at_full = [lagged_differential_thrust(p) for p in commands]
    fit = {axis: fitted_gain([m[axis] for m in at_full], measured[axis]) for axis in AXES}
    out = {axis: {"full": slow(residual([m[axis] for m in at_full], measured[axis], fit[axis])),
                  "kept": [], "refitted": [], "error": []} for axis in AXES}
    drift = []
    for phase in range(10):
        models = [lagged_differential_thrust(held(p, phase)) for p in commands]
        error = {}
        for axis in AXES:
            model = [m[axis] for m in models]
            out[axis]["kept"].append(slow(residual(model, measured[axis], fit[axis])))
            out[axis]["refitted"].append(slow(residual(model, measured[axis], fitted_gain(model, measured[axis]))))
            error[axis] = [block_means([fit[axis][0] * (h - f) for h, f in zip(m[axis], a[axis])])
                           for m, a in zip(models, at_full)]
            out[axis]["error"].append(slow(error[axis]))
        drift.append(one_second_drift(error["roll"], error["pitch"]))
    return out, drift


def arpl(path):
    commands, gyro = arpl_pieces(path)
    print(f"ARPL log 10, 1 kHz: {sum(map(len, commands)) / 1000:.1f} s airborne in {len(commands)} pieces "
          "between the motor cuts; fraction of the mean command [nominal rad/s^2]")
    full = [differential(p) for p in commands]
    means = [differential([[sum(c[k] for c in p[i:i + 10]) / 10 for k in range(4)] for i in range(0, len(p) - 9, 10)])
             for p in commands]
    for axis in AXES:
        fast = band_rms([d[axis] for d in full], 1000, FAST_BANDS)
        print(f"  {axis:5s} band RMS: {SLOW[0]:g}-{SLOW[1]:g} Hz {slow([m[axis] for m in means]):.4f} (10 ms means), " +
              ", ".join(f"{lo:g}-{hi:g} Hz {v:.4f}" for (lo, hi), v in zip(FAST_BANDS, fast)))
    added, tops, piece_ratio = folding(commands)
    ratio = {a: rms(added[a]) / rms(tops[a]) for a in AXES}
    check = estimator_check(commands, ratio)
    for axis in AXES:
        a = rms(added[axis])
        print(f"  {axis:5s} a sample every 10 ms adds to the slow band {a:.4f} [{rad_s2(a, axis):.2f}] "
              f"(phases {min(added[axis]):.4f}-{max(added[axis]):.4f}); the samples' top band {rms(tops[axis]):.4f}; "
              f"folded into the slow band {ratio[axis]:.3f} of it (pieces "
              f"{min(piece_ratio[axis]):.2f}-{max(piece_ratio[axis]):.2f}); through NanoBench's pipeline the "
              f"estimate finds {check[axis]:.2f} of the folded part")
    out, drift = consequence(commands, gyro)
    print(f"  a moment model fitted to the gyro (lag {MOTOR_LAG} s), its residual's slow band [rad/s^2]:")
    for axis in AXES:
        o = out[axis]
        print(f"  {axis:5s} 1 kHz commands {o['full']:.2f}; held from a 10 ms tick, the 1 kHz gain kept "
              f"{rms(o['kept']):.2f} ({min(o['kept']):.2f}-{max(o['kept']):.2f}), refitted {rms(o['refitted']):.2f} "
              f"({min(o['refitted']):.2f}-{max(o['refitted']):.2f}); the moment error the holding makes "
              f"{rms(o['error']):.2f}")
    mean_drift = sum(drift) / len(drift)
    print(f"  that moment error alone over 1 s (linearised, no damping): {mean_drift:.3f} m "
          f"(phases {min(drift):.3f}-{max(drift):.3f})")
    error_slow = rms([v for axis in AXES for v in out[axis]["error"]])
    return ratio, check, mean_drift / error_slow, piece_ratio


# ---- 2. the NanoBench flights ----

def nanobench(folder, ratio, residual_slow):
    """Prints each flight's line; returns the folded estimates of the unsaturated flights."""
    print("NanoBench flights, 100 Hz: fraction of the mean command [nominal rad/s^2]")
    print("  flight, axis: slow band of the logged commands | top band | folded into the slow band, "
          "estimated with the ARPL ratio" + (" | the extended model's residual, slow band" if residual_slow else ""))
    pairs, unsaturated = [], []
    for path in sorted(glob.glob(os.path.join(glob.escape(folder), "B*.csv"))):  # "[1]" in a folder is no pattern
        with open(path, newline="") as f:
            commands = [[float(r[f"motor_motor_m{i}"]) for i in range(1, 5)] for r in csv.DictReader(f)]
        first, last = airborne_stretch(commands, 300)
        name = os.path.splitext(os.path.basename(path))[0]
        mark = " (saturated)" if name in SATURATED else ""
        for axis, x in differential(commands[first:last]).items():
            s, t = slow([x]), top([x])
            folded = ratio[axis] * t
            if not mark:
                unsaturated.append((axis, folded))
            line = (f"  {terminal_text(name) + mark:36s} {axis:5s} {s:.4f} [{rad_s2(s, axis):.2f}] | {t:.4f} | "
                    f"{folded:.4f} [{rad_s2(folded, axis):.2f}]")
            if name in residual_slow and residual_slow[name][axis] is None:
                line += " | (no 3 s without a gap)"
            elif name in residual_slow:
                line += f" | [{residual_slow[name][axis]:.2f}]"
                if not mark:
                    pairs.append((folded, residual_slow[name][axis]))
            print(line)
    if len(pairs) >= 3:
        print(f"  across the unsaturated flights and axes ({len(pairs)}), the folded estimate and the residual's "
              f"slow band correlate at {correlation([f for f, _ in pairs], [r for _, r in pairs]):+.2f}")
    if not unsaturated:  # said here, not as min() of nothing further on (helper-105)
        sys.exit(f"{terminal_text(folder)}: no unsaturated NanoBench flight (B*.csv) to estimate the folding on")
    return unsaturated


def as_a_rollout(unsaturated, check, metres_per_slow, piece_ratio, ratio):
    """The folded estimates of the unsaturated flights as rad/s^2 of the model's moment (the
    estimate's share found through NanoBench's pipeline undone, the answer to the commands
    applied) and as a 1 s rollout error, linearised and scaled by the rollouts' ratio."""
    low = min(rad_s2(f, a) / check[a] for a, f in unsaturated) * ANSWER[0]
    high = max(rad_s2(f, a) / check[a] for a, f in unsaturated) * ANSWER[1]
    spread = (min(min(piece_ratio[a]) / ratio[a] for a in AXES), max(max(piece_ratio[a]) / ratio[a] for a in AXES))
    print(f"  the folded slow moment on the unsaturated flights, the pipeline's share undone and through the "
          f"{ANSWER[0]}-{ANSWER[1]} answer: {low:.2f}-{high:.2f} rad/s^2; at the ARPL log's {metres_per_slow:.2f} m "
          f"per rad/s^2 of slow band, linearised {low * metres_per_slow:.2f}-{high * metres_per_slow:.2f} m at 1 s, "
          f"scaled by the rollouts' {ROLLOUT_RATIO[0]:.2f}-{ROLLOUT_RATIO[1]:.2f}: "
          f"{low * metres_per_slow * ROLLOUT_RATIO[0]:.2f}-{high * metres_per_slow * ROLLOUT_RATIO[1]:.2f} m "
          f"({low * metres_per_slow * ROLLOUT_RATIO[0] * spread[0]:.2f}-"
          f"{high * metres_per_slow * ROLLOUT_RATIO[1] * spread[1]:.2f} m with the ratio's spread between the ARPL pieces)")


def residuals_slow_band(diagnoses):
    """Per flight and axis the slow band of the extended model's residual, over the stretches
    without a gap (disturbance_floor.MAX_GAP) of 3 s or more (a spectral window and a margin)."""
    out = {}
    for folder in diagnoses:
        if not os.path.isfile(os.path.join(folder, "residuals.csv")):
            sys.exit(f"{terminal_text(folder)}: no diagnosis folder (no residuals.csv in it)")
        series, meta = moment_residuals.read(folder)
        flights = meta.get("flights", [])
        if len(flights) != 1:
            sys.exit(f"{terminal_text(folder)}: give a single-flight diagnosis")
        samples = meta["samples"]["training"] + meta["samples"]["validation"]
        if len(series["pdot"]) < 0.9 * samples:
            sys.exit(f"{terminal_text(folder)}: residuals.csv holds {len(series['pdot'])} residuals of {samples} samples: thinned "
                     "for its plot, too coarse for a spectrum")
        name = os.path.splitext(os.path.basename(flights[0]))[0]
        out[name] = {}
        for channel, axis in zip(moment_residuals.CHANNELS, AXES):
            stretches, current = [], [series[channel][0]]
            for point in series[channel][1:]:
                if point[0] - current[-1][0] > disturbance_floor.MAX_GAP:
                    stretches.append(current)
                    current = []
                current.append(point)
            stretches.append(current)
            long_enough = [s for s in stretches if s[-1][0] - s[0][0] >= 3]
            # None where the fit dropped so many samples that no stretch is long enough (B6)
            out[name][axis] = slow([on_a_grid([p[0] for p in s], [p[1] for p in s], 100) for s in long_enough]) \
                if long_enough else None
    return out


def main(argv):
    data = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data", "crazyflie")
    if argv[:1] == ["--data"]:
        if len(argv) < 2:
            sys.exit(__doc__)
        data, argv = argv[1], argv[2:]
    if any(a.startswith("-") for a in argv):
        sys.exit(__doc__)
    residual_slow = residuals_slow_band(argv)
    ratio, check, metres_per_slow, piece_ratio = arpl(os.path.join(data, "arpl", "log10.csv"))
    unsaturated = nanobench(os.path.join(data, "nanobench"), ratio, residual_slow)
    as_a_rollout(unsaturated, check, metres_per_slow, piece_ratio, ratio)


if __name__ == "__main__":
    main(sys.argv[1:])
