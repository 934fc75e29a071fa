"""The roll and pitch moment residuals a diagnosis leaves, as the scripts that study them
read them: the extended model's pdot and qdot equation-error residuals (rad/s^2) from a
diagnosis folder's residuals.csv, with where its held-out part starts (diagnosis.json's
samples.validation_from_s). Shared by disturbance_floor.py and slow_moment_residual.py."""
import csv
import json

CHANNELS = ("pdot", "qdot")


def read(diagnosis):
    """(series, meta): series maps "pdot" and "qdot" to their (t, residual) points sorted by
    time; meta is diagnosis.json."""
    series = {c: [] for c in CHANNELS}
    with open(f"{diagnosis}/residuals.csv", newline="") as f:
        for r in csv.DictReader(f):
            channel = r["panel"].split(" ")[0]
            if r["series"].startswith("extended") and channel in series:
                series[channel].append((float(r["x"]), float(r["y"])))
    for points in series.values():
        points.sort()
    with open(f"{diagnosis}/diagnosis.json") as f:
        meta = json.load(f)
    return series, meta


def held_out_from(meta):
    return meta["samples"]["validation_from_s"]
