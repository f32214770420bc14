"""Mass/funnel-flow boundary (docs/theory/hopper_theory.md §h) and the radial stress field behind it."""
import math

import pytest

from bulkflow.theory import flow_mode as F
from bulkflow.theory import jenike as J


def _exists(delta, phi_w, theta):
    try:
        J.radial_stress_field(delta, phi_w, theta, "conical")
        return True
    except ValueError:
        return False


@pytest.mark.parametrize("delta,phi_w,tol", [(40, 20, 0.3), (50, 30, 0.3)])
def test_conical_closed_form_matches_radial_field_existence_limit(delta, phi_w, tol):
    tc = F.conical_mass_flow_limit(delta, phi_w)
    lo, hi = tc - 3.0, tc + 3.0
    assert _exists(delta, phi_w, lo) and not _exists(delta, phi_w, hi)
    for _ in range(9):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _exists(delta, phi_w, mid) else (lo, mid)
    assert lo == pytest.approx(tc, abs=tol)


def test_conical_limit_value_and_trends():
    assert F.conical_mass_flow_limit(40, 20) == pytest.approx(27.0, abs=0.05)
    assert F.conical_mass_flow_limit(40, 25) < F.conical_mass_flow_limit(40, 20)   # rougher: steeper


def test_plane_boundary_is_flagged_approximate():
    r = F.plane_boundary_rule_of_thumb(40, 20)
    assert r["approximate"] is True and "not the chart" in r["caveat"]
    assert r["theta_c_deg"] == pytest.approx(F.conical_mass_flow_limit(40, 20) + 10.0)
    assert F.plane_boundary_rule_of_thumb(20, 0)["theta_c_deg"] <= 90.0


def test_mass_flow_index():
    assert F.mass_flow_index([0.1, 0.2], [-0.5, -0.5]) == pytest.approx(0.3)
    assert F.classify_mfi(0.31) == "mass" and F.classify_mfi(0.29) == "funnel"


def test_plane_radial_field_wall_condition():
    f = J.radial_stress_field(44.72, 20.0, 30.0, "plane")
    from bulkflow.theory.mohr import wall_angle_passive_deg
    assert math.degrees(f.psi[-1]) == pytest.approx(90 + wall_angle_passive_deg(44.72, 20.0), abs=1e-6)
    assert math.degrees(f.psi[0]) == pytest.approx(90.0, abs=0.01)
