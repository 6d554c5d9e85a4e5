"""Runs in lockstep give every run the bits it has alone, whatever the batch."""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.errors import CommandError
from mitos_cli.resources import packaged_path
from mitos_cli.sim import kinematics, loop, movers, rows
from mitos_cli.sim.lockstep import Lockstep, run_lockstep
from mitos_cli.sim.loop import STUCK_TIME, Batch, Simulation, prepare, simulate
from mitos_cli.sim.planner import FuzzyPlanner, make_planner
from mitos_cli.sim.worldfile import load_world

WORLDS = ("corridor", "slalom", "moving", "intersection", "multirobot", "office", "detour",
          "figure4")
TINY = Path(__file__).parent / "data" / "tiny.yaml"


def recorded(res) -> dict:
    out = {key: getattr(res, key) for key in ("t", "pose", "speed", "steering", "command",
                                               "ranges", "clearance", "obstacles", "active",
                                               "progress")}
    out.update({f"p_{k}": v for k, v in res.perceived.items()})
    return out


def assert_same_run(a, b) -> None:
    assert a.ticks == b.ticks
    for key, value in recorded(a).items():
        other = recorded(b)[key]
        assert value.shape == other.shape and value.tobytes() == other.tobytes(), key
    assert a.summary() == b.summary()
    assert [(k, i) for k, i, _ in a.replanned] == [(k, i) for k, i, _ in b.replanned]


@pytest.mark.parametrize("name", WORLDS)
def test_each_shipped_world_runs_alone_and_in_a_batch_alike(name):
    world = dataclasses.replace(load_world(packaged_path("worlds", f"{name}.yaml")),
                                time_limit=1.0)
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    seeds = [world.seed, world.seed + 7]
    together = run_lockstep(world, planner, seeds, randomise=True, scene=scene)
    for seed, res in zip(seeds, together):
        assert_same_run(simulate(world, planner, seed, randomise=True, scene=scene), res)


def _barn_2079(time_limit: float) -> tuple:
    """BARN field 2079 (the poles unknown) cut to ``time_limit``, its planner, its scene and
    three seeds: its robot backs out beside the corridor's wall and among the poles."""
    from mitos_cli.sim import barn

    world = dataclasses.replace(barn.world_of(barn.field(2079, *barn.difficulty(2079))),
                                time_limit=time_limit)
    return (world, FuzzyPlanner(None, world.behavior), prepare(world),
            [world.seed, world.seed + 1, world.seed + 2])


def test_runs_whose_brake_counts_the_squares_flush_with_a_wall_run_in_a_batch_as_alone():
    """A BARN field (seed 2079, the poles unknown) whose top wall runs through its map's free
    row: the brake's squares flush with it (:func:`.knowledge.wall_faces`) are found for the
    whole batch at once, and each run keeps the bits it has alone while its robot backs out
    beside that wall (10-14 s)."""
    world, planner, scene, seeds = _barn_2079(time_limit=14.0)
    together = run_lockstep(world, planner, seeds, scene=scene)
    alone = [simulate(world, planner, s, scene=scene) for s in seeds]
    assert len(Simulation(world, planner, seeds[0], scene=scene)._maps[0].faces)
    assert any(len(r.backed_out) for r in alone)
    for a, b in zip(alone, together):
        assert_same_run(a, b)


def moving_draw_in_a_batch_as_alone(seed: int, draw: int, limit: float) -> Simulation:
    """`moving` with the navigation benchmark's clutter draw ``draw`` of ``seed`` (as
    ``bench_nav.py`` builds it), cut to ``limit`` s: three runs of it in a batch, each held to
    the bits it has alone; a fresh, unstepped :class:`Simulation` of the first, to replay."""
    from mitos_cli.sim.clutter import clutter

    base = load_world(packaged_path("worlds", "moving.yaml"))
    base_scene = prepare(base)
    rng = np.random.default_rng(np.random.SeedSequence([seed, 3]).spawn(draw + 1)[draw])
    world = clutter(base, base_scene.static, base_scene.routes[0], rng, int(rng.integers(3, 7)))
    world = dataclasses.replace(world, seed=base.seed + draw, time_limit=limit)
    planner = FuzzyPlanner(None, world.behavior)
    seeds = [world.seed, world.seed + 1, world.seed + 2]
    together = run_lockstep(world, planner, seeds, scene=base_scene)
    for s, b in zip(seeds, together):
        assert_same_run(simulate(world, planner, s, scene=base_scene), b)
    return Simulation(world, planner, seeds[0], scene=base_scene)


