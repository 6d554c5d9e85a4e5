"""From result rows to the study's numbers: per-combination summaries and the ranking.

Which runs each figure uses:

- rates (success, collision, timeout, stuck): all runs, Wilson 95% interval;
- time to goal, path length, steering total variation, mean speed: successful runs only (how
  well a choice drives when it gets there; a run cut short by a collision has a short path and
  little steering, which would read as "better");
- minimum clearance: all runs (a collision is clearance 0 or less, which is what a safety margin
  should count);
- replans and backouts (routes planned again, times a robot backed out): all runs, as the
  collisions are counted (a run that timed out backing out again and again is what they should
  show).

Ranking (pooled over all worlds): success rate, higher first; ties by mean time to goal, lower
first; then by mean minimum clearance, higher first. Because every choice drives the same
seeded runs, each choice's successes are compared with the leader's run by run with an exact
McNemar test (two-sided), which says whether the difference in success could be chance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..words import plural
from .spec import Choice
from .stats import Mean, Rate, mean_interval, wilson
from .store import OUTCOMES, ROBOT_OUTCOMES

ALL_WORLDS = "all worlds"

#: (field, label, unit ("" for a count), which runs: "success" or "all")
METRICS = (
    ("time_s", "time to goal", "s", "success"),
    ("path_length_in", "path length", "in", "success"),
    ("min_clearance_in", "min clearance", "in", "all"),
    ("steering_total_variation_deg", "steering TV", "deg", "success"),
    ("mean_speed_in_s", "mean speed", "in/s", "success"),
    ("replans", "replans", "", "all"),
    ("backouts", "backed out", "", "all"),
)

#: The metrics no run can give below 0 (the others: clearance, negative where a body is
#: inside another): their t intervals are cut at 0, which keeps every interval's coverage
#: (the true mean cannot lie below 0) and reads as the quantity does. A count of 3 runs read
#: "replans 2.67 +- 2.08 [-2.50, 7.84]".
NOT_NEGATIVE = frozenset({"time_s", "path_length_in", "steering_total_variation_deg",
                          "mean_speed_in_s", "replans", "backouts"})


@dataclass(frozen=True)
class Summary:
    """The figures of one choice in one world (or pooled over all worlds); in a world of
    several robots, the fleet's (a run's outcome and figures over all its robots), with each
    robot's own under :attr:`robots` (``robot``: its name; its rates also of ``stopped``)."""

    world: str
    choice: Choice
    n: int
    rates: dict[str, Rate]
    metrics: dict[str, Mean]
    robot: str | None = None
    robots: tuple[Summary, ...] = ()

    def __repr__(self) -> str:   # the generated one spelt out every rate and mean (1,100 chars)
        ok = self.rates.get("success")
        rate = (f", success {ok.k / ok.n:.0%} [{ok.lo:.0%}, {ok.hi:.0%}]"
                if ok is not None and ok.n else "")
        time = self.metrics.get("time_s")
        timed = f", time to goal {time.mean:.3g} s" if time is not None and time.mean is not None else ""
        who = f", robot {self.robot!r}" if self.robot is not None else ""
        fleet = f", {plural(len(self.robots), 'robot')}" if self.robots else ""
        return (f"<Summary {self.world!r}{who}, {self.choice.label}: {plural(self.n, 'run')}"
                f"{rate}{timed}{fleet}>")


@dataclass(frozen=True)
class Rank:
    place: int
    summary: Summary
    paired_n: int            # runs both this choice and the leader drove
    wins: int                # runs this choice succeeded in and the leader did not
    losses: int              # runs the leader succeeded in and this choice did not
    p_value: float | None    # exact McNemar, None for the leader itself

    def __repr__(self) -> str:   # the generated one held the Summary's (1,200 chars)
        ok = self.summary.rates.get("success")
        rate = f" {ok.k / ok.n:.0%} success" if ok is not None and ok.n else ""
        against = ("leader" if self.p_value is None else
                   f"{self.wins} won / {self.losses} lost vs leader, McNemar p {self.p_value:.3g}")
        return f"<Rank {self.place}: {self.summary.choice.label},{rate}; {against}>"


def choice_of(row: dict) -> Choice:
    return Choice(row["planner"], row["and"], row["or"], row["inference"])


