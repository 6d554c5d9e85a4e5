"""What moves, as the robot's own readings show it, and where it is going.

The robot is told nothing of what moves. Each tick, the readings its map does not explain (the
news perception marks) are cut into objects along the ring of beams: neighbouring beams whose
echoes lie within ``LINK`` of each other are one object (:func:`objects`), as a laser scan is
segmented. A :class:`Tracker` matches each object to the track it kept from the ticks before
(the nearest predicted place within ``GATE``; across the robot's line of sight, far off,
within the spacing of its beams there too, :func:`sight_lines`: a cart wider than that is
echoed at one front corner, then at the other, and stays one track) and fits its velocity to
the centres it was seen at over the last ``WINDOW`` seconds (a Theil-Sen slope: the echoes
of a cart hop from one end of it to the other, and a median does not follow them).

A track is a *mover* when most of its recent echoes came from space a beam had passed
through a moment before (:class:`FreeSpace`: something came where nothing was), or closed
along the lines of the beams before that ended on them faster than a standing object's
echo can (which comes no nearer along one line, however the robot drives: a cart coming
head-on is echoed by one ray of a ring, each tick 1-2 in nearer than it was, too little
for any one beam to tell but a closing speed to the beams of half a second), its centre
travelled ``MIN_TRAVEL`` or more, it moves at ``MIN_SPEED`` to ``MAX_SPEED`` and it is no
longer than ``MAX_EXTENT`` (a cart, a person, a robot: not a wall); :meth:`Tracker.movers`
lists those that come toward the robot (within 60 deg of the robot's bearing from it,
closing faster than the robot draws away). The echoes of a standing object slide along its
faces as the robot drives by, but seldom into space a beam had just passed through, nor
farther than the object is long.

Where a mover goes (:func:`swept`) is a capsule from its centre along its velocity, as wide
as the object and ``HALF_WIDTH`` at least (a sonar ring sees one or two echoes of a cart:
its middle, not its edges): to ``PAST`` body lengths past the robot once its heading is
known (``SETTLE`` s of track); and while it comes down the robot's lane, straight at the
robot. Replanning (:func:`.knowledge.replan`) keeps the route clear of it, keeping right
of what comes down the robot's lane where there is room (and, where that mover comes on the
robot's left, squeezing past on the right without the room rather than crossing in front of
it: two robots that met swerved across each other's way);
where no way to the goal is left,
it sends the robot to the nearest place out of its way (a *refuge*), and the robot waits
there until nothing comes toward it (standing at its refuge, till what comes has passed it:
a cart beside it is 60 deg off its bearing long before it has passed, and a tricycle that
turns round for its goal swings into the cart's lane): planning in time, in the simplest
form a route can say.
"""

from __future__ import annotations

import bisect
import functools
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .geometry import clip_arrays

LINK = 12.0          # in: echoes of neighbouring beams closer than this are one object
GATE = 15.0          # in: the farthest an object is matched from its track's predicted place
WINDOW = 1.5         # s: the track history the velocity is fitted over
COVER = 0.6          # of WINDOW: how much of it a track must have been followed
MIN_TRAVEL = 12.0    # in: the least a mover's place moves in WINDOW s
MIN_SPEED = 6.0      # in/s: slower than this, an object is taken to stand still
MAX_SPEED = 120.0    # in/s: faster than this, the match was two different objects
MAX_EXTENT = 48.0    # in: longer than this, an object is a wall, not a mover
MAX_MISS = 0.5       # s: a track not seen for this long is dropped
HALF_WIDTH = 12.0    # in: the least half width given to a mover's path
PAST = 2.0           # body lengths: how far past the robot a mover's path is kept
HORIZON = 10.0       # s: the farthest ahead a mover's path is predicted
APPROACH = 0.5       # cos 60 deg: a mover comes toward the robot within this cone
SETTLE = 2.5         # s: a track followed this long has a heading to go by
VOTE = 0.5           # s: the sightings a track's moving is voted over
SHORT = 4.0          # in: a beam passes through what lies up to this short of its echo
STEP = 2.0           # in: an echo is tested this far beyond it
SURE = 2.0           # standard deviations: a closing speed is told from the sensor's noise


@dataclass(frozen=True, eq=False)
class Mover:
    """A tracked object that moves: its centre (in), its velocity (in/s) and its half size."""

    centre: np.ndarray        # [2]
    velocity: np.ndarray      # [2]
    radius: float             # in, half its extent as seen
    settled: bool = True      # followed long enough that its heading is known


@dataclass(frozen=True, eq=False)
class Sweep:
    """Where what moves toward a robot will pass while it gets out of the way: the cells of
    its map (:func:`swept` of each mover) and how wide the widest way is. With movers down
    its lane, ``keep_right``: the cells a robot that keeps right of them avoids, as people
    in a corridor do, so that two robots that meet step aside to opposite sides (the ways
    wider, by what the route asks beyond its least clearance: a route may squeeze past a
    wall where nothing wider leads on, but it keeps right of a mover only with room)."""

    cells: np.ndarray                       # bool [rows, cols]
    wide: float                             # in
    keep_right: np.ndarray | None = None    # bool [rows, cols]
    # keep_right without the room, where a mover comes down the lane on the robot's left:
    # the robot squeezes past on its right rather than cross the mover's way
    left: np.ndarray | None = None          # bool [rows, cols]
    # the robot's right of the movers down its lane on its right: where a route that cannot
    # keep right of them with room does not go (it would squeeze across their way)
    right: np.ndarray | None = None         # bool [rows, cols]