def test_runs_that_follow_a_far_cart_as_one_track_run_in_a_batch_as_alone():
    """`moving` with the benchmark's clutter draw 5 of seed 0: the cart is echoed 100 in off
    at one front corner, then at the other, and matched in the gate its line of sight from
    the robot gives (:func:`.movers.sight_lines`), the whole batch's at once; each run keeps
    the bits it has alone while it follows the cart and gets out of its way (to 19 s)."""
    sim = moving_draw_in_a_batch_as_alone(0, 5, 19.0)
    wide = False
    while not sim.done:
        sim.step()
        wide = wide or any(tr.mover and np.hypot(*(tr.centres[-1] - sim.pose[0, :2])) > 90
                           for tr in sim._trackers[0].tracks)
    assert wide                                     # a mover followed 90 in off or more


def test_runs_that_wait_at_their_refuge_for_a_cart_beside_them_run_in_a_batch_as_alone():
    """`moving` with the benchmark's clutter draw 9 of dev seed 6000: a robot standing at its
    refuge waits for the cart beside it till it has passed (:meth:`.RobotMap.at_refuge`),
    one on its way there does not; each run of a batch keeps the bits it has alone (to 26 s,
    after the first has left its refuge)."""
    sim = moving_draw_in_a_batch_as_alone(6000, 9, 26.0)
    at = False
    while not sim.done:
        sim.step()
        at = at or sim._maps[0].at_refuge(sim.pose[0, :2])
    assert at                                       # it stood at its refuge


def test_runs_that_end_at_different_ticks_drop_out_and_the_rest_go_on():
    world = load_world(TINY)
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    seeds = [3, 5]
    alone = [simulate(world, planner, s, randomise=True, scene=scene) for s in seeds]
    assert len({r.ticks for r in alone}) > 1              # they do end at different ticks
    for a, b in zip(alone, run_lockstep(world, planner, seeds, randomise=True, scene=scene)):
        assert_same_run(a, b)


def test_finished_gives_each_run_as_it_ends_with_its_bits_alone():
    world = load_world(TINY)
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    seeds = [3, 5, 8]
    got = list(Lockstep(world, planner, seeds, randomise=True, scene=scene).finished())
    assert sorted(i for i, _ in got) == [0, 1, 2]
    assert [res.ticks for _, res in got] == sorted(res.ticks for _, res in got)  # as they end
    for i, res in got:
        assert_same_run(simulate(world, planner, seeds[i], randomise=True, scene=scene), res)


def test_finished_with_a_clock_gives_the_same_runs_and_where_the_runs_going_are():
    from mitos_cli.sim.lockstep import Clock

    world = load_world(TINY)
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    seeds = [3, 5, 8]
    items = list(Lockstep(world, planner, seeds, randomise=True, scene=scene).finished(0.5))
    runs = [item for item in items if not isinstance(item, Clock)]
    clocks = [item.seconds for item in items if isinstance(item, Clock)]
    plain = list(Lockstep(world, planner, seeds, randomise=True, scene=scene).finished())
    assert [i for i, _ in runs] == [i for i, _ in plain]
    for (_, a), (_, b) in zip(runs, plain):
        assert_same_run(a, b)
    first = min(res.ticks for _, res in runs) * world.dt      # no run ended before it
    assert clocks[0] == pytest.approx(0.5) and len(clocks) >= int(first / 0.5) - 1
    assert all(0.5 - 1e-9 <= b - a < 0.5 + world.dt for a, b in zip(clocks, clocks[1:]))


