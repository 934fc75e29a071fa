#!/usr/bin/env python3
"""A yardstick for `predict --controller` (docs/simulation.md, "Flying the logged set points"):
how far 1 s ahead a predictor gets that knows no dynamics at all, only the attitude set points
and the measured thrust. From each start (every 5th airborne sample of the last 30 % of a
NanoBench flight, as predict's rollouts), position and velocity are integrated with the
accelerometer's measured body-z specific force turned by the logged roll and pitch set points
`delay` samples earlier (and the measured yaw), and compared with the measured position 1 s
later. Two inputs here are measured over the horizon that the model has to predict itself:
the thrust and the yaw. So this is an optimistic kinematic yardstick, not a model; it tells
what the set points alone carry. Also printed: the same with the measured (marker) attitude in
place of the set points.

With --slopes it prints instead, per flight, how far the logged motor commands move per count
of the firmware's collective command (`controller.cmd_thrust`): least squares of the mean
motor command's changes on cmd_thrust's over 200 ms, airborne rows with no motor near full
duty. The firmware logs the motor commands after its battery compensation and the command
before it, so this is the compensation's local slope, which `predict --controller-gain` takes.

Usage: set_point_kinematics.py [DELAY_SAMPLES | --slopes] (default 12: the lag, at 100 Hz, at
which B3_figure8_medium_rep2's measured roll best follows its set point) over every NanoBench
flight in ../shared/data/crazyflie/nanobench."""
import csv
import math
import sys
from pathlib import Path

from markdown_cell import cell  # folder and file names shown as text

DATA = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "crazyflie" / "nanobench"
G0 = 9.80665  # the accelerometer's unit, g
HORIZON = 100  # samples at 100 Hz: 1 s


def body_z_in_world(roll, pitch, yaw):
    cr, sr, cp, sp, cy, sy = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw), math.sin(yaw)
    return (cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr)  # third column of Rz Ry Rx


def load(path):
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def error_at_1s(rows, start, attitude_of):
    p = [rows[start]["px"], rows[start]["py"], rows[start]["pz"]]
    v = [rows[start]["vx"], rows[start]["vy"], rows[start]["vz"]]
    for k in range(start, start + HORIZON):
        dt = rows[k + 1]["t"] - rows[k]["t"]
        thrust = rows[k]["imu_acc_z"] * G0
        z = body_z_in_world(*attitude_of(k))
        a = [thrust * z[0], thrust * z[1], thrust * z[2] - 9.81]
        for j in range(3):
            p[j] += v[j] * dt + 0.5 * a[j] * dt * dt
            v[j] += a[j] * dt
    end = rows[start + HORIZON]
    return math.dist(p, (end["px"], end["py"], end["pz"]))


def flight(path, delay):
    rows = load(path)
    airborne = [r["pz"] > 0.1 and r["motor_motor_m1"] > 3000 for r in rows]
    # The firmware logs degrees and its pitch positive nose up (data/mappings/nanobench.yaml).
    set_points = lambda k: (math.radians(rows[k - delay]["pid_controller_roll"]),
                            -math.radians(rows[k - delay]["pid_controller_pitch"]), rows[k]["yaw"])
    measured = lambda k: (rows[k]["roll"], rows[k]["pitch"], rows[k]["yaw"])
    errors = {"set points": [], "measured attitude": []}
    # The held-out part as quadgen cuts it (fit::training_cut): the last 30 % of the airborne
    # flight, first to last airborne row (until 2026-12-05 this took the last 30 % of all rows,
    # the ground before take-off and after landing included).
    first = airborne.index(True)
    last = len(airborne) - 1 - airborne[::-1].index(True)
    cut = rows[first]["t"] + 0.7 * (rows[last]["t"] - rows[first]["t"])
    for start in range(next(k for k, r in enumerate(rows) if r["t"] >= cut), len(rows) - HORIZON, 5):
        if not all(airborne[start - delay:start + HORIZON + 1]):
            continue
        errors["set points"].append(error_at_1s(rows, start, set_points))
        errors["measured attitude"].append(error_at_1s(rows, start, measured))
    return {k: sum(e) / len(e) for k, e in errors.items() if e}, len(errors["set points"])


def collective_slope(path, lag=20):
    rows = load(path)
    thrust = [r["pid_controller_cmd_thrust"] for r in rows]
    motors = [[r[f"motor_motor_m{i}"] for i in range(1, 5)] for r in rows]
    usable = [r["pz"] > 0.2 and max(m) < 64000 and c > 20000 for r, m, c in zip(rows, motors, thrust)]
    sxy = sxx = 0.0
    for k in range(lag, len(rows)):
        if usable[k] and usable[k - lag]:
            dx = thrust[k] - thrust[k - lag]
            dy = (sum(motors[k]) - sum(motors[k - lag])) / 4
            sxy, sxx = sxy + dx * dy, sxx + dx * dx
    return sxy / sxx if sxx > 0 else None


def main():
    if sys.argv[1:] == ["--slopes"]:
        print("| flight | logged command counts per count of cmd_thrust (200 ms changes) |")
        print("|---|---|")
        for path in sorted(DATA.glob("*.csv")):
            slope = collective_slope(path)
            print(f"| {cell(path.stem)} | {'– (no usable rows: the motors saturate)' if slope is None else f'{slope:.3f}'} |")
        return
    delay = int(sys.argv[1]) if len(sys.argv) > 1 else 12
    print(f"| flight | set points ({10 * delay} ms earlier): pos 1 s [m] | measured attitude: pos 1 s [m] | starts |")
    print("|---|---|---|---|")
    for path in sorted(DATA.glob("*.csv")):
        means, starts = flight(path, delay)
        print(f"| {cell(path.stem)} | {means['set points']:.3f} | {means['measured attitude']:.3f} | {starts} |")


if __name__ == "__main__":
    main()
