#!/usr/bin/env python3
"""Is the slow roll and pitch moment that no logged signal predicts an artefact of how the
motor commands were logged? A Crazyflie log block takes each motor command as it is at the
instant of its 100 Hz tick, while the rate loop changes the command at 500 Hz. What the
command holds above 50 Hz, which the rotors never follow (they lag by 40-70 ms), then folds
into the logged samples at every frequency, the slow band included, and a model that reads
the log turns it into a slow moment the vehicle never felt.

Measured on the differential commands, roll (-m1 - m2 + m3 + m4) / (4 mean) and pitch
(-m1 + m2 + m3 - m4) / (4 mean), fractions of the mean command, in the slow band 0.2-2 Hz
(the slow residual's correlation time is 0.3-1 s):

  1. ARPL log 10 (1 kHz on one clock: the one log here that holds what a 100 Hz log leaves
     out). Its band RMS at full rate; what a sample every 10 ms adds to the slow band against
     the mean of the 10 ms around it (all ten phases the tick could have); and how that
     compares with the samples' own top band (25-50 Hz), the one trace of folding a 100 Hz
     log keeps. Then the consequence: a moment model (the log authors' thrust curve, a
     first-order lag of 0.062 s, gain and offset fitted by least squares to the gyro's
     angular acceleration) fed the 1 kHz commands and fed the commands held from each 10 ms
     tick: the slow band of its residual both ways.
  2. Each NanoBench flight (100 Hz, interpolated onto the Vicon grid): the slow band of the
     logged commands (what a model turns into its slow moment), their top band, and the
     folded part estimated from it with the ratio measured on the ARPL log. Linear
     interpolation lowers a top band by up to half (2/3 on average over the phases), so the
     estimate may be low by that much.

Fractions are said as angular acceleration with thrust ~ command^2 about hover: a fraction d
moves roll by 2 * arm * m * g * d / J (arm 0.0325 m, m 0.0271 kg, J 1.395e-5 / 1.436e-5
kg m^2, vehicles/crazyflie21.yaml and Foerster 2015), before the 0.6-0.75 answer to the
commands the diagnoses measure. Given DIAGNOSIS_DIRs (single-flight diagnoses of the
NanoBench flights, residuals.csv unthinned), the slow band of the extended model's own roll
and pitch residual is printed beside each flight.

Usage: command_aliasing.py [--data DIR] [DIAGNOSIS_DIR ...]
  DIR holds arpl/log10.csv and nanobench/B*.csv (default: ../shared/data/crazyflie)"""
import cmath
import csv
import glob
import math
import os
import sys

import moment_residuals

SLOW = (0.2, 2.0)  # Hz
TOP = (25.0, 50.0)  # Hz: the top band of a 100 Hz log
BANDS = [SLOW, (2, 10), (10, 25), TOP, (50, 100), (100, 250), (250, 500)]
AIRBORNE = 15000  # command: from the first row with every motor above it to the last
G, MASS, ARM = 9.80665, 0.0271, 0.0325
INERTIA = {"roll": 1.395e-5, "pitch": 1.436e-5}
AXES = ("roll", "pitch")
MOTOR_LAG = 0.062  # s: quadgen's fit of the ARPL log (the authors give 0.072 s)


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
    """RMS in each band of a signal given as contiguous pieces (Welch: Hann windows of ~2.5 s,
    half overlapping, within each piece)."""
    n = 1 << round(math.log2(2.56 * rate))
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


def slow(pieces, rate):
    return band_rms(pieces, rate, [SLOW])[0]


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values))


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


# ---- 1. the ARPL log ----

def arpl_pieces(path):
    """The airborne rows on a 1 kHz grid as (commands, gyro rad/s) pieces of at least 2.56 s,
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
            if len(current) >= 2560:
                pieces.append(current)
            current = []
        else:
            current.append(row)
    return [[c for c, _ in p] for p in pieces], [[w for _, w in p] for p in pieces]


def ticks(piece, phase):
    return range(5 + phase, len(piece) - 5, 10)


def folding(pieces):
    """Per axis: what a sample every 10 ms adds to the slow band, against the mean of the
    10 ms around it, and the samples' top band, each for the ten phases."""
    added, top = {a: [] for a in AXES}, {a: [] for a in AXES}
    for phase in range(10):
        sampled = [differential([p[i] for i in ticks(p, phase)]) for p in pieces]
        means = [differential([[sum(c[k] for c in p[i - 5:i + 5]) / 10 for k in range(4)] for i in ticks(p, phase)])
                 for p in pieces]
        for axis in AXES:
            added[axis].append(slow([[s - m for s, m in zip(d[axis], e[axis])] for d, e in zip(sampled, means)], 100))
            top[axis].append(band_rms([d[axis] for d in sampled], 100, [TOP])[0])
    return added, top


