#!/usr/bin/env python3
"""Summarises the diagnoses written by scripts/real_flights.sh as a markdown table and
checks every finding against the naming rules: a closed 95 % interval, not containing the
parameter's "off" value (for at least one parameter), and a held-out gain above its
standard error (open-loop position; or one-step equation error with neither the position
gain nor any channel group's one-step gain — translational, horizontal, rotational, yaw — below
minus its standard error; or, for a flight's own quantity acting on the force, the force
model alone — position with the measured attitude replayed — with the one-step gain above and
no channel group below its spread); and every `scope` diagnosis.json gives (findings, suspects,
stand-ins, `effect_scopes`) against this script's own list of the flight's own effects. Exit
status 1 on a violation."""
import json
import math
import pathlib
import sys

from markdown_cell import cell  # folder and file names shown as text


def fmt(v, digits=3):
    return "open" if v is None else f"{v:.{digits}g}"


def finding_text(f):
    parts = []
    for name, p in f["parameters"].items():
        if p.get("reference"):
            continue
        lo, hi = p["ci95"]
        parts.append(f"{cell(name)} = {fmt(p['value'])} [{fmt(lo)}, {fmt(hi)}]")
    how = {"one-step equation error": " (held out: one step)",
           "force model alone (attitude replayed)": " (held out: force model alone)"}.get(f.get("accepted_by"), "")
    return f"**{cell(f['effect'])}**{how} " + "; ".join(parts)


# The catalogue's per-flight effects (docs/effects.md), written down again like PLAUSIBLE below,
# and those of them that act on the force (judged by the force model alone).
PER_FLIGHT = {"motor_gain", "wind", "attitude_bias"}
ON_THE_FORCE = {"wind", "attitude_bias"}


def above_spread(g, floor=0.0):
    m, se = g.get("gain_mean"), g.get("gain_standard_error")
    return m is not None and se is not None and m > floor and m > se


def held_out_gain(f):
    """The open-loop position gain above its standard error over the folds, the one-step cost not
    higher with it; or the one-step
    (equation-error) gain above its standard error with the position gain, and the one-step gains
    of the translational channels (together, and the horizontal force apart; the vertical counts
    in the sum only) and of the rotational ones (together, and the yaw apart), each not below minus its own standard error; or, for a flight's own quantity
    acting on the force, the force model alone's position gain above its standard error with the
    one-step gain above and no channel group below its spread."""
    g, o = f["gain"], f.get("one_step_gain") or {}
    # The rollouts stand behind it unless the held-out one-step cost is higher with it
    # (since the sixteenth session; without one-step folds the rollouts are the one-step cost).
    if above_spread(g) and (not o.get("fold_gains") or o.get("gain_mean", 0) >= 0):
        return True

    def not_worse(x, negligible=0.0):
        m, se = x.get("gain_mean"), x.get("gain_standard_error")
        return m is not None and se is not None and (m >= -se or m >= -negligible)
    groups = ("translation", "horizontal", "rotation") + (("yaw",) if "yaw" in o else ())  # yaw: since 2026-11-27
    no_group_worse = all(not_worse(o.get(k, {}), 1.0) for k in groups)  # 1 %: diagnose's kNegligibleChange
    if f["effect"] in PER_FLIGHT:  # a flight's own quantity: the rollouts, or the force model alone
        return (f["effect"] in ON_THE_FORCE and above_spread(f.get("force_alone_gain") or {})
                and bool(o.get("fold_gains")) and above_spread(o) and no_group_worse)
    return bool(o.get("fold_gains")) and above_spread(o) and not_worse(g) and no_group_worse


def violations(f):
    out = []
    params = [p for p in f["parameters"].values() if not p.get("reference")]
    if any(p["ci95"][0] is None or p["ci95"][1] is None for p in params):
        out.append("open interval")
    excludes = any(p["ci95"][0] is not None and p["ci95"][1] is not None and not (p["ci95"][0] <= 0 <= p["ci95"][1])
                   for p in params)
    if not excludes:
        out.append("every interval contains off")
    if not held_out_gain(f):
        out.append("no held-out gain beyond its standard error")
    return out + wrong_scope(f["effect"], f.get("scope"))


def scope_of(effect):
    return "flight" if effect in PER_FLIGHT else "airframe"


def wrong_scope(effect, said):
    """A scope diagnosis.json gives an effect against this script's own list."""
    return [] if said == scope_of(effect) else [f"{cell(effect)}: scope {cell(repr(said))}, not {scope_of(effect)!r}"]


def scope_violations(j):
    """The scopes of the entries besides findings: suspects, stand-ins and every candidate."""
    out = []
    for e in j.get("suspected", []) + j.get("stand_ins", []):
        out += wrong_scope(e["effect"], e.get("scope"))
    for effect, said in j.get("effect_scopes", {}).items():
        out += wrong_scope(effect, said)
    return out + [f"no scope for {cell(e)}" for e in j.get("candidates_considered", []) if e not in j.get("effect_scopes", {})]


