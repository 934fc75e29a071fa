#!/usr/bin/env python3
"""The motor map's slope chosen without the flight it is judged on (README, the targets' table).

vehicles/crazyflie21_nanobench.yaml turns the stock motor map to a slope of 0.6, read from the
five usable NanoBench flights, and the README's one-step target (roll and pitch residuals 5x
below the nominal model's) is scored on the held-out parts of those same flights. Here each
flight gets the slope the *other four* give (the mean of their roll and pitch gains at ~4-8 Hz,
scripts/motor_map_slope.py), written into a copy of the vehicle file; the flight is diagnosed
with it (`quadgen diagnose`), and its held-out one-step roll and pitch residuals are set against
the nominal model's (`quadgen predict` with the stock vehicles/crazyflie21.yaml, nothing
measured on the airframe). Prints one table: the slope, the residuals, their ratio (target
>= 5), the 1 s open-loop error, and the effects named.

  scripts/held_out_slope.py [OUT_DIR]      (default out/held_out_slope)

SLOPES="B2_circle_medium_rep1:0.586 ..." takes those slopes instead of measuring them (another
measure's; each NAME one of the five flights); QUADGEN=BINARY selects the quadgen binary
(default build/quadgen). A flight whose OUT_DIR/NAME/diagnosis_slope_S/diagnosis.json exists for
its slope S is not diagnosed again (another slope gets a folder of its own). About 3-5 minutes on 2
cores: the copied file is no compiled-in model, so each diagnosis runs on the expression tape.
Needs the build (./setup.sh --no-run) and ../shared/data beside the clone; standard library
and PyYAML only (as motor_map_slope.py)."""
import json
import os
import pathlib
import re
import subprocess
import sys

import motor_map_slope as mms
from markdown_cell import cell  # folder and file names shown as text
from prediction_table import value  # a horizon's statistic, as the benchmark's table reads it

ROOT = mms.ROOT
VEHICLE = ROOT / "vehicles" / "crazyflie21_nanobench.yaml"
NOMINAL = ROOT / "vehicles" / "crazyflie21.yaml"
MAPPING = ROOT / "data" / "mappings" / "nanobench.yaml"
BAND_4_8_HZ = 1  # index into motor_map_slope.BANDS


def measured_gains():
    """Each flight's mean of its roll and pitch gains at ~4-8 Hz against the stock map."""
    gains = {}
    for name in mms.FLIGHTS:
        out, _ = mms.analyse(str(mms.DATA / f"{name}.csv"))
        gains[name] = (out["roll"][BAND_4_8_HZ][0] + out["pitch"][BAND_4_8_HZ][0]) / 2
    return gains


def leave_one_out(gains):
    """The slope for each flight: the mean of the other flights' gains, to three decimals."""
    return {name: round(sum(g for other, g in gains.items() if other != name) / (len(gains) - 1), 3)
            for name in gains}


def vehicle_with_slope(slope, folder):
    """A copy of the NanoBench vehicle file with its map's slope set (the one line changed)."""
    text = VEHICLE.read_text()
    changed, count = re.subn(r"^(\s*slope: \{value: )0\.6(,)", rf"\g<1>{slope}\g<2>", text, flags=re.M)
    if count != 1:
        sys.exit(f"{VEHICLE}: expected one 'slope: {{value: 0.6, ...}}' line, found {count}")
    path = folder / f"crazyflie21_nanobench_slope_{slope}.yaml"
    partial = path.with_name(path.name + ".partial")  # a run cut short leaves no half file
    partial.write_text(changed)
    os.replace(partial, path)
    return path


def run(quadgen, args, log_path):
    with open(log_path, "w") as log:
        done = subprocess.run([quadgen, *map(str, args)], stdout=log, stderr=subprocess.STDOUT, cwd=ROOT)
    if done.returncode != 0:
        sys.exit(f"quadgen {args[0]} failed (exit {done.returncode}); its output: {log_path}")


def one_flight(quadgen, name, slope, out):
    folder = out / name
    folder.mkdir(parents=True, exist_ok=True)
    flight = mms.DATA / f"{name}.csv"
    # One folder per slope: a second run with other slopes into the same OUT_DIR printed the
    # first run's diagnosis beside the new slope (hostile-input audit, helper-105).
    diagnosed = folder / f"diagnosis_slope_{slope}"
    if not (diagnosed / "diagnosis.json").exists():
        vehicle = vehicle_with_slope(slope, folder)
        run(quadgen, ["diagnose", vehicle, flight, "--mapping", MAPPING, "--out", diagnosed],
            folder / f"diagnosis_slope_{slope}.log")
    if not (folder / "nominal" / "prediction.json").exists():
        run(quadgen, ["predict", NOMINAL, flight, "--mapping", MAPPING, "--out", folder / "nominal"],
            folder / "nominal.log")
    diagnosis = json.loads((diagnosed / "diagnosis.json").read_text())
    nominal = json.loads((folder / "nominal" / "prediction.json").read_text())
    return diagnosis, nominal


def row(name, slope, diagnosis, nominal):
    after = diagnosis["prediction"]["after"]
    ext = after["one_step"]["angular_acceleration_rad_s2"]
    nom = nominal["one_step"]["angular_acceleration_rad_s2"]
    open_loop = value(after, "open_loop", 1.0, "position_m", "mean")
    effects = ", ".join(cell(f["effect"]) for f in diagnosis["findings"])
    return (f"| {cell(name)} | {slope:.3f} | {nom['x']:.3g} / {nom['y']:.3g} | {ext['x']:.3g} / {ext['y']:.3g} | "
            f"{nom['x'] / ext['x']:.1f} / {nom['y'] / ext['y']:.1f} | {open_loop} | {effects} |")


def given_slopes(text):
    """SLOPES="NAME:SLOPE ...": each NAME a flight of motor_map_slope.FLIGHTS (a name is a
    folder under OUT_DIR: a path in its place would write elsewhere), each SLOPE a number."""
    slopes = {}
    for pair in text.split():
        name, colon, number = pair.rpartition(":")
        try:
            slope = float(number)
        except ValueError:
            slope = float("nan")
        if not colon or name not in mms.FLIGHTS or not 0 < slope < 10 or name in slopes:
            sys.exit(f"SLOPES: {pair!r} is not NAME:SLOPE with NAME one of {', '.join(mms.FLIGHTS)} "
                     "(each once) and SLOPE a positive number")
        slopes[name] = slope
    return slopes


def main():
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "out" / "held_out_slope").resolve()
    quadgen = str((ROOT / os.environ.get("QUADGEN", "build/quadgen")).resolve())
    if os.environ.get("SLOPES"):
        slopes = given_slopes(os.environ["SLOPES"])
        source = "given (SLOPES)"
    else:
        gains = measured_gains()
        slopes = leave_one_out(gains)
        source = "the other four flights' mean roll/pitch gain at ~4-8 Hz (" + ", ".join(
            f"{cell(n)} {g:.3f}" for n, g in gains.items()) + ")"
    print(f"slope of each flight: {source}")
    print("| flight | slope | one step ṗ / q̇ nominal [rad/s²] | extended | ratio (target ≥ 5) | 1 s open loop [m] | named |")
    print("|---|---|---|---|---|---|---|")
    for name, slope in slopes.items():
        print(f"== {name}: slope {slope}", file=sys.stderr, flush=True)
        diagnosis, nominal = one_flight(quadgen, name, slope, out)
        print(row(name, slope, diagnosis, nominal), flush=True)


if __name__ == "__main__":
    if any(a in ("-h", "--help") for a in sys.argv[1:]):
        print(__doc__)
        sys.exit(0)
    main()