@dataclass
class Track:
    """One object followed from tick to tick: the times and centres it was seen at."""

    times: list[float] = field(default_factory=list, repr=False)
    centres: list[np.ndarray] = field(default_factory=list, repr=False)
    radius: float = 0.0
    moved: list[bool | None] = field(default_factory=list, repr=False)
    # per sighting: whether its echoes came where a beam passed before (None: no beam's
    # line crossed them)
    mover: bool = False          # found moving once, it stays a mover while it is followed
    # and fitted a velocity of 6-120 in/s (told at each sighting)
    v: np.ndarray | None = None  # its velocity when it was last seen, if a mover
    fit: np.ndarray | None = None   # its :meth:`velocity` when it was last seen
    born: float = 0.0            # when it was first seen

    def moving(self, now: float) -> bool:
        """Whether most of its sightings over the last ``VOTE`` s had an echo in space a
        beam had passed through (:class:`FreeSpace`): something came where nothing was."""
        recent = self.moved[bisect.bisect_left(self.times, now - VOTE):]    # (times ascend)
        return recent.count(True) > recent.count(False)

    def travelled(self, now: float) -> bool:
        """Whether its place moved ``MIN_TRAVEL`` or more over the last ``WINDOW`` s: the
        echoes of a standing object slide along its sides as the robot drives by, but not
        farther than the object is long."""
        first = min(bisect.bisect_left(self.times, now - WINDOW), len(self.times) - 1)
        return math.dist(self.centres[first], self.centres[-1]) >= MIN_TRAVEL

    def velocity(self, now: float) -> np.ndarray | None:
        """The Theil-Sen slope of the centre over the last ``WINDOW`` s (the median of the
        slopes between every two sightings at least ``WINDOW / 2`` apart: echoes that hop
        from one end of an object to the other move its centre by its width, and a median
        does not follow them); ``None`` when the track covers too little of the window."""
        first = bisect.bisect_left(self.times, now - WINDOW)
        if len(self.times) - first < 3 or self.times[-1] - self.times[first] < COVER * WINDOW:
            return None
        t = np.array(self.times[first:])
        c = np.array(self.centres[first:])
        i, j = _pairs(len(t))
        far = t[j] - t[i] >= WINDOW / 2
        if not np.count_nonzero(far):
            return None
        i, j = i[far], j[far]
        return _median((c[j] - c[i]) / (t[j] - t[i])[:, None])

    def predicted(self, now: float) -> np.ndarray:
        """Where the track should be at ``now``: its last centre moved on at its velocity."""
        last = self.centres[-1]
        return last if self.fit is None else last + self.fit * (now - self.times[-1])


@functools.lru_cache(maxsize=64)
def _pairs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.triu_indices(n, 1)``, worked out once for each ``n`` (a track's sightings in
    ``WINDOW`` s are a few tens at most)."""
    i, j = np.triu_indices(n, 1)
    i.flags.writeable = j.flags.writeable = False
    return i, j


def _median(x: np.ndarray) -> np.ndarray:
    """``np.median(x, axis=0)`` of finite ``x [K, 2]`` (K > 0) without its Python: the mean
    of the middle one or two of each column sorted, summed from 0 as np.mean sums (no -0)."""
    s = np.sort(x, axis=0)
    k = len(s) // 2
    return 0.0 + s[k] if len(s) % 2 else (0.0 + s[k - 1] + s[k]) / 2


def objects(hits: np.ndarray, seen: np.ndarray, ring: bool) -> list[np.ndarray]:
    """The beams ``seen`` cut into objects by their echoes ``hits [B, 2]``: runs of
    neighbouring beams (around the ring when ``ring``) whose echoes lie within ``LINK`` of
    each other. Each object is the array of its beams' indices."""
    idx = seen.nonzero()[0]
    order, starts = _cut(seen[None], np.zeros_like(idx), idx, hits[idx], ring)
    beams = idx if order is None else idx[order]
    return [beams[a:b] for a, b in zip(starts, [*starts[1:], len(beams)])]


def _cut(seen: np.ndarray, robot: np.ndarray, beam: np.ndarray, pts: np.ndarray, ring: bool
         ) -> tuple[np.ndarray | None, list[int]]:
    """The echoes ``pts [N, 2]`` of the beams ``seen [R, B]`` (robot ``robot [N]`` and beam
    ``beam [N]`` of each, as ``seen.nonzero()`` gives them) cut into :func:`objects`: where
    each object starts, and the order to take the echoes in (``None``: as they come). An
    object across the first beam of a ring is one, its last run first."""
    if not len(pts):
        return None, []
    gap = np.hypot(*(pts[1:] - pts[:-1]).T)
    cut = (robot[1:] != robot[:-1]) | (beam[1:] - beam[:-1] > 1) | (gap > LINK)
    starts = [0, *(cut.nonzero()[0] + 1).tolist()]
    order = None
    for r in (seen[:, 0] & seen[:, -1]).nonzero()[0].tolist() if ring else ():
        a, z = int(robot.searchsorted(r)), int(robot.searchsorted(r, "right")) - 1
        k = bisect.bisect_right(starts, z) - 1                 # its last run starts there
        s = starts[k]
        if s == a or math.dist(pts[a], pts[z]) > LINK:
            continue
        if order is None:
            order = np.arange(len(pts))
        order[a:z + 1] = np.concatenate((order[s:z + 1], order[a:s]))
        m = bisect.bisect_left(starts, a)
        starts[m + 1:k + 1] = [t + z + 1 - s for t in starts[m + 1:k]]
    return order, starts


