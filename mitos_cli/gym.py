"""Gymnasium environments of the simulator (the ``gym`` extra: ``pip install 'gymnasium>=1.0'``).

Importing this module registers ``mitos/World-v0`` (any world file: ``gymnasium.make(
"mitos/World-v0", world="path.yaml")``) and one environment per packaged single-robot world,
named after its file (``mitos/Corridor-v0``, ``mitos/Slalom-v0``, ``mitos/Figure4-v0``, ...).
``gymnasium.make("mitos_cli.gym:mitos/Corridor-v0")`` imports it on the way.

Each step is one tick of :class:`mitos_cli.sim.Simulation` (``dt`` of the world, 0.05 s in the
packaged ones), driven by the action instead of the planner; the simulator does everything else
as ``mitos simulate`` does (sensor noise, moving obstacles, replanning, the verdict).

- **observation**: the rule base's inputs as the robot perceives them, in the compiled order of
  the behavior (``env.unwrapped.input_names``), clamped to each variable's universe (which is
  what the rule base reads: the engine clamps the same way), a ``Box`` of ``float64`` with the
  universes as bounds. With ``observe_ranges=True`` a ``Dict`` of ``inputs`` and ``ranges``
  (the noisy sonar readings, ``[0, sensor range]`` inches, one per beam).
- **action**: ``[steering (deg, 90 straight, below 90 left), speed (in/s)]`` in a ``Box`` over
  the robot's steering limits and ``[-max_reverse, max_speed]`` (below 0 it drives backward);
  the robot's own brake (:mod:`.sim.safety`; ``robot: {brake: false}`` takes it away) holds
  the speed to what it can stop from before its body touches what it knows, and backs out of
  a pocket it has held it in; the kinematics clamp a command to the limits and then apply the
  steering rate and acceleration limits (the command is recorded as the robot carried it out).
- **reward**: ``PROGRESS_REWARD`` (0.01) per inch by which the route left to the goal shrank
  in the step (a replanned, longer route counts as going back), ``COLLISION_PENALTY`` (-10) when
  the robot touches something, ``GOAL_BONUS`` (+10) when it reaches its goal.
- **terminated** on the goal or a collision; **truncated** at the world's time limit, and when
  the simulator finds the robot stuck (it drove less than 3 in in 6 s, or came no more than
  1 in nearer its goal, in a straight line or along its route, in 40 s). At truncation the
  observation is the last one perceived (the simulator senses no tick past its limit).
- **info**: ``t`` (s simulated, ticks times ``dt`` as ``mitos simulate`` counts them),
  ``pose`` (x, y in, heading deg), ``clearance`` (in), ``outcome``.
- **render_mode** ``rgb_array``: the map, the obstacles, the footprint and the trail as an RGB
  image (matplotlib's Agg canvas); ``human``: a window where a display is, else the terminal
  live view of ``mitos simulate --live`` on stderr.
- **seeding**: ``reset(seed=s)`` runs the world from seed ``s`` (``SeedSequence(s)``, as
  ``mitos simulate --seed s``): the same seed and actions give the same observations bit for
  bit. ``reset()`` without a seed uses the world's on the first call, seeds the
  environment's own generator with it, and draws each later episode's seed from that
  generator: the same resets give the same episodes in every process.

Worlds with several robots are refused (one agent acts). The fuzzy planner is the policy of
``mitos simulate``: driving this environment with ``env.unwrapped.fuzzy_policy`` gives the
same trajectory bit for bit (docs/gym.md).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
except ImportError as exc:  # pragma: no cover - the extra is missing
    from .errors import MitosError, install_hint

    raise MitosError("the Gymnasium environments need gymnasium, which is not installed",
                     hint=install_hint("gym")) from exc

from .errors import CommandError, InputError, WorldError, closest, unknown
from .sim.world import World

if TYPE_CHECKING:                      # drawn only when rendered: imported there
    from .draw.frame import RunFrame
    from .sim.live import LiveView
    from .sim.planner import Percepts

    #: an observation: the inputs, or with observe_ranges a dict of them and the ranges
    Observation = np.ndarray | dict[str, np.ndarray]

PROGRESS_REWARD = 0.01      # per inch of route
COLLISION_PENALTY = -10.0
GOAL_BONUS = 10.0


class SeedError(InputError, gymnasium.error.Error):
    """A seed ``reset`` does not take: Gymnasium's contract is ``None`` or an int of 0 or more.
    Also Gymnasium's own ``error.Error``, which ``Env.reset`` raised for these (in its words:
    "Seed must be a python integer, actual type: <class 'float'>"), so a caller's ``except``
    still catches it."""


class EnvOptionError(InputError, ValueError):
    """A keyword the environment does not have (``gymnasium.make(id, **kwargs)`` passes its
    unknown keywords on to it), or a value one does not take, said with the known options and
    a "did you mean". Also a ``ValueError``, which a bad ``render_mode`` was; not a
    ``TypeError``, which Python's own "unexpected keyword argument" was: ``gymnasium.make``
    rebuilds a ``TypeError`` from its text alone, with the environment's kwargs appended."""


