#!/usr/bin/env python3
"""Writes a synthetic multirotor vehicle file for scaling measurements (scripts/codegen_targets.sh).

  multirotor_vehicle.py ROTORS BLOCKS OUT.yaml

ROTORS rotors on a circle of 0.25 m radius (alternating spin, so the yaw torques cancel in
hover), a hub block, one arm and one motor block per rotor, and filler blocks (avionics,
cables: small cuboids on a grid, every fourth one turned by 30 deg so the exact inertia
carries irrational rotation entries) up to BLOCKS blocks in all. The numbers are of an
ordinary 1.5 kg octocopter class; they only need to be valid, not any real vehicle's.
"""
import math
import sys


def main():
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    rotors, blocks, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    if rotors < 4 or rotors % 2:
        sys.exit("ROTORS: an even number, at least 4")
    fixed = 1 + 2 * rotors
    if blocks < fixed:
        sys.exit("BLOCKS: at least %d (hub, an arm and a motor per rotor)" % fixed)
    arm = 0.25
    lines = [
        "name: multirotor_%d_%d" % (rotors, blocks),
        "description: synthetic %d-rotor vehicle of %d blocks (scripts/multirotor_vehicle.py)" % (rotors, blocks),
        "environment:",
        "  g: {value: 9.81, unit: m/s^2}",
        "  rho: {value: 1.2041, unit: kg/m^3}",
        "frame:",
        '  c_w: {value: 1.0, unit: "1", bounds: [0.05, 3.0], fit: true}',
        "rotor_model:",
        '  c_t: {value: 0.01, unit: "1", bounds: [0.001, 0.1], fit: true}',
        "  kappa: {value: 0.01, unit: m, bounds: [0.0001, 0.1], fit: true}",
        "motor_map:",
        "  a0: {value: 0, unit: rad/s}",
        "  a1: {value: 900, unit: rad/s}",
        "  a2: {value: 0, unit: rad/s}",
        "blocks:",
        "  - {name: hub, mass: 0.4, size: [0.12, 0.12, 0.04], centre: [0, 0, 0]}",
    ]
    rotor_lines = ["rotors:"]
    for i in range(rotors):
        a = 2 * math.pi * (i + 0.5) / rotors
        deg = math.degrees(a)
        c, s = math.cos(a), math.sin(a)
        lines.append("  - {name: arm_R%d, mass: 0.03, size: [0.2, 0.02, 0.01], centre: [%.6f, %.6f, 0], "
                     "orientation_deg: [%.4f, 0, 0]}" % (i + 1, 0.15 * c, 0.15 * s, deg))
        lines.append("  - {name: motor_R%d, mass: 0.06, size: [0.03, 0.03, 0.03], centre: [%.6f, %.6f, 0.01]}"
                     % (i + 1, arm * c, arm * s))
        rotor_lines.append("  - {name: R%d, position: [%.6f, %.6f, 0.03], spin: %s, radius: 0.1, disc_area: 0.0314}"
                           % (i + 1, arm * c, arm * s, "ccw" if i % 2 == 0 else "cw"))
    filler = blocks - fixed
    side = max(1, math.ceil(filler ** (1.0 / 3.0)))
    for k in range(filler):
        i, j, l = k % side, (k // side) % side, k // (side * side)
        yaw = ", orientation_deg: [30, 0, 0]" if k % 4 == 3 else ""
        lines.append("  - {name: part_%d, mass: %.4f, size: [0.01, 0.012, 0.004], centre: [%.4f, %.4f, %.4f]%s}"
                     % (k, 0.001 + 0.0001 * (k % 7), 0.015 * (i - side / 2), 0.015 * (j - side / 2),
                        -0.03 - 0.006 * l, yaw))
    with open(out, "w") as f:
        f.write("\n".join(lines + rotor_lines) + "\n")


if __name__ == "__main__":
    main()