def test_a_large_map_is_stepped_in_smaller_batches_with_the_same_bits(monkeypatch):
    """A batch of 64 runs on a 4,000 x 4,000 map kept 20 GB of the robots' maps; a batch now
    takes as many runs as :data:`MAP_MEMORY` holds, and the runs keep their bits."""
    from mitos_cli.sim import lockstep, runs

    world = dataclasses.replace(load_world(packaged_path("worlds", "office.yaml")),
                                time_limit=1.0)
    assert lockstep.batch_for(world) == lockstep.BATCH        # 600 x 600: a full batch
    big = dataclasses.replace(world.grid, occupied=np.zeros((4000, 4000), dtype=bool))
    assert lockstep.batch_for(dataclasses.replace(world, grid=big)) == 6
    monkeypatch.setattr(lockstep, "MAP_MEMORY", 2 * 360_000 * lockstep.CELL_BYTES)
    assert lockstep.batch_for(world) == 2
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    seeds = [1, 2, 3, 4, 5]
    made = []
    monkeypatch.setattr(lockstep, "Lockstep", lambda *a, **k: made.append(len(a[2])) or
                        Lockstep(*a, **k))
    got = run_lockstep(world, planner, seeds, randomise=True, scene=scene)
    assert made == [2, 2, 1]
    for seed, res in zip(seeds, got):
        assert_same_run(simulate(world, planner, seed, randomise=True, scene=scene), res)
    made.clear()
    summaries = runs.run_many([world], runs=5, seed=1, planner=planner, workers=1)
    assert made == [2, 2, 1]
    assert list(summaries.worlds[0].summaries) == [res.summary() for res in got]


@pytest.mark.parametrize("name", ["potential_field", "dwa"])   # dwa: with the route ahead
def test_a_planner_other_than_the_fuzzy_one_plans_each_run_itself(name):
    world = dataclasses.replace(load_world(TINY), time_limit=1.0)
    planner = make_planner(name, world)
    lock = Lockstep(world, planner, [1, 2], randomise=True)
    for seed, res in zip([1, 2], lock.results()):
        assert_same_run(simulate(world, planner, seed, randomise=True), res)
    assert lock.done


def test_a_batch_sees_the_news_each_run_sees_alone_with_its_own_noise():
    """Each randomised run draws its own sensor noise, so its own news threshold."""
    world = load_world(packaged_path("worlds", "corridor.yaml"))
    runs = [Simulation(world, None, seed, randomise=True) for seed in range(7000, 7006)]
    assert len({run.world.sensors.noise for run in runs}) > 1
    batch = Batch(runs)
    got = rows.sense([part for run in runs for part in run.sense_rows()], runs[0].angles,
                     world.sensors.range)
    rng = np.random.default_rng(1)          # readings a little short of the walls, or at range
    ranges = np.where(rng.random(got.ranges.shape) < 0.2, world.sensors.range,
                      got.static - rng.uniform(0.0, 8.0, got.ranges.shape))
    got = rows.Sensed(got.dirs, got.static, ranges, got.clearance)
    sensed = batch.sensed(got)
    together = batch.seeing()
    alone = np.concatenate([run.seeing(s) for run, s in zip(runs, sensed)])
    assert 0 < np.count_nonzero(alone) < alone.size
    assert together.tobytes() == alone.tobytes()


