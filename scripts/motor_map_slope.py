#!/usr/bin/env python3
"""How strongly a change of motor command moves the Crazyflie in flight, against what the
vehicle file's stand motor map says, band by band (docs/crazyflie_evidence.md section 7).

For each NanoBench log: the thrust each rotor gives by the stand map (thrust proportional to
the squared rotor speed of `motor_map` in vehicles/crazyflie21.yaml, the common factor fitted
away), summed into the roll and pitch moment of the firmware's motor layout and into the
collective thrust. Both are band-passed with the measured angular acceleration (the
differentiated gyro) and vertical specific force (accelerometer z) by differences of running
means, shifted by the delay (0-8 samples) that correlates best in the band, and the
regression slope of the measured on the map's is divided by the slope the map predicts:
  - collective: the hover ratio of accelerometer z to summed thrust (what a fitted thrust
    constant gives), so 1 means the map's slope at the operating point is right;
  - roll, pitch: that thrust constant times the arm over the blocks' inertia.
A gain below 1 in every band says the map changes the thrust faster with the command than
the airframe does. The lowest band (below ~2 Hz) carries the controller's answer to slow
disturbances (a closed loop holds the response there near zero), so the 3-12 Hz bands are
the ones to read.

  scripts/motor_map_slope.py [LOG.csv ...]   (default: the five usable NanoBench flights)
A log in quadgen's canonical layout (a simulated flight) is read too: a closed-loop flight
simulated with vehicles/crazyflie21_nanobench.yaml, whose motors have 0.6 of the stock map's
slope, is the check that the measure recovers a known slope (docs/crazyflie_evidence.md).
Standard library and PyYAML only."""
import csv
import math
import pathlib
import sys

import yaml

from markdown_cell import cell  # folder and file names shown as text

ROOT = pathlib.Path(__file__).resolve().parent.parent
DATA = ROOT.parent / "shared" / "data" / "crazyflie" / "nanobench"
FLIGHTS = ["B2_circle_medium_rep1", "B3_figure8_medium_rep1", "B3_figure8_medium_rep2",
           "B3_figure8_slow_rep1", "B5_helix_slow_rep1"]
G = 9.80665
# Band edges as half-widths of running means [samples at 100 Hz]: [3, 6] is ~6-12 Hz,
# [6, 12] ~3-6 Hz, [12, 25] ~1.5-3 Hz, [25, 60] below ~1.5 Hz.
BANDS = [(3, 6), (6, 12), (12, 25), (25, 60)]


def vehicle():
    v = yaml.safe_load((ROOT / "vehicles" / "crazyflie21.yaml").read_text())
    m = v["motor_map"]
    a = [m[k]["value"] for k in ("a0", "a1", "a2")]  # rpm
    mass = sum(b["mass"] for b in v["blocks"])
    # The blocks' inertia as the vehicle's derivation reports it (generated/crazyflie21).
    j_xx, j_yy = 1.4324e-5, 1.4738e-5
    arm = abs(v["rotors"][0]["position"][1])
    return a, mass, j_xx, j_yy, arm


def running_mean(x, w):
    c = [0.0]
    for v in x:
        c.append(c[-1] + v)
    n = len(x)
    return [(c[min(n, i + w + 1)] - c[max(0, i - w)]) / (min(n, i + w + 1) - max(0, i - w)) for i in range(n)]


def band(x, lo, hi):
    a, b = running_mean(x, lo), running_mean(x, hi)
    return [p - q for p, q in zip(a, b)]


def slope(x, y):
    mx, my = sum(x) / len(x), sum(y) / len(y)
    sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    sxx = sum((a - mx) ** 2 for a in x)
    syy = sum((b - my) ** 2 for b in y)
    return sxy / sxx, sxy / math.sqrt(sxx * syy)


def best_gain(drive, response, idx, lo, hi):
    """Slope and correlation of the band-passed response on the drive delayed by 0-8 samples,
    at the delay of the highest correlation."""
    y = band(response, lo, hi)
    best = None
    for d in range(9):
        shifted = [drive[max(0, k - d)] for k in range(len(drive))]
        x = band(shifted, lo, hi)
        b, r = slope([x[k] for k in idx], [y[k] for k in idx])
        if best is None or r > best[1]:
            best = (b, r, d)
    return best


