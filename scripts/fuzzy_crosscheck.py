"""Cross-checks plumetrace's onboard fuzzy engine against scikit-fuzzy 0.5.0.

Run through fuzzy_crosscheck.sh, which prepares the environment and the Rust side. Two steps:

  inputs   writes N random inputs (left_m, front_m, right_m, head_ang_deg) to a CSV;
  compare  builds the same Mamdani system with skfuzzy.control (Table I membership functions of
           seed 001, the rule table the Rust test exported, min for AND, max accumulation,
           centroid defuzzification on the same output grids), evaluates every input and compares
           with the Rust engine's outputs; exits 1 when the largest difference of an output is
           more than the tolerance (a fraction of the output's range).

The membership functions are written here from Table I, independently of the Rust code; the rule
table is read from the Rust side (FUZZY_RULES) so that one list of rules exists. Output ranges
for the comparison: speed 0.25..2 m/s (1.75), turn -10..10 deg (20), the values a centroid can
take. The output grids are the Rust engine's: numpy.linspace(-0.7, 2.8, 211) m/s and
numpy.linspace(-20, 20, 201) deg.
"""
import argparse
import csv
import math
import sys
import time

import numpy as np
import skfuzzy as fuzz
from skfuzzy import control as ctrl

# Table I centres.
SIDE_C = (5.0, 10.0, 15.0)
FRONT_C = (10.0, 15.0, 20.0)
ANGLE_C = (-50.0, 0.0, 50.0)
SPEED_C = (0.25, 1.2, 2.0)
TURN_C = (-10.0, 0.0, 10.0)

# Input universes: every breakpoint is a grid point, so skfuzzy's linear interpolation of the
# sampled membership functions is exact; inputs beyond the ends are clipped (the shoulders are flat
# there), and "no obstacle" (infinite) becomes the upper end (fully far).
SIDE_U = np.linspace(0.0, 20.0, 81)
FRONT_U = np.linspace(0.0, 25.0, 101)
ANGLE_U = np.linspace(-180.0, 180.0, 361)
# Output universes: the Rust engine's grids.
SPEED_U = np.linspace(-0.7, 2.8, 211)
TURN_U = np.linspace(-20.0, 20.0, 201)

SPEED_RANGE = SPEED_C[2] - SPEED_C[0]
TURN_RANGE = TURN_C[2] - TURN_C[0]


def shoulders(var, u, c, names):
    """Left shoulder, triangle, right shoulder at centres c (Table I inputs)."""
    lo, hi = u[0], u[-1]
    var[names[0]] = fuzz.trapmf(u, [lo, lo, c[0], c[1]])
    var[names[1]] = fuzz.trimf(u, [c[0], c[1], c[2]])
    var[names[2]] = fuzz.trapmf(u, [c[1], c[2], hi, hi])


def triangles(var, u, c, names):
    """Three triangles at centres c, the outer ones mirrored about their centres."""
    var[names[0]] = fuzz.trimf(u, [c[0] - (c[1] - c[0]), c[0], c[1]])
    var[names[1]] = fuzz.trimf(u, [c[0], c[1], c[2]])
    var[names[2]] = fuzz.trimf(u, [c[1], c[2], c[2] + (c[2] - c[1])])


def build_system(rules_path):
    left = ctrl.Antecedent(SIDE_U, "left_obs")
    front = ctrl.Antecedent(FRONT_U, "front_obs")
    right = ctrl.Antecedent(SIDE_U, "right_obs")
    angle = ctrl.Antecedent(ANGLE_U, "head_ang")
    speed = ctrl.Consequent(SPEED_U, "velocity_c", defuzzify_method="centroid")
    turn = ctrl.Consequent(TURN_U, "head_c", defuzzify_method="centroid")
    dist_names = ("near", "med", "far")
    shoulders(left, SIDE_U, SIDE_C, dist_names)
    shoulders(right, SIDE_U, SIDE_C, dist_names)
    shoulders(front, FRONT_U, FRONT_C, dist_names)
    shoulders(angle, ANGLE_U, ANGLE_C, ("neg", "z", "pos"))
    triangles(speed, SPEED_U, SPEED_C, ("slow", "med", "fast"))
    triangles(turn, TURN_U, TURN_C, ("neg", "z", "pos"))

    rules = []
    with open(rules_path, newline="") as f:
        for row in csv.DictReader(f):
            terms = [
                var[row[key]]
                for var, key in ((left, "left"), (front, "front"), (right, "right"), (angle, "head_ang"))
                if row[key] != "any"
            ]
            antecedent = terms[0]
            for t in terms[1:]:
                antecedent = antecedent & t
            rules.append(ctrl.Rule(antecedent, (speed[row["velocity_c"]], turn[row["head_c"]])))
    return ctrl.ControlSystem(rules), len(rules)