#: The environment's own keywords, and those of ``gymnasium.make`` (a misspelt one of these
#: reaches the environment too).
OPTIONS = ("world", "rulebase", "behavior", "observe_ranges", "render_mode")
MAKE_OPTIONS = ("max_episode_steps", "disable_env_checker", "autoreset")


class _Commanded:
    """The Simulation's planner slot while the environment drives: every command is given."""

    name = "gym"

    def plan(self, percepts: Percepts  # pragma: no cover - step() always passes the command
             ) -> tuple[np.ndarray, np.ndarray]:
        raise RuntimeError("the environment passes every command")


class MitosEnv(gymnasium.Env):
    """One robot of a world, stepped tick by tick (see the module's docstring)."""

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 20}

    def __init__(self, world: str | Path | World | None = None, *,
                 rulebase: str | Path | None = None,
                 behavior: str | None = None, observe_ranges: bool = False,
                 render_mode: str | None = None, **others: Any) -> None:
        from .sim.loop import Simulation
        from .sim.planner import fuzzy_planner
        from .sim.worldcheck import check_built
        from .sim.worldfile import load_world

        _check_options(others, observe_ranges, render_mode, self.metadata["render_modes"])
        if world is None:            # (mitos/World-v0 without world= drove the corridor)
            # (any id: `make("mitos/Corridor-v0", world=None)` lands here too)
            raise EnvOptionError("the environment needs world=: a world file, a packaged "
                                 "world's name or a loaded World, not None",
                                 hint='gymnasium.make("mitos/World-v0", world="path.yaml"); '
                                      'a packaged world has its own: "mitos/Corridor-v0"')

        # a World loaded (or changed) in Python, else a file or a packaged world's name
        loaded = world if isinstance(world, World) else load_world(world)
        check_built(loaded)          # before its numbers make the spaces (a NaN Box bound)
        if len(loaded.agents) != 1:
            raise WorldError(f"world `{loaded.name}` has {len(loaded.agents)} robots; a "
                             f"Gymnasium environment drives one",
                             hint="give a world with one robot (no `robots:` list)")
        self.world = loaded
        self.render_mode = render_mode
        self.observe_ranges = observe_ranges
        self.metadata = {**self.metadata, "render_fps": round(1.0 / loaded.dt)}
        self.fuzzy = fuzzy_planner(loaded, rulebase, behavior)
        compiled = self.fuzzy.compiled
        self.input_names: tuple[str, ...] = tuple(compiled.inputs)
        self._lo = np.ascontiguousarray(compiled.universe[:, 0], dtype=np.float64)
        self._hi = np.ascontiguousarray(compiled.universe[:, 1], dtype=np.float64)
        inputs = spaces.Box(self._lo, self._hi, dtype=np.float64)
        robot, sen = loaded.agents[0].robot, loaded.sensors
        if observe_ranges:
            beams = len(sen.angles)
            self.observation_space: spaces.Space = spaces.Dict({
                "inputs": inputs,
                "ranges": spaces.Box(0.0, float(sen.range), (beams,), dtype=np.float64)})
        else:
            self.observation_space = inputs
        self.action_space = spaces.Box(
            np.array([robot.steering_min, -robot.max_reverse]),
            np.array([robot.steering_max, robot.max_speed]),
            dtype=np.float64)
        self.sim = Simulation(loaded, _Commanded(), loaded.seed)
        self._seeded = False
        self._trail: list[np.ndarray] | None = None        # the robot's places; None till reset
        self._frame: RunFrame | None = None
        self._live: LiveView | None = None

    # -- the policy mitos simulate uses -------------------------------------------------------

    def fuzzy_policy(self, observation: object) -> np.ndarray:
        """The rule base's command for ``observation``: what ``mitos simulate`` would do,
        ``[steering, speed]``. A batch of observations ``[n, k]`` (a vector environment's, or
        its ``Dict`` one) gives the ``[n, 2]`` actions in one evaluation of the rule network,
        each row the bits it has alone (it was refused: "call it on each row")."""
        from .engine.evaluation import evaluate, evaluate_one

        x = self._rows(_inputs_of(observation))
        outputs = self.fuzzy.compiled.outputs
        pick = [outputs.index("steering"), outputs.index("speed")]
        if x.ndim == 2:
            return evaluate(self.fuzzy.compiled, x, detail=False).outputs[:, pick]
        out = evaluate_one(self.fuzzy.compiled, x.tolist())
        return np.array([out[pick[0]], out[pick[1]]])

    def _rows(self, x: object) -> np.ndarray:
        """One observation ``[k]`` or a batch ``[n, k]`` as the floats the rule base reads,
        else an :class:`InputError` (bools, dates and structured arrays are refused as the
        engine's inputs are)."""
        from .engine.inputs import floats

        rows = floats(x, "the observation's values", many=True)
        k = len(self.input_names)
        if rows.shape != (k,) and (rows.ndim != 2 or rows.shape[1] != k):
            # (the engine said "of shape [n, 13] ..., not (1, 3)")
            raise InputError(f"an observation is the {k} inputs ({', '.join(self.input_names)}), "
                             f"or a batch of them [n, {k}], not of shape {rows.shape}",
                             hint="give it the observation reset() or step() returned")
        return rows

    # -- Gymnasium ----------------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None
              ) -> tuple[Observation, dict]:
        seed = _check_seed(seed)
        randomise = _randomise(options)          # (checked before the generator moves)
        if seed is None and not self._seeded:
            # the first reset without a seed runs the world's seed, and seeds the generator
            # later resets draw from with it: Gymnasium's own would take the OS's entropy, a
            # different second episode in every process (docs/gym.md)
            super().reset(seed=self.world.seed)
            seed = self.world.seed
        else:
            super().reset(seed=seed)
            if seed is None:
                seed = int(self.np_random.integers(2**31))
        self._seeded = True
        self.sim.reset(seed, randomise=randomise)
        self._trail = [self.sim.pose[0, :2].copy()]
        obs = self._observe()
        self._remaining = self._left()
        if self.render_mode == "human":
            self.render()
        return obs, self._info()

    def step(self, action: object) -> tuple[Observation, float, bool, bool, dict]:
        sim = self.sim
        trail = _begun(self._trail, "step")
        if sim.done:
            raise RuntimeError("the episode has ended: call reset()")
        command = _command(action)
        sim.step(command)
        if not sim.done:
            trail.append(sim.pose[0, :2].copy())
            obs = self._observe()
            if sim.ending:                  # contact or arrival: the run ends at this tick
                sim.step(command)
        else:                               # no tick past the end: the last one perceived
            obs = _copied(self._last_obs)
        left = self._left()
        reward = PROGRESS_REWARD * (self._remaining - left)
        self._remaining = left
        outcome = sim.robot_outcomes[0] if sim.done else "driving"
        terminated = outcome in ("success", "collision")
        if outcome == "success":
            reward += GOAL_BONUS
        elif outcome == "collision":
            reward += COLLISION_PENALTY
        truncated = sim.done and not terminated
        if self.render_mode == "human":
            self.render()
        return obs, float(reward), terminated, truncated, self._info()

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gymnasium.logger.warn("render() without a render_mode: give render_mode='rgb_array' "
                                  "or 'human' to gymnasium.make")
            return None
        trail = _begun(self._trail, "render")
        sim = self.sim
        pose, obstacles = self._shown()
        if self.render_mode == "human" and self._live is not None:
            self._live.update(0, self._state())
            return None
        if self._frame is None:
            from .draw.frame import RunFrame
            from .draw.output import DrawError

            try:
                self._frame = RunFrame(self.world, sim.scene.static, sim.routes,
                                       show=self.render_mode == "human")
            except DrawError:
                if self.render_mode != "human":
                    raise
                from .sim.live import LiveView

                # unpaced, every call drawn: the environment's caller sets the pace
                self._live = LiveView(self.world, sim.scene, speed=0.0,
                                      fps=float("inf")).__enter__()
                self._live.update(0, self._state())
                return None
        if self.render_mode == "rgb_array":
            return self._frame.rgb(pose, obstacles, trail, sim.time, sim.routes)
        self._frame.update(pose, obstacles, trail, sim.time, sim.routes)
        import matplotlib.pyplot as plt

        plt.pause(0.001)
        return None

    def close(self) -> None:
        if self._frame is not None:
            self._frame.close()
            self._frame = None
        if self._live is not None:
            self._live.__exit__(None, None, None)
            self._live = None

    # -- helpers ------------------------------------------------------------------------------

    def _observe(self) -> Observation:
        s = self.sim.observe()
        x = np.array([s.inputs[k][0] for k in self.input_names], dtype=np.float64)
        x = np.minimum(np.maximum(x, self._lo), self._hi)
        obs: Any = x
        if self.observe_ranges:
            obs = {"inputs": x, "ranges": np.array(s.ranges[0], dtype=np.float64)}
        self._last_obs = obs
        return obs

    def _left(self) -> float:
        """Route left to the goal (in) where the robot was last perceived, along its route
        then: the route and the progress of one observation (a tick recorded before a replan
        measured its progress along the old route)."""
        sim = self.sim
        return max(0.0, sim.routes[0].length - float(sim.progress[0]))

    def _shown(self) -> tuple[np.ndarray, np.ndarray]:
        """The robot's pose and the obstacles' places a frame shows: of the tick the last
        observation perceived (the frame drew the tick before it, one ``dt`` behind the
        observation, ``info`` and its own title), else of the last tick the run recorded."""
        sim = self.sim
        if not sim.done and sim.observed:
            return sim.pose[0], sim.observe().where
        if sim.record:
            return sim.record[-1].pose[0], sim.record[-1].obstacles
        return sim.pose[0], np.zeros((0, 2))

    def _state(self) -> dict:
        sim = self.sim
        if sim.done:                                        # the last tick it drove
            inputs, obstacles = sim.record[-1].inputs, sim.record[-1].obstacles
        else:                                               # the tick it stands in
            s = sim.observe()
            inputs, obstacles = s.inputs, s.where
        return {"t": sim.time, "pose": sim.pose, "speed": sim.speed, "steering": sim.steering,
                "inputs": inputs, "clearance": sim.clearance, "obstacles": obstacles}

    def _info(self) -> dict:
        sim = self.sim
        return {"t": round(sim.time, 6), "pose": sim.pose[0],
                "clearance": float(sim.clearance[0]),
                "outcome": sim.robot_outcomes[0] if sim.done else "driving"}


