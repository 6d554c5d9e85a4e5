"""The study's tables: in the terminal (rich) and in ``report.md`` (Markdown, with the plots)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from ..resources import display_world
from ..words import percent, plural
from .spec import Choice
from .stats import Mean, Rate
from .summary import ALL_WORLDS, METRICS, Rank, Summary

if TYPE_CHECKING:
    from collections.abc import Callable

    from rich.table import Table

RATE_COLUMNS = (("success", "success"), ("collision", "collision"), ("timeout", "timeout"),
                ("stuck", "stuck"))
#: the rates of a study with a world of several robots: a robot's own outcome may be `stopped`
#: (still driving when another robot's collision or stuck ended the run; a run's is never)
FLEET_RATE_COLUMNS = (*RATE_COLUMNS, ("stopped", "stopped"))
TABLE_METRICS = ("time_s", "path_length_in", "min_clearance_in", "steering_total_variation_deg",
                 "replans", "backouts")


def fmt_rate(r: Rate, ci: bool = True) -> str:
    if r.n == 0:
        return "-"
    text = percent(r.k, r.n)
    return f"{text} [{100 * r.lo:.0f}, {100 * r.hi:.0f}]" if ci else text


def _digits(value: float) -> int:
    return 0 if abs(value) >= 100 else 1 if abs(value) >= 10 else 2


def fmt_mean(m: Mean, ci: bool = True) -> str:
    """``mean +- std [lo, hi]``; ``-`` without values, no interval with one value."""
    if m.mean is None:
        return "-"
    d = _digits(m.mean)
    if m.std is None:
        return f"{m.mean:.{d}f} (n=1)"
    text = f"{m.mean:.{d}f} ± {m.std:.{d}f}"
    return f"{text} [{m.lo:.{d}f}, {m.hi:.{d}f}]" if ci else text


def fmt_p(p: float | None) -> str:
    if p is None:
        return "leader"
    return "< 0.001" if p < 0.001 else f"{p:.3f}"


def _metric_heading(field: str) -> str:
    for f, label, unit, which in METRICS:
        if f == field:
            return label + (f" ({unit})" if unit else "") + (" *" if which == "success" else "")
    raise KeyError(field)


def _rate_columns(summaries: list[Summary]) -> tuple[tuple[str, str], ...]:
    """The rates the tables show: with a `stopped` column where a world has several robots."""
    return FLEET_RATE_COLUMNS if any(s.robots for s in summaries) else RATE_COLUMNS


def _with_robots(summaries: list[Summary]) -> list[Summary]:
    """The tables' rows: each summary, then its robots' (indented under it, as `mitos
    simulate --runs` shows them)."""
    return [row for s in summaries for row in (s, *s.robots)]


def _cell_rate(s: Summary, outcome: str, fmt: Callable[[Rate], str]) -> str:
    """A rate's cell: ``-`` where the summary has none (a run is never `stopped`)."""
    return fmt(s.rates[outcome]) if outcome in s.rates else "-"


def _world_names(summaries: list[Summary]) -> dict[str, str]:
    """Each world as the tables show it: its file's stem, or its path as given where two
    worlds of the study share a stem (`corr.yaml` and `sub/corr.yaml`)."""
    worlds = list(dict.fromkeys(s.world for s in summaries))
    stems = [Path(w).stem for w in worlds if w != ALL_WORLDS]
    return {w: w if w == ALL_WORLDS or stems.count(Path(w).stem) > 1 else Path(w).stem
            for w in worlds}


# -- terminal -------------------------------------------------------------------------------

def _compact_rate(r: Rate) -> str:
    if r.n == 0:
        return "-"
    return f"{percent(r.k, r.n)} [{100 * r.lo:.0f},{100 * r.hi:.0f}]"


def _compact_mean(m: Mean) -> str:
    if m.mean is None:
        return "-"
    d = _digits(m.mean)
    return f"{m.mean:.{d}f}" if m.std is None else f"{m.mean:.{d}f}±{m.std:.{d}f}"


TERMINAL_HEADINGS = {"time_s": "time s*", "path_length_in": "path in*",
                     "min_clearance_in": "clear in", "steering_total_variation_deg": "steer TV*",
                     "replans": "replans", "backouts": "backed out"}


