"""The outlet-narrowing model of a discharge rate refined in the cell: MDR(h) = M0 (1 − κ h/b)^e.

Why this form. A continuum discharging through an outlet of width b has no length of its own but
b, so its rate scales as b^e (e = 3/2 for a slot, Beverloo's exponent in plane flow). On the grid
the wall condition of the floor (or of the hopper wall) is carried by nodes whose shape functions
reach about a cell into the opening, so the sand flows as through an outlet narrowed by a length
proportional to the cell, κ h: the role Beverloo's empty annulus k d plays for grains, with the
cell in place of the grain. Then f^(1/e) is linear in h (Beverloo's plot, with h on the axis instead of b), and its
line gives both the limit M0 = f(0) and κ, the narrowing in cells. The model is an assumption
about the leading error, checked in docs/accuracy.md ("The discharge rate against the cell: an
outlet-narrowing model and its checks"): it predicted the eccentric bin's b/13 member from b/7-b/11
to 0.3 %, but not the 1 m hopper's finer members (1.5-3 % low) nor the concentric bin's b/15
(3-4 % high), and at a fixed cell the bins' Beverloo intercept is 1.5-2 cells against the
concentric family's κ = 2.5. So M0 is not a reference; bulkflow-accuracy does not use it.

No solver and no files here; tests/python/test_accuracy_outlet_cell.py checks it against
closed-form families.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

EXPONENT = 1.5   #: Beverloo's exponent for a slot (plane flow)
MIN_MEMBERS = 3  #: two members fit any line exactly: a third is the model's only check


@dataclass
class OutletCellFit:
    limit: float                  #: M0, the rate at h → 0
    kappa: float                  #: the narrowing of the outlet, in cells (κ of κ h)
    width: float                  #: the outlet width b the cells are measured against
    exponent: float               #: e
    limit_se: float               #: standard error of M0 from the line's residuals (nan: exact fit)
    kappa_se: float               #: standard error of κ (nan: exact fit)
    residuals: list[float] = field(default_factory=list)  #: (f − model)/f per member, finest first
    limit_without_coarsest: float | None = None  #: M0 of the fit without the coarsest (≥ 4 members)
    uncertainty: float = math.nan  #: band on M0: max(2 se, |M0 − M0 without the coarsest|)

    def rate(self, h: float) -> float:
        """The model's rate at cell h."""
        return self.limit * (1.0 - self.kappa * h / self.width) ** self.exponent

    def error(self, h: float) -> float:
        """The model's relative error of a member of cell h: 1 − f(h)/M0."""
        return 1.0 - self.rate(h) / self.limit

    def cell_for_error(self, target: float) -> float:
        """The largest cell whose model error is within `target` (0.01 for 1 %)."""
        return self.width / self.kappa * (1.0 - (1.0 - target) ** (1.0 / self.exponent))

    def cell_for_step(self, target: float, ratio: float) -> float:
        """The largest cell h at which refining to h/ratio changes the model's rate by less than
        `target`: the "two finest agree within target" criterion, as this model sees it."""
        if not ratio > 1.0:
            raise ValueError(f"the refinement ratio must be > 1 (got {ratio:g})")

        def step(h):
            return self.rate(h / ratio) / self.rate(h) - 1.0

        lo, hi = 0.0, self.width / self.kappa * (1.0 - 1e-9)   # step → 0 at h → 0, grows with h
        if step(hi) <= target:
            return hi
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if step(mid) > target:
                hi = mid
            else:
                lo = mid
        return lo


def _line(h, y):
    """Least-squares y = a − c h: (a, c, se_a, se_c); the standard errors are nan for an exact fit
    of two points (no degree of freedom)."""
    n = h.size
    A = np.column_stack([np.ones(n), -h])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    a, c = float(coef[0]), float(coef[1])
    dof = n - 2
    if dof < 1:
        return a, c, math.nan, math.nan
    s2 = float(np.sum((y - A @ coef) ** 2)) / dof
    cov = s2 * np.linalg.inv(A.T @ A)
    return a, c, math.sqrt(cov[0, 0]), math.sqrt(cov[1, 1])