def test_a_batch_watches_what_each_run_watches_alone():
    """The robots that follow something (tracks kept, or news seen) and what the tracker
    looks at for them, of every run at once, are each run's own, in run order."""
    world = load_world(packaged_path("worlds", "multirobot.yaml"))
    runs = [Simulation(world, None, seed, randomise=True) for seed in range(7000, 7004)]
    batch = Batch(runs)
    got = rows.sense([part for run in runs for part in run.sense_rows()], runs[0].angles,
                     world.sensors.range)
    rng = np.random.default_rng(2)          # news for some robots, none for the others
    short = got.static - rng.uniform(8.0, 16.0, got.ranges.shape)
    ranges = np.where(rng.random((len(short), 1)) < 0.5, world.sensors.range, short)
    got = rows.Sensed(got.dirs, got.static, ranges, got.clearance)
    sensed = batch.sensed(got)
    seen = batch.seeing()
    own = np.concatenate([run.seeing(s) for run, s in zip(runs, sensed)])   # each run's own
    assert seen.tobytes() == own.tobytes()
    owner = [(run, i) for run in runs for i in range(run.n)]
    quiet = [owner[row] for row in range(len(owner)) if not seen[row].any()]
    assert quiet and len(quiet) < len(batch.maps)
    quiet[0][0]._trackers[quiet[0][1]].tracks.append(movers.Track([0.0], [np.zeros(2)]))
    learned = [False] * len(batch.maps)     # whether each row's map was marked
    spaces, follows, *looks = batch.watching(learned)
    for j in range(len(runs)):              # (kept for the runs whose robots aims() replans)
        batch._watch(j)
    together = [run._watched for run in runs]
    alone = [run.watching(s, learned[a:b]) for run, s, (a, b) in zip(runs, sensed, batch.spans)]
    assert [w[1:] for w in together] == [run._watched[1:] for run in runs]
    assert len(follows) == len(spaces) == sum(len(w[0]) for w in alone)
    assert len(follows) == len(batch.maps) - len(quiet) + 1
    assert all(a is b for a, b in zip(spaces, [f for w in alone for f in w[0]]))
    for j, look in enumerate(looks):
        assert look.tobytes() == np.concatenate([w[1 + j] for w in alone]).tobytes()


def test_runs_stuck_in_a_batch_are_stuck_at_the_tick_they_are_alone():
    world = dataclasses.replace(load_world(packaged_path("worlds", "multirobot.yaml")),
                                time_limit=STUCK_TIME + 3.0)
    start = world.agents[0].start

    class Stands:                           # the first robot drives 5 in, then stands
        name = "stands"

        def plan(self, p):
            off = np.hypot(p.pose[:, 0] - start.x, p.pose[:, 1] - start.y)
            return np.full(len(p.pose), 90.0), np.where((p.robots == 0) & (off > 5.0), 0.0, 20.0)

    lock = Lockstep(world, Stands(), [1, 2, 3], randomise=True)
    for seed, res in zip([1, 2, 3], lock.results()):
        assert res.robot_outcomes[0] == "stuck"
        assert_same_run(simulate(world, Stands(), seed, randomise=True), res)


def _short(name: str, seconds: float):
    return dataclasses.replace(load_world(packaged_path("worlds", f"{name}.yaml")),
                               time_limit=seconds)


def test_runs_started_again_inside_a_lockstep_run_as_started_alone():
    """A batch is of the runs as they were started: reset() gives a run new maps."""
    world = _short("office", 4.0)
    lock = Lockstep(world, None, [1, 2], randomise=True)
    for _ in range(5):
        lock.step()
    for run, seed in zip(lock.runs, [3, 4]):
        run.reset(seed)
    for seed, res in zip([3, 4], lock.results()):
        assert_same_run(simulate(world, None, seed, randomise=True), res)


@pytest.mark.parametrize("name", ["multirobot", "office"])
def test_a_run_stepped_alone_inside_a_lockstep_keeps_its_bits(name):
    """A user may step one run ahead of the others: the runs are then at different ticks."""
    world = _short(name, 3.0)
    lock = Lockstep(world, None, [1, 2, 3], randomise=True)
    lock.step()
    lock.runs[1].step()
    for seed, res in zip([1, 2, 3], lock.results()):
        assert_same_run(simulate(world, None, seed, randomise=True), res)


def test_runs_each_stepped_alone_between_two_batch_ticks_keep_their_bits():
    """Every run stepped alone a tick is at one tick with the others again, and their batch
    still serves them: it reads the places the runs moved to alone, not those it left."""
    world = _short("slalom", 3.0)
    lock = Lockstep(world, None, [1, 2, 3], randomise=True)
    for _ in range(3):
        lock.step()
    batch = lock._batch
    for run in lock.runs:
        run.step()
    lock.step()
    assert lock._batch is batch                          # the same batch went on
    for seed, res in zip([1, 2, 3], lock.results()):
        assert_same_run(simulate(world, None, seed, randomise=True), res)


