#!/usr/bin/env python3
"""Prints the prediction benchmark's table (scripts/prediction_benchmark.sh) as Markdown:
per flight, the nominal model, the diagnosis' base fit and its extended model, and any
further model in a folder of its own beside them, with the targets and the published anchors.
The body-rates-held and attitude-held columns are the model without its moments (angular
acceleration zero, or the attitude kept at the start's); the constant-velocity columns use no
model (the measured start moved on at its velocity): the baseline any model's open loop has
to beat at that horizon. Usage: prediction_table.py OUT_DIR"""
import json
import math
import sys
from pathlib import Path

from markdown_cell import cell  # folder and file names shown as text

COLUMNS = [  # (header, view, horizon or axis, quantity, statistic)
    ("pos 0.1 s [m]", "open_loop", 0.1, "position_m", "mean"),
    ("pos 0.5 s [m]", "open_loop", 0.5, "position_m", "mean"),
    ("pos 1 s [m]", "open_loop", 1.0, "position_m", "mean"),
    ("body rates held: pos 0.5 s [m]", "body_rates_held", 0.5, "position_m", "mean"),
    ("body rates held: pos 1 s [m]", "body_rates_held", 1.0, "position_m", "mean"),
    ("attitude held: pos 0.5 s [m]", "attitude_held", 0.5, "position_m", "mean"),
    ("attitude held: pos 1 s [m]", "attitude_held", 1.0, "position_m", "mean"),
    ("constant velocity, no model: pos 0.5 s [m]", "constant_velocity", 0.5, "position_m", "mean"),
    ("constant velocity, no model: pos 1 s [m]", "constant_velocity", 1.0, "position_m", "mean"),
    ("past disturbance held: pos 1 s [m]", "open_loop_past_disturbance", 1.0, "position_m", "mean"),
    ("tilt 0.5 s [rad]", "open_loop", 0.5, "tilt_rad", "mean"),
    ("attitude 0.5 s, whole rotation [rad]", "open_loop", 0.5, "attitude_rad", "mean"),
    ("moments alone: tilt 0.5 s [rad]", "translation_replayed", 0.5, "tilt_rad", "mean"),
    ("heading 1 s [rad]", "open_loop", 1.0, "heading_rad", "mean"),
    ("replayed pos 1 s [m]", "attitude_replayed", 1.0, "position_m", "mean"),
    ("set points flown: pos 0.5 s [m]", "set_points_flown", 0.5, "position_m", "mean"),
    ("set points flown: pos 1 s [m]", "set_points_flown", 1.0, "position_m", "mean"),
    ("f_x [m/s²]", "one_step", "x", "specific_force_m_s2", None),
    ("f_y [m/s²]", "one_step", "y", "specific_force_m_s2", None),
    ("f_z [m/s²]", "one_step", "z", "specific_force_m_s2", None),
    ("ṗ [rad/s²]", "one_step", "x", "angular_acceleration_rad_s2", None),
    ("q̇ [rad/s²]", "one_step", "y", "angular_acceleration_rad_s2", None),
    ("vertical [m/s²]", "one_step", None, "vertical_acceleration_world_m_s2", None),
]
TARGETS = ["≤ 0.01", "≤ 0.10", "≤ 0.10 (#14; 0.30 in the first prediction issue)", "—", "—", "—", "—", "—", "—", "—", "≤ 0.10", "—", "≤ 0.10", "≤ 0.05", "≤ 0.10", "—", "—", "≤ 0.25", "≤ 0.25", "≤ 0.5", "≤ 4", "≤ 4", "—"]
# How each is made: docs/validation.md, "Published anchors" (the NanoBench MLP's are one rollout
# its repository prints, not a benchmark statistic).
PUBLISHED = ["IDSIA physics, ω̇ = 0: 0.0126", "IDSIA hybrid 0.112; NanoBench MLP, one rollout 0.193", "NanoBench MLP, one rollout 0.533", "—", "—", "—", "—", "—", "—", "—", "—", "IDSIA att. (geodesic) 0.227", "—", "—", "—",
             "none (other inputs)", "none (other inputs)",
             "NeuroBEM 0.24", "NeuroBEM 0.25", "NeuroBEM 0.79", "NeuroBEM ≈3.9", "NeuroBEM ≈5.0", "NanoBench Task 1: 2.17"]


def value(pred, view, key, quantity, stat):
    if view == "one_step":
        v = pred["one_step"][quantity]
        v = v[key] if key else v
    else:
        rows = [r for r in pred.get(view, []) if abs(r["horizon_s"] - key) < 1e-9]
        v = rows[0][quantity][stat] if rows and quantity in rows[0] else None
    return "–" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.3g}"


def main(out):
    print("| flight | model | " + " | ".join(c[0] for c in COLUMNS) + " |")
    print("|---|---|" + "---|" * len(COLUMNS))
    print("| target | | " + " | ".join(TARGETS) + " |")
    print("| published | | " + " | ".join(PUBLISHED) + " |")
    for flight in sorted(p for p in Path(out).iterdir() if p.is_dir()):
        models = []
        nominal = flight / "nominal" / "prediction.json"
        if nominal.exists():
            models.append(("nominal", json.loads(nominal.read_text())))
        diagnosis = flight / "diagnosis" / "diagnosis.json"
        if diagnosis.exists():
            d = json.loads(diagnosis.read_text())
            if "prediction" in d:
                effects = ", ".join(d["extended_model"]["effects"]) or "nothing found"
                models += [("base fit", d["prediction"]["before"]), (f"extended ({effects})", d["prediction"]["after"])]
        # Further models, one folder each (named by what they are): a joint fit's values, an
        # unseen flight predicted with the airframe's values, calibrated or not.
        for sub in sorted(p for p in flight.iterdir() if p.name not in ("nominal", "diagnosis") and p.is_dir()):
            if (sub / "prediction.json").exists():
                models.append((sub.name, json.loads((sub / "prediction.json").read_text())))
        for name, pred in models:
            print(f"| {cell(flight.name)} | {cell(name)} | " + " | ".join(value(pred, *c[1:]) for c in COLUMNS) + " |")
            if "one_step_linear_correction" in pred:  # one-step columns only
                corrected = {"one_step": pred["one_step_linear_correction"]}
                print(f"| {cell(flight.name)} | {cell(name)} + linear correction (fitted on the first 70 %) | " +
                      " | ".join(value(corrected, *c[1:]) for c in COLUMNS) + " |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/prediction_benchmark")
