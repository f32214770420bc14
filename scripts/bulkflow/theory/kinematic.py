"""Kinematic velocity model (Nedderman & Tüzün 1979), thesis eqs. 1.2, 1.3 = 4.4.

    ∂v/∂y = −D ∂²v/∂x²      →      v(x, y) = v_centreline(y) exp(−x²/(4 D y))     (1.3)

v: vertical velocity (downward flow), x: distance from the centreline, y: vertical distance from
the point sink (the thesis does not say whether up or down; here y > 0 is the height above the
sink), D: the diffusion length (a few particle diameters; it grows with height in the thesis FEM
and in experiments). The plane point-sink solution is the heat kernel
v = Q/√(4π D y) exp(−x²/(4 D y)) with Q the volumetric flow per unit length
(docs/theory/hopper_theory.md §g, derived): its integral over x is Q at every height (the flux is conserved).
Sign: the magnitude of the downward velocity is returned (positive).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["kinematic_velocity", "point_sink_velocity", "centreline_velocity", "flux",
           "fit_diffusion_length"]


def kinematic_velocity(x, y, v_centreline, D):
    """Eq. 1.3: v(x, y) = v_c(y) exp(−x²/(4 D y)) for a given centreline velocity at height y."""
    x = np.asarray(x, dtype=float)
    return v_centreline * np.exp(-x * x / (4.0 * D * y))


def centreline_velocity(y, Q, D):
    """v_c(y) = Q/√(4π D y) of the plane point sink with flow Q per unit length."""
    return Q / np.sqrt(4.0 * math.pi * D * np.asarray(y, dtype=float))


def point_sink_velocity(x, y, Q, D):
    """Plane point-sink solution of eq. 1.2: Q/√(4πDy) exp(−x²/(4Dy)); solves ∂v/∂y = D ∂²v/∂x²
    with y the height above the sink (the thesis's minus sign is y measured downward)."""
    return kinematic_velocity(x, y, centreline_velocity(y, Q, D), D)


def flux(x, v):
    """Volumetric flow per unit length ∫ v dx (trapezoid) over the sampled profile."""
    x = np.asarray(x, dtype=float)
    v = np.asarray(v, dtype=float)
    return float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(x)))


def fit_diffusion_length(x, v, y):
    """D at height y from a velocity profile: least squares of ln v against x² (positive v only),
    ln v = ln v_c − x²/(4 D y). Returns (D, v_c)."""
    x = np.asarray(x, dtype=float)
    v = np.asarray(v, dtype=float)
    keep = v > 0.0
    A = np.column_stack([np.ones(keep.sum()), x[keep] ** 2])
    (c0, c1), *_ = np.linalg.lstsq(A, np.log(v[keep]), rcond=None)
    if c1 >= 0.0:
        raise ValueError("profile does not decay away from the centreline: no diffusion length")
    return -1.0 / (4.0 * y * c1), math.exp(c0)