def fit_outlet_cell(h, f, width: float, exponent: float = EXPONENT) -> OutletCellFit:
    """Fit f = M0 (1 − κ h/b)^e to members of cell h and rate f (any order) by a straight line
    through (h, f^(1/e)). Raises ValueError for fewer than three members, repeated cells, a rate
    that is not positive, or a fit in which the rate does not rise with refinement (κ ≤ 0: not the
    narrowing this model describes) or a member's cell is wider than the narrowed outlet."""
    h = np.asarray(h, dtype=float)
    f = np.asarray(f, dtype=float)
    if h.shape != f.shape or h.size < MIN_MEMBERS:
        raise ValueError(f"need at least {MIN_MEMBERS} members with one rate each (got {h.size} cells, {f.size} rates)")
    if not (width > 0 and exponent > 0):
        raise ValueError("the outlet width and the exponent must be > 0")
    order = np.argsort(h)
    h, f = h[order], f[order]
    if np.any(h <= 0) or np.any(np.diff(h) <= 0):
        raise ValueError(f"cells must be positive and distinct: {h.tolist()}")
    if np.any(f <= 0) or not np.all(np.isfinite(f)):
        raise ValueError(f"rates must be positive numbers: {f.tolist()}")
    y = f ** (1.0 / exponent)
    a, c, se_a, se_c = _line(h, y)
    kappa = c * width / a
    if not kappa > 0:
        raise ValueError(f"the rates {f.tolist()} do not rise with refinement (κ = {kappa:.3g} cells): "
                         "not an outlet narrowed by the cell")
    if np.any(kappa * h >= width):
        raise ValueError(f"κ = {kappa:.3g} cells: the narrowing κ h is wider than the outlet at the coarsest "
                         f"member (h = {h[-1]:.3g}, b = {width:.3g}); leave it out")
    limit = a ** exponent
    # delta method: M0 = a^e, κ = c b / a
    limit_se = exponent * a ** (exponent - 1.0) * se_a
    kappa_se = width * math.hypot(se_c / a, c * se_a / a ** 2)
    model = limit * (1.0 - kappa * h / width) ** exponent
    fit = OutletCellFit(limit=limit, kappa=kappa, width=width, exponent=exponent, limit_se=limit_se,
                        kappa_se=kappa_se, residuals=[float(v) for v in (f - model) / f])
    if h.size > MIN_MEMBERS:
        a2, _, _, _ = _line(h[:-1], y[:-1])
        fit.limit_without_coarsest = a2 ** exponent
    bands = [2.0 * limit_se] if math.isfinite(limit_se) else []
    if fit.limit_without_coarsest is not None:
        bands.append(abs(limit - fit.limit_without_coarsest))
    fit.uncertainty = max(bands) if bands else math.nan
    return fit


def describe(fit: OutletCellFit, quantity: str = "MDR", ratio: float | None = None) -> list[str]:
    """Lines for a report: the fit, its residuals, and the cells the model asks for ±1 % and ±2 %."""
    unc = "no band (exact fit)" if not math.isfinite(fit.uncertainty) else f"± {fit.uncertainty:.3g}"
    lines = [f"outlet-narrowing fit {quantity} = M0 (1 − κ h/b)^{fit.exponent:g}, b = {fit.width:g}: "
             f"M0 {fit.limit:.6g} {unc}, κ {fit.kappa:.3g} ± {fit.kappa_se:.2g} cells; "
             "residuals (finest first) " + ", ".join(f"{100 * r:+.2f} %" for r in fit.residuals)]
    for target in (0.01, 0.02):
        hc = fit.cell_for_error(target)
        text = (f"  within ±{100 * target:g} % of M0 the model needs h ≤ {hc:.3g} "
                f"({fit.width / hc:.0f} cells across the outlet)")
        if ratio:
            hs = fit.cell_for_step(target, ratio)
            text += (f"; two members h and h/{ratio:.3g} agree within {100 * target:g} % from h ≤ {hs:.3g} "
                     f"({fit.width / hs:.0f} cells across)")
        lines.append(text)
    return lines


def main(argv=None) -> int:
    """python -m bulkflow.accuracy.outlet_cell --width B --across N1 N2 N3 ... --values F1 F2 F3 ...
    [--predict N ...]: the fit of members with N cells across an outlet B wide, and the model's rate
    at further members (a prediction to hold against a run)."""
    import argparse

    p = argparse.ArgumentParser(prog="python -m bulkflow.accuracy.outlet_cell",
                                description=" ".join(main.__doc__.split()))
    p.add_argument("--width", type=float, required=True, help="outlet width b (the unit of the cells)")
    p.add_argument("--across", type=float, nargs="+", required=True, help="each member's cells across the outlet, b/h")
    p.add_argument("--values", type=float, nargs="+", required=True, help="each member's rate")
    p.add_argument("--exponent", type=float, default=EXPONENT)
    p.add_argument("--predict", type=float, nargs="*", default=[], help="cells across the outlet to predict at")
    a = p.parse_args(argv)
    if len(a.across) != len(a.values):
        p.error("--across and --values need one entry per member")
    try:
        fit = fit_outlet_cell([a.width / n for n in a.across], a.values, a.width, a.exponent)
    except ValueError as exc:
        p.error(str(exc))
    n = sorted(a.across, reverse=True)
    print("\n".join(describe(fit, ratio=n[0] / n[1])))
    for m in a.predict:
        print(f"  predicted at {m:g} cells across: {fit.rate(a.width / m):.6g}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
