"""Flow functions f_c(σ₁): unconfined yield strength against the major consolidation stress.

Sources
-------
* Linear flow function, thesis eq. 6.1: f_c = f_c0 + k σ₁ (Enstad 1975; Jenike).
* Bilinear flow function, thesis §6.5.4 and Fig. 6.11 (fine SiC powder): f_c0 of the bilinear
  function is half that of the linear one, and the two merge where the linear function meets the
  line f_c = σ₁, i.e. at σ₁* = f_c0 / (1 − k) (needs k < 1). Between 0 and σ₁* the bilinear
  function is the straight line from (0, f_c0/2) to (σ₁*, σ₁*); above σ₁* it is the linear one.
* c ↔ f_c: thesis eq. 6.9 (see :mod:`bulkflow.theory.mohr`).

Only the linear flow function is compatible with the closed forms of Enstad's theory (eq. 6.6–6.8);
the bilinear one can be used with the root-finding forms of McLean and Jenike
(:func:`bulkflow.theory.jenike.critical_width_general`) and the numerical Enstad ODE
(:func:`bulkflow.theory.enstad.sigma2_bar_numeric`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .mohr import c_from_fc, fc_from_c

__all__ = ["LinearFlowFunction", "BilinearFlowFunction", "fc_from_c", "c_from_fc"]


@dataclass(frozen=True)
class LinearFlowFunction:
    """f_c = f_c0 + k σ₁ (thesis eq. 6.1). f_c0 in Pa, k dimensionless."""

    fc0: float
    k: float

    def __call__(self, sigma1):
        return self.fc0 + self.k * np.asarray(sigma1, dtype=float)

    def intersection_with_identity(self) -> float:
        """σ₁ where f_c = σ₁ (the flow function meets the ff = 1 line): f_c0/(1 − k)."""
        if self.k >= 1.0:
            raise ValueError("k >= 1: the linear flow function never meets f_c = sigma1")
        return self.fc0 / (1.0 - self.k)

    def bilinear(self, ratio: float = 0.5) -> "BilinearFlowFunction":
        """The thesis Fig. 6.11 modification of this function (f_c0 scaled by `ratio`)."""
        return BilinearFlowFunction(self.fc0, self.k, ratio)


@dataclass(frozen=True)
class BilinearFlowFunction:
    """Thesis Fig. 6.11: f_c0^bilinear = ratio · f_c0^linear (ratio = 0.5 in the thesis), merging
    with the linear function f_c0 + k σ₁ at its intersection with f_c = σ₁, σ₁* = f_c0/(1 − k).

    fc0 and k are those of the *linear* function being modified.
    """

    fc0: float
    k: float
    ratio: float = 0.5

    @property
    def sigma_merge(self) -> float:
        return LinearFlowFunction(self.fc0, self.k).intersection_with_identity()

    @property
    def fc0_bilinear(self) -> float:
        return self.ratio * self.fc0

    @property
    def k_low(self) -> float:
        """Slope of the low-stress branch: (σ₁* − ratio f_c0)/σ₁*, which with σ₁* = f_c0/(1 − k)
        is 1 − ratio (1 − k) for every f_c0. Written in that closed form so that a cohesionless
        material (f_c0 = 0, σ₁* = 0: the low branch shrinks to the origin and the function is
        k σ₁) has a slope instead of 0/0."""
        if self.k >= 1.0:
            raise ValueError("k >= 1: the linear flow function never meets f_c = sigma1")
        return 1.0 - self.ratio * (1.0 - self.k)

    def __call__(self, sigma1):
        s1 = np.asarray(sigma1, dtype=float)
        low = self.fc0_bilinear + self.k_low * s1
        high = self.fc0 + self.k * s1
        return np.where(s1 < self.sigma_merge, low, high)
