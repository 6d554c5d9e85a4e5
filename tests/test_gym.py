"""The Gymnasium environments: the checker, seeding, the fuzzy policy's trajectory equals
``mitos simulate``'s, the spaces, the refusal of several robots, rendering."""

from __future__ import annotations

import re

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

from mitos_cli import gym as mgym  # noqa: E402
from mitos_cli.errors import WorldError  # noqa: E402
from mitos_cli.resources import packaged_path  # noqa: E402
from mitos_cli.sim import load_world, simulate  # noqa: E402


@pytest.fixture
def short_world(tmp_path):
    """The packaged slalom cut to 3 s (60 ticks), so a test run takes a fraction of a second."""
    text = packaged_path("worlds", "slalom.yaml").read_text(encoding="utf-8")
    path = tmp_path / "slalom3.yaml"
    path.write_text(text.replace("time_limit: 60", "time_limit: 3"), encoding="utf-8")
    return path


def drive(env, seed, policy=None, limit=10_000):
    obs, _ = env.reset(seed=seed)
    seen, rewards = [obs], []
    for _ in range(limit):
        action = policy(obs) if policy else env.unwrapped.fuzzy_policy(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        seen.append(obs)
        rewards.append(reward)
        if terminated or truncated:
            return seen, rewards, terminated, truncated, info
    raise AssertionError("the episode did not end")


def test_every_packaged_single_robot_world_is_registered():
    assert "mitos/World-v0" in mgym.ENVIRONMENTS
    for name in ("mitos/Corridor-v0", "mitos/Slalom-v0", "mitos/Figure4-v0", "mitos/Office-v0"):
        assert name in gymnasium.registry
    assert "mitos/Multirobot-v0" not in gymnasium.registry
    assert mgym.env_name("figure4.yaml") == "mitos/Figure4-v0"


# The action is the tricycle's own [steering deg, speed in/s] (docs/gym.md), not a normalised
# box: the checker's advice to normalise it is a choice this environment does not take.
@pytest.mark.filterwarnings("ignore:.*symmetric and normalized space:UserWarning")
def test_passes_gymnasiums_checker(short_world):
    from gymnasium.utils.env_checker import check_env

    env = gymnasium.make("mitos/World-v0", world=str(short_world), render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    env = gymnasium.make("mitos/World-v0", world=str(short_world), observe_ranges=True)
    check_env(env.unwrapped)


def test_fuzzy_policy_drives_the_trajectory_of_simulate_bit_for_bit(short_world):
    env = gymnasium.make("mitos/World-v0", world=str(short_world))
    _, rewards, terminated, truncated, info = drive(env, seed=4)
    ran = env.unwrapped.sim.result()
    ref = simulate(load_world(short_world), seed=4)
    assert ran.ticks == ref.ticks == 60
    assert np.array_equal(ran.pose, ref.pose)
    assert np.array_equal(ran.command, ref.command)
    assert (terminated, truncated, info["outcome"]) == (False, True, ref.outcome)
    # the reward is the route's progress: 0.01 per inch by which the route left shrank (the
    # route the robot follows at each tick: a replanned one from its replanning on)
    k = ref.ticks - 1
    left = ref.route_at(k, 0).length - ref.progress[k, 0]
    assert sum(rewards) == pytest.approx(0.01 * (ref.routes[0].length - left))


def test_a_steps_reward_is_that_steps_progress():
    """Straight down the corridor's straight route, each step's reward is 0.01 per inch the
    step moved the robot, the first step's too (the reward once came a step late: the
    progress of the tick recorded before the motion)."""
    env = gymnasium.make("mitos/Corridor-v0")
    _, info = env.reset(seed=1)
    x = info["pose"][0]
    for _ in range(5):
        _, reward, *_, info = env.step(np.array([90.0, 60.0]))
        assert reward == pytest.approx(mgym.PROGRESS_REWARD * (info["pose"][0] - x), abs=1e-12)
        assert reward > 0
        x = info["pose"][0]


def test_a_replan_rewards_only_the_change_in_the_route_left():
    """`moving` replans round a cart after 15.6 s onto a route 14 in longer than what was
    left: that step's reward is about -0.14, not +3.5 then -3.6 (the new route's length was
    once taken less the progress made along the old one)."""
    env = gymnasium.make("mitos/Moving-v0")
    obs, _ = env.reset(seed=1)
    sim, replans, steps = env.unwrapped.sim, [], []
    while True:
        before = sim.routes[0]
        left = before.length - sim.progress[0]
        obs, reward, terminated, truncated, info = env.step(env.unwrapped.fuzzy_policy(obs))
        if terminated or truncated:
            break
        steps.append(reward)
        now = sim.routes[0].length - sim.progress[0]
        assert reward == pytest.approx(mgym.PROGRESS_REWARD * (left - now), abs=1e-12)
        if sim.routes[0] is not before:
            replans.append(reward)
    assert info["outcome"] == "success" and replans
    assert max(abs(r) for r in steps) < 0.5        # a tick moves the robot 3 in at most


def test_the_documented_example_reaches_the_goal_as_simulate_does(capsys):
    """docs/gym.md's example, run as written: the goal, the bonus, simulate's trajectory."""
    import re
    from pathlib import Path

    page = (Path(__file__).resolve().parents[1] / "docs" / "gym.md").read_text(encoding="utf-8")
    code = re.search(r"```python\n(.*?)```", page, re.S).group(1)
    scope: dict = {}
    exec(compile(code, "docs/gym.md", "exec"), scope)
    printed = re.search(r"print\(.*\)\s+# (.*)", code).group(1)     # what the page says
    assert capsys.readouterr().out.split() == printed.split()
    assert scope["terminated"] and not scope["truncated"]
    assert scope["reward"] >= mgym.GOAL_BONUS
    assert scope["info"]["t"] == scope["same"].metrics["time_s"]


def test_the_brake_stops_a_policy_short_of_the_wall(short_world):
    env = gymnasium.make("mitos/World-v0", world=str(short_world))
    # full speed, half left: the robot's own brake stops it short of the corridor's wall
    _, _, terminated, _, info = drive(env, seed=1, policy=lambda obs: np.array([50.0, 60.0]))
    assert not terminated or info["outcome"] != "collision"
    run = env.unwrapped.sim.result()
    assert run.clearance.min() > 0.0 and run.speed[-1, 0] < 1.0


def test_a_collision_terminates_with_the_penalty(short_world):
    text = short_world.read_text(encoding="utf-8")
    short_world.write_text(text.replace("  acceleration: 40", "  acceleration: 40\n  brake: false"),
                           encoding="utf-8")
    env = gymnasium.make("mitos/World-v0", world=str(short_world))
    # full speed, half left: into the corridor's wall after 1.6 s
    _, rewards, terminated, _, info = drive(env, seed=1, policy=lambda obs: np.array([50.0, 60.0]))
    assert terminated and info["outcome"] == "collision"
    assert rewards[-1] <= mgym.COLLISION_PENALTY + 1.0


def test_the_step_that_ends_an_episode_is_timed_as_every_other(short_world):
    """`t` is the steps taken times dt on every step: the step that ended an episode (a
    contact here) read one dt more (1.7 s after 33 steps of 0.05 s), as `mitos simulate`
    timed the run; both now time it to the tick of the contact."""
    text = short_world.read_text(encoding="utf-8")
    short_world.write_text(text.replace("  acceleration: 40", "  acceleration: 40\n  brake: false"),
                           encoding="utf-8")
    env = gymnasium.make("mitos/World-v0", world=str(short_world))
    seen, _, terminated, _, info = drive(env, seed=1, policy=lambda obs: np.array([50.0, 60.0]))
    steps = len(seen) - 1
    assert terminated and info["outcome"] == "collision"
    assert info["t"] == round(steps * 0.05, 6)
    assert env.unwrapped.sim.result().summary()["time_s"] == info["t"]


@pytest.mark.parametrize("observe_ranges", [False, True])
def test_the_observation_at_the_time_limit_is_not_the_step_befores_object(short_world,
                                                                          observe_ranges):
    """At the time limit no tick is perceived past the end, and the step returned the very
    observation of the step before: a policy normalising that one in place changed the last
    one too (out of its space)."""
    env = gymnasium.make("mitos/World-v0", world=str(short_world), observe_ranges=observe_ranges)
    seen, _, _, truncated, info = drive(env, seed=1, policy=lambda obs: np.array([90.0, 10.0]))
    assert truncated and info["outcome"] == "timeout"
    before, last = seen[-2], seen[-1]
    for key in (("inputs", "ranges") if observe_ranges else (None,)):
        a, b = (before[key], last[key]) if key else (before, last)
        assert np.array_equal(a, b) and not np.shares_memory(a, b)
        a[...] = -1.0
    assert env.observation_space.contains(last)


def test_the_same_seed_gives_the_same_observations_and_another_seed_others(short_world):
    env = gymnasium.make("mitos/World-v0", world=str(short_world), observe_ranges=True)
    a = drive(env, seed=7)[0]
    b = drive(env, seed=7)[0]
    c = drive(env, seed=8)[0]
    assert len(a) == len(b)
    assert all(np.array_equal(x["inputs"], y["inputs"]) and np.array_equal(x["ranges"], y["ranges"])
               for x, y in zip(a, b))
    assert any(not np.array_equal(x["ranges"], y["ranges"]) for x, y in zip(a, c))


def test_spaces_are_the_universes_and_the_robots_limits():
    env = gymnasium.make("mitos/Corridor-v0")
    u = env.unwrapped
    assert u.input_names == tuple(u.fuzzy.compiled.inputs)
    assert np.array_equal(env.observation_space.low, u.fuzzy.compiled.universe[:, 0])
    robot = u.world.agents[0].robot
    assert env.action_space.low.tolist() == [robot.steering_min, -robot.max_reverse]
    assert env.action_space.high.tolist() == [robot.steering_max, robot.max_speed]
    obs, _ = env.reset(seed=1)
    assert env.observation_space.contains(obs)     # the goal 540 in away reads as 400
    with pytest.raises(ValueError, match="finite"):
        env.step(np.array([np.nan, 10.0]))


def test_several_robots_are_refused():
    with pytest.raises(WorldError, match="has 2 robots; a Gymnasium environment drives one"):
        gymnasium.make("mitos/World-v0", world="multirobot")


def test_rgb_array_shows_the_robot(short_world):
    env = gymnasium.make("mitos/World-v0", world=str(short_world), render_mode="rgb_array")
    env.reset(seed=1)
    for _ in range(10):
        env.step(np.array([90.0, 40.0]))
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    blue = np.array([0x1F, 0x5F, 0xBF])
    assert (np.abs(frame.astype(int) - blue).sum(axis=2) < 6).sum() > 20
    env.close()


def test_a_frame_is_of_the_tick_observed_with_the_route_as_replanned(tmp_path):
    """The frame drew the robot and the obstacles one tick behind the observation, `info` and
    its own title, and the first route to the end (through the stack detour's robot turned
    back from at 8.65 s)."""
    from mitos_cli.sim.geometry import rect_corners

    text = packaged_path("worlds", "detour.yaml").read_text(encoding="utf-8")
    path = tmp_path / "detour10.yaml"
    path.write_text(text.replace("time_limit: 90", "time_limit: 10"), encoding="utf-8")
    env = gymnasium.make("mitos/World-v0", world=str(path), render_mode="rgb_array")
    obs, _ = env.reset(seed=4)
    u = env.unwrapped
    while u.sim.routes[0] is u.sim.scene.routes[0]:          # until it replans
        obs, _, _, _, info = env.step(u.fuzzy_policy(obs))
    env.render()
    frame = u._frame
    x, y, heading = info["pose"]
    robot = u.world.agents[0].robot
    assert np.allclose(frame._robot.get_xy()[:4],
                       rect_corners(x, y, np.deg2rad(heading), robot.length, robot.width))
    where = u.sim.observe().where
    assert all(np.allclose(patch.get_xy()[:4], rect_corners(
        *where[j], np.deg2rad(o.angle), o.length, o.width))
        for j, (o, patch) in enumerate(frame._obstacles))
    assert np.array_equal(frame._routes[0].get_xydata(), u.sim.routes[0].points)
    env.close()


def test_rgb_array_draws_a_dollar_in_the_worlds_name_as_written(short_world):
    # the frame's texts went to matplotlib's mathtext, which stopped on `$x^$`
    text = short_world.read_text(encoding="utf-8")
    short_world.write_text(re.sub(r"(?m)^name: .*$", 'name: "sla $x^$ lom"', text),
                           encoding="utf-8")
    env = gymnasium.make("mitos/World-v0", world=str(short_world), render_mode="rgb_array")
    env.reset(seed=1)
    assert env.render().ndim == 3
    env.close()


def test_reset_reports_where_the_robot_stands(short_world):
    # reset's info said clearance inf (and its picture every input 0): no tick was recorded
    env = gymnasium.make("mitos/World-v0", world=str(short_world))
    _, info = env.reset(seed=4)
    ref = simulate(load_world(short_world), seed=4)
    assert info["clearance"] == ref.clearance[0, 0]
    state = env.unwrapped._state()
    assert all(state["inputs"][k][0] == ref.perceived[k][0, 0] for k in ref.perceived)


@pytest.mark.parametrize("action", ["go", ["90", 20], ("5_0", 10.0), np.array(["90", "20"]),
                                    np.array([90.0, "20"], dtype=object)])
def test_an_action_holding_text_is_refused(action):
    """``step(["90", 20])`` steered at 90 deg and ``("5_0", 10)`` at 50: NumPy reads text as
    ``float()`` does. Text is refused, as bools are, and the episode is left as it was."""
    from mitos_cli.errors import CommandError

    env = gymnasium.make("mitos/Corridor-v0")
    env.reset(seed=1)
    with pytest.raises(CommandError, match="the action must be numbers, not text"):
        env.step(action)
    assert env.unwrapped.sim.ticks == 0


@pytest.mark.parametrize("action, says", [
    (5.0, "not `5.0`"),
    (None, "not `None`"),
    ([90.0, 10.0, 1.0], "not of shape (3,)"),
])
def test_an_action_that_is_not_steering_and_speed_says_what_an_action_is(action, says):
    """step(5) met NumPy's "cannot reshape array of size 1 into shape (1,2)", step("go") its
    "could not convert string to float"; a refused action leaves the episode as it was."""
    from mitos_cli.errors import CommandError

    env = gymnasium.make("mitos/Corridor-v0")
    env.reset(seed=1)
    with pytest.raises(CommandError, match=r"an action is \[steering deg, speed in/s\]") as exc:
        env.step(action)
    assert says in exc.value.message and isinstance(exc.value, ValueError)
    assert env.unwrapped.sim.ticks == 0
    env.step(np.array([[90.0, 10.0]], dtype=np.float32))     # [1, 2] and float32 are fine
    assert env.unwrapped.sim.ticks == 1


@pytest.mark.parametrize("action", [[True, 30], np.array([True, False]), (np.bool_(True), 3.0),
                                    np.array([True, 3.0], dtype=object)])
def test_an_action_holding_a_bool_is_refused(action):
    """[True, 30] was a steering command of 1 deg, where fuzzy_policy, reset(seed=True) and
    simulate(seed=True) refuse bools."""
    from mitos_cli.errors import CommandError

    env = gymnasium.make("mitos/Corridor-v0")
    env.reset(seed=1)
    with pytest.raises(CommandError, match="the action must be numbers, not bools"):
        env.step(action)
    assert env.unwrapped.sim.ticks == 0


def test_an_action_past_a_floats_range_is_refused_and_the_episode_goes_on():
    """step([90, 10**400]) met NumPy's bare OverflowError ("int too large to convert")."""
    from mitos_cli.errors import CommandError

    env = gymnasium.make("mitos/Corridor-v0")
    env.reset(seed=1)
    with pytest.raises(CommandError, match="the action must be finite numbers: one is too large"):
        env.step([90.0, 10**400])
    assert env.step([90.0, 10.0])[4]["t"] == 0.05


def test_a_rulebase_or_behavior_the_environment_cannot_read_says_so():
    """rulebase=3 met "'int' object has no attribute 'behavior'"; behavior="" drove the
    world's behavior, as if none were given."""
    from mitos_cli.errors import NameError_, RuleBaseError

    with pytest.raises(RuleBaseError, match="a rule base is read from a file"):
        gymnasium.make("mitos/Corridor-v0", rulebase=3)
    with pytest.raises(NameError_, match="unknown behavior `''`"):
        gymnasium.make("mitos/Corridor-v0", behavior="")


def test_a_rulebase_without_the_worlds_behavior_is_said_at_the_world_with_behavior_eq():
    """`make("mitos/Figure4-v0", rulebase="tipper.fis")` said "unknown behavior `drive`,
    expected one of main", with no place and no word of `behavior=`: as `mitos simulate`, at
    the world's `behavior:` line, with how to choose another."""
    from pathlib import Path

    from mitos_cli.errors import NameError_

    tipper = Path(__file__).parent / "data" / "interop" / "tipper.fis"
    with pytest.raises(NameError_, match="unknown behavior `drive`") as info:
        gymnasium.make("mitos/Figure4-v0", rulebase=str(tipper))
    assert info.value.span is not None and info.value.span.path.endswith("figure4.yaml")
    assert "behavior= from Python" in info.value.hint


def test_fuzzy_policy_of_a_batch_gives_each_rows_action_in_one_evaluation():
    """A vector environment's observations ``[n, 13]`` were refused ("call it on each row":
    a Python loop over the samples); they give the ``[n, 2]`` actions, each row's bits those
    of the observation alone, the Dict form too."""
    from mitos_cli.errors import InputError

    env = gymnasium.make("mitos/Corridor-v0")
    obs, _ = env.reset(seed=1)
    policy = env.unwrapped.fuzzy_policy
    assert np.array_equal(policy(obs[None]), policy(obs)[None])
    envs = gymnasium.make_vec("mitos/Slalom-v0", num_envs=3)
    batch, _ = envs.reset(seed=4)
    for _ in range(40):                       # apart: each copy its own seed and place
        batch, *_ = envs.step(policy(batch))
    actions = policy(batch)
    assert actions.shape == (3, 2)
    assert all(np.array_equal(actions[i], policy(batch[i])) for i in range(3))
    assert len({tuple(a) for a in actions.tolist()}) == 3
    ranges = gymnasium.make_vec("mitos/Slalom-v0", num_envs=2, observe_ranges=True)
    both, _ = ranges.reset(seed=4)
    assert np.array_equal(policy(both), policy(both["inputs"])) and policy(both).shape == (2, 2)
    assert policy(np.empty((0, 13))).shape == (0, 2)
    with pytest.raises(InputError, match=r"or a batch of them \[n, 13\], not of shape \(2, 3\)"):
        policy(obs[None, :3].repeat(2, axis=0))
    with pytest.raises(InputError, match=r"not of shape \(1, 1, 13\)"):
        policy(obs[None, None])
    # the engine said "expected inputs of shape [n, 13] (...), not (1, 3)"
    with pytest.raises(InputError, match=r"an observation is the 13 inputs \(road, .*\), "
                                         r"or a batch of them \[n, 13\], not of shape \(3,\)\n"):
        env.unwrapped.fuzzy_policy(obs[:3])
    assert np.array_equal(env.unwrapped.fuzzy_policy(list(obs)), env.unwrapped.fuzzy_policy(obs))


def test_stepping_or_drawing_before_reset_is_gymnasiums_reset_needed():
    """Used without Gymnasium's OrderEnforcing wrapper (`env.unwrapped`, a vector or SB3
    wrapper), step() and render() before reset() met "'MitosEnv' object has no attribute
    '_trail'"; render_mode="human" drew nothing without a word."""
    for mode in ("rgb_array", "human"):
        env = mgym.MitosEnv("corridor", render_mode=mode)
        with pytest.raises(gymnasium.error.ResetNeeded,
                           match=r"Cannot call env\.render\(\) before calling env\.reset\(\)"):
            env.render()
    env = gymnasium.make("mitos/Corridor-v0").unwrapped
    with pytest.raises(gymnasium.error.ResetNeeded,
                       match=r"Cannot call env\.step\(\) before calling env\.reset\(\)"):
        env.step(np.array([90.0, 10.0]))
    env.reset(seed=1)
    env.step(np.array([90.0, 10.0]))
    assert env.sim.ticks == 1


def test_a_loaded_world_makes_an_environment_and_a_non_world_says_what_is_taken():
    """A World loaded (or changed) in Python: `expected str, bytes or os.PathLike object,
    not World`; now it is driven as it is."""
    import dataclasses

    world = dataclasses.replace(load_world(packaged_path("worlds", "corridor.yaml")),
                                time_limit=1.0)
    env = gymnasium.make("mitos/World-v0", world=world)
    assert env.unwrapped.world is world
    _, _, terminated, truncated, info = drive(env, seed=2)
    assert truncated and not terminated and info["t"] == 1.0
    with pytest.raises(WorldError, match="expected a path or a packaged world's name"):
        gymnasium.make("mitos/World-v0", world=3)


@pytest.mark.parametrize("name, kwargs", [("mitos/World-v0", {}),
                                          ("mitos/World-v0", {"world": None}),
                                          ("mitos/Corridor-v0", {"world": None})])
def test_world_v0_without_a_world_says_it_needs_one(name, kwargs):
    """`make("mitos/World-v0")` without `world=` trained on the packaged corridor without a
    word; `world=None` given to a packaged world's id was told "mitos/World-v0 needs world=",
    an id it did not use."""
    with pytest.raises(mgym.EnvOptionError, match="the environment needs world=: a world file, "
                                                  "a packaged world's name or a loaded World"):
        gymnasium.make(name, **kwargs)
    assert gymnasium.make("mitos/Corridor-v0").unwrapped.world.name == "corridor"


def test_a_collision_run_differs_from_simulate_only_in_the_last_command():
    """docs/gym.md: at the tick where a collision ends the run the environment asks for no
    action and records the one before it; everything else is simulate()'s run."""
    env = gymnasium.make("mitos/Figure4-v0")                 # collides at B
    _, _, terminated, _, info = drive(env, seed=3)
    ran = env.unwrapped.sim.result()
    ref = simulate(load_world(packaged_path("worlds", "figure4.yaml")), seed=3)
    assert terminated and info["outcome"] == ref.outcome == "collision"
    for key in ("pose", "speed", "steering", "ranges", "clearance", "obstacles"):
        assert np.array_equal(getattr(ran, key), getattr(ref, key)), key
    assert np.array_equal(ran.command[:-1], ref.command[:-1])
    assert np.array_equal(ran.command[-1], ran.command[-2])
    assert ran.summary() == ref.summary()


def test_fuzzy_policy_refuses_an_observation_that_is_not_numbers():
    """`np.asarray(x, dtype=float)` read bools as 1 and 0 and a structure of one field as it."""
    from mitos_cli.errors import InputError

    env = gymnasium.make("mitos/Corridor-v0")
    obs, _ = env.reset(seed=1)
    with pytest.raises(InputError, match="the observation's values must be numbers, not bools"):
        env.unwrapped.fuzzy_policy(obs > 0)
    record = np.array([(x,) for x in obs], dtype=[("v", "f8")])
    with pytest.raises(InputError, match=r"the observation's values are structured \(field `v`\)"):
        env.unwrapped.fuzzy_policy(record)


def test_fuzzy_policy_of_a_dict_without_inputs_says_what_it_holds():
    """{"x": 1} met a bare KeyError: 'inputs'."""
    from mitos_cli.errors import InputError

    env = gymnasium.make("mitos/Corridor-v0", observe_ranges=True)
    obs, _ = env.reset(seed=1)
    with pytest.raises(InputError, match=r"holds `inputs` \(and `ranges`\), not keys `ranges`"):
        env.unwrapped.fuzzy_policy({"ranges": obs["ranges"]})
    assert np.array_equal(env.unwrapped.fuzzy_policy(obs), env.unwrapped.fuzzy_policy(obs["inputs"]))


@pytest.mark.parametrize(("seed", "says"), [
    (-1, "a seed must be 0 or more, not -1"),
    (np.int64(-2), "a seed must be 0 or more, not -2"),
    pytest.param(-10**5000, "a seed must be 0 or more, not a number of 16,610 bits",
                 id="-10**5000"),                                             # str() fails
    (1.5, "a seed is a whole number, not a float: `1.5`"),
    (3.0, "a seed is a whole number, not a float: `3.0`"),
    ("3", "a seed is a whole number, not text: `'3'`"),
    (True, "a seed is a whole number, not a bool: `True`"),        # Gymnasium took it as 1
])
def test_a_seed_reset_does_not_take_is_said_in_words(seed, says):
    """Gymnasium's own "Seed must be greater or equal to zero, actual value: -1" (or "must be
    a python integer, actual type: <class 'float'>"); still a `gymnasium.error.Error`."""
    from mitos_cli.errors import InputError

    env = gymnasium.make("mitos/Corridor-v0")
    with pytest.raises(mgym.SeedError) as info:
        env.reset(seed=seed)
    assert info.value.message == says
    assert isinstance(info.value, InputError) and isinstance(info.value, gymnasium.error.Error)
    assert "an int of 0 or more, or None" in str(info.value)


def test_the_seeds_gymnasium_takes_give_its_runs_and_a_numpy_int_its_int():
    env = gymnasium.make("mitos/Corridor-v0")
    first, _ = env.reset(seed=7)
    assert env.unwrapped.np_random_seed == 7 and env.unwrapped.sim.seed == 7
    again, _ = env.reset(seed=np.int64(7))        # Gymnasium refused a NumPy int
    assert np.array_equal(first, again) and env.unwrapped.np_random_seed == 7
    env.reset(seed=0)
    env.reset(seed=2**70)                          # SeedSequence takes any size
    assert env.unwrapped.sim.seed == 2**70
    env.reset()
    assert env.unwrapped.sim.seed is not None


def _unseeded_resets(n=3):
    env = gymnasium.make("mitos/Corridor-v0")
    first = env.reset()[0]
    return [first] + [env.reset()[0] for _ in range(n - 1)], env.unwrapped.sim.seed


def test_resets_without_a_seed_give_the_same_episodes_in_every_environment():
    # the second reset drew its seed from Gymnasium's generator, which a reset without a seed
    # left seeded from the OS's entropy: another episode in every process
    a, seed_a = _unseeded_resets()
    b, seed_b = _unseeded_resets()
    assert all(np.array_equal(x, y) for x, y in zip(a, b)) and seed_a == seed_b
    world = load_world(packaged_path("worlds", "corridor.yaml"))
    env = gymnasium.make("mitos/Corridor-v0")
    assert np.array_equal(env.reset()[0], env.reset(seed=world.seed)[0])   # the world's seed first
    assert not np.array_equal(a[0], a[1])                 # later episodes are other episodes


def test_a_vector_environment_reset_without_seeds_is_the_same_in_every_process():
    def episodes(seed):
        envs = gymnasium.make_vec("mitos/Corridor-v0", num_envs=2, vectorization_mode="sync")
        return [envs.reset(seed=seed)[0], envs.reset()[0], envs.reset()[0]]

    for seed in (None, 5):
        assert all(np.array_equal(x, y) for x, y in zip(episodes(seed), episodes(seed)))
    seeded = episodes(5)                        # seed s: sub-environment i runs s + i
    assert not np.array_equal(seeded[0][0], seeded[0][1])


@pytest.mark.parametrize(("kwargs", "says", "hint"), [
    ({"obsreve_ranges": True}, "unknown keyword `obsreve_ranges` of the MITOS environment",
     "did you mean `observe_ranges`?"),
    ({"rulebse": "x.rules"}, "unknown keyword `rulebse` of the MITOS environment",
     "did you mean `rulebase`?"),
    ({"max_episode_step": 5}, "unknown keyword `max_episode_step` of the MITOS environment",
     "did you mean `max_episode_steps` (a keyword of gymnasium.make)?"),
    ({"colour": "red"}, "unknown keyword `colour` of the MITOS environment", None),
    ({"render_mode": "rgb"}, "unknown render_mode `rgb`", "did you mean `rgb_array`?"),
    ({"observe_ranges": "no"}, "observe_ranges is True or False, not `'no'`",
     "observe_ranges=True adds the sonar ranges to the observation"),
])
@pytest.mark.filterwarnings("ignore:.*not in the possible render_modes:UserWarning")
def test_a_misspelt_keyword_is_said_with_the_options(kwargs, says, hint):
    """`gymnasium.make(id, obsreve_ranges=True)` was Python's "MitosEnv.__init__() got an
    unexpected keyword argument ... was raised from the environment creator for ... with
    kwargs (...)"; `render_mode="rgb"` a bare ValueError."""
    for make in (lambda: gymnasium.make("mitos/Corridor-v0", **kwargs),
                 lambda: mgym.MitosEnv("corridor", **kwargs)):
        with pytest.raises(mgym.EnvOptionError) as info:
            make()
        assert (info.value.message, info.value.hint) == (says, hint)
        assert isinstance(info.value, ValueError) and not isinstance(info.value, TypeError)
    if "keyword" in says:
        assert info.value.expected == \
            "one of world, rulebase, behavior, observe_ranges, render_mode"


def test_every_keyword_the_options_list_is_one_the_environment_takes():
    import inspect

    params = inspect.signature(mgym.MitosEnv.__init__).parameters
    assert set(mgym.OPTIONS) == {p for p in params if p not in ("self", "others")}


def test_a_randomised_reset_is_the_run_simulate_randomises_and_the_next_reset_is_not():
    """`reset(options=...)` was ignored whatever it held: `{"randomise": True}` gave the
    world as written, without a word."""
    path = packaged_path("worlds", "moving.yaml")
    env = gymnasium.make("mitos/Moving-v0")
    obs, _ = env.reset(seed=7, options={"randomise": True})
    for _ in range(40):
        obs, *_ = env.step(env.unwrapped.fuzzy_policy(obs))
    ran = env.unwrapped.sim.result()
    ref = simulate(load_world(path), seed=7, randomise=True)
    assert ran.ticks == 40
    assert np.array_equal(ran.pose, ref.pose[:40])
    assert env.unwrapped.sim.world.obstacles != load_world(path).obstacles
    env.reset(seed=7)
    assert env.unwrapped.sim.world.obstacles == load_world(path).obstacles


@pytest.mark.parametrize(("options", "says", "hint"), [
    ({"randomize": True}, "unknown option `randomize` of reset", "did you mean `randomise`?"),
    ({"randomise": "yes"}, "randomise is True or False, not `'yes'`",
     "randomise=True draws the world's randomise: ranges"),
    (["randomise"], "reset's options are a dict, not `['randomise']`",
     'reset(options={"randomise": True})'),
])
def test_a_reset_option_the_environment_does_not_take_is_said_with_the_options(
        options, says, hint):
    env = mgym.MitosEnv("corridor")
    with pytest.raises(mgym.EnvOptionError) as info:
        env.reset(seed=1, options=options)
    assert (info.value.message, info.value.hint) == (says, hint)


def test_an_episode_that_goes_back_and_forth_without_progress_is_truncated_stuck(monkeypatch):
    """Forward 1 s, back 1 s, and again: the robot drives on, but comes no nearer its goal in
    ``PROGRESS_TIME`` (shortened to 4 s): truncated, ``stuck``, at 4-6 s."""
    from mitos_cli.sim import loop

    monkeypatch.setattr(loop, "PROGRESS_TIME", 4.0)
    env = gymnasium.make("mitos/Corridor-v0")
    steps = iter(range(10_000))

    def swing(obs):
        return np.array([90.0, 15.0 if (next(steps) // 20) % 2 == 0 else -15.0])

    _, _, terminated, truncated, info = drive(env, seed=1, policy=swing)
    assert (terminated, truncated, info["outcome"]) == (False, True, "stuck")
    assert 4.0 <= info["t"] <= 6.0
