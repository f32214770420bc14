"""The convergence study's profile comparison (scripts/bulkflow/mpm/studies.py)."""
import math

import numpy as np
import pytest

from bulkflow.mpm.studies import profile_difference


def test_identical_profiles_differ_by_zero():
    s = np.linspace(0.0, 1.0, 11)
    v = np.sin(s) + 2
    assert profile_difference(s, v, s, v) == 0.0


def test_constant_offset_gives_offset_over_rms():
    s = np.linspace(0.0, 1.0, 21)
    ref = np.full_like(s, 4.0)
    # a coarse profile sampled elsewhere, 1.0 above the reference everywhere
    sc = np.linspace(0.0, 1.0, 6)
    assert profile_difference(s, ref, sc, np.full_like(sc, 5.0)) == pytest.approx(0.25)


def test_only_the_overlap_counts():
    s = np.linspace(0.0, 2.0, 21)
    ref = np.ones_like(s)
    sc = np.array([0.0, 1.0])             # covers half of the reference range
    other = np.array([1.0, 1.0])
    assert profile_difference(s, ref, sc, other) == 0.0
    # the half it does not cover may be wildly different: it is not compared
    ref[s > 1.0] = 100.0
    assert profile_difference(s, ref, sc, other) == 0.0


def test_nan_bins_of_the_coarse_profile_are_skipped_and_no_overlap_is_nan():
    s = np.linspace(0.0, 1.0, 5)
    ref = np.ones_like(s)
    other = np.array([1.0, np.nan, 1.0, 1.0, 1.0])
    assert profile_difference(s, ref, s, other) == 0.0
    assert math.isnan(profile_difference(s, ref, np.array([5.0, 6.0]), np.array([1.0, 1.0])))
