"""Mean ± standard error over groups of rows, the form every paper figure reports.

Rows are plain dicts (one per trace, or per trace × stratum); NaN values (undefined
correlations) are left out of a mean and do not count towards its n.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np


def mean_se(values: Iterable[float | None]) -> tuple[float, float, int]:
    """(mean, standard error, n) of the finite values; SE is NaN for n < 2."""
    arr = np.asarray(
        [float(v) for v in values if v is not None and not math.isnan(float(v))], dtype=float
    )
    n = len(arr)
    if n == 0:
        return math.nan, math.nan, 0
    mean = float(arr.mean())
    se = float(arr.std(ddof=1) / math.sqrt(n)) if n > 1 else math.nan
    return mean, se, n


def group_mean_se(
    rows: list[dict[str, Any]],
    metric: str,
    key: Callable[[dict[str, Any]], Any] | str,
) -> dict[Any, tuple[float, float, int]]:
    """mean_se of `metric` per group; rows whose group is None are skipped."""
    getter = (lambda r: r.get(key)) if isinstance(key, str) else key
    groups: dict[Any, list[float]] = defaultdict(list)
    for r in rows:
        g = getter(r)
        if g is None:
            continue
        v = r.get(metric)
        if v is not None:
            groups[g].append(v)
    return {g: mean_se(vs) for g, vs in groups.items()}


def fmt_mean_se(mean: float, se: float, digits: int = 2) -> str:
    """'0.53 ± 0.04' (or '–' when undefined) for tables."""
    if mean is None or math.isnan(mean):
        return "–"
    if se is None or math.isnan(se):
        return f"{mean:.{digits}f}"
    return f"{mean:.{digits}f} ± {se:.{digits}f}"


def finite_or_none(x: float | None) -> float | None:
    """JSON has no NaN: undefined numbers are written as null."""
    if x is None:
        return None
    x = float(x)
    return None if math.isnan(x) or math.isinf(x) else x