def _inputs_of(observation: object) -> object:
    """The inputs of an observation: itself, or a ``Dict`` observation's ``inputs`` (a dict
    without them met a bare ``KeyError: 'inputs'``)."""
    if not isinstance(observation, dict):
        return observation
    if "inputs" not in observation:
        keys = ", ".join(f"`{k!s:.20}`" for k in list(observation)[:5]) or "none"
        raise InputError(f"an observation given as a dict holds `inputs` (and `ranges`), not "
                         f"keys {keys}",
                         hint="give it the observation reset() or step() returned")
    return observation["inputs"]


def _copied(obs: Any) -> Any:
    """A copy of an observation given already: the step that ends an episode at the time limit
    returned the very array (or dict) of the step before, so writing into that one (an
    in-place normalisation, a buffer's row) changed the final observation too."""
    if isinstance(obs, dict):
        return {key: value.copy() for key, value in obs.items()}
    return obs.copy()


def _begun(trail: list[np.ndarray] | None, call: str) -> list[np.ndarray]:
    """The episode's trail, else Gymnasium's :class:`~gymnasium.error.ResetNeeded` in its
    words, which its ``OrderEnforcing`` wrapper gives: the environment used without it
    (``env.unwrapped``, a vector or SB3 wrapper) met "'MitosEnv' object has no attribute
    '_trail'", or drew nothing without a word."""
    if trail is None:
        raise gymnasium.error.ResetNeeded(f"Cannot call env.{call}() before calling "
                                          "env.reset(): the episode has not begun")
    return trail


