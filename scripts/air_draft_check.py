#!/usr/bin/env python3
"""Is what the extended model still gets wrong about the roll and pitch moments moving air?

A draft of the room's air, w (body x, y; not in the model), is seen by the blade-flapping
moment and by the rotor-drag force alike (docs/effects.md). With the model flying at its
ground velocity and the rotors at sum of speeds S, model minus measured is

    pdot: +k_f S w_y / J_xx      qdot: -k_f S w_x / J_yy
    a_y:  -k_d S w_y / m         a_x:  -k_d S w_x / m

so, whatever S and w, the force residual is tied to the moment residual by a fixed ratio:

    a_y = -(k_d J_xx / (k_f m)) pdot        a_x = +(k_d J_yy / (k_f m)) qdot.

A trim or a CoG offset has no reason to keep that sign. (The frame's own drag, 1/2 c_w rho A
v|v| on the air-relative velocity, adds a speed-dependent force to a draft's, so the ratio
holds only where that is small.) This script takes the slow part of the residuals (running
means over 1 s, where the moment residual lives; docs/history.md, "Where the open-loop error comes from") on the training
and the held-out part and prints the regression of the force residual on the moment residual
(slope and correlation r) beside the ratio the draft predicts. The force residual is the
pose-derived world acceleration rotated into the heading frame (the flights tilt little).
Noise in the moment residual pulls a regression slope towards zero, so the reverse
regression's slope (1 / slope of pdot on a_y, its bound from the other side) is printed too.
Slow signals correlate by chance far more often than white ones, so the correlation is
judged by a sign-flip test of the moment's cosine (DCT-II) coefficients, which are nearly
uncorrelated for a slow series: 1999 random sign patterns from SplitMix64 with a fixed seed,
one-sided in the draft's direction, p = (1 + #{surrogate r >= r}) / 2000 — diagnose's own
draft check (diagnose/draft_signature.cpp, sign_flip_p) is the same test with the same bits.
Bartlett's effective sample size, n / (1 + 2 sum_k rho_f(k) rho_m(k)), is printed as a
measure of how slow the series are. The running means are taken on a uniform 0.1 s grid.

A common scale error of the airspeed terms (k_d and k_f off by one factor, or the rotor
speeds S off) leaves the same signature with w replaced by a multiple of the body velocity.
So the force and the moment means are first regressed on the body velocity along the axis
(and a constant), and the partial correlation of what is left is the one tested.

It also prints the draft speed the moment residual would imply, |w| from the RMS of the
slow pdot and qdot (mean included: an upper bound for a draft), with S the hover's sum of
rotor speeds (m g = k_T S^2 / 4, k_T from the Crazyflie thrust stand).

`--self-test` runs the test on synthetic slow series instead: a draft (the signature with
noise) and independent slow forces, to show the false-alarm rate at the 5 % level.

Reads a diagnosis folder (residuals.csv, diagnosis.json, fitted_parameters.yaml,
extended_model.json) whose final model has both rotor_drag and blade_flapping, or takes their
values from --airframe DIR (e.g. a joint diagnosis), and the NanoBench log it was fitted to.

Usage: air_draft_check.py DIAGNOSIS_DIR LOG.csv [--airframe DIR]
       air_draft_check.py --self-test"""
import bisect
import csv
import json
import math
import random
import re
import sys

WIDTH = 1.0  # s, running means
GRID = 0.1  # s, where they are taken
LEVEL = 0.05
# Thrust per squared rotor speed [N s^2], the Crazyflie thrust stand fitted by this project
# (README, "How well it works"); only for the draft speed's order of magnitude.
THRUST_STAND_K = 2.02e-8


def fitted_values(folder):
    """name -> value from fitted_parameters.yaml (one parameter per line, as diagnose writes it)."""
    values = {}
    for line in open(f"{folder}/fitted_parameters.yaml"):
        m = re.match(r"\s+([A-Za-z_][\w.@]*): \{value: ([-+0-9.eE]+)", line)
        if m:
            values[m.group(1)] = float(m.group(2))
    return values


def grid_means(ts, ys, grid):
    """Mean of the values in [g, g + WIDTH) for every grid time g (None where it holds none)."""
    out, start, end, total = [], 0, 0, 0.0
    for g in grid:
        while end < len(ts) and ts[end] < g + WIDTH:
            total += ys[end]
            end += 1
        while start < end and ts[start] < g:
            total -= ys[start]
            start += 1
        out.append(total / (end - start) if end > start else None)
    return out


def centred(v):
    m = sum(v) / len(v)
    return [x - m for x in v]


def residual_on(y, x):
    """y minus its least-squares fit on x and a constant."""
    xc, yc = centred(x), centred(y)
    sxx = sum(a * a for a in xc)
    b = sum(a * c for a, c in zip(xc, yc)) / sxx if sxx > 0 else 0.0
    return [c - b * a for a, c in zip(xc, yc)]


def acf(v, max_lag):
    c = centred(v)
    c0 = sum(x * x for x in c)
    return [sum(c[i] * c[i + k] for i in range(len(c) - k)) / c0 for k in range(max_lag + 1)]