def _turned_by_hand(run) -> None:
    """A tick of ``run`` driven by a user's own kinematics: turned on the spot, its x and y
    (the very arrays :meth:`Simulation.motion` gave) kept."""
    _, moves = run.decide()
    if moves:
        x, y, h, v, steer, _, _ = run.motion()
        run.move_to(x, y, h + 0.05, v, steer)
        run.moved()


def test_runs_moved_by_hand_between_two_batch_ticks_are_sensed_where_they_were_moved():
    """A run moved by hand (:meth:`Simulation.move_to`) with its own x holds a state the
    batch did not leave: the batch senses and moves it from there, as the run alone would."""
    world = _short("slalom", 3.0)
    lock = Lockstep(world, None, [1, 2], randomise=True)
    alone = [Simulation(world, None, seed, randomise=True) for seed in (1, 2)]
    for _ in range(3):
        lock.step()
        for run in alone:
            run.step()
    for run in lock.runs + alone:
        _turned_by_hand(run)
    for res, run in zip(lock.results(), alone):
        while not run.done:
            run.step()
        assert_same_run(run.result(), res)


def test_a_lockstep_copied_mid_run_gives_the_runs_of_the_original():
    """A copy (``copy.deepcopy``) holds runs of their own arrays, not views of the batch's:
    it makes its batch afresh, and the copy and the original end as the runs alone do (each
    run's robots arrive one after the other: one drives on where the other stopped)."""
    world = _short("multirobot", 30.0)
    lock = Lockstep(world, None, [1, 2], randomise=True)
    for _ in range(3):
        lock.step()
    copied = copy.deepcopy(lock)
    while not copied.done:                   # each run's robots drive as its record says
        copied.step()
        for run in copied.runs:
            assert run.done or np.array_equal(run.active, run.record[-1].active)
    for seed, res, again in zip([1, 2], lock.results(), copied.results()):
        want = simulate(world, None, seed, randomise=True)
        assert_same_run(want, res)
        assert_same_run(want, again)


def test_a_refused_command_is_told_as_alone_and_moves_no_robot(monkeypatch):
    world = _short("corridor", 2.0)
    lock = Lockstep(world, None, [1, 2, 3])
    lock.step()
    real = Lockstep._commands

    def broken(self, live, blocks, active):
        out = real(self, live, blocks, active)
        out[-1] = np.nan
        return out

    monkeypatch.setattr(Lockstep, "_commands", broken)
    with pytest.raises(CommandError, match=r"the command of planner `.+` at 0\.05 s"):
        lock.step()
    monkeypatch.setattr(Lockstep, "_commands", real)
    moved, real_step = [], kinematics.step

    def step(x, y, h, v, steer, c_steer, c_speed, *rest):
        moved.append(np.stack([c_steer, c_speed], axis=1))
        return real_step(x, y, h, v, steer, c_steer, c_speed, *rest)

    monkeypatch.setattr(loop.kinematics, "step", step)
    lock.step()                 # the robots move by the commands this tick recorded
    recorded = np.concatenate([run.record[-1].command for run in lock.runs])
    assert len(moved) == 1 and moved[0].tobytes() == recorded.tobytes()


def test_what_a_run_recorded_in_a_batch_no_later_tick_changes():
    """A run's tick holds views of the batch's arrays of that tick."""
    lock = Lockstep(_short("slalom", 1.0), None, [1, 2], randomise=True)
    lock.step()
    first = [copy.deepcopy(run.record[0]) for run in lock.runs]
    lock.results()
    for kept, run in zip(first, lock.runs):
        now = run.record[0]
        for f in dataclasses.fields(now):
            a, b = getattr(kept, f.name), getattr(now, f.name)
            if isinstance(a, dict):
                assert all(a[k].tobytes() == b[k].tobytes() for k in a)
            else:
                assert np.asarray(a).tobytes() == np.asarray(b).tobytes()