# The symmetric SI plausible ranges of the catalogue (docs/effects.md; motor_lag and
# input_delay are one-sided, their bounds keep them >= 0), written down again here so that
# this check does not rely on the code it checks: a named finding beyond them breaks the
# rule that stand-ins for missing physics are not named.
PLAUSIBLE = {"wind": {"indoor": 0.5, "unknown": 15.0, "outdoor": 15.0}, "attitude_bias": 0.052, "motor_gain": 0.35,
             "input_delay": 0.1, "motor_lag": 0.25}


def implausible(f, environment):
    limit = PLAUSIBLE.get(f["effect"])
    if isinstance(limit, dict):
        limit = limit.get(environment, 15.0)
    if limit is None:
        return []
    return [f"{cell(n)} = {p['value']:.3g} beyond ±{limit}" for n, p in f["parameters"].items()
            if abs(p["value"]) > limit + 1e-12]


def per_flight_verdict(check, one):
    """One check's verdict from diagnosis.json: `one` of the whole diagnosis, "not measured",
    and for a joint diagnosis also each flight's."""
    if not check:
        return "?"
    if not check.get("measured"):
        return "not measured"
    per = [f"{i + 1}: {one(f)}" for i, f in enumerate(check.get("per_flight", [])) if f.get("measured")]
    return one(check) + (f" (per flight {'; '.join(per)})" if per else "")


def draft_verdict(j):
    """The draft check's verdict (diagnose/draft_signature.hpp): the axes showing a draft's
    signature on both parts, "not measured" without rotor drag and blade flapping."""
    return per_flight_verdict(j.get("draft_signature"), lambda d: ", ".join(cell(a) for a in d.get("axes_showing_it", [])) or "none")


def command_gain_verdict(j):
    """The command-gain check (diagnose/command_gain.hpp): roll / pitch gain at 4-8 Hz against
    the base model (1: its motor map's slope is right), "lead" when it prints one."""
    def one(x):
        band = 1  # the lead band, 4-8 Hz
        rp = [a["bands"][band]["gain"] for a in x["axes"][:2]]
        return f"{rp[0]:.2f} / {rp[1]:.2f}" + (" lead" if x.get("slope_looks_off") else "")
    return per_flight_verdict(j.get("command_gain"), one)


def main(root):
    rows, bad = [], 0
    for d in sorted(pathlib.Path(root).iterdir()):
        j_path = d / "diagnosis.json"
        if not j_path.is_file():
            continue
        j = json.loads(j_path.read_text())
        named = []
        for f in j["findings"]:
            v = violations(f) + implausible(f, j.get("environment", "unknown"))
            bad += len(v)
            named.append(finding_text(f) + (" ⚠ " + ", ".join(v) if v else ""))
        scopes = scope_violations(j)
        bad += len(scopes)
        if scopes:
            named.append("⚠ " + ", ".join(scopes))
        suspected = [f"{cell(s['effect'])} ({cell(s['failed'].split(' (')[0])})" for s in j["suspected"]]
        groups = [" or ".join(map(cell, a["effects"])) for a in j.get("ambiguous", [])]
        stand_ins = [f"{cell(s['effect'])} ({cell(s['parameter'])} = {s['value']:.3g} {cell(s['unit'])})" for s in j.get("stand_ins", [])]
        # Beyond the catalogue: proposed terms with their held-out RMS before -> after.
        proposed = [f"{cell(t['expression'])} ({fmt(t['held_out_rms'][0])} → {fmt(t['held_out_rms'][1])} {cell(t['unit'])})"
                    for t in j.get("discovered_terms", []) if t.get("proposed")]
        pb, pa = j.get("prediction", {}).get("before", {}), j.get("prediction", {}).get("after", {})

        def at(p, h):  # mean position error at horizon h of the open-loop view
            for e in p.get("open_loop", []):
                if abs(e.get("horizon_s", -1) - h) < 1e-9:
                    return e["position_m"]["mean"]
            return None
        pred = f"{fmt(at(pb, 0.5))} → {fmt(at(pa, 0.5))}"
        rows.append((cell(d.name), "<br>".join(named) or "—", ", ".join(stand_ins) or "—", ", ".join(suspected) or "—",
                     ", ".join(groups) or "—", "<br>".join(proposed) or "—", draft_verdict(j), command_gain_verdict(j), pred,
                     f"{j.get('timing_s', float('nan')):.0f}" if isinstance(j.get("timing_s"), (int, float)) else "?"))
    print("| flight | named (95 % interval) | stand-ins (not named) | suspected (failed) | look-alike groups | "
          "proposed terms (held-out RMS before → after) | draft hypothesis (axis; per flight when joint) | "
          "answer to the commands, roll / pitch at 4-8 Hz (1: as the model) | "
          "0.5 s open-loop error before → after [m] | s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")
    print(f"\n{bad} rule violations in {len(rows)} diagnoses")
    look_alike_classes(root)
    agreement_tables(root)
    return 1 if bad else 0