def _check_options(others: dict[str, Any], observe_ranges: object, render_mode: object,
                   modes: list[str]) -> None:
    """Refuse a keyword the environment does not have (Python's "unexpected keyword
    argument", re-raised by ``gymnasium.make`` with its kwargs), a ``render_mode`` it cannot
    draw in and an ``observe_ranges`` that is not a bool (``"no"`` was true)."""
    if others:
        name = str(next(iter(others)))
        near = closest(name, OPTIONS)
        hint = (f"did you mean `{near}`?" if near else
                f"did you mean `{made}` (a keyword of gymnasium.make)?"
                if (made := closest(name, MAKE_OPTIONS)) else None)
        raise EnvOptionError(f"unknown keyword `{name}` of the MITOS environment",
                             expected="one of " + ", ".join(OPTIONS), hint=hint)
    if render_mode is not None and render_mode not in modes:
        error = unknown("render_mode", f"{render_mode}", modes, cls=EnvOptionError)
        error.hint = error.hint or "render_mode=None (the default) draws nothing"
        raise error
    if not isinstance(observe_ranges, (bool, np.bool_)):
        raise EnvOptionError(f"observe_ranges is True or False, not `{observe_ranges!r:.40}`",
                             hint="observe_ranges=True adds the sonar ranges to the observation")