def test_a_batch_aims_and_replans_each_robot_as_its_run_alone(monkeypatch):
    """At every tick where a robot is due a replanning check, the batch's aims, routes
    (planned again or not) and places on them are those each run finds alone."""
    world = load_world(packaged_path("worlds", "multirobot.yaml"))
    world = dataclasses.replace(world, time_limit=80 * world.dt)
    replans = []
    aims = Batch.aims

    def checked(self, frames, near):
        if not loop.knowledge.checks_due(self.maps, self.ticks[0].t, self._when):
            return aims(self, frames, near)
        for j in range(len(self.runs)):     # each run's watch, as alone (the batch keeps it
            self._watch(j)                  # only for the runs it replans)
        runs, ticks, frames_, near_ = copy.deepcopy((self.runs, self.ticks, frames, near))
        got = aims(self, frames, near)
        want = [aim for run, s, (a, b) in zip(runs, ticks, self.spans)
                for aim in run.aims(s, frames_[a:b], near_[a:b])]
        for x, y in zip(got, want, strict=True):
            assert x.route.points.tobytes() == y.route.points.tobytes()
            assert (x.f.s, x.f.e, x.radius, x.need) == (y.f.s, y.f.e, y.radius, y.need)
            assert x.p.tobytes() == y.p.tobytes() and x.cells.tobytes() == y.cells.tobytes()
        for a, b in zip(self.runs, runs):
            assert a._s_hint.tobytes() == b._s_hint.tobytes()
            assert [(k, i) for k, i, _ in a._replanned] == [(k, i) for k, i, _ in b._replanned]
        replans.append(sum(len(run._replanned) for run in runs))
        return got

    monkeypatch.setattr(Batch, "aims", checked)
    run_lockstep(world, None, [7000, 7001, 7002], randomise=True)
    assert len(replans) > 10 and replans[-1] >= 2         # checks made, routes planned again


def stacked_tick_by_tick(run: Simulation) -> dict:
    """A run's recorded fields joined an array a tick (:meth:`Simulation.result`'s plain way)."""
    return {f: np.array([getattr(tick, f) for tick in run.record]) for f in loop._RECORDED}


@pytest.mark.parametrize("name", ["slalom", "multirobot"])
def test_a_result_read_from_the_batches_pages_is_the_record_joined_tick_by_tick(name):
    """A run stepped in lockstep batches (pages filled, runs dropping out) gets its result
    from the batches' pages; the same arrays as its ticks joined one by one."""
    lock = Lockstep(_short(name, 5.0), None, [1, 2, 3], randomise=True)
    lock.runs[1].steps = 70                  # ends first: the others go on in a new batch
    lock.results()
    for run in lock.runs:
        booked = run._booked()
        assert booked is not None and len(run._pages) > 1
        for f, value in stacked_tick_by_tick(run).items():
            assert booked[f].shape == value.shape and booked[f].dtype == value.dtype, f
            assert booked[f].tobytes() == value.tobytes(), f


def test_a_result_of_ticks_recorded_otherwise_is_joined_tick_by_tick():
    """A tick stepped alone, or a copy of the run, is not read from the pages."""
    lock = Lockstep(_short("slalom", 2.0), None, [1, 2], randomise=True)
    lock.step()
    lock.step()
    copied = copy.deepcopy(lock.runs[1])
    assert lock.runs[1]._booked() is not None and copied._booked() is None
    lock.runs[0].step()                     # a tick of its own, then the lockstep again
    lock.step()
    assert lock.runs[0]._booked() is None
    for run in (lock.runs[0], copied):
        res = run.result()
        for f, value in stacked_tick_by_tick(run).items():
            got = res.perceived if f == "block" else getattr(res, f)
            if f == "block":
                got = np.stack([got[k] for k in run.record[0].inputs], axis=1)
            assert np.asarray(got).tobytes() == value.tobytes(), f


