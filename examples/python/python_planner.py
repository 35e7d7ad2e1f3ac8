"""A planner written in Python that flies the demo to a declaration: it surges up the current
while in contact with the plume, casts across it when contact is lost, and declares the most
upflow detection once casting has found nothing for a while.

    python python_planner.py [--seed 9]

Prints the outcome and the declaration's error (distance to the true source).
"""

import argparse
import math

import plumetrace


class SurgeCast:
    """Upflow surge in contact, crossflow cast out of it, declare when the plume is lost."""

    decision_period_s = 1.0

    def __init__(self, threshold: float = 0.1, give_up_s: float = 180.0) -> None:
        self.threshold = threshold
        self.give_up_s = give_up_s
        self.last_hit = None
        self.best = None  # (distance upflow, position) of the most upflow detection
        self.cast_side = 1
        self.flow_to = 90.0

    def decide(self, s: dict) -> dict:
        if s["flow"] is not None:
            u, v = s["flow"]["velocity_mps"]
            if math.hypot(u, v) > 0.02:
                self.flow_to = math.degrees(math.atan2(u, v)) % 360.0  # where the water goes
        up = (self.flow_to + 180.0) % 360.0
        pos = s["nav"]["pos_m"]
        t = s["time_s"]
        if pos is not None and any(c["reading"] > self.threshold for c in s["chem"]):
            self.last_hit = t
            along = pos[0] * math.sin(math.radians(up)) + pos[1] * math.cos(math.radians(up))
            if self.best is None or along > self.best[0]:
                self.best = (along, pos)
        cmd = {"speed_mps": 1.0, "altitude_m": 3.0}
        if self.last_hit is None:  # find the plume: zigzag across the flow, upflow
            cmd.update(heading_deg=up - 60.0 * self.cast_side, behaviour="find")
            if int(t) % 120 == 0:
                self.cast_side = -self.cast_side
        elif t - self.last_hit < 8.0:  # in contact: surge upflow
            cmd.update(heading_deg=up, behaviour="track_in")
        elif t - self.last_hit < self.give_up_s:  # lost: cast, each leg longer than the last
            lost = t - self.last_hit - 8.0
            leg, k, start = 10.0, 0, 0.0
            while start + leg * (k + 1) <= lost:
                start += leg * (k + 1)
                k += 1
            side = 1 if k % 2 == 0 else -1
            cmd.update(heading_deg=up + 80.0 * side, behaviour="reacquire")
        else:  # the plume ends here: declare the most upflow detection
            cmd.update(heading_deg=up, declare=tuple(self.best[1]), done=True, behaviour="done")
        return cmd


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=9)
    args = ap.parse_args()
    r = plumetrace.run("demo", seed=args.seed, planner=SurgeCast())
    d = r.summary["first_declaration"]
    print(f"outcome: {r.outcome}")
    if d is None:
        raise SystemExit("no declaration")
    print(f"declared at {d['t_s']:.0f} s at ({d['x_m']:.1f}, {d['y_m']:.1f}): "
          f"{d['error_m']:.1f} m from the source "
          f"({d['error_along_m']:+.1f} m along, {d['error_cross_m']:+.1f} m across the flow)")


if __name__ == "__main__":
    main()