RESET_OPTIONS = ("randomise",)


def _randomise(options: object) -> bool:
    """Whether ``reset(options=...)`` asks for a randomised episode (``{"randomise": True}``:
    obstacle places and sensor noise drawn from the world's ``randomise:`` ranges by the seed,
    as ``mitos simulate --seed S --randomise`` does). Another key, or a value that is not a
    bool, is an :class:`EnvOptionError`: an option ignored would be a silently different run."""
    if options is None:
        return False
    if not isinstance(options, dict):
        raise EnvOptionError(f"reset's options are a dict, not `{options!r:.40}`",
                             hint='reset(options={"randomise": True})')
    for name in options:
        if name not in RESET_OPTIONS:
            near = closest(str(name), RESET_OPTIONS)
            raise EnvOptionError(f"unknown option `{name!s:.40}` of reset",
                                 expected="one of " + ", ".join(RESET_OPTIONS),
                                 hint=f"did you mean `{near}`?" if near else None)
    value = options.get("randomise", False)
    if not isinstance(value, (bool, np.bool_)):
        raise EnvOptionError(f"randomise is True or False, not `{value!r:.40}`",
                             hint="randomise=True draws the world's randomise: ranges")
    return bool(value)


def _check_seed(seed: object) -> int | None:
    """``seed`` as Gymnasium's ``reset`` takes it (``None`` or an int of 0 or more), else a
    :class:`SeedError` in words. A NumPy integer (``rng.integers(...)``) is taken as the int it
    is, where Gymnasium refused it; a bool is refused, where Gymnasium took ``True`` as 1."""
    if seed is None:
        return None
    expected = "an int of 0 or more, or None (Gymnasium's `reset(seed=...)`)"
    hint = "env.reset(seed=1); env.reset() continues the environment's own generator"
    if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
        value = int(seed)
        if value >= 0:
            return value
        bits = value.bit_length()         # str() of over 4,300 digits is a ValueError
        shown = f"{value}" if bits < 1000 else f"a number of {bits:,} bits"
        raise SeedError(f"a seed must be 0 or more, not {shown}", expected=expected, hint=hint)
    kind = type(seed).__name__
    raise SeedError(f"a seed is a whole number, not {'a ' + kind if kind != 'str' else 'text'}"
                    f": `{seed!r:.40}`", expected=expected, hint=hint)


