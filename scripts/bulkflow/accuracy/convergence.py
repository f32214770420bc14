"""Pure logic of a convergence study: observed order, Richardson extrapolation, the grid
convergence index, and the cheapest member of a family that meets a target accuracy.

No solver and no files here, so every function is checked against closed-form inputs
(tests/python/test_accuracy_convergence.py). Conventions: `h` is the member's size parameter
(element or cell size; smaller is finer), `f` the quantity it produced. docs/accuracy.md gives the
formulas and their assumptions (Richardson 1911; Roache 1998 for the grid convergence index).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def _finest_three(h, f):
    """(h, f) of the three finest members, finest first; errors if fewer or repeated sizes."""
    h = np.asarray(h, dtype=float)
    f = np.asarray(f, dtype=float)
    if h.shape != f.shape or h.size < 3:
        raise ValueError(f"need at least three members with one value each (got {h.size} sizes, {f.size} values)")
    order = np.argsort(h)
    h, f = h[order][:3], f[order][:3]
    if not (h[0] < h[1] < h[2]) or h[0] <= 0:
        raise ValueError(f"sizes must be positive and distinct: {h.tolist()}")
    return h, f


def order_from_errors(h, err) -> float:
    """Observed order p of err ≈ C h^p: least-squares slope of log err against log h over the three
    finest members (an exact reference is known). nan when an error is zero."""
    h, e = _finest_three(h, np.abs(err))
    if np.any(e <= 0):
        return math.nan
    return float(np.polyfit(np.log(h), np.log(e), 1)[0])


def order_from_values(h, f) -> float:
    """Observed order p from three solutions without a reference (f = f0 + C h^p): solves
    (f3 − f2)/(f2 − f1) = (r32^p − 1)/(r21^p − 1) · r21^p for p, r21 = h2/h1, r32 = h3/h2
    (Roache 1998; for a constant ratio r it is p = ln((f3 − f2)/(f2 − f1))/ln r).
    nan when the differences change sign (oscillatory convergence: no single order)."""
    h, f = _finest_three(h, f)
    d21, d32 = f[1] - f[0], f[2] - f[1]
    if d21 == 0 or d32 == 0 or (d21 > 0) != (d32 > 0):
        return math.nan
    r21, r32 = h[1] / h[0], h[2] / h[1]
    ratio = d32 / d21
    if math.isclose(r21, r32, rel_tol=1e-12):
        p = math.log(ratio) / math.log(r21)
        return p if p > 0 else math.nan
    # g(p) = r21^p (r32^p − 1)/(r21^p − 1) − ratio is increasing in p > 0: bisect.
    def g(p):
        return r21 ** p * (r32 ** p - 1) / (r21 ** p - 1) - ratio
    lo, hi = 1e-6, 20.0
    if g(lo) > 0 or g(hi) < 0:
        return math.nan
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(mid) > 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


@dataclass
class Richardson:
    value: float          #: extrapolated f at h → 0
    order: float          #: the order used
    gci: float            #: grid convergence index of the finest member (relative, Fs = 1.25)
    uncertainty: float    #: GCI as an absolute band on the extrapolated value: |f1| · gci


def _show(values) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"


MIN_ORDER = 0.5   #: below it the extrapolation is refused (see richardson)


def richardson(h, f, order: float | None = None, safety: float = 1.25, min_order: float = MIN_ORDER) -> Richardson:
    """Richardson (1911) extrapolation from the two finest members with the observed order of the
    three finest (or `order` if given): f_ext = f1 + (f1 − f2)/(r^p − 1), r = h2/h1. The grid
    convergence index of the finest member (Roache 1998) GCI = Fs |(f2 − f1)/f1| / (r^p − 1), with
    the safety factor Fs = 1.25 for three or more members. Raises ValueError when no order can be
    observed (oscillatory or stalled convergence) and none is given, or when the observed order is
    below `min_order`: the correction (f1 − f2)/(r^p − 1) then multiplies the last difference by
    more than 1/(r^0.5 − 1) (2.4 for r = 2, 8.5 for r = 1.25), so the reference would be the
    members' noise amplified, not a limit."""
    hs, fs = _finest_three(h, f)
    p = order if order is not None else order_from_values(h, f)
    if not (p > 0):
        d21, d32 = fs[1] - fs[0], fs[2] - fs[1]
        why = ("the three values are equal (nothing changes with refinement at this resolution)"
               if d21 == 0 and d32 == 0 else
               "one difference is zero (a value repeats)" if d21 * d32 == 0 else
               "the differences change sign (oscillatory convergence)" if d21 * d32 < 0 else
               "the differences do not shrink fast enough with refinement (not in the asymptotic range)")
        raise ValueError(f"no observed order from {_show(fs)} at h = {_show(hs)}: {why}; "
                         "refine further or give the order")
    if order is None and p < min_order:
        raise ValueError(f"observed order {p:.2f} from {_show(fs)} at h = {_show(hs)} is below {min_order}: "
                         "not in the asymptotic range, no extrapolation")
    r = hs[1] / hs[0]
    factor = r ** p - 1
    value = fs[0] + (fs[0] - fs[1]) / factor
    gci = safety * abs((fs[1] - fs[0]) / fs[0]) / factor if fs[0] != 0 else math.inf
    return Richardson(float(value), float(p), float(gci), float(abs(fs[0]) * gci))


def recommend(members, target: float, key_error: str = "error", key_cost: str = "wall"):
    """The cheapest member (least `key_cost`) whose |`key_error`| is within `target` (a relative
    error, 0.02 for ±2 %) and stays within it in every costlier member; None when no member meets
    it. `members` is a sequence of dicts; members without a finite error are not candidates and
    do not break the run. Why "stays": in a family that scatters about its reference a coarse
    member can land on it by chance (the 1 m hopper with an open outlet edge: the 3-cell member
    within 0.14 % of Richardson's value while the 11-cell one was 3.7 % off); a member is worth
    recommending only if refining from it does not leave the band."""
    valued = sorted((m for m in members if m.get(key_error) is not None and math.isfinite(m[key_error])),
                    key=lambda m: m[key_cost])
    for i, m in enumerate(valued):
        if all(abs(n[key_error]) <= target for n in valued[i:]):
            return m
    return None
