#!/usr/bin/env python3
"""A quadgen model (any vehicle, base or with effects) written independently in SymPy, for a side-by-side comparison
with quadgen's generated header (scripts/sympy_compare.sh drives it).

The physics is written here from the vehicle file (rotor layout, radius, disc area, spin),
the effect formulas of docs/effects.md and the variable lists of the model.json that
`quadgen derive` writes (names and order of states, inputs and parameters, the effects);
nothing is taken from quadgen's generated expressions. f and all
Jacobians (df/dx, df/du, df/dp) go through sympy.cse jointly and are printed as C++ with
integer powers written as products.

  sympy_compare.py emit VEHICLE.yaml MODEL.json OUTDIR   -> OUTDIR/sympy_model.hpp, harness.cpp
  sympy_compare.py count HEADER.hpp OUTDIR/sympy_model.hpp  -> operation counts of both

Operation count (both sides, on the C++ text of the function bodies): binary + - * /,
unary minus, and calls (sin, cos, abs_value, sign_of, pow, ...); literals, casts
(Scalar(...)) and array reads are free, a minus sign in front of a literal is part of it.
"""
import json
import re
import sys
import time
from fractions import Fraction

import sympy as sp
import yaml
from sympy.printing.c import C99CodePrinter


def exact(v):
    """Decimal text of a vehicle-file number as an exact rational, as quadgen reads it."""
    return sp.Rational(str(v))


def build_model(vehicle_path, model_json_path):
    veh = yaml.safe_load(open(vehicle_path))
    mj = json.load(open(model_json_path))
    state_names = [s["name"] for s in mj["states"]]
    input_names = [s["name"] for s in mj["inputs"]]
    param_names = [s["name"] for s in mj["parameters"]]
    effects = set(mj["effects"])
    X = sp.symbols(" ".join("x_" + n for n in state_names), real=True)
    U = sp.symbols(" ".join("u_" + n for n in input_names), real=True)
    P = sp.symbols(" ".join("p_" + n for n in param_names), real=True)
    S = dict(zip(state_names, X))
    In = dict(zip(input_names, U))
    Pm = dict(zip(param_names, P))

    qw, qx, qy, qz = S["qw"], S["qx"], S["qy"], S["qz"]
    v = sp.Matrix([S["vx"], S["vy"], S["vz"]])
    w = sp.Matrix([S["p"], S["q"], S["r"]])
    # Body -> world rotation of the unit quaternion (qw, qx, qy, qz).
    R = sp.Matrix([[1 - 2 * (qy**2 + qz**2), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)],
                   [2 * (qx * qy + qw * qz), 1 - 2 * (qx**2 + qz**2), 2 * (qy * qz - qw * qx)],
                   [2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx**2 + qy**2)]])
    c = sp.Matrix([Pm["cog_x"], Pm["cog_y"], Pm["cog_z"]])
    rho, c_t, c_w, kappa = Pm["rho"], Pm["c_t"], Pm["c_w"], Pm["kappa"]
    # The effects (docs/effects.md), each written here from its formula there.
    if "cog_offset" in effects:
        c = c + sp.Matrix([Pm["cog_offset.x"], Pm["cog_offset.y"], 0])
    v_air = v - sp.Matrix([Pm["wind.x"], Pm["wind.y"], 0]) if "wind" in effects else v
    vb = R.T * v_air  # body-frame air velocity

    force = sp.zeros(3, 1)
    torque = sp.zeros(3, 1)
    extra_rates = []
    speeds = []
    for i, rot in enumerate(veh["rotors"]):
        u = In["u_" + rot["name"]]
        commanded = Pm["motor_a0"] + Pm["motor_a1"] * u + Pm["motor_a2"] * u**2  # rad/s
        if "motor_lag" in effects:  # first-order lag: the rotor speed is a state
            speed = S["w_" + rot["name"]]
            tau = Pm["motor_lag.tau"]
            if "motor_lag_spread" in effects:  # each motor its own time constant, tau (1 + spread)
                tau = tau * (1 + Pm["motor_lag_spread." + rot["name"]])
            extra_rates.append((commanded - speed) / tau)
        else:
            speed = commanded
        speeds.append(speed)
    speed_sum = sum(speeds)
    for i, rot in enumerate(veh["rotors"]):
        speed = speeds[i]
        radius = exact(rot["radius"])
        pos = sp.Matrix([exact(a) for a in rot["position"]])
        arm = pos - c
        scale = 1
        if "motor_gain" in effects:
            scale *= 1 + Pm["motor_gain." + rot["name"]]
        if "thrust_decay" in effects:
            scale *= 1 - Pm["thrust_decay.rate"] * In["t"]
        if "battery_sag" in effects:
            scale *= (In["vbat"] / Pm["vbat_ref"]) ** Pm["battery_sag.exponent"]
        if "ground_effect" in effects:
            # As docs/effects.md gives the law: z^2 taken as (z^8 + z_min^8 + floor^8)^(1/4), with
            # z_min = R / (4 sqrt(1/2)) where (R / 4z)^2 reaches 1/2, and a floor of 1 mm
            # (held below twice the thrust, finite on the ground)
            radius_ge = Pm["ground_effect.radius"]
            z_min = radius_ge / (4 * sp.sqrt(sp.Rational(1, 2)))
            z2 = (S["z"] ** 8 + z_min**8 + sp.Rational(1, 10**3) ** 8) ** sp.Rational(1, 4)
            scale /= 1 - radius_ge**2 / (16 * z2)
        loss = 0  # thrust loss with the rotor's climb speed through the air
        if "inflow" in effects:
            climb = vb[2] + w.cross(arm)[2]
            loss = Pm["inflow.k"] * climb / radius
        thrust = scale * c_t * rho * exact(rot["disc_area"]) * radius**2 * speed * (speed - loss)
        F = sp.Matrix([0, 0, thrust])
        torque += arm.cross(F)
        spin = 1 if rot["spin"] == "ccw" else -1  # reaction torque opposes the rotor's spin
        torque[2] -= spin * kappa * thrust
        force += F
    if "rotor_drag" in effects:  # a horizontal force at the CoG
        force += sp.Matrix([-Pm["rotor_drag.k"] * speed_sum * vb[0], -Pm["rotor_drag.k"] * speed_sum * vb[1], 0])
    if "blade_flapping" in effects:  # a moment on the body-frame airspeed
        torque += sp.Matrix([Pm["blade_flapping.k"] * speed_sum * vb[1], -Pm["blade_flapping.k"] * speed_sum * vb[0], 0])
    areas = [Pm["A_x"], Pm["A_y"], Pm["A_z"]]
    for k in range(3):
        force[k] -= sp.Rational(1, 2) * c_w * rho * areas[k] * vb[k] * sp.Abs(vb[k])
    J = sp.Matrix([[Pm["J_xx"], Pm["J_xy"], Pm["J_xz"]],
                   [Pm["J_xy"], Pm["J_yy"], Pm["J_yz"]],
                   [Pm["J_xz"], Pm["J_yz"], Pm["J_zz"]]])
    rhs = torque - w.cross(J * w)
    def det3(a):  # cofactor expansion, not expanded into monomials
        return (a[0, 0] * (a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]) - a[0, 1] * (a[1, 0] * a[2, 2] - a[1, 2] * a[2, 0])
                + a[0, 2] * (a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]))

    D = det3(J)
    wdot = sp.zeros(3, 1)
    for col in range(3):  # Cramer's rule
        M = J.copy()
        M[:, col] = rhs
        wdot[col] = det3(M) / D
    ab = force / Pm["mass"] - wdot.cross(c) - w.cross(w.cross(c))
    acc = R * ab
    acc[2] -= Pm["g"]
    f = [S["vx"], S["vy"], S["vz"], acc[0], acc[1], acc[2],
         -sp.Rational(1, 2) * (qx * w[0] + qy * w[1] + qz * w[2]),
         sp.Rational(1, 2) * (qw * w[0] + qy * w[2] - qz * w[1]),
         sp.Rational(1, 2) * (qw * w[1] - qx * w[2] + qz * w[0]),
         sp.Rational(1, 2) * (qw * w[2] + qx * w[1] - qy * w[0]),
         wdot[0], wdot[1], wdot[2]] + extra_rates
    assert len(f) == len(X), "states beyond the ones written here: %s" % state_names
    return X, U, P, f