@pytest.mark.parametrize("call, says", [
    (lambda w: run_lockstep(w, None, seeds=5), "seeds is a list of seeds, not int `5`"),
    (lambda w: run_lockstep(w, None, seeds=None), "seeds is a list of seeds, not NoneType"),
    (lambda w: run_lockstep(w, None, seeds=[-1]), "a seed is a whole number, 0 or more"),
    (lambda w: run_lockstep(w, None, seeds=[1], batch=2.5), "batch is a whole number of runs"),
    (lambda w: run_lockstep(w, None, seeds=[1], batch=0), "batch is a whole number of runs"),
    (lambda w: run_lockstep("moving", None, seeds=[1]), "a simulation runs a loaded World"),
    (lambda w: Lockstep("moving"), "a simulation runs a loaded World, not str `'moving'`"),
    (lambda w: Lockstep(w, seeds=3), "seeds is a list of seeds, not int `3`"),
])
def test_run_lockstep_says_what_is_wrong_with_its_arguments(call, says):
    """seeds=5 met "object of type 'int' has no len()", a path for the world "'str' object
    has no attribute 'given'" (or 'behavior'), batch=2.5 range()'s TypeError, and batch=0
    was taken as 1."""
    import re

    from mitos_cli.errors import InputError, WorldError

    world = dataclasses.replace(load_world(packaged_path("worlds", "moving.yaml")),
                                time_limit=0.2)
    with pytest.raises((InputError, WorldError), match=re.escape(says)):
        call(world)
    assert len(run_lockstep(world, None, seeds=range(2), batch=1)) == 2


def test_runs_stuck_without_progress_in_a_batch_are_stuck_at_the_tick_they_are_alone(
        monkeypatch):
    """BARN field 2079 (the poles unknown), three seeds, with ``PROGRESS_TIME`` shortened to
    4 s: each robot replans and backs out, then comes no nearer its goal for 4 s and is
    stuck (at 8.95-13.45 s, each at its own tick, while it still drives more than
    ``STUCK_DISTANCE`` in ``STUCK_TIME``); in a batch each run ends at the tick, and with
    the bits, it has alone."""
    from mitos_cli.sim.loop import STUCK_DISTANCE

    monkeypatch.setattr(loop, "PROGRESS_TIME", 4.0)
    world, planner, scene, seeds = _barn_2079(time_limit=20.0)
    together = run_lockstep(world, planner, seeds, scene=scene)
    alone = [simulate(world, planner, s, scene=scene) for s in seeds]
    assert len({r.ticks for r in alone}) == 3 and all(r.replanned for r in alone)
    window = int(round(STUCK_TIME / world.dt))
    for a, b in zip(alone, together):
        assert a.outcome == "stuck" and a.metrics["time_s"] < world.time_limit
        xy = a.pose[-window:, 0, :2]
        assert np.hypot(*np.diff(xy, axis=0).T).sum() > STUCK_DISTANCE   # it still drove
        assert_same_run(a, b)


def test_robots_of_many_robot_runs_stuck_without_progress_in_a_batch_are_as_alone(monkeypatch):
    """``multirobot`` (two robots head-on), each robot driving 8 in back and forth along its
    start heading, ``PROGRESS_TIME`` shortened to 4 s: three randomised runs in lockstep (the
    batch's rows two a run) end stuck at the tick, and with the bits, each has alone."""
    monkeypatch.setattr(loop, "PROGRESS_TIME", 4.0)
    world = dataclasses.replace(load_world(packaged_path("worlds", "multirobot.yaml")),
                                time_limit=STUCK_TIME + 4.0)
    starts = np.array([[a.start.x, a.start.y, np.radians(a.start.heading)]
                       for a in world.agents])

    class Swing:
        name = "swing"

        def plan(self, p):
            s = starts[p.robots]
            off = ((p.pose[:, 0] - s[:, 0]) * np.cos(s[:, 2])
                   + (p.pose[:, 1] - s[:, 1]) * np.sin(s[:, 2]))
            speed = np.where(off > 8.0, -15.0,
                             np.where(off < 0.0, 15.0, np.where(p.speed >= 0.0, 15.0, -15.0)))
            return np.full(len(off), 90.0), speed

    lock = Lockstep(world, Swing(), [1, 2, 3], randomise=True)
    for seed, res in zip([1, 2, 3], lock.results()):
        # both robots, before STUCK_TIME, each having driven over 50 in
        assert res.robot_outcomes == ("stuck", "stuck") and 4.0 <= res.metrics["time_s"] < 6.0
        assert all(m["path_length_in"] > 50.0 for m in res.robot_metrics)
        assert_same_run(simulate(world, Swing(), seed, randomise=True), res)