def make_inputs(path, n, seed):
    """Random inputs: distances uniform in 0..24 m with a tenth 'no obstacle' (inf) and a tenth on
    a Table I breakpoint, angles uniform in (-180, 180] with a tenth on a breakpoint."""
    rng = np.random.default_rng(seed)
    side_b = [0.0, 5.0, 7.5, 10.0, 12.5, 15.0]
    front_b = [0.0, 10.0, 12.5, 15.0, 17.5, 20.0]

    def dist(breaks):
        u = rng.random()
        if u < 0.1:
            return math.inf
        if u < 0.2:
            return float(rng.choice(breaks))
        return float(rng.uniform(0.0, 24.0))

    with open(path, "w") as f:
        f.write("left_m,front_m,right_m,head_ang_deg\n")
        for _ in range(n):
            a = float(rng.choice([-50.0, -25.0, 0.0, 25.0, 50.0, 180.0])) if rng.random() < 0.1 \
                else float(180.0 - rng.uniform(0.0, 360.0))
            f.write(f"{dist(side_b)!r},{dist(front_b)!r},{dist(side_b)!r},{a!r}\n")


def read_csv(path):
    with open(path, newline="") as f:
        r = csv.reader(f)
        next(r)
        return [[float(x) for x in row] for row in r if row]


def compare(args):
    system, n_rules = build_system(args.rules)
    inputs = read_csv(args.inputs)
    rust = read_csv(args.outputs)
    if len(inputs) != len(rust):
        print(f"{len(inputs)} inputs but {len(rust)} Rust outputs", file=sys.stderr)
        return 2
    sim = ctrl.ControlSystemSimulation(system, cache=False)
    worst = {"speed": (0.0, None), "turn": (0.0, None)}
    t0 = time.perf_counter()
    for x, (r_speed, r_turn) in zip(inputs, rust):
        clip = lambda v, u: float(min(max(v, u[0]), u[-1]))
        sim.input["left_obs"] = clip(x[0], SIDE_U)
        sim.input["front_obs"] = clip(x[1], FRONT_U)
        sim.input["right_obs"] = clip(x[2], SIDE_U)
        sim.input["head_ang"] = clip(x[3], ANGLE_U)
        sim.compute()
        p_speed, p_turn = sim.output["velocity_c"], sim.output["head_c"]
        for key, p, r, rng in (("speed", p_speed, r_speed, SPEED_RANGE), ("turn", p_turn, r_turn, TURN_RANGE)):
            d = abs(p - r) / rng
            if d > worst[key][0] or worst[key][1] is None:
                worst[key] = (d, (x, p, r))
    dt = time.perf_counter() - t0
    print(f"scikit-fuzzy {fuzz.__version__}: {n_rules} rules, {len(inputs)} inputs ({dt:.1f} s)")
    ok = True
    for key, unit, rng in (("speed", "m/s", SPEED_RANGE), ("turn", "deg", TURN_RANGE)):
        d, (x, p, r) = worst[key]
        print(f"largest {key} difference: {100 * d:.4f} % of {rng:g} {unit} "
              f"(input {x}: skfuzzy {p:.6f}, rust {r:.6f})")
        ok &= d <= args.tolerance
    print("agreement within %g %%: %s" % (100 * args.tolerance, "yes" if ok else "NO"))
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("inputs", help="write random inputs")
    a.add_argument("--out", required=True)
    a.add_argument("--n", type=int, default=1000)
    a.add_argument("--seed", type=int, default=1)
    c = sub.add_parser("compare", help="compare skfuzzy with the Rust outputs")
    c.add_argument("--inputs", required=True)
    c.add_argument("--outputs", required=True)
    c.add_argument("--rules", required=True)
    c.add_argument("--tolerance", type=float, default=0.01, help="fraction of the output range")
    args = ap.parse_args()
    if args.cmd == "inputs":
        make_inputs(args.out, args.n, args.seed)
        return 0
    return compare(args)


if __name__ == "__main__":
    sys.exit(main())