class Printer(C99CodePrinter):
    """C++ for a Scalar-free double function: integer powers as products."""

    def _print_Pow(self, e):
        b, n = e.base, e.exp
        if n.is_Integer:
            k = int(n)
            base = self.parenthesize(b, 100)  # always parenthesised unless atomic
            prod = "*".join([base] * abs(k))
            if k > 0:
                return prod if k == 1 else "(" + prod + ")"
            return "1.0/(" + prod + ")"
        return "pow(%s, %s)" % (self._print(b), self._print(n))

    def _print_Abs(self, e):
        return "std::fabs(%s)" % self._print(e.args[0])

    def _print_sign(self, e):
        return "sign_of(%s)" % self._print(e.args[0])

    def _print_Rational(self, e):
        return repr(float(e.p) / float(e.q))

    def _print_Integer(self, e):
        return "%d.0" % int(e)

    def _print_Symbol(self, e):
        return self.names[e]


def emit(vehicle, model_json, outdir):
    t0 = time.time()
    X, U, P, f = build_model(vehicle, model_json)
    outputs = [("f", i, e) for i, e in enumerate(f)]
    for name, V in (("dfdx", X), ("dfdu", U), ("dfdp", P)):
        k = 0
        for i, e in enumerate(f):
            for j, s in enumerate(V):
                d = sp.diff(e, s)
                if d != 0:
                    outputs.append((name, (i, j, k), d))
                    k += 1
    t1 = time.time()
    repl, reduced = sp.cse([e for _, _, e in outputs])
    t2 = time.time()
    pr = Printer()
    pr.names = {}
    for i, s in enumerate(X):
        pr.names[s] = "x[%d]" % i
    for i, s in enumerate(U):
        pr.names[s] = "u[%d]" % i
    for i, s in enumerate(P):
        pr.names[s] = "p[%d]" % i
    for s, _ in repl:
        pr.names[s] = str(s)
    body = []
    for s, e in repl:
        body.append("  const double %s = %s;" % (s, pr.doprint(e)))
    sparsity = {"dfdx": [], "dfdu": [], "dfdp": []}
    for (name, idx, _), e in zip(outputs, reduced):
        if name == "f":
            body.append("  f[%d] = %s;" % (idx, pr.doprint(e)))
        else:
            i, j, k = idx
            sparsity[name].append((i, j))
            body.append("  %s[%d] = %s;" % (name, k, pr.doprint(e)))
    arr = lambda v: "{" + ", ".join(str(a) for a in v) + "}"
    with open(outdir + "/sympy_model.hpp", "w") as out:
        out.write("// Written by scripts/sympy_compare.py: SymPy model of %s, sympy.cse of f and all Jacobians.\n"
                  % vehicle)
        out.write("#pragma once\n#include <cmath>\nnamespace sympy_model {\n")
        out.write("inline double sign_of(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }\n")
        for name, sp_ in sparsity.items():
            out.write("inline constexpr int k%sNnz = %d;\n" % (name, len(sp_)))
            out.write("inline constexpr int k%sRow[] = %s;\n" % (name, arr([a for a, _ in sp_])))
            out.write("inline constexpr int k%sCol[] = %s;\n" % (name, arr([b for _, b in sp_])))
        out.write("inline void rhs(const double* x, const double* u, const double* p, double* f, double* dfdx,\n"
                  "                double* dfdu, double* dfdp) {\n")
        out.write("\n".join(body) + "\n}\n}  // namespace sympy_model\n")
    print("sympy: model + %d Jacobian nonzeros in %.1f s, cse in %.1f s (%d temporaries)"
          % (len(outputs) - len(f), t1 - t0, t2 - t1, len(repl)))