def thrust(command):
    u = command / 65536.0
    return 0.02127 - 0.01118 * u + 0.12013 * u * u  # N, the log authors' curve


def lagged_differential_thrust(commands):
    alpha = 0.001 / (MOTOR_LAG + 0.001)
    T = [thrust(c) for c in commands[0]]
    out = {"roll": [], "pitch": []}
    for c in commands:
        T = [t + alpha * (thrust(x) - t) for t, x in zip(T, c)]
        out["roll"].append(-T[0] - T[1] + T[2] + T[3])
        out["pitch"].append(-T[0] + T[1] + T[2] - T[3])
    return out


def angular_acceleration(gyro, axis):
    """Centred difference of the gyro averaged over 20 ms, rad/s^2."""
    k = AXES.index(axis)
    w = [sum(g[k] for g in gyro[max(0, i - 10):i + 10]) / len(gyro[max(0, i - 10):i + 10]) for i in range(len(gyro))]
    return [(w[min(i + 1, len(w) - 1)] - w[max(i - 1, 0)]) * 500 for i in range(len(w))]


def fitted_gain(model, measured):
    """Least squares of measured = gain * model + offset over every piece, the lag's first
    0.2 s of each piece left out: (gain, offset)."""
    x = [v for p in model for v in p[200:]]
    y = [v for p in measured for v in p[200:]]
    mx, my = sum(x) / len(x), sum(y) / len(y)
    gain = sum((a - mx) * (b - my) for a, b in zip(x, y)) / sum((a - mx) ** 2 for a in x)
    return gain, my - gain * mx


def at_100_hz(pieces):
    """Block means of 10 ms: the slow band and a 1 s rollout need no more."""
    return [[sum(r[i:i + 10]) / 10 for i in range(200, len(r) - 9, 10)] for r in pieces]


def residual_slow_band(model, measured):
    gain, offset = fitted_gain(model, measured)
    return slow(at_100_hz([[b - offset - gain * a for a, b in zip(pm, py)] for pm, py in zip(model, measured)]), 100)


def one_second_drift(roll, pitch):
    """Mean position error [m] that an angular-acceleration error makes over 1 s, linearised
    about hover as scripts/disturbance_floor.py does (rate, tilt, g times tilt, position; no
    damping), from a start every 0.05 s of each 100 Hz piece."""
    errors = []
    for p, q in zip(roll, pitch):
        for start in range(0, len(p) - 100, 5):
            drift = []
            for b in (p, q):
                rate = tilt = velocity = position = 0.0
                for k in range(start, start + 100):
                    rate += b[k] * 0.01
                    tilt += rate * 0.01
                    velocity += G * tilt * 0.01
                    position += velocity * 0.01
                drift.append(position)
            errors.append(math.hypot(*drift))
    return sum(errors) / len(errors)