def _command(action: object) -> np.ndarray:
    """``action`` as the ``[1, 2]`` command it is, else a :class:`CommandError` saying what an
    action is (``step(5)`` met NumPy's "cannot reshape array of size 1 into shape (1,2)"; a
    bool was read as 1 or 0, where every other entry point refuses it)."""
    from .engine.inputs import holds_bool, holds_text

    if holds_bool(action):
        raise CommandError(f"the action must be numbers, not bools: `{action!r:.80}`",
                           hint="give numbers: True and False would be read as 1 and 0")
    if holds_text(action):
        raise CommandError(f"the action must be numbers, not text: `{action!r:.80}`",
                           hint="give numbers: NumPy reads text as Python's float() does, "
                                "`'5_0'` as 50")
    try:
        command = np.asarray(action, dtype=np.float64)
    except OverflowError:               # (an int past a float's range: 10**400)
        raise CommandError("the action must be finite numbers: one is too large for a float",
                           expected="numbers of magnitude at most 1.8e308") from None
    except (TypeError, ValueError):
        command = None
    if command is None or command.size != 2:
        shape = (f"of shape {command.shape}" if command is not None and command.ndim
                 else f"`{action!r:.40}`")
        raise CommandError(f"an action is [steering deg, speed in/s], not {shape}",
                           hint="env.action_space.sample() is one; so is "
                                "env.unwrapped.fuzzy_policy(observation)")
    if not np.isfinite(command).all():
        raise CommandError(f"the action must be finite numbers, not {action!r:.80}")
    return command.reshape(1, 2)



def env_name(world_file: str) -> str:
    """``figure4.yaml`` -> ``mitos/Figure4-v0``."""
    stem = Path(world_file).stem
    return "mitos/" + "".join(part[:1].upper() + part[1:] for part in re.split(r"[_\-]", stem)) \
        + "-v0"


def register_envs() -> list[str]:
    """Register ``mitos/World-v0`` and one environment per packaged single-robot world (a
    world file with a ``robots:`` list has several); the names registered."""
    from .resources import data_dir

    names = []
    if "mitos/World-v0" not in gymnasium.registry:
        gymnasium.register("mitos/World-v0", entry_point="mitos_cli.gym:MitosEnv")
    names.append("mitos/World-v0")
    for entry in sorted(data_dir("worlds").iterdir(), key=lambda e: e.name):
        if not entry.name.endswith(".yaml"):
            continue
        if re.search(r"^robots:", entry.read_text(encoding="utf-8"), re.MULTILINE):
            continue
        name = env_name(entry.name)
        if name not in gymnasium.registry:
            gymnasium.register(name, entry_point="mitos_cli.gym:MitosEnv",
                               kwargs={"world": entry.name})
        names.append(name)
    return names


ENVIRONMENTS = register_envs()