def function_body(text, signature):
    """The body of the first function whose header contains `signature`."""
    i = text.index(signature)
    i = text.index("{", i)
    depth, j = 0, i
    while True:
        if text[j] == "{":
            depth += 1
        elif text[j] == "}":
            depth -= 1
            if depth == 0:
                return text[i + 1:j]
        j += 1


TOKEN = re.compile(r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)|(?P<id>[A-Za-z_][A-Za-z_0-9:.]*)|(?P<op>\S))")


def count_ops(body):
    """+ - * / (binary and unary minus), and calls, in C++ statements."""
    ops = 0
    for stmt in body.splitlines():  # one statement a line on both sides
        stmt = stmt.strip()
        if not stmt.endswith(";") or "=" not in stmt:
            continue
        rhs = stmt.split("=", 1)[1]
        rhs = re.sub(r"Scalar\(\s*(-?[0-9.eE+-]+)\s*\)", r"\1", rhs)  # literals are free
        prev = "start"
        toks = [m for m in TOKEN.finditer(rhs) if m.group(0).strip()]
        for n, m in enumerate(toks):
            kind = m.lastgroup
            tok = m.group(kind)
            if kind == "op" and tok in "+-*/":
                unary = prev in ("start", "op(", "op,", "op+", "op-", "op*", "op/")
                nxt = toks[n + 1] if n + 1 < len(toks) else None
                if unary and tok == "-" and nxt is not None and nxt.lastgroup == "num":
                    pass  # a negative literal
                else:
                    ops += 1
            if kind == "id" and n + 1 < len(toks) and toks[n + 1].group(0).strip() == "(" and tok not in ("if",):
                ops += 1
            prev = ("op" + tok) if kind == "op" else kind
    return ops


def count(header, sympy_hpp):
    qtext = open(header).read()
    rhs = function_body(qtext, "inline void rhs(")
    pre = function_body(qtext, "inline void precompute(")
    # The f-only part of quadgen's rhs: everything before the Jacobian block.
    f_only = rhs.split("  if (dfdx")[0]
    stext = open(sympy_hpp).read()
    srhs = function_body(stext, "inline void rhs(")
    q, s = count_ops(rhs), count_ops(srhs)
    print("operations (+ - * / and calls, integer powers as products), f and all Jacobians:")
    print("  quadgen rhs             %6d  (+ %d in precompute(), once per parameter vector; f alone %d)"
          % (q, count_ops(pre), count_ops(f_only)))
    print("  sympy.cse               %6d" % s)
    print("  quadgen / sympy          %5.2fx" % (q / s))


if __name__ == "__main__":
    if sys.argv[1] == "emit":
        emit(*sys.argv[2:5])
    elif sys.argv[1] == "count":
        count(*sys.argv[2:4])
    else:
        sys.exit(__doc__)