def summarize(world: str, choice: Choice, rows: list[dict], robot: str | None = None) -> Summary:
    """The summary of ``rows``: runs, or (``robot``: its name) one robot's rows of them,
    whose rates are also of ``stopped``; a run's rows with their robots' under ``robots``
    give the fleet's summary with each robot's."""
    n = len(rows)
    outcomes = OUTCOMES if robot is None else ROBOT_OUTCOMES
    rates = {o: wilson(sum(r["outcome"] == o for r in rows), n) for o in outcomes}
    ok = [r for r in rows if r["outcome"] == "success"]
    metrics = {f: mean_interval((r[f] for r in (ok if which == "success" else rows)),
                                floor=0.0 if f in NOT_NEGATIVE else None)
               for f, _label, _unit, which in METRICS}
    out = Summary(world, choice, n, rates, metrics, robot)
    names = list(dict.fromkeys(x["robot"] for r in rows for x in r.get("robots", ())))
    if robot is None and names:
        out = replace(out, robots=tuple(
            summarize(world, choice, [x for r in rows for x in r.get("robots", ())
                                      if x["robot"] == name], name) for name in names))
    return out


def summaries(rows: list[dict], worlds: list[str], choices: list[Choice]) -> list[Summary]:
    """One summary per (world, choice) in study order (in a world of several robots, with
    each robot's), then one per choice over all worlds (the fleets' runs, without robots)."""
    groups: dict[tuple[str, Choice], list[dict]] = {}
    for r in rows:
        groups.setdefault((r["world"], choice_of(r)), []).append(r)
    out = [summarize(w, c, groups.get((w, c), [])) for w in worlds for c in choices]
    if len(worlds) > 1:
        for c in choices:
            pooled = [r for w in worlds for r in groups.get((w, c), [])]
            out.append(replace(summarize(ALL_WORLDS, c, pooled), robots=()))
    return out


def mcnemar(wins: int, losses: int) -> float:
    """Exact two-sided McNemar p-value for ``wins`` vs ``losses`` discordant pairs."""
    n = wins + losses
    if n == 0:
        return 1.0
    k = min(wins, losses)
    if n <= EXACT_PAIRS:
        tail = sum(math.comb(n, i) for i in range(k + 1)) / 2.0 ** n
        return min(1.0, 2.0 * tail)
    return min(1.0, 2.0 * math.exp(_log_lower_tail(n, k)))


#: the most discordant pairs whose tail is summed as integers over ``2.0 ** n`` (beyond 1023
#: that is no float: a study of more runs stopped at its end with an OverflowError)
EXACT_PAIRS = 1000


def _log_lower_tail(n: int, k: int) -> float:
    """``log P(X <= k)`` for ``X ~ Binomial(n, 1/2)``, ``k <= n / 2``: its terms in logs, from
    ``k`` down (each no larger than the one before) until they no longer count."""
    def log_term(i: int) -> float:
        return (math.lgamma(n + 1) - math.lgamma(i + 1) - math.lgamma(n - i + 1)
                - n * math.log(2.0))

    top = log_term(k)
    total = 0.0
    for i in range(k, -1, -1):
        step = log_term(i) - top
        if step < -40.0:               # (e^-40: below a double's precision of the sum)
            break
        total += math.exp(step)
    return top + math.log(total)


def _sort_key(s: Summary) -> tuple[float, float, float, str]:
    def num(m: Mean, sign: float) -> float:
        return sign * m.mean if m.mean is not None else math.inf

    success = s.rates["success"].value
    return (-(success if success is not None else -1.0),
            num(s.metrics["time_s"], 1.0), num(s.metrics["min_clearance_in"], -1.0),
            s.choice.label)


def rank(rows: list[dict], pooled: list[Summary]) -> list[Rank]:
    """The choices ordered by the ranking criterion, each compared run by run with the leader."""
    ordered = sorted(pooled, key=_sort_key)
    if not ordered:
        return []
    success: dict[Choice, dict[tuple[str, int], bool]] = {}
    for r in rows:
        success.setdefault(choice_of(r), {})[(r["world"], r["run"])] = r["outcome"] == "success"
    leader = success.get(ordered[0].choice, {})
    out = []
    for place, s in enumerate(ordered, start=1):
        mine = success.get(s.choice, {})
        common = [k for k in mine if k in leader]
        wins = sum(mine[k] and not leader[k] for k in common)
        losses = sum(leader[k] and not mine[k] for k in common)
        p = None if place == 1 else mcnemar(wins, losses)
        out.append(Rank(place, s, len(common), wins, losses, p))
    return out