def look_alike_classes(root):
    """Flights diagnosed one at a time, effect by effect, with the look-alikes any of them
    could not separate (diagnosis.json `ambiguous`) joined into one class: per flight whether
    the class is named (which member), in the model as an ambiguous pair, suspected, or absent.
    Which member of a pair a flight names is what the data cannot decide; that a member is in
    the model is what the flights can be compared on. "of the": whether the class describes the
    airframe (every flight should carry it) or the flight (PER_FLIGHT; diagnosis.json's own
    `scope` fields are checked against it in main()). (A carried member of a pair is not
    tested on held-out data: acceptance judges named effects only.)"""
    singles = []
    for d in sorted(pathlib.Path(root).iterdir()):
        j_path = d / "diagnosis.json"
        if j_path.is_file():
            j = json.loads(j_path.read_text())
            if len(j.get("flights", [])) == 1:
                singles.append((d.name, j))
    if not singles:
        return
    parent = {}

    def find(e):
        parent.setdefault(e, e)
        while parent[e] != e:
            e = parent[e]
        return e
    for _, j in singles:
        for e in [f["effect"] for f in j["findings"]] + [s["effect"] for s in j["suspected"]]:
            find(e)
        for a in j.get("ambiguous", []):
            x, y = (find(e) for e in a["effects"])
            parent[max(x, y)] = min(x, y)
    classes = {}
    for e in sorted(parent):
        classes.setdefault(find(e), []).append(e)
    print("\nFlights diagnosed alone, look-alikes joined (named: which member; ambiguous: a pair the flight "
          "cannot separate, its stronger member carried; suspected; —: absent)\n")
    print("| effect (or look-alikes) | of the | " + " | ".join(cell(n) for n, _ in singles) +
          " | named, or carried as an ambiguous pair, on |")
    print("|---|---|" + "---|" * len(singles) + "---|")
    for members in sorted(classes.values(), key=lambda m: m[0]):
        of = " / ".join(sorted({scope_of(m) for m in members}))
        cells, in_model = [], 0
        for _, j in singles:
            named = [cell(f["effect"]) for f in j["findings"] if f["effect"] in members]
            pairs = [" or ".join(map(cell, a["effects"])) for a in j.get("ambiguous", []) if set(a["effects"]) & set(members)]
            suspected = [cell(s["effect"]) for s in j["suspected"] if s["effect"] in members]
            if named or pairs:
                in_model += 1
            cells.append(", ".join(named + [f"ambiguous ({p})" for p in pairs]) or
                         (f"suspected ({', '.join(suspected)})" if suspected else "—"))
        print(f"| {' / '.join(map(cell, members))} | {of} | " + " | ".join(cells) + f" | {in_model} of {len(singles)} |")


def agreement_tables(root):
    """Joint diagnoses: each airframe effect refitted on each flight alone (diagnosis.json
    `agreement`), one row per flight, so agreement or disagreement shows at a glance."""
    for d in sorted(pathlib.Path(root).iterdir()):
        j_path = d / "diagnosis.json"
        if not j_path.is_file():
            continue
        for a in json.loads(j_path.read_text()).get("agreement", []):
            state = "agree" if a["agree"] else "disagree"
            named = "named" if a["named"] else "suspected"
            print(f"\n{cell(d.name)}: **{cell(a['parameter'])}** [{cell(a['unit'])}] ({named}) — flights {state}: joint "
                  f"{fmt(a['joint_value'])}, pooled {fmt(a['pooled'])}, spread {fmt(100 * a['spread'] if a['spread'] is not None else None)} %"
                  + (f" (if they agree: median {fmt(100 * a['spread_if_agree'], 2)} %, p = {fmt(a['spread_p_value'], 2)})"
                     if a.get("spread_if_agree") is not None else "") + ", "
                  f"Cochran's Q {fmt(a['cochran_q'])} (p = {fmt(a['q_p_value'], 2)})\n")
            print("| flight | value | 95 % interval | alone: LR statistic | alone: p |")
            print("|---|---|---|---|---|")
            for f in a["flights"]:
                lo, hi = f["ci95"]
                print(f"| {cell(pathlib.Path(f['flight']).stem)} | {fmt(f['value'])} | [{fmt(lo)}, {fmt(hi)}] | "
                      f"{fmt(f['alone']['statistic'])} | {fmt(f['alone']['p_value'], 2)} |")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "/tmp/quadgen_real_flights"))