MASK = (1 << 64) - 1


def splitmix64(state):
    """SplitMix64 (Steele, Lea & Flood 2014): the next state and its 64 random bits, the
    stream diagnose draws its signs from, so that both give the same p."""
    state = (state + 0x9E3779B97F4A7C15) & MASK
    z = ((state ^ (state >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return state, z ^ (z >> 31)


def cosine_table(n):
    """cos(pi j / (2n)) for j = 0 .. 4n-1: every cosine the DCT-II of n samples needs."""
    return [math.cos(math.pi * j / (2 * n)) for j in range(4 * n)]


def cosine_coefficients(z, table):
    """Orthonormal DCT-II coefficients k = 1 .. n-1 (the mean left out), from cosine_table(n)."""
    n, period = len(z), len(table)
    scale = math.sqrt(2 / n)
    return [scale * sum(z[t] * table[(k * (2 * t + 1)) % period] for t in range(n)) for k in range(1, n)]


def sign_flip_p(moment, force_res, velocity, flips=1999, seed=0x5EED0001):
    """One-sided p of the partial correlation of the moment means with `force_res` (turned so
    that a draft correlates positively; velocity and constant partialled out), the velocity
    partialled out of the moment too: the moment's cosine coefficients, nearly uncorrelated
    for a slow series, get random signs, and the surrogate correlations at or above the
    measured one are counted."""
    u = centred(velocity)
    norm = math.sqrt(sum(x * x for x in u))
    u = [x / norm if norm > 0 else 0.0 for x in u]
    table = cosine_table(len(moment))
    c, d, e = (cosine_coefficients(z, table) for z in (moment, force_res, u))
    w = [a * b for a, b in zip(c, d)]
    g = [a * b for a, b in zip(c, e)]
    cc, ff = sum(x * x for x in c), sum(x * x for x in force_res)

    def correlation(signs):
        num = sum(s * x for s, x in zip(signs, w))
        projection = sum(s * x for s, x in zip(signs, g))
        den = (cc - projection * projection) * ff
        return num / math.sqrt(den) if den > 0 else 0.0
    measured = correlation([1.0] * len(w))
    state, at_or_above = seed, 0
    for _ in range(flips):
        signs = []
        for k in range(len(w)):
            if k % 64 == 0:
                state, word = splitmix64(state)
            signs.append(-1.0 if (word >> (k % 64)) & 1 else 1.0)
        at_or_above += correlation(signs) >= measured - 1e-12
    return (1 + at_or_above) / (flips + 1)


def correlation_test(moment, force, velocity, sign):
    """The partial correlation r of the force means on the moment means (the velocity and a
    constant partialled out of both), Bartlett's effective n (how slow they are), the
    one-sided p in the direction `sign` by the sign-flip test, and the slopes."""
    x, y = residual_on(moment, velocity), residual_on(force, velocity)
    sxx, syy = sum(a * a for a in x), sum(b * b for b in y)
    sxy = sum(a * b for a, b in zip(x, y))
    r = sxy / math.sqrt(sxx * syy)
    lag = len(x) // 4
    ax, ay = acf(x, lag), acf(y, lag)
    inflate = 1 + 2 * sum(ax[k] * ay[k] for k in range(1, lag + 1))
    n_eff = min(len(x), max(3.0, len(x) / max(1.0, inflate)))
    p = sign_flip_p(moment, [sign * b for b in y], velocity)
    return r, n_eff, p, sxy / sxx, (syy / sxy if sxy else math.inf)


def pair_line(name, moment, force, velocity, ratio):
    sign = math.copysign(1, ratio)
    mc, fc = centred(moment), centred(force)
    r_raw = sum(a * b for a, b in zip(mc, fc)) / math.sqrt(sum(a * a for a in mc) * sum(b * b for b in fc))
    r, n_eff, p, slope, reverse = correlation_test(moment, force, velocity, sign)
    shows = p <= LEVEL
    return (f"{name}: r {r_raw:+.2f}, with the velocity partialled out {r:+.2f} (n_eff {n_eff:.1f}, p {p:.3f}"
            f"{', the draft' + chr(39) + 's sign' if shows else ''}), slope {slope:+.4f} (reverse {reverse:+.4f}; "
            f"draft {ratio:+.4f})"), shows


def main(folder, log_path, airframe):
    model = json.load(open(f"{folder}/extended_model.json"))
    m, (jxx, jyy) = model["mass"], (model["inertia"][0][0], model["inertia"][1][1])
    values = fitted_values(airframe or folder)
    if "rotor_drag.k" not in values or "blade_flapping.k" not in values:
        sys.exit(f"{airframe or folder}: the final model needs rotor_drag and blade_flapping (use --airframe)")
    kd, kf = values["rotor_drag.k"], values["blade_flapping.k"]
    ratio_y, ratio_x = -kd * jxx / (kf * m), kd * jyy / (kf * m)
    channels = {}
    for r in csv.DictReader(open(f"{folder}/residuals.csv")):
        if r["series"].startswith("extended"):
            channels.setdefault(r["panel"].split(" ")[0], []).append((float(r["x"]), float(r["y"])))
    log = list(csv.DictReader(open(log_path)))
    t_first = float(log[0]["t"])
    log_t = [float(r["t"]) - t_first for r in log]
    split = json.load(open(f"{folder}/diagnosis.json"))["samples"]["validation_from_s"]
    ts = [t for t, _ in channels["pdot"]]
    rows = [log[min(bisect.bisect_left(log_t, t), len(log) - 1)] for t in ts]
    yaw = [float(r["yaw"]) for r in rows]

    def heading_frame(x, y):
        return ([math.cos(p) * a + math.sin(p) * b for p, a, b in zip(yaw, x, y)],
                [-math.sin(p) * a + math.cos(p) * b for p, a, b in zip(yaw, x, y)])
    ax, ay = heading_frame([v for _, v in channels["ax_world"]], [v for _, v in channels["ay_world"]])
    vx, vy = heading_frame([float(r["vx"]) for r in rows], [float(r["vy"]) for r in rows])
    series = {"pdot": [v for _, v in channels["pdot"]], "qdot": [v for _, v in channels["qdot"]],
              "ax": ax, "ay": ay, "vx": vx, "vy": vy}
    speeds_sum = 4 * math.sqrt(m * 9.81 / 4 / THRUST_STAND_K)  # hover: m g = k_T S^2 / 4
    print(f"{folder}: draft ratios a_y/pdot {ratio_y:+.4f}, a_x/qdot {ratio_x:+.4f} "
          f"(k_d {kd:.3g}, k_f {kf:.3g}, m {m:.4g}, J {jxx:.3g} {jyy:.3g}); {WIDTH:g} s means every {GRID:g} s")
    for part, lo, hi in (("training", -math.inf, split), ("held-out", split, math.inf)):
        idx = [i for i, t in enumerate(ts) if lo <= t < hi]
        t_part = [ts[i] for i in idx]
        grid = [t_part[0] + GRID * k for k in range(int((t_part[-1] - WIDTH - t_part[0]) / GRID) + 1)]
        means = {k: grid_means(t_part, [v[i] for i in idx], grid) for k, v in series.items()}
        keep = [g for g in range(len(grid)) if all(means[k][g] is not None for k in means)]
        cols = {k: [v[g] for g in keep] for k, v in means.items()}
        y_line, _ = pair_line("a_y on pdot", cols["pdot"], cols["ay"], cols["vy"], ratio_y)
        x_line, _ = pair_line("a_x on qdot", cols["qdot"], cols["ax"], cols["vx"], ratio_x)
        rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v))
        w = math.hypot(rms(cols["pdot"]) * jxx, rms(cols["qdot"]) * jyy) / (kf * speeds_sum)
        print(f"  {part} ({len(keep)} means): {y_line}; {x_line}; draft speed the moments would imply at most "
              f"{w:.2f} m/s")


def self_test():
    """The test on synthetic 1 s means (100 Hz noise averaged): a draft, an independent slow
    force, and its false-alarm rate over many independent pairs."""
    rng = random.Random(1)
    ratio = -0.024

    def slow(n):  # AR(1), 2 s time constant at 100 Hz, averaged over 1 s and taken every 0.1 s
        w, out = 0.0, []
        raw = []
        for _ in range(n * 10 + 100):
            w = 0.995 * w + rng.gauss(0, 0.02)
            raw.append(w)
        return [sum(raw[k * 10:k * 10 + 100]) / 100 for k in range(n)]
    n = 120  # 12 s of means, like a held-out part
    velocity = [0.75 * math.cos(0.05 * k) for k in range(n)]  # a circle's, 12.6 s per turn
    alarms, tries = 0, 200
    for _ in range(tries):
        moment, force = [14.7 * x + rng.gauss(0, 0.3) for x in slow(n)], [0.35 * x for x in slow(n)]
        alarms += correlation_test(moment, force, velocity, -1)[2] <= LEVEL
    w = slow(n)
    moment = [14.7 * x + rng.gauss(0, 0.3) for x in w]
    force = [ratio * y + rng.gauss(0, 0.01) for y in moment]
    r, n_eff, p, slope, _ = correlation_test(moment, force, velocity, -1)
    print(f"a draft: r {r:+.2f}, n_eff {n_eff:.1f}, p {p:.3g}, slope {slope:+.4f} (true {ratio:+.4f})")
    print(f"independent slow forces: {alarms} of {tries} pass at the {LEVEL:g} level ({100 * alarms / tries:.1f} %)")


if __name__ == "__main__":
    args = sys.argv[1:]
    if args == ["--self-test"]:
        self_test()
        sys.exit(0)
    airframe = None
    if "--airframe" in args:
        i = args.index("--airframe")
        if i + 1 >= len(args):
            sys.exit(__doc__)
        airframe = args[i + 1]
        del args[i:i + 2]
    if len(args) != 2:
        sys.exit(__doc__)
    main(args[0], args[1], airframe)
