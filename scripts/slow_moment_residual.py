#!/usr/bin/env python3
"""What is left of the roll and pitch moments after a diagnosis, and whether anything simple
predicts it on the held-out part. Reads a diagnosis folder's residuals.csv (the extended
model's equation-error residuals; the held-out part starts at diagnosis.json's
samples.validation_from_s) and the log it was fitted to (the NanoBench column names), and prints per channel (pdot, qdot):

  - the held-out mean and RMS of the residual, and the RMS of its 0.25 s running mean: when
    that is close to the RMS, the residual is slow, and an open-loop rollout integrates it
    into a body-rate and attitude drift instead of averaging it out;
  - the held-out RMS after a correction fitted by least squares on the training part and
    applied unchanged to the held-out part: a constant; a linear trend in time; the battery
    voltage; u_i^2 per rotor (motor trims again); u_i^2 and u_i^2 * vbat (per-rotor battery
    dependence); u_i^2 and u_i^2 * t (per-rotor drift); the position in the arena, linear (a
    draft in one part of the room; a figure-8 passes the same places in both parts). A
    correction that lowers the held-out
    RMS predicts part of the slow residual; one that raises it does not.

Usage: slow_moment_residual.py DIAGNOSIS_DIR LOG.csv"""
import bisect
import csv
import math
import sys

import moment_residuals

CORRECTIONS = ["constant", "time", "vbat", "u2", "u2 vbat", "u2 time", "position"]


def solve(rows, targets):
    """Least squares by the normal equations (a handful of columns, scaled by the ridge)."""
    n = len(rows[0])
    g = [[sum(r[i] * r[j] for r in rows) for j in range(n)] + [sum(r[i] * y for r, y in zip(rows, targets))]
         for i in range(n)]
    for i in range(n):
        g[i][i] += 1e-9 * (g[i][i] + 1)
    for i in range(n):
        p = max(range(i, n), key=lambda r: abs(g[r][i]))
        g[i], g[p] = g[p], g[i]
        for r in range(n):
            if r != i:
                f = g[r][i] / g[i][i]
                g[r] = [a - f * b for a, b in zip(g[r], g[i])]
    return [g[i][n] / g[i][i] for i in range(n)]


def regressors(sample, t, kind):
    u = [float(sample[f"motor_motor_m{i}"]) / 65535 for i in (1, 2, 3, 4)]
    vbat = float(sample["pwr_pm_vbat"])
    u2 = [x * x for x in u]
    if kind == "position":
        return [1] + [float(sample[c]) for c in ("px", "py", "pz")]
    return {"constant": [1], "time": [1, t], "vbat": [1, vbat], "u2": [1] + u2,
            "u2 vbat": [1] + u2 + [x * vbat for x in u2], "u2 time": [1] + u2 + [x * t for x in u2]}[kind]


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values))


def running_means(points, width):
    """Means of the values whose times lie in [t, t + width), for a start t every fifth point
    (residuals.csv may be thinned, so the window is a time span, not a sample count)."""
    means, end, total = [], 0, 0.0
    for i, (t, _) in enumerate(points):
        while end < len(points) and points[end][0] < t + width:
            total += points[end][1]
            end += 1
        if points[-1][0] < t + width:
            break  # the last window must be full
        if i % 5 == 0:
            means.append(total / (end - i))
        total -= points[i][1]
    return means


def main(diagnosis, log_path):
    log = list(csv.DictReader(open(log_path)))
    t_first = float(log[0]["t"])
    log_t = [float(r["t"]) - t_first for r in log]
    series, meta = moment_residuals.read(diagnosis)
    held_out_from = moment_residuals.held_out_from(meta)
    for channel in moment_residuals.CHANNELS:
        data = [(t, log[min(bisect.bisect_left(log_t, t), len(log) - 1)], y) for t, y in series[channel]]
        train = [d for d in data if d[0] < held_out_from]
        held = [d for d in data if d[0] >= held_out_from]
        y = [v for *_, v in held]
        running = running_means([(t, v) for t, _, v in held], 0.25)
        line = [f"{channel}: held-out mean {sum(y) / len(y):.2f}, RMS {rms(y):.2f}, 0.25 s running mean RMS {rms(running):.2f};"
                " after a correction fitted on the training part:"]
        for kind in CORRECTIONS:
            c = solve([regressors(s, t, kind) for t, s, _ in train], [v for *_, v in train])
            left = [v - sum(a * b for a, b in zip(regressors(s, t, kind), c)) for t, s, v in held]
            line.append(f"{kind} {rms(left):.2f}")
        print(" ".join(line[:1]), ", ".join(line[1:]))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