def arpl(path):
    commands, gyro = arpl_pieces(path)
    print(f"ARPL log 10, 1 kHz: {sum(map(len, commands)) / 1000:.1f} s airborne in {len(commands)} pieces "
          "without dropouts; fraction of the mean command [nominal rad/s^2]")
    full = [differential(p) for p in commands]
    for axis in AXES:
        print(f"  {axis:5s} band RMS at 1 kHz: " + ", ".join(
            f"{lo:g}-{hi:g} Hz {v:.4f}" for (lo, hi), v in zip(BANDS, band_rms([d[axis] for d in full], 1000, BANDS))))
    added, top = folding(commands)
    ratio = {}
    for axis in AXES:
        a, t = rms(added[axis]), rms(top[axis])
        ratio[axis] = a / t
        print(f"  {axis:5s} a sample every 10 ms adds to {SLOW[0]:g}-{SLOW[1]:g} Hz {a:.4f} [{rad_s2(a, axis):.2f}] "
              f"(phases {min(added[axis]):.4f}-{max(added[axis]):.4f}); the samples' top band {t:.4f}: "
              f"{ratio[axis]:.3f} of it folded into the slow band")
    print(f"  a moment model fitted to the gyro (lag {MOTOR_LAG} s), its residual's slow band [rad/s^2]:")
    measured = {axis: [angular_acceleration(g, axis) for g in gyro] for axis in AXES}
    at_full = [lagged_differential_thrust(p) for p in commands]
    gain = {axis: fitted_gain([m[axis] for m in at_full], measured[axis])[0] for axis in AXES}
    held, drift, error_slow = {axis: [] for axis in AXES}, [], []
    for phase in range(10):
        models = [lagged_differential_thrust([p[max(5 + phase, (i - 5 - phase) // 10 * 10 + 5 + phase)] for i in range(len(p))])
                  for p in commands]
        for axis in AXES:
            held[axis].append(residual_slow_band([m[axis] for m in models], measured[axis]))
        # the moment error holding the commands makes by itself, through the 1 kHz fit's gain
        error = {axis: at_100_hz([[gain[axis] * (h - f) for h, f in zip(m[axis], a[axis])] for m, a in zip(models, at_full)])
                 for axis in AXES}
        drift.append(one_second_drift(error["roll"], error["pitch"]))
        error_slow += [slow(error[axis], 100) for axis in AXES]
    for axis in AXES:
        f = residual_slow_band([m[axis] for m in at_full], measured[axis])
        print(f"  {axis:5s} 1 kHz commands {f:.2f}; held from a 10 ms tick {rms(held[axis]):.2f} "
              f"(phases {min(held[axis]):.2f}-{max(held[axis]):.2f})")
    print(f"  the moment error holding the commands makes: slow band {rms(error_slow):.2f} rad/s^2; alone over 1 s "
          f"(linearised, no damping) {sum(drift) / len(drift):.3f} m (phases {min(drift):.3f}-{max(drift):.3f})")
    return ratio


# ---- 2. the NanoBench flights ----

def nanobench(folder, ratio, residual_slow):
    print("NanoBench flights, 100 Hz: fraction of the mean command [nominal rad/s^2]")
    print("  flight, axis: slow band of the logged commands | top band | folded into the slow band, "
          "estimated with the ARPL ratio" + (" | the extended model's residual, slow band" if residual_slow else ""))
    for path in sorted(glob.glob(os.path.join(folder, "B*.csv"))):
        with open(path, newline="") as f:
            commands = [[float(r[f"motor_motor_m{i}"]) for i in range(1, 5)] for r in csv.DictReader(f)]
        first, last = airborne_stretch(commands, 300)
        name = os.path.splitext(os.path.basename(path))[0]
        for axis, x in differential(commands[first:last]).items():
            s, t = band_rms([x], 100, [SLOW, TOP])
            folded = ratio[axis] * t
            line = (f"  {name:24s} {axis:5s} {s:.4f} [{rad_s2(s, axis):.2f}] | {t:.4f} | "
                    f"{folded:.4f} [{rad_s2(folded, axis):.2f}]")
            if name in residual_slow:
                line += f" | [{residual_slow[name][axis]:.2f}]"
            print(line)


def residuals_slow_band(diagnoses):
    out = {}
    for folder in diagnoses:
        if not os.path.isfile(os.path.join(folder, "residuals.csv")):
            sys.exit(f"{folder}: no diagnosis folder (no residuals.csv in it)")
        series, meta = moment_residuals.read(folder)
        flights = meta.get("flights", [])
        if len(flights) != 1:
            sys.exit(f"{folder}: give a single-flight diagnosis")
        name = os.path.splitext(os.path.basename(flights[0]))[0]
        out[name] = {}
        for channel, axis in zip(moment_residuals.CHANNELS, AXES):
            times = [p[0] for p in series[channel]]
            out[name][axis] = slow([on_a_grid(times, [p[1] for p in series[channel]], 100)], 100)
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
    ratio = arpl(os.path.join(data, "arpl", "log10.csv"))
    nanobench(os.path.join(data, "nanobench"), ratio, residual_slow)


if __name__ == "__main__":
    main(sys.argv[1:])