def shapes(pts: np.ndarray, starts: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """The centres ``[O, 2]`` and half sizes ``[O]`` of objects whose echoes ``pts [N, 2]``
    start at ``starts`` (those of many robots together are each the bits of its own)."""
    if not len(pts):
        return np.zeros((0, 2)), np.zeros(0)
    bounds = np.array([*starts, len(pts)])
    sizes = bounds[1:] - bounds[:-1]
    centres = np.add.reduceat(pts, starts, axis=0) / sizes[:, None]
    spread = np.hypot(*(pts - centres.repeat(sizes, axis=0)).T)
    return centres, np.maximum.reduceat(spread, starts)


Seen = tuple[np.ndarray, np.ndarray, list[bool | None], np.ndarray]   # what :meth:`Tracker.follow` takes


def sight_lines(centres: np.ndarray, origins: np.ndarray, step: float) -> np.ndarray:
    """How far across its robot's line of sight each object seen may lie from its track's
    place: ``[O, 3]``, the line's direction (unit) and ``GATE`` over the gate across it.
    Neighbouring beams ``step`` rad apart are ``2 r sin(step / 2)`` apart at range ``r``,
    so an object wider than that is echoed now by one, now by the other, and its echoes hop
    that far across the line (a ring of 36 beams sees a cart's two front corners, 16 in
    apart, from 90 in on); along the line they stay within ``GATE``. Where the beams lie
    closer than ``GATE`` (a dense fan, or objects near) the gate is round, and the row
    ``(1, 0, 1)``: the plain distance."""
    out = np.zeros((len(centres), 3))
    out[:, 0] = out[:, 2] = 1.0
    rel = centres - origins
    r = np.hypot(rel[:, 0], rel[:, 1])
    across = 2 * r * math.sin(abs(step) / 2)
    wide = across > GATE
    out[wide, :2] = rel[wide] / r[wide, None]
    out[wide, 2] = GATE / across[wide]
    return out


def _gated(gap: np.ndarray, sight: np.ndarray) -> np.ndarray:
    """The length of ``gap [..., 2]`` (a track's place less an object's) in the gate of the
    object's :func:`sight_lines` row ``sight [..., 3]``: along its line of sight as it is,
    across it scaled down to ``GATE`` (``(1, 0, 1)``: ``hypot`` of the gap, bit for bit)."""
    gx, gy = gap[..., 0], gap[..., 1]
    ux, uy = sight[..., 0], sight[..., 1]
    return np.hypot(gx * ux + gy * uy, (gy * ux - gx * uy) * sight[..., 2])


def sightings(spaces: Sequence[FreeSpace], now: float, origins: np.ndarray, ranges: np.ndarray,
              dirs: np.ndarray, seen: np.ndarray) -> list[Seen]:
    """What each robot sees that its map does not show, as :meth:`Tracker.follow` takes it:
    the :func:`objects` of its beams ``seen [R, B]`` (cast from ``origins [R, 2]`` along
    ``dirs [R, B, 2]``, echoes at ``ranges [R, B]``), their centres and half sizes
    (:func:`shapes`), and whether most of the echoes of each that a beam kept in
    ``spaces[r]`` crossed came where it had passed (:func:`entered`; ``None``: none
    crossed). All robots at once (runs in lockstep see theirs together): they see a few
    echoes each, and one pass is cheaper than one each."""
    robot, beam = seen.nonzero()
    if not len(robot):
        return [(np.zeros((0, 2)), np.zeros(0), [], np.zeros((0, 3))) for _ in range(len(seen))]
    along = dirs[robot, beam]
    pts = origins[robot] + ranges[robot, beam, None] * along                # the echoes
    crossed, came = entered(spaces, now, pts, along, robot)
    order, starts = _cut(seen, robot, beam, pts, spaces[0].ring)
    if order is not None:
        pts, robot, crossed, came = pts[order], robot[order], crossed[order], came[order]
    centres, radii = shapes(pts, starts)
    sight = sight_lines(centres, origins[robot[starts]], spaces[0].step)
    crossed = np.add.reduceat(crossed, starts, dtype=np.intp).tolist()
    came = np.add.reduceat(came, starts, dtype=np.intp).tolist()
    moved = [None if not n else 2 * e >= n for n, e in zip(crossed, came)]
    if len(seen) == 1:
        return [(centres, radii, moved, sight)]
    ends = [0, *itertools.accumulate(np.bincount(robot[starts], minlength=len(seen)).tolist())]
    return [(centres[a:b], radii[a:b], moved[a:b], sight[a:b])
            for a, b in zip(ends[:-1], ends[1:])]


@dataclass
class Tracker:
    """The tracks one robot keeps of the objects its readings show and its map does not."""

    tracks: list[Track] = field(default_factory=list)

    def update(self, now: float, found: list[np.ndarray], moved: list[bool | None]) -> None:
        """:meth:`follow` the objects whose echoes are ``found`` (``[k, 2]`` each)."""
        starts = [0, *itertools.accumulate(len(o) for o in found[:-1])]
        pts = np.concatenate(found) if found else np.zeros((0, 2))
        self.follow(now, *shapes(pts, starts), moved)

    def follow(self, now: float, centres: np.ndarray, radii: np.ndarray,
               moved: list[bool | None], sight: np.ndarray | None = None) -> None:
        """Match the objects seen at time ``now`` (centres ``[O, 2]``, half sizes ``[O]``;
        ``moved``: whether each has an echo in space a beam had passed through; ``sight``:
        their :func:`sight_lines`, ``None``: a round gate) to the tracks (nearest first in
        that gate, each track and object once), start a track for each object left, drop
        stale tracks (:func:`follow_all` of one)."""
        if sight is None:
            sight = sight_lines(centres, centres, 0.0)
        follow_all([self], now, [(centres, radii, moved, sight)])

    def _match(self, now: float, live: list[Track], centres: np.ndarray, radii: np.ndarray,
               moved: list[bool | None], sight: np.ndarray, apart: list[float],
               order: list[int]) -> None:
        """:meth:`follow` with the live tracks' distances to the objects ``apart`` (row-major
        ``[T * O]``, in the objects' gates) and their order, nearest first (one track and one
        object in its gate, most often, are matched by :func:`follow_all` itself)."""
        half = radii.tolist()
        used_t: set[int] = set()
        used_o: set[int] = set()
        for k in order:                                          # nearest first, each once
            if not apart[k] <= GATE:             # the rest lie farther (NaN sorts last)
                break
            j, i = divmod(k, len(half))
            if j in used_t or i in used_o:
                continue
            used_t.add(j)
            used_o.add(i)
            self._sighted(live[j], now, centres[i], half[i], moved[i])
        taken = None
        for i in range(len(half)):           # (an object by a track is a piece of its object)
            if i in used_o or 2 * half[i] > MAX_EXTENT:
                continue
            if taken is None:
                taken = np.array([live[j].centres[-1] for j in sorted(used_t)]).reshape(-1, 2)
            if len(taken) and _gated(taken - centres[i], sight[i]).min() <= GATE:
                continue
            live.append(Track([now], [centres[i]], half[i], [moved[i]], born=now))
        self.tracks = live

    @staticmethod
    def _sighted(tr: Track, now: float, centre: np.ndarray, radius: float,
                 moved: bool | None) -> None:
        """``tr`` seen again at ``now``, at ``centre``."""
        tr.times.append(now)
        tr.centres.append(centre)
        tr.radius = radius
        tr.moved.append(moved)
        if now - tr.times[0] > 2 * WINDOW:         # keep what the window and the vote read
            first = bisect.bisect_left(tr.times, now - WINDOW)
            del tr.times[:first], tr.centres[:first], tr.moved[:first]
        # (what stands is matched where it was: only what may move is worth a fit)
        tr.fit = v = tr.velocity(now) if tr.mover or tr.moving(now) else None
        if 2 * radius > MAX_EXTENT:          # a wall, for now: neither found nor lost moving
            return
        speed = 0.0 if v is None else float(np.hypot(*v))
        # (a fit means it was a mover or moving)
        tr.mover = (v is not None and (tr.mover or tr.travelled(now))
                    and MIN_SPEED <= speed <= MAX_SPEED)
        tr.v = v

    def movers(self, now: float, robot: np.ndarray, own: np.ndarray, waiting: bool = False
               ) -> list[Mover]:
        """The tracks that move toward the robot at ``robot [2]`` driving at velocity ``own
        [2]`` (see the module docstring): those seen at ``now``, and the movers among those
        missed for at most ``MAX_MISS`` s, where they should be by now (a sonar ring loses a
        cart between two beams for a tick or two). A robot ``waiting`` at its refuge (standing
        there, :meth:`.knowledge.RobotMap.at_refuge`) waits for what has not passed it yet:
        the cone is a half plane (a cart beside it, 60 deg or more off its bearing, still
        comes on, and a tricycle that turns round for its goal swings into its lane)."""
        cone = 0.0 if waiting else APPROACH
        out = []
        for tr in self.tracks:
            v = tr.v
            if 2 * tr.radius > MAX_EXTENT or not tr.mover or v is None:
                continue
            speed = float(np.hypot(*v))
            centre = (tr.centres[-1] if tr.times[-1] == now
                      else tr.centres[-1] + v * (now - tr.times[-1]))
            to_robot = robot - centre
            dist = float(np.hypot(*to_robot))
            # it heads for the robot, and the robot does not draw away from it faster
            if float(v @ to_robot) < cone * speed * dist or float((v - own) @ to_robot) <= 0:
                continue
            out.append(Mover(centre, v, tr.radius, now - tr.born >= SETTLE))
        return out


def follow_all(trackers: Sequence[Tracker], now: float, seen: Sequence[Seen]) -> None:
    """:meth:`Tracker.follow` of every tracker with what it saw (``seen``, as
    :func:`sightings` gives it): the distances from the live tracks to the objects of all
    at once (:func:`_apart`), the matching tracker by tracker."""
    lives = [[tr for tr in t.tracks if now - tr.times[-1] <= MAX_MISS] for t in trackers]
    apart, order, pairs = _apart(lives, seen, now)
    start = 0
    sighted = Tracker._sighted
    for tracker, live, (centres, radii, moved, sight), n in zip(trackers, lives, seen, pairs):
        if n == 1 and apart[start] <= GATE:      # (most often: the one thing it follows,
            sighted(live[0], now, centres[0], radii.item(0), moved[0])   # again: _match's)
            tracker.tracks = live
        elif not len(centres):
            tracker.tracks = live
            continue
        else:
            tracker._match(now, live, centres, radii, moved, sight, apart[start:start + n],
                           [k - start for k in order[start:start + n]])
        start += n


def _apart(lives: list[list[Track]], seen: Sequence[Seen], now: float
           ) -> tuple[list[float], list[int], list[int]]:
    """The distances from each tracker's live tracks (``lives``), where they should be by
    ``now``, to its objects (``seen``), row-major ``[T * O]`` a tracker, one tracker after
    the other, each the bits of its own; their order, nearest first, tracker by tracker (one
    stable sort by tracker and distance: NaN last, as the tracker's own stable argsort);
    and how many each tracker has."""
    objects = [len(got[0]) for got in seen]
    sizes = [len(live) if o else 0 for live, o in zip(lives, objects)]
    pairs = [t * o for t, o in zip(sizes, objects)]
    if not any(pairs):
        return [], [], pairs
    pred = np.concatenate([tr.predicted(now) for live, t in zip(lives, sizes) if t
                           for tr in live]).reshape(-1, 2)                   # [T, 2]
    if len(seen) == 1:                                          # (one: no pairs to lay out)
        d = _gated(pred[:, None] - seen[0][0][None], seen[0][3][None]).ravel()
        return d.tolist(), d.argsort(kind="stable").tolist(), pairs
    counts, size, many = np.array(pairs), np.array(sizes), np.array(objects)
    owner = np.repeat(np.arange(len(seen)), counts)
    k = np.arange(len(owner)) - (np.cumsum(counts) - counts)[owner]     # row-major, each
    per = many[owner]
    track = (np.cumsum(size) - size)[owner] + k // per
    thing = (np.cumsum(many) - many)[owner] + k % per
    d = _gated(pred[track] - np.concatenate([got[0] for got in seen])[thing],
               np.concatenate([got[3] for got in seen])[thing])
    return d.tolist(), np.lexsort((d, owner)).tolist(), pairs


@dataclass
class FreeSpace:
    """The beams of the last ``WINDOW`` s, as they were cast (the robot's pose and its
    readings): an echo from where a beam passed a moment ago came from something that moved
    there. A beam passes through what lies within half a map cell of its line and ``SHORT``
    short of its echo, so that noise on the echo of a standing object never reads as one.
    The beams are those of one layout (``angles``: evenly spaced, as every layout's are)."""

    a0: float                   # rad: the first beam's direction from the heading
    step: float                 # rad between neighbouring beams
    ring: bool                  # the beams go all round
    times: np.ndarray = field(repr=False)     # [J] s (-inf: an empty slot)
    poses: np.ndarray = field(repr=False)     # [J, 3] x, y (in), heading (rad)
    ranges: np.ndarray = field(repr=False)    # [J, B] in
    near: float                 # in: how near a beam's line a point it passed lies
    slot: int = 0
    noise: float = 0.0          # in: the standard deviation of a range (the sensor's)
    far: float = math.inf       # in: the sensor's range (a beam that read it saw nothing)
    rows: np.ndarray = field(init=False, repr=False)   # [J] where each slot's ranges start
    # in ranges.reshape(-1)

    def __post_init__(self) -> None:
        self.rows = np.arange(len(self.times)) * self.ranges.shape[1]

    @classmethod
    def of(cls, angles: np.ndarray, ring: bool, dt: float, resolution: float,
           noise: float = 0.0, far: float = math.inf) -> FreeSpace:
        """For beams at ``angles`` (rad from the heading), ticks of ``dt`` s and a map of
        ``resolution`` (a beam passes through what lies within half a cell of its line), of
        a sensor with range ``far`` and Gaussian ``noise`` (in)."""
        keep = int(math.ceil(WINDOW / dt)) + 1
        step = float(angles[1] - angles[0]) if len(angles) > 1 else 0.0
        return cls(float(angles[0]), step, ring, np.full(keep, -np.inf), np.zeros((keep, 3)),
                   np.zeros((keep, len(angles))), resolution / 2, noise=noise, far=far)

    def update(self, now: float, p: np.ndarray, dirs: np.ndarray, ranges: np.ndarray) -> None:
        """Keep the beams ``dirs [B, 2]`` cast from ``p`` at ``now`` and their ``ranges [B]``
        (in place of the oldest kept)."""
        k = self.slot
        self.times[k] = now
        self.poses[k] = p[0], p[1], math.atan2(dirs[0, 1], dirs[0, 0]) - self.a0
        self.ranges[k] = ranges
        self.slot = (k + 1) % len(self.times)

    def entered(self, now: float, points: np.ndarray, dirs: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
        """For echoes ``points [P, 2]`` (of beams ``dirs [P, 2]``), tested ``STEP`` beyond the
        echo against the beams kept from the last ``WINDOW`` s (before ``now``): which lie on
        the line of one (within ``near``: the robot's map clears a mark the same way), and
        which of those lay short of its echo then (something came where nothing was), or
        close on the beams that ended on their line at ``MIN_SPEED`` or faster
        (:func:`_closing`)."""
        return entered([self], now, points, dirs)


class Spaces(Sequence[FreeSpace]):
    """The :class:`FreeSpace` of robots stepped together whose arrays are rows of one stack
    each (:meth:`stacked`; ``rows``: those of them it holds, in order): the beams of all kept
    in one write (:meth:`update`) and looked up by :func:`entered` where they lie."""

    def __init__(self, every: list[FreeSpace], times: np.ndarray, poses: np.ndarray,
                 ranges: np.ndarray, rows: np.ndarray, noise: np.ndarray) -> None:
        self.every, self.rows = every, rows
        self.times, self.poses, self.ranges = times, poses, ranges   # [R, J], [R, J, 3], [R, J, B]
        self.noise = noise                                            # [R] in, each sensor's

    @classmethod
    def stacked(cls, spaces: list[FreeSpace]) -> Spaces | None:
        """``spaces`` (of one layout: ``None`` otherwise), their arrays copied into one stack
        each and each made a view of its row."""
        first = spaces[0]
        if any((sp.a0, sp.step, sp.ring, sp.near, sp.far, sp.ranges.shape)
               != (first.a0, first.step, first.ring, first.near, first.far, first.ranges.shape)
               for sp in spaces):
            return None
        out = cls(spaces, np.array([sp.times for sp in spaces]),
                  np.array([sp.poses for sp in spaces]), np.array([sp.ranges for sp in spaces]),
                  np.arange(len(spaces)), np.array([sp.noise for sp in spaces]))
        for j, sp in enumerate(spaces):
            sp.times, sp.poses, sp.ranges = out.times[j], out.poses[j], out.ranges[j]
        return out

    def __len__(self) -> int:
        return len(self.rows)

    def __getitem__(self, i: int) -> FreeSpace:  # type: ignore[override]  # (no slices)
        return self.every[self.rows[i]]

    def picked(self, rows: np.ndarray) -> Spaces:
        """The spaces ``rows`` (ascending) of :attr:`every`."""
        return Spaces(self.every, self.times, self.poses, self.ranges, rows, self.noise)

    def update(self, now: float, points: np.ndarray, dirs: np.ndarray,
               ranges: np.ndarray) -> None:
        """:meth:`FreeSpace.update` of every space (``points [R, 2]``, ``dirs [R, B, 2]``,
        ``ranges [R, B]``) in one write when they keep their beams in the same slot (robots
        stepped together from their start), else one by one."""
        every = self.every
        k = every[0].slot
        if any(sp.slot != k for sp in every):
            for sp, p, d, r in zip(every, points, dirs, ranges):
                sp.update(now, p, d, r)
            return
        a0 = every[0].a0
        self.times[:, k] = now
        self.poses[:, k, :2] = points
        self.poses[:, k, 2] = [math.atan2(y, x) - a0 for x, y in dirs[:, 0].tolist()]
        self.ranges[:, k] = ranges
        slot = (k + 1) % self.times.shape[1]
        for sp in every:
            sp.slot = slot


def entered(spaces: Sequence[FreeSpace], now: float, points: np.ndarray, dirs: np.ndarray,
            owner: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:meth:`FreeSpace.entered` of the echoes of many robots at once: ``points [P, 2]`` and
    ``dirs [P, 2]`` against ``spaces[owner[p]]`` (``None``: all against ``spaces[0]``;
    beams of one layout). A robot's echoes are a handful, so one ``[P, J]`` pass for all is
    cheaper than one per robot; each element is worked as it would be alone, and the beams
    not kept from the last ``WINDOW`` s are masked out instead of left out."""
    if not len(points):
        none = np.zeros(0, dtype=bool)
        return none, none
    first = spaces[0]
    slots, beams = first.ranges.shape
    if owner is None or len(spaces) == 1:     # one robot: its own arrays, broadcast ([1, J])
        times, pose, ranges, row = first.times[None], first.poses[None], first.ranges, first.rows
    elif isinstance(spaces, Spaces):          # rows of one stack: looked up where they lie
        at = spaces.rows[owner]
        times, pose, ranges = spaces.times[at], spaces.poses[at], spaces.ranges
        row = at[:, None] * (slots * beams) + first.rows
    else:
        times = np.array([sp.times for sp in spaces])[owner]                  # [P, J]
        pose = np.array([sp.poses for sp in spaces])[owner]                   # [P, J, 3]
        ranges = np.array([sp.ranges for sp in spaces])                       # [R, J, B]
        row = owner[:, None] * (slots * beams) + first.rows                   # [P, J]
    live = (times >= now - WINDOW) & (times < now)
    age = now - times                                                         # [P or 1, J]
    q = points + dirs * STEP
    rel = q[:, None, :] - pose[..., :2]                                       # [P, J, 2]
    dist = np.hypot(rel[..., 0], rel[..., 1])
    ahead = np.arctan2(rel[..., 1], rel[..., 0]) - pose[..., 2]           # from the heading
    if not first.ring:       # a fan's beams do not wrap round: (-pi, pi] before its first
        ahead = np.mod(ahead + np.pi, 2 * np.pi) - np.pi
    bearing = ahead - first.a0
    k = np.rint(bearing / first.step) if first.step else np.zeros_like(bearing)
    if first.ring:          # every direction has its beam (a NaN would fail the look-up)
        k = np.mod(k, beams).astype(np.int64)
    else:
        live = live & (k >= 0) & (k < beams)
        k = clip_arrays(k, 0, beams - 1).astype(np.int64)
    off = np.mod(bearing - k * first.step + np.pi, 2 * np.pi) - np.pi        # from that beam
    on = (np.abs(off) < np.pi / 2) & (dist * np.abs(np.sin(off)) < first.near) & live
    # (how far along its beam, only where it lies on one: a few of the [P, J])
    at = np.flatnonzero(on)
    passed = np.zeros(on.shape, dtype=bool)
    reach = ranges.reshape(-1)[(row + k).reshape(-1)[at]]
    along = dist.reshape(-1)[at] * np.cos(off.reshape(-1)[at])
    passed.reshape(-1)[at] = along < reach - SHORT
    came = np.logical_or.reduce(passed, axis=1)
    # how far the echo came nearer along each beam that ended on its line (an echo, not a
    # beam that read nothing in its range), against that beam's age: the closing speed
    # fitted through (0, 0) and the evidence for it, sum(a t) and sum(t t), row by row
    if owner is None or len(spaces) == 1:
        noise = np.full(len(points), first.noise)
    elif isinstance(spaces, Spaces):
        noise = spaces.noise[spaces.rows[owner]]
    else:
        noise = np.array([sp.noise for sp in spaces])[owner]
    came |= _closing(len(points), at // slots, reach - along + STEP,
                     np.broadcast_to(age, on.shape).reshape(-1)[at],
                     dist.reshape(-1)[at] * np.sin(off.reshape(-1)[at]),
                     (reach < first.far) & ~passed.reshape(-1)[at], noise)
    return np.logical_or.reduce(on, axis=1), came


def _closing(n: int, rows: np.ndarray, a: np.ndarray, t: np.ndarray, side: np.ndarray,
             ok: np.ndarray, noise: np.ndarray) -> np.ndarray:
    """Which of ``n`` echoes close on the robot's beams at ``MIN_SPEED`` or faster, ``SURE``
    standard deviations of the sensor's noise beyond doubt. Each echo (``rows``) lies ``a``
    in nearer than a beam cast ``t`` s before that ended on its line, ``side`` in to one
    side of it (``ok``: that beam read an echo, and did not pass it). A standing object's
    echo comes no nearer along one line however the robot drives, but the lines are only
    the same to within half a map cell: on a face the beams meet aslant (a box's side seen
    at 13 deg, 4.3 in along for each inch across), a beam that passed 1 in to the side
    ended 4 in farther on, and a robot that turns sweeps its beams across the face, so that
    ``side``, and with it ``a``, grows with ``t``. So ``a`` is fitted through (0, 0) on both,
    ``a = s t + c side``, and the closing speed ``s`` is what ``side`` does not explain:
    ``(sum(a t) - sum(a side) k) / d``, ``k = sum(t side) / sum(side side)``, ``d = sum(t t)
    - sum(t side) k``, its standard deviation that of ``a`` (two readings: ``sqrt(2)``
    times the sensor's ``noise [n]``) over ``sqrt(d)``. Where the beams drifted across the
    line as steadily as they aged, ``d`` is 0 and nothing is told; where they lay on it,
    ``s = sum(a t) / sum(t t)``. A beam of a moment ago cannot tell a cart 15 in/s away from
    a box, but the beams of the last half second along one line can."""
    w = np.where(ok, t, 0.0)
    x = np.where(ok, side, 0.0)
    sat = np.bincount(rows, weights=a * w, minlength=n)
    stt = np.bincount(rows, weights=t * w, minlength=n)
    sas = np.bincount(rows, weights=a * x, minlength=n)
    sts = np.bincount(rows, weights=t * x, minlength=n)
    sss = np.bincount(rows, weights=side * x, minlength=n)
    k = np.divide(sts, sss, out=np.zeros(n), where=sss > 0)
    d = stt - sts * k
    doubt = SURE * math.sqrt(2.0) * noise * np.sqrt(np.maximum(d, 0.0))
    told = d > 1e-9 * stt            # (d is 0 but for rounding where side and t are in step)
    return told & (sat - sas * k - doubt >= MIN_SPEED * d)


Capsule = tuple[np.ndarray, np.ndarray, float]     # a segment's two ends and a radius


def lane(m: Mover, robot: np.ndarray, heading: float, width: float) -> bool:
    """Whether ``m`` comes down the lane of a robot at ``robot [2]`` heading ``heading``
    (rad), ``width`` inches wide: its path (as wide as it, ``HALF_WIDTH`` each side at least)
    overlaps the robot's lane."""
    to_robot = robot - m.centre
    return (abs(math.cos(heading) * to_robot[1] - math.sin(heading) * to_robot[0])
            < width / 2 + max(m.radius, HALF_WIDTH))


def swept(m: Mover, robot: np.ndarray, heading: float, length: float, width: float
          ) -> list[Capsule]:
    """The ways a mover may sweep while a robot at ``robot [2]`` heading ``heading`` (rad),
    ``length`` by ``width`` inches, gets out of its way: along its velocity once its heading
    is known (:attr:`Mover.settled`), and straight at the robot while it comes down the
    robot's :func:`lane`. A ring of sonars measures the heading of an object it has seen for
    a second or two to some tens of degrees, its range, and so how fast it closes, much
    better; once the robot stands aside, only the heading says where the mover goes on."""
    out = []
    radius = max(m.radius, HALF_WIDTH)
    if m.settled:
        speed = float(np.hypot(*m.velocity))
        along = m.velocity / speed
        reach = float((robot - m.centre) @ along) + PAST * length
        span = min(max(reach, 0.0), speed * HORIZON)
        out.append((m.centre, m.centre + along * span, radius))
    if lane(m, robot, heading, width):
        out.append((m.centre, np.array(robot, float), radius))
    return out


def sweep(found: list[Mover], robot: np.ndarray, heading: float, length: float, width: float,
          shape: tuple[int, int], resolution: float, origin: tuple[float, float],
          room: float = 0.0, far: float = 150.0, waiting: bool = False) -> Sweep | None:
    """The cells of a map (``shape``, ``resolution``, ``origin``) that the movers ``found``
    will sweep while the robot (see :func:`swept`) gets out of their way; ``None`` when
    none. With movers in its lane, :attr:`Sweep.keep_right` too: the same ways ``room``
    wider, and the robot's left of those movers up to ``far``; :attr:`Sweep.left`, the
    robot's left alone, when one of them comes on its left (:func:`_on_left`); and
    :attr:`Sweep.right`, the robot's right of those that come on its right. A robot
    ``waiting`` (bound for a refuge, or at it) waits while anything is ``found`` (an empty
    sweep): a mover whose heading is not
    known yet sweeps nothing once the robot has turned out of its lane for the refuge, and
    it comes on all the same."""
    cells = np.zeros(shape, dtype=bool)
    roomy = np.zeros(shape, dtype=bool)
    left = np.zeros(shape, dtype=bool)
    right = np.zeros(shape, dtype=bool)
    wide = 0.0
    for m in found:
        for a, b, radius in swept(m, robot, heading, length, width):
            cells |= capsule_cells(shape, resolution, origin, a, b, radius)
            roomy |= capsule_cells(shape, resolution, origin, a, b, radius + room)
            wide = max(wide, radius)
        if lane(m, robot, heading, width):
            left |= left_cells(shape, resolution, origin, robot, m.centre, HALF_WIDTH, far)
            if _on_left(m, robot, heading, width, side=-1.0):
                right |= left_cells(shape, resolution, origin, robot, m.centre, HALF_WIDTH,
                                    far, side=-1.0)
    if not wide and not (waiting and found):
        return None
    return Sweep(cells, wide, (left | roomy) if left.any() else None,
                 left if left.any() and any(_on_left(m, robot, heading, width) for m in found)
                 else None, right if right.any() else None)


def _on_left(m: Mover, robot: np.ndarray, heading: float, width: float,
             side: float = 1.0) -> bool:
    """Whether ``m`` comes down the robot's lane on its left (``side`` -1: on its right),
    half a body width or more off its line: going that side of it would cross its way."""
    rel = m.centre - robot
    return (lane(m, robot, heading, width)
            and side * (math.cos(heading) * rel[1] - math.sin(heading) * rel[0]) >= width / 2)


def capsule_cells(shape: tuple[int, int], resolution: float, origin: tuple[float, float],
                  a: np.ndarray, b: np.ndarray, radius: float) -> np.ndarray:
    """A boolean grid ``shape`` with the cells whose centres lie within ``radius`` of the
    segment ``a``-``b`` set (only the segment's bounding box is visited)."""
    out = np.zeros(shape, dtype=bool)
    ox, oy = origin
    lo, hi = np.minimum(a, b) - radius, np.maximum(a, b) + radius
    rows, cols = shape
    c0, c1 = max(int((lo[0] - ox) // resolution), 0), min(int((hi[0] - ox) // resolution) + 1, cols)
    r0, r1 = max(int((lo[1] - oy) // resolution), 0), min(int((hi[1] - oy) // resolution) + 1, rows)
    if c0 >= c1 or r0 >= r1:
        return out
    xs = ox + (np.arange(c0, c1) + 0.5) * resolution
    ys = oy + (np.arange(r0, r1) + 0.5) * resolution
    px, py = np.meshgrid(xs, ys)
    e = b - a
    ee = float(e @ e)
    t = np.zeros_like(px) if ee == 0 else np.clip(((px - a[0]) * e[0] + (py - a[1]) * e[1]) / ee,
                                                   0.0, 1.0)
    d = np.hypot(px - a[0] - t * e[0], py - a[1] - t * e[1])
    out[r0:r1, c0:c1] = d <= radius
    return out


def left_cells(shape: tuple[int, int], resolution: float, origin: tuple[float, float],
               robot: np.ndarray, mover: np.ndarray, near: float, far: float,
               side: float = 1.0) -> np.ndarray:
    """A boolean grid ``shape`` with the cells set that lie on the robot's left facing the
    mover (``side`` -1: on its right), between the two (along the line from ``robot`` to
    ``mover``), from ``near`` to ``far`` inches off that line: where a robot keeping right
    does not go to let the mover by."""
    out = np.zeros(shape, dtype=bool)
    e = mover - robot
    length = float(np.hypot(*e))
    if length == 0:
        return out
    u = e / length
    n = side * np.array([-u[1], u[0]])          # the robot's left (right), facing the mover
    corners = np.array([robot + n * near, robot + n * far, mover + n * near, mover + n * far])
    ox, oy = origin
    rows, cols = shape
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    c0, c1 = max(int((lo[0] - ox) // resolution), 0), min(int((hi[0] - ox) // resolution) + 1, cols)
    r0, r1 = max(int((lo[1] - oy) // resolution), 0), min(int((hi[1] - oy) // resolution) + 1, rows)
    if c0 >= c1 or r0 >= r1:
        return out
    px, py = np.meshgrid(ox + (np.arange(c0, c1) + 0.5) * resolution,
                         oy + (np.arange(r0, r1) + 0.5) * resolution)
    rx, ry = px - robot[0], py - robot[1]
    along = rx * u[0] + ry * u[1]
    side = rx * n[0] + ry * n[1]
    out[r0:r1, c0:c1] = (along >= 0) & (along <= length) & (side >= near) & (side <= far)
    return out