def rich_tables(summaries: list[Summary], ranks: list[Rank]) -> tuple[Table, Table]:
    """The per-combination table and the ranking as rich renderables (compact: the metrics'
    t intervals are in report.md)."""
    from rich import box
    from rich.table import Table

    rates = _rate_columns(summaries)
    caption = ("rates: % [Wilson 95%]; metrics: mean±std (t intervals in report.md); "
               "* successful runs only")
    if rates is FLEET_RATE_COLUMNS:
        caption += ("\n" + FLEET_NOTE)
    table = Table(title="Outcomes per world and choice", title_justify="left",
                  caption=caption, caption_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    table.add_column("world", no_wrap=True)
    table.add_column("choice", no_wrap=True)
    table.add_column("n", justify="right")
    for _f, heading in rates:
        table.add_column(heading, justify="right", no_wrap=True)
    for f in TABLE_METRICS:
        table.add_column(TERMINAL_HEADINGS[f], justify="right", no_wrap=True)
    last = None
    names = _world_names(summaries)
    for s in _with_robots(summaries):
        world = names[s.world]
        if last is not None and world != last:
            table.add_section()
        table.add_row(world if world != last else "",
                      s.choice.label if s.robot is None else f"  {s.robot}", str(s.n),
                      *(_cell_rate(s, f, _compact_rate) for f, _h in rates),
                      *(_compact_mean(s.metrics[f]) for f in TABLE_METRICS))
        last = world
    ranking = Table(title=RANK_TITLE, title_justify="left", box=box.SIMPLE_HEAD,
                    pad_edge=False)
    for name in ("#", "choice", "success", "time s*", "clear in", "won/lost", "McNemar p"):
        ranking.add_column(name, justify="left" if name == "choice" else "right",
                           no_wrap=True)
    for r in ranks:
        s = r.summary
        ranking.add_row(str(r.place), s.choice.label, _compact_rate(s.rates["success"]),
                        _compact_mean(s.metrics["time_s"]),
                        _compact_mean(s.metrics["min_clearance_in"]),
                        "-" if r.p_value is None else f"{r.wins}/{r.losses}",
                        fmt_p(r.p_value))
    return table, ranking


#: what the rows of a world of several robots are (under the tables of a study with one)
FLEET_NOTE = ("with several robots: a choice's row is the fleet's (a run succeeds when every "
              "robot does, is a collision when one collides; time until the last robot "
              "stopped, path, steering, replans and backed out summed over the robots, the "
              "least clearance of any), and each robot's own row is under it; stopped: still "
              "driving when another robot's collision or stuck ended the run")

RANK_TITLE = ("Ranking (all worlds): success rate, then time to goal, then clearance; "
              "won/lost and McNemar p: paired runs vs the leader")


# -- Markdown -------------------------------------------------------------------------------

def _md_table(header: list[str], rows: list[list[str]], align: list[str]) -> str:
    def esc(text: str) -> str:
        return text.replace("|", "\\|")

    lines = ["| " + " | ".join(esc(h) for h in header) + " |",
             "| " + " | ".join("---:" if a == "r" else "---" for a in align) + " |"]
    lines += ["| " + " | ".join(esc(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def outcome_table_md(summaries: list[Summary]) -> str:
    rates = _rate_columns(summaries)
    header = ["world", "choice", "n", *(h for _f, h in rates),
              *(_metric_heading(f) for f in TABLE_METRICS)]
    names = _world_names(summaries)
    rows = [[names[s.world], s.choice.label if s.robot is None else f"↳ {s.robot}", str(s.n),
             *(_cell_rate(s, f, fmt_rate) for f, _h in rates),
             *(fmt_mean(s.metrics[f]) for f in TABLE_METRICS)] for s in _with_robots(summaries)]
    return _md_table(header, rows, ["l", "l"] + ["r"] * (len(header) - 2))


def ranking_md(ranks: list[Rank]) -> str:
    header = ["#", "choice", "success [95% CI]", "time to goal (s) *", "min clearance (in)",
              "runs won / lost vs leader", "McNemar p"]
    rows = [[str(r.place), r.summary.choice.label, fmt_rate(r.summary.rates["success"]),
             fmt_mean(r.summary.metrics["time_s"]),
             fmt_mean(r.summary.metrics["min_clearance_in"]),
             "-" if r.p_value is None else f"{r.wins} / {r.losses}", fmt_p(r.p_value)]
            for r in ranks]
    return _md_table(header, rows, ["r", "l", "r", "r", "r", "r", "r"])


def render_markdown(manifest: dict, summaries: list[Summary], ranks: list[Rank],
                    images: dict[str, str], n_rows: int, n_tasks: int) -> str:
    """The whole ``report.md``."""
    choices = manifest.get("choices", [])
    worlds = manifest.get("worlds", [])
    lines = [
        "# MITOS comparison study",
        "",
        f"- worlds: {', '.join(f'`{display_world(w)}`' for w in worlds)}",
        f"- choices: {', '.join(f'`{c}`' for c in choices)}",
        f"- runs per world and choice: {manifest.get('runs')}, seed {manifest.get('seed')}"
        f" ({n_rows} of {plural(n_tasks, 'run')} finished)",
        f"- rule base: `{manifest.get('rulebase') or 'packaged default'}`"
        + (f", behavior `{manifest['behavior']}`" if manifest.get("behavior") else ""),
        f"- command: `{manifest.get('command', 'mitos compare')}`",
        "",
        "**Paired comparison.** Run *r* of a world uses the same seed for every choice "
        "(`SeedSequence(seed)` spawned per world, then per run), so all choices drive exactly "
        "the same randomized worlds: obstacle placements and sensor noise are identical, only "
        "the planner or its operators differ. The ranking compares each choice with the "
        "leader run by run (exact McNemar test on the runs where exactly one of the two "
        "succeeded).",
        "",
        "## Ranking",
        "",
        "Criterion: success rate over all worlds (higher first); ties broken by mean time to "
        "goal over successful runs (lower first), then by mean minimum clearance (higher "
        "first). A McNemar p above 0.05 means the data cannot tell that choice's success "
        "rate from the leader's.",
        "",
        ranking_md(ranks),
        "",
        "## Outcomes per world and choice",
        "",
        "Rates with the Wilson 95% interval; metrics as mean ± std [95% t interval, cut at 0 "
        "where a metric cannot be negative]. "
        "Columns marked * use successful runs only; minimum clearance, replans and backed "
        "out (times a robot backed out) use all runs."
        + (" " + FLEET_MD if any(s.robots for s in summaries) else ""),
        "",
        outcome_table_md(summaries),
        "",
    ]
    if images:
        lines += ["## Plots", ""]
        for title, name in images.items():
            lines += [f"![{title}]({name})", ""]
    return "\n".join(lines)


#: what report.md says of the rows of a world of several robots
FLEET_MD = ("In a world of several robots a choice's row is the fleet's: a run is a success "
            "when every robot reached its goal and a collision when any robot collided; its "
            "time is until the last robot stopped, its path length, steering TV, replans and "
            "backed out are summed over the robots, its minimum clearance is the least of "
            "any robot. Each robot's own outcome and figures follow in the rows marked ↳ "
            "(`stopped`: still driving when another robot's collision or stuck ended the "
            "run). The ranking counts the fleet's outcome.")


def overlap_note(ranks: list[Rank]) -> str | None:
    """A sentence naming the choices the data cannot separate from the leader (or None)."""
    if len(ranks) < 2:
        return None
    tied = [r.summary.choice.label for r in ranks[1:]
            if r.p_value is not None and not math.isnan(r.p_value) and r.p_value > 0.05]
    if not tied:
        return None
    return (f"{len(tied)} of {plural(len(ranks) - 1, 'choice')} "
            f"{'is' if len(tied) == 1 else 'are'} not distinguishable from the leader "
            f"({ranks[0].summary.choice.label}) in success rate (McNemar p > 0.05): "
            + ", ".join(tied))


def choice_labels(choices: list[Choice]) -> list[str]:
    return [c.label for c in choices]
