"""bulkflow.arching.studies meshdiag: the mesh sequence of COW searches, on a stand-in for the
solver (a trial flows iff B exceeds a threshold that depends on the mesh)."""
import math

import pytest

from bulkflow.arching import studies
from bulkflow.arching.cow import Search
from bulkflow.arching.scene import scene_from_case


class FakeSearch(Search):
    """Search whose trials flow above `threshold[n_arc]` (m), without running the solver."""

    def __init__(self, scene, threshold):
        super().__init__(scene, "unused", 1, lambda m: None)
        self.threshold = threshold

    def trial(self, width, n_arc):
        key = (round(width, 6), n_arc)
        if key not in self.known:
            rec = type("R", (), dict(wall=1.0, cpu=0.5))()
            self.runs.append(rec)
            self.known[key] = width > self.threshold[n_arc]
        return self.known[key]


@pytest.mark.parametrize("threshold", [{16: 0.374, 30: 0.366, 60: 0.355},      # drifting (ψ = 0 like)
                                       {16: 0.386, 30: 0.384, 60: 0.385},      # converged (ψ = φ like)
                                       {16: 0.300, 30: 0.330, 60: 0.360}])     # rising by more than the margin
def test_mesh_sequence_brackets_each_mesh(threshold):
    sc = scene_from_case("B", "c0", height=1.0, n_arc=16)
    srch = FakeSearch(sc, threshold)
    rows = studies.mesh_sequence(srch, [16, 30, 60], 0.37, 0.004, 0.004, log=lambda m: None)
    assert [r["n_arc"] for r in rows] == [16, 30, 60]
    for r in rows:
        lo, hi = r["fem_no_flow"], r["fem_flow"]
        assert lo <= threshold[r["n_arc"]] < hi, r
        assert hi - lo <= 0.004 + 1e-12
        assert r["runs"] >= 1 and math.isclose(r["wall"], r["runs"] * 1.0)
    assert sum(r["runs"] for r in rows) == len(srch.runs)


def test_meshdiag_table_shifts():
    rows = [dict(variant="v", n_arc=16, fem_no_flow=0.370, fem_flow=0.374, runs=7, wall=7.0),
            dict(variant="v", n_arc=30, fem_no_flow=0.360, fem_flow=0.364, runs=4, wall=20.0)]
    t = studies.meshdiag_table(rows).splitlines()
    assert t[2].split("|")[4].strip() == "—"
    assert t[3].split("|")[4].strip() == "-10.0"


def test_meshdiag_variants_are_scene_fields():
    sc = scene_from_case("B", "c0", height=1.0, n_arc=16)
    for name, over in studies.MESHDIAG_VARIANTS.items():
        for k in over:
            assert hasattr(sc, k), (name, k)


def test_band_widths_counts_elements_above_half_the_ray_maximum():
    import numpy as np
    from bulkflow.arching.bands import band_widths
    mrad, n = 6, 3
    g = np.zeros((mrad, n))
    g[2, 0] = 1.0                       # ray 0: a band one element wide
    g[1:5, 1] = [0.6, 1.0, 0.9, 0.2]    # ray 1: three elements above half the maximum
    w = band_widths(g.ravel(), mrad, n)  # element order of the mesh: row by row from the outlet
    assert w[0] == 1 and w[1] == 3 and np.isnan(w[2])
