"""The published benchmarks' scores of a run: BARN's navigation score and MRPB's safety.

- **BARN** (Perille et al. 2020; the BARN challenge's ``score``): a run that reaches the goal
  scores ``t_opt / clip(t, 2 t_opt, 8 t_opt)``, any other run 0, with ``t_opt`` the shortest
  path's length over 2 m/s. The best possible score is 0.5 (a run at twice the optimal time or
  faster); a run slower than 8 ``t_opt`` still scores 0.125.
- **MRPB** (Wen et al. 2021, ``metrics.cpp``): *safety* is the fraction of the run's time with
  the robot's distance to the nearest obstacle below a safety distance (lower is safer).
  Here the distance is the simulator's clearance (footprint to the nearest wall or obstacle,
  the truth, not what the robot perceived), and every tick is one ``dt`` of time.
"""

from __future__ import annotations

import numpy as np

from .gridmap import INCH_PER_M

BARN_SPEED_IN_S = 2.0 * INCH_PER_M     # in/s: BARN's reference speed for t_opt (2 m/s)
MRPB_SAFETY_IN = 0.1 * INCH_PER_M      # in: the safety distance used here (0.1 m)


def optimal_time(path_length_in: float) -> float:
    """BARN's ``t_opt`` (s) for a shortest path of ``path_length_in`` inches."""
    return float(path_length_in) / BARN_SPEED_IN_S


def barn_score(success: bool, time_s: float, t_opt: float) -> float:
    """``success * t_opt / clip(time_s, 2 t_opt, 8 t_opt)``."""
    if not success or t_opt <= 0:
        return 0.0
    return float(t_opt / np.clip(time_s, 2.0 * t_opt, 8.0 * t_opt))


def mrpb_safety(clearance: np.ndarray, safety_in: float = MRPB_SAFETY_IN) -> float:
    """Fraction of the ticks ``clearance [T]`` (in) spent below ``safety_in``; 0 for no ticks."""
    c = np.asarray(clearance, dtype=float).reshape(-1)
    return float(np.mean(c < safety_in)) if len(c) else 0.0
