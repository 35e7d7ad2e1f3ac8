"""A planner written in Python flies a mission through the same seam as the built-in ones."""

import math

import pytest

import plumetrace


class SurgeCast:
    """Upflow surge while in contact, crossflow cast when contact is lost; declares at the most
    upflow detection once casting has found nothing for `give_up_s`."""

    decision_period_s = 1.0

    def __init__(self, threshold=0.1, give_up_s=180.0):
        self.threshold = threshold
        self.give_up_s = give_up_s
        self.last_hit = None
        self.best = None
        self.cast_side = 1
        self.flow_to = 90.0
        self.seen = []

    def decide(self, s):
        self.seen.append(s["time_s"])
        if s["flow"] is not None:
            u, v = s["flow"]["velocity_mps"]
            if math.hypot(u, v) > 0.02:
                self.flow_to = math.degrees(math.atan2(u, v)) % 360.0
        up = (self.flow_to + 180.0) % 360.0
        pos = s["nav"]["pos_m"]
        hit = any(c["reading"] > self.threshold for c in s["chem"])
        t = s["time_s"]
        if hit and pos is not None:
            self.last_hit = t
            along = pos[0] * math.sin(math.radians(up)) + pos[1] * math.cos(math.radians(up))
            if self.best is None or along > self.best[0]:
                self.best = (along, pos)
        cmd = {"speed_mps": 1.0, "altitude_m": 3.0}
        if self.last_hit is None:
            cmd.update(heading_deg=up - 60.0 * self.cast_side, behaviour="find")
            if int(t) % 120 == 0:
                self.cast_side = -self.cast_side
        elif t - self.last_hit < 8.0:
            cmd.update(heading_deg=up, behaviour="track_in")
        elif t - self.last_hit < self.give_up_s:
            # Casts across the flow, each leg longer than the last (10 s, 20 s, 30 s, ...).
            lost = t - self.last_hit - 8.0
            leg, k, start = 10.0, 0, 0.0
            while start + leg * (k + 1) <= lost:
                start += leg * (k + 1)
                k += 1
            side = 1 if k % 2 == 0 else -1
            cmd.update(heading_deg=up + 80.0 * side, behaviour="reacquire")
        else:
            cmd.update(heading_deg=up, declare=tuple(self.best[1]), done=True, behaviour="done")
        return cmd


def test_a_surge_cast_planner_flies_the_demo_to_a_declaration():
    p = SurgeCast()
    r = plumetrace.run("demo", seed=9, planner=p)
    assert r.outcome in {"declared", "declared_false"} or r.outcome.startswith("declared")
    assert r.summary["first_declaration"]["rule"] == "custom"
    assert r.summary["first_declaration"]["error_m"] < 100.0
    assert {"find", "track_in"} <= set(r.trajectory["behaviour"])
    # Asked every second of the mission, never more often.
    gaps = [b - a for a, b in zip(p.seen, p.seen[1:])]
    assert min(gaps) == pytest.approx(1.0, abs=0.11)


def test_the_same_planner_and_seed_give_the_same_mission():
    a = plumetrace.run("demo", seed=4, planner=SurgeCast())
    b = plumetrace.run("demo", seed=4, planner=SurgeCast())
    assert a.summary == b.summary


class Raises:
    def decide(self, s):
        if s["time_s"] > 30:
            raise RuntimeError("planner bug at 30 s")
        return {"heading_deg": 0.0, "speed_mps": 1.0, "altitude_m": 3.0}


class BadCommand:
    def decide(self, s):
        return {"heading_deg": float("nan"), "speed_mps": 1.0, "altitude_m": 3.0}


class NoVertical:
    def decide(self, s):
        return {"heading_deg": 10.0, "speed_mps": 1.0}


def test_an_exception_in_decide_reaches_the_caller():
    with pytest.raises(RuntimeError, match="planner bug at 30 s"):
        plumetrace.run("demo", seed=1, planner=Raises())


@pytest.mark.parametrize(
    "planner, words",
    [(BadCommand(), ["heading_deg", "finite"]), (NoVertical(), ["altitude_m", "depth_m"])],
)
def test_a_bad_command_is_an_error_naming_the_key(planner, words):
    with pytest.raises(plumetrace.PlumetraceError) as e:
        plumetrace.run("demo", seed=1, planner=planner)
    for w in words:
        assert w in str(e.value)


def test_an_object_without_decide_is_refused():
    with pytest.raises(plumetrace.PlumetraceError, match="decide"):
        plumetrace.run("demo", planner=object())


class HoldsAPoint:
    """Due east at `speed` (the demo's east edge is 50 m from its start); holds a point it
    declares only when told its run ended."""

    decision_period_s = 1.0

    def __init__(self, speed, answer=(101.0, 2.0)):
        self.speed = speed
        self.answer = answer
        self.told = []

    def decide(self, s):
        return {"heading_deg": 90.0, "speed_mps": self.speed, "altitude_m": 3.0}

    def run_ended(self, t_s):
        self.told.append(t_s)
        return self.answer


def test_a_held_point_is_declared_when_the_run_ends_for_the_world():
    # Out of the domain: the point is declared after the incident, once; the outcome stays it.
    p = HoldsAPoint(2.5)
    r = plumetrace.run("demo", seed=1, planner=p, set={"mission.time_limit_s": 600.0})
    assert r.outcome == "left_domain"
    assert len(p.told) == 1 and p.told[0] < 100.0
    d = r.summary["first_declaration"]
    assert (d["x_m"], d["y_m"]) == (101.0, 2.0)
    assert d["rule"] == "custom"
    # The time limit: declared then, and the mission counts it.
    p = HoldsAPoint(0.5)
    r = plumetrace.run("demo", seed=1, planner=p, set={"mission.time_limit_s": 60.0})
    assert r.outcome == "declared" and len(p.told) == 1
    # Nothing held: nothing declared.
    r = plumetrace.run(
        "demo", seed=1, planner=HoldsAPoint(0.5, None), set={"mission.time_limit_s": 60.0}
    )
    assert r.summary["first_declaration"] is None


def test_a_bad_held_point_is_an_error_naming_run_ended():
    with pytest.raises(plumetrace.PlumetraceError, match="run_ended at .* not None or a point"):
        plumetrace.run(
            "demo",
            seed=1,
            planner=HoldsAPoint(0.5, (1.0, float("nan"))),
            set={"mission.time_limit_s": 60.0},
        )
