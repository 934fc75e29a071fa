#!/usr/bin/env python3
"""How far the roll and pitch moment residual a diagnosis leaves carries an open-loop
rollout by itself: an estimate (linearised, no damping) of the 1 s position error it makes,
as it is and after simple corrections a better model might make.

Reads a diagnosis folder's residuals.csv (the extended model's equation-error residuals of
pdot and qdot, rad/s^2) and diagnosis.json (where the held-out part starts). From every start
on the held-out part (every --stride seconds, with --horizon seconds of samples ahead), the
residual is integrated as a rollout would meet it, linearised about hover: body-rate error
= the integral of the residual, tilt error = the integral of that, horizontal acceleration
error = g times the tilt error, position error = its double integral; roll moves y, pitch x.
Printed: mean and RMS over the starts of the position error's length at the horizon, for

  - the residual as it is;
  - less its mean over the held-out part (a model that knew the flight's mean imbalance);
  - less its mean over the 0.5 s before each start (the past disturbance held, as
    `quadgen predict --disturbance-window 0.5` does for the whole acceleration);
  - less its plain mean over each start's own horizon (an oracle that knew every second's
    mean moment error; what is left is the wander within the second. Not a bound: another
    single number per second, the mean weighted by (T - s)^3, would zero the error at T);

beside the diagnosis's own 1 s open-loop error (prediction.csv, extended model), which
this linear floor should approach when the moment residual is what sets it.

A single-flight diagnosis only (a joint one shares a clock over its flights). residuals.csv
is plot data, thinned above 3000 samples a channel: a thinned file is refused.

Usage: disturbance_floor.py DIAGNOSIS_DIR [--horizon 1.0] [--stride 0.05]"""
import csv
import math
import sys

import moment_residuals

G = 9.80665
MAX_GAP = 0.05  # s: a start whose horizon holds a longer gap is skipped (take-off, landing)


def held_out_residuals(diagnosis):
    series, meta = moment_residuals.read(diagnosis)
    if len(meta.get("flights", [])) > 1:
        sys.exit(f"{diagnosis}: a joint diagnosis of {len(meta['flights'])} flights; give a single flight's")
    start = moment_residuals.held_out_from(meta)
    all_samples = meta["samples"]["training"] + meta["samples"]["validation"]
    # One residual per interval between samples: a few fewer than samples (gaps, ends); a
    # plot thinned by a stride of 2 or more holds half of them or fewer.
    if len(series["pdot"]) < 0.9 * all_samples:
        sys.exit(f"{diagnosis}: residuals.csv holds {len(series['pdot'])} residuals of {all_samples} samples: thinned "
                 "for its plot, too coarse to integrate")
    p, q = ([point for point in series[c] if point[0] >= start] for c in moment_residuals.CHANNELS)
    if len(p) != len(q) or any(abs(a[0] - b[0]) > 1e-9 for a, b in zip(p, q)):
        sys.exit(f"{diagnosis}: pdot and qdot residuals are not on one time grid")
    return [t for t, _ in p], [v for _, v in p], [v for _, v in q]


def integrate_four_times(t, b):
    """The fourfold integral of b over t (trapezoids), from 0 at t[0]: rate, angle, velocity
    (before g), position (before g)."""
    level = list(b)
    for _ in range(4):
        out = [0.0]
        for k in range(1, len(t)):
            out.append(out[-1] + 0.5 * (level[k] + level[k - 1]) * (t[k] - t[k - 1]))
        level = out
    return level[-1]


def floors(t, p, q, horizon, stride):
    mean_p, mean_q = sum(p) / len(p), sum(q) / len(q)
    views = {"as it is": [], "less the held-out mean": [], "less the past 0.5 s mean": [], "less each horizon's plain mean": []}
    next_start = t[0] + 0.5  # the past window must exist
    for i, t0 in enumerate(t):
        if t0 < next_start:
            continue
        end = i
        while end + 1 < len(t) and t[end + 1] <= t0 + horizon + 1e-9:
            end += 1
        if t[end] < t0 + horizon - 0.02:
            break
        window = range(i, end + 1)
        if any(t[k] - t[k - 1] > MAX_GAP for k in range(i + 1, end + 1)):
            continue
        next_start = t0 + stride
        past = [k for k in range(i) if t[k] >= t0 - 0.5]
        ts = [t[k] for k in window]
        corrections = {
            "as it is": (0.0, 0.0),
            "less the held-out mean": (mean_p, mean_q),
            "less the past 0.5 s mean": (sum(p[k] for k in past) / len(past), sum(q[k] for k in past) / len(past)),
            "less each horizon's plain mean": (sum(p[k] for k in window) / len(window), sum(q[k] for k in window) / len(window)),
        }
        for view, (cp, cq) in corrections.items():
            y = G * integrate_four_times(ts, [p[k] - cp for k in window])
            x = G * integrate_four_times(ts, [q[k] - cq for k in window])
            views[view].append(math.hypot(x, y))
    return views


def measured_open_loop(diagnosis, horizon):
    for r in csv.DictReader(open(f"{diagnosis}/prediction.csv")):
        if (r["panel"].startswith("open loop: mean position error") and r["series"] == "extended model"
                and abs(float(r["x"]) - horizon) < 1e-9):
            return float(r["y"])
    return float("nan")


def main(argv):
    if not argv or argv[0] in ("-h", "--help"):
        sys.exit(__doc__)
    diagnosis, horizon, stride = argv[0], 1.0, 0.05
    options = argv[1:]
    while options:
        if len(options) < 2 or options[0] not in ("--horizon", "--stride"):
            sys.exit(__doc__)
        value = float(options[1])
        if options[0] == "--horizon":
            horizon = value
        else:
            stride = value
        options = options[2:]
    t, p, q = held_out_residuals(diagnosis)
    views = floors(t, p, q, horizon, stride)
    starts = len(views["as it is"])
    if not starts:
        sys.exit(f"{diagnosis}: no start on the held-out part has {horizon} s of samples ahead")
    print(f"{diagnosis}: {starts} starts; open-loop position error at {horizon} s of the extended model "
          f"(prediction.csv, mean): {measured_open_loop(diagnosis, horizon):.3f} m")
    for view, errors in views.items():
        rms = math.sqrt(sum(e * e for e in errors) / len(errors))
        print(f"  moment residual {view}: mean {sum(errors) / len(errors):.3f} m, RMS {rms:.3f} m")


if __name__ == "__main__":
    main(sys.argv[1:])
