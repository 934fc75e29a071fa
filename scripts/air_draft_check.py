#!/usr/bin/env python3
"""Is what the extended model still gets wrong about the roll and pitch moments moving air?

A draft of the room's air, w (body x, y; not in the model), is seen by the blade-flapping
moment and by the rotor-drag force alike (docs/effects.md). With the model flying at its
ground velocity and the rotors at sum of speeds S, model minus measured is

    pdot: +k_f S w_y / J_xx      qdot: -k_f S w_x / J_yy
    a_y:  -k_d S w_y / m         a_x:  -k_d S w_x / m

so, whatever S and w, the force residual is tied to the moment residual by a fixed ratio:

    a_y = -(k_d J_xx / (k_f m)) pdot        a_x = +(k_d J_yy / (k_f m)) qdot.

A trim, a CoG offset or a mis-fitted coefficient has no reason to keep that sign. This script
takes the slow part of the residuals (running means over 0.25 s and 1 s, where the moment
residual lives; docs/validation.md, "Where the open-loop error comes from") on the training
and the held-out part and prints the regression of the force residual on the moment residual
(slope and correlation r) beside the ratio the draft predicts. The force residual is the
pose-derived world acceleration rotated into the heading frame (the flights tilt little).
Noise in the moment residual pulls a regression slope towards zero, so the reverse
regression's slope (1 / slope of pdot on a_y, its bound from the other side) is printed too.
Slow signals of a repeated trajectory correlate by chance, so as a control the force residual
is shifted circularly against the moments by every whole 0.5 s from 2 s to half the part's
length, both ways: printed is the share of shifts whose correlation lies as far in the
draft's direction as the unshifted one (a permutation-style p; small means the alignment in
time matters).

It also prints the draft speed the moment residual implies, |w| from the RMS of the slow
pdot and qdot, with S the hover's sum of rotor speeds (m g = k_T S^2 / 4, k_T from the
Crazyflie thrust stand).

Reads a diagnosis folder (residuals.csv, diagnosis.json, fitted_parameters.yaml,
extended_model.json) whose final model has both rotor_drag and blade_flapping, or takes their
values from --airframe DIR (e.g. a joint diagnosis), and the NanoBench log it was fitted to.

Usage: air_draft_check.py DIAGNOSIS_DIR LOG.csv [--airframe DIR]"""
import bisect
import csv
import json
import math
import re
import sys

WIDTHS = (0.25, 1.0)  # s, running-mean windows
CONTROL_MIN_SHIFT, CONTROL_STEP = 2.0, 0.5  # s
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


def running_means(ts, ys, width):
    """Mean of the values in [t, t + width) for every sample t whose window is full."""
    out, total, end = [], 0.0, 0
    for i, t in enumerate(ts):
        while end < len(ts) and ts[end] < t + width:
            total += ys[end]
            end += 1
        if ts[-1] < t + width:
            break
        out.append(total / (end - i))
        total -= ys[i]
    return out


def regression(x, y):
    """Slope of y on x, the reverse regression's slope (1 / slope of x on y) and r."""
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    sxx = sum((a - mx) ** 2 for a in x)
    syy = sum((b - my) ** 2 for b in y)
    sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    return sxy / sxx, syy / sxy if sxy else math.inf, sxy / math.sqrt(sxx * syy)


def residual_channels(folder):
    channels = {}
    for r in csv.DictReader(open(f"{folder}/residuals.csv")):
        if r["series"].startswith("extended"):
            channels.setdefault(r["panel"].split(" ")[0], []).append((float(r["x"]), float(r["y"])))
    return channels


def shift_control(ts, moment, force, draft_sign):
    """Share of circular shifts of `force` against `moment` whose correlation lies as far in
    the draft's direction (sign of the draft ratio) as the unshifted one."""
    r0 = draft_sign * regression(moment, force)[2]
    span = ts[-1] - ts[0]
    dt = span / (len(ts) - 1)
    shifts, s = [], CONTROL_MIN_SHIFT
    while s <= span / 2:
        k = int(round(s / dt))
        shifts += [k, len(ts) - k]
        s += CONTROL_STEP
    if not shifts:
        return math.nan
    beyond = sum(draft_sign * regression(moment, force[k:] + force[:k])[2] >= r0 for k in shifts)
    return beyond / len(shifts)


def main(folder, log_path, airframe):
    model = json.load(open(f"{folder}/extended_model.json"))
    m, (jxx, jyy) = model["mass"], (model["inertia"][0][0], model["inertia"][1][1])
    values = fitted_values(airframe or folder)
    if "rotor_drag.k" not in values or "blade_flapping.k" not in values:
        sys.exit(f"{airframe or folder}: the final model needs rotor_drag and blade_flapping (use --airframe)")
    kd, kf = values["rotor_drag.k"], values["blade_flapping.k"]
    ratio_y, ratio_x = -kd * jxx / (kf * m), kd * jyy / (kf * m)
    channels = residual_channels(folder)
    log = list(csv.DictReader(open(log_path)))
    t_first = float(log[0]["t"])
    log_t = [float(r["t"]) - t_first for r in log]
    split = json.load(open(f"{folder}/diagnosis.json"))["samples"]["validation_from_s"]
    ts = [t for t, _ in channels["pdot"]]
    yaw = [float(log[min(bisect.bisect_left(log_t, t), len(log) - 1)]["yaw"]) for t in ts]
    ax, ay = [v for _, v in channels["ax_world"]], [v for _, v in channels["ay_world"]]
    heading_x = [math.cos(p) * a + math.sin(p) * b for p, a, b in zip(yaw, ax, ay)]
    heading_y = [-math.sin(p) * a + math.cos(p) * b for p, a, b in zip(yaw, ax, ay)]
    pdot, qdot = [v for _, v in channels["pdot"]], [v for _, v in channels["qdot"]]
    speeds_sum = 4 * math.sqrt(m * 9.81 / 4 / THRUST_STAND_K)  # hover: m g = k_T S^2 / 4
    print(f"{folder}: draft ratios a_y/pdot {ratio_y:+.4f}, a_x/qdot {ratio_x:+.4f} "
          f"(k_d {kd:.3g}, k_f {kf:.3g}, m {m:.4g}, J {jxx:.3g} {jyy:.3g})")
    for part, inside in (("training", lambda t: t < split), ("held-out", lambda t: t >= split)):
        idx = [i for i, t in enumerate(ts) if inside(t)]
        t_part = [ts[i] for i in idx]
        for width in WIDTHS:
            cols = {name: running_means(t_part, [series[i] for i in idx], width)
                    for name, series in (("pdot", pdot), ("qdot", qdot), ("ax", heading_x), ("ay", heading_y))}
            n = len(cols["pdot"])
            t_means = t_part[:n]
            line = [f"  {part}, {width} s means (n {n}):"]
            for force, moment, ratio in (("ay", "pdot", ratio_y), ("ax", "qdot", ratio_x)):
                slope, reverse, r = regression(cols[moment], cols[force])
                p = shift_control(t_means, cols[moment], cols[force], math.copysign(1, ratio))
                line.append(f"{force} on {moment}: slope {slope:+.4f} (reverse {reverse:+.4f}; draft {ratio:+.4f}) "
                            f"r {r:+.2f}, shifts as far {p:.2f}")
            rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v))
            w = math.hypot(rms(cols["pdot"]) * jxx, rms(cols["qdot"]) * jyy) / (kf * speeds_sum)
            line.append(f"draft speed the moments imply {w:.2f} m/s")
            print(line[0] + " " + "; ".join(line[1:]))


if __name__ == "__main__":
    args = sys.argv[1:]
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
