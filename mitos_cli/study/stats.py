"""Confidence intervals for a study, with ``math`` and NumPy only (no SciPy).

- rates (success, collision, ...): the Wilson score interval, which stays inside [0, 1] and
  behaves at 0 and n successes, where the normal ("Wald") interval collapses to a point;
- means (time to goal, clearance, ...): the Student t interval ``mean +- t(1 - a/2, n - 1) s/sqrt(n)``,
  with the t quantile computed from the regularized incomplete beta function.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Iterable

LEVEL = 0.95


@dataclass(frozen=True)
class Rate:
    """``k`` of ``n`` runs, with its Wilson interval (``lo``, ``hi``); ``n = 0`` has none."""

    k: int
    n: int
    lo: float
    hi: float

    @property
    def value(self) -> float | None:
        return self.k / self.n if self.n else None


@dataclass(frozen=True)
class Mean:
    """Mean, sample standard deviation and t interval of ``n`` values.

    ``n = 0``: all ``None``; ``n = 1``: a mean with no spread and no interval.
    """

    n: int
    mean: float | None
    std: float | None
    lo: float | None
    hi: float | None


def z_quantile(p: float) -> float:
    return NormalDist().inv_cdf(p)


def wilson(k: int, n: int, level: float = LEVEL) -> Rate:
    """The Wilson score interval of ``k`` successes in ``n`` trials."""
    if not 0 <= k <= n:
        raise ValueError(f"need 0 <= k <= n, got k={k}, n={n}")
    if n == 0:
        return Rate(0, 0, math.nan, math.nan)
    z = z_quantile(0.5 + level / 2)
    p = k / n
    z2n = z * z / n
    centre = (p + z2n / 2) / (1 + z2n)
    half = z / (1 + z2n) * math.sqrt(p * (1 - p) / n + z2n / (4 * n))
    # at k = 0 (k = n) the bound is exactly 0 (1); keep it so despite rounding
    lo = 0.0 if k == 0 else max(0.0, centre - half)
    hi = 1.0 if k == n else min(1.0, centre + half)
    return Rate(k, n, lo, hi)


def _betacf(a: float, b: float, x: float) -> float:
    """Continued fraction of the incomplete beta function (modified Lentz)."""
    tiny = 1e-300
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c, d = 1.0, 1.0 - qab * x / qap
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 400):
        m2 = 2 * m
        aa = m * (b - m) * x / ((qam + m2) * (a + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        h *= d * c
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < 1e-15:
            break
    return h


def betainc(a: float, b: float, x: float) -> float:
    """The regularized incomplete beta function ``I_x(a, b)``."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    log_front = (math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b)
                 + a * math.log(x) + b * math.log1p(-x))
    if x < (a + 1.0) / (a + b + 2.0):
        return math.exp(log_front) * _betacf(a, b, x) / a
    return 1.0 - math.exp(log_front) * _betacf(b, a, 1.0 - x) / b


def t_cdf(t: float, df: float) -> float:
    """The CDF of Student's t distribution with ``df`` degrees of freedom."""
    tail = 0.5 * betainc(df / 2.0, 0.5, df / (df + t * t))
    return 1.0 - tail if t > 0 else tail


def t_quantile(p: float, df: float) -> float:
    """The ``p`` quantile of Student's t with ``df`` degrees of freedom (``0.5 < p < 1``)."""
    if not 0.5 < p < 1.0:
        raise ValueError(f"t_quantile takes 0.5 < p < 1, got {p}")
    lo, hi = 0.0, 1.0
    while t_cdf(hi, df) < p:      # bracket, then bisect: monotone and safe for any df >= 1
        lo, hi = hi, hi * 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if t_cdf(mid, df) < p:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-13 * max(1.0, hi):
            break
    return 0.5 * (lo + hi)


def mean_interval(values: Iterable[float | None], level: float = LEVEL, *,
                  floor: float | None = None) -> Mean:
    """Mean, sample std (``ddof=1``) and the t interval of the finite ``values``; the
    interval cut at ``floor``, where the values cannot lie below it (so neither can their
    mean: the cut interval covers it as often)."""
    x = np.asarray([v for v in values if v is not None], dtype=float)
    x = x[np.isfinite(x)]
    n = int(x.size)
    if n == 0:
        return Mean(0, None, None, None, None)
    m = float(np.mean(x))
    if n == 1:
        return Mean(1, m, None, None, None)
    s = float(np.std(x, ddof=1))
    half = t_quantile(0.5 + level / 2, n - 1) * s / math.sqrt(n)
    lo = m - half if floor is None else max(floor, m - half)
    return Mean(n, m, s, lo, m + half)