def columns(rows):
    """Column names of commands, gyro and vertical specific force, the latter's scale to
    m/s^2, and the height: a NanoBench log's, or quadgen's canonical layout (a simulated flight)."""
    if "u_M1" in rows[0]:
        return [f"u_M{i}" for i in (1, 2, 3, 4)], 1.0, ("p", "q"), "az", 1.0, "z"
    return [f"motor_motor_m{i}" for i in (1, 2, 3, 4)], 1 / 65535, ("imu_gyro_x", "imu_gyro_y"), "imu_acc_z", G, "pz"


def analyse(path):
    (a0, a1, a2), mass, j_xx, j_yy, arm = vehicle()
    rows = list(csv.DictReader(open(path)))
    motor_cols, u_scale, (gyro_x, gyro_y), acc_z, acc_scale, z_col = columns(rows)
    t = [float(r["t"]) for r in rows]
    u = [[float(r[c]) * u_scale for r in rows] for c in motor_cols]
    thrust = [[(a0 + a1 * x + a2 * x * x) ** 2 for x in ui] for ui in u]  # up to the thrust constant
    n = len(t)
    # Firmware layout: M1 front right, M2 rear right, M3 rear left, M4 front left (x forward, y left).
    roll = [-thrust[0][k] - thrust[1][k] + thrust[2][k] + thrust[3][k] for k in range(n)]
    pitch = [-thrust[0][k] + thrust[1][k] + thrust[2][k] - thrust[3][k] for k in range(n)]
    total = [sum(thrust[i][k] for i in range(4)) for k in range(n)]

    def rate_dot(col):
        w = [float(r[col]) for r in rows]
        return [0.0] + [(w[k + 1] - w[k - 1]) / (t[k + 1] - t[k - 1]) for k in range(1, n - 1)] + [0.0]
    p_dot, q_dot = rate_dot(gyro_x), rate_dot(gyro_y)
    a_z = [float(r[acc_z]) * acc_scale for r in rows]
    # Airborne (above 0.1 m, as quadgen's loader keeps samples: on the ground the
    # accelerometer does not follow the thrust), no rotor saturated, away from the ends (the
    # widest running mean). Before 2026-11-28 the height was not checked, and the take-off and
    # landing rows pulled the collective's gain down to 0.3-0.4 (docs/crazyflie_evidence.md).
    z = [float(r[z_col]) for r in rows]
    idx = [k for k in range(70, n - 70) if min(u[i][k] for i in range(4)) > 0.3 and max(u[i][k] for i in range(4)) < 0.99
           and min(z[max(0, k - 60):k + 61]) > 0.1]
    k_over_m = sum(a_z[k] for k in idx) / sum(total[k] for k in idx)  # the hover's thrust constant / mass
    expected = {"collective": k_over_m, "roll": k_over_m * mass * arm / j_xx, "pitch": k_over_m * mass * arm / j_yy}
    out = {}
    for name, drive, response in (("roll", roll, p_dot), ("pitch", pitch, q_dot), ("collective", total, a_z)):
        out[name] = [best_gain(drive, response, idx, lo, hi) for lo, hi in BANDS]
        out[name] = [(b / expected[name], r, d) for b, r, d in out[name]]
    hover_u = sum(sum(u[i][k] for i in range(4)) / 4 for k in idx) / len(idx)
    return out, hover_u


def main(paths):
    print("gain in flight / gain of the stand map (correlation, delay in samples), per band")
    print("| flight | hover u | axis | " + " | ".join(f"~{50 / hi:.1f}-{50 / lo:.0f} Hz" for lo, hi in BANDS) + " |")
    print("|---|---|---|" + "---|" * len(BANDS))
    for path in paths:
        out, hover_u = analyse(path)
        for axis in ("roll", "pitch", "collective"):
            cells = " | ".join(f"{g:.2f} (r {r:.2f}, {d})" for g, r, d in out[axis])
            print(f"| {cell(pathlib.Path(path).stem)} | {hover_u:.2f} | {axis} | {cells} |")


if __name__ == "__main__":
    if any(a in ("-h", "--help") for a in sys.argv[1:]):
        print(__doc__)
        sys.exit(0)
    main(sys.argv[1:] or [str(DATA / f"{f}.csv") for f in FLIGHTS])
