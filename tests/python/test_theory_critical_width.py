"""Critical outlet widths: the thesis's Fig. 6.2 statements, McLean/Jenike identities and the
reference numbers of docs/theory/hopper_theory.md §c, §i.2, §i.5."""
import math

import numpy as np
import pytest

from bulkflow.theory import Hopper, Material, critical_width_estimates, jenike, mclean
from bulkflow.theory.cases import case
from bulkflow.theory.mohr import delta_mod_deg, fc_from_c, wall_angle_passive_deg

HEIGHTS = [0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0]


def est(key, H, **kw):
    c = case(key)
    return critical_width_estimates(c.hopper(H), c.material(), **kw)


def test_fig_6_2_case_B_at_60_cm_jenike_and_enstad_flow_mclean_not():
    for H in HEIGHTS:
        e = critical_width_estimates(case("B").hopper(H, outlet_width=0.60), case("B").material())
        assert e["flows"] == {"mclean": False, "jenike": True, "enstad": True}, H


def test_fig_6_2_case_B_at_30_cm_enstad_flows_above_about_1_m():
    for H in HEIGHTS:
        e = critical_width_estimates(case("B").hopper(H, outlet_width=0.30), case("B").material())
        assert not e["flows"]["jenike"] and not e["flows"]["mclean"]
        assert e["flows"]["enstad"] == (H > 1.0), H   # "flow as long as the height is > about 1 m"
    assert not critical_width_estimates(case("B").hopper(0.9, 0.30), case("B").material())["flows"]["enstad"]
    assert critical_width_estimates(case("B").hopper(1.2, 0.30), case("B").material())["flows"]["enstad"]


def test_fig_6_2_height_dependence_case_A_weak_case_B_strong():
    a = [est("A", H)["enstad"] for H in HEIGHTS]
    b = [est("B", H)["enstad"] for H in HEIGHTS]
    assert (max(a) - min(a)) / max(a) < 0.08          # 48.6 .. 52.3 cm
    assert (max(a[2:]) - min(a[2:])) / max(a) < 0.01   # flat from 1 m
    assert max(b) / min(b) > 2.5                       # 53.6 .. 18.4 cm
    assert np.all(np.diff(b) < 0)
    for key in "AB":   # Jenike and McLean do not depend on the height
        j = {round(est(key, H)["jenike"], 12) for H in HEIGHTS}
        m = {round(est(key, H)["mclean"], 12) for H in HEIGHTS}
        assert len(j) == 1 and len(m) == 1


def test_k_zero_makes_consolidation_irrelevant():
    c = case("B")
    base = critical_width_estimates(c.hopper(2.0), c.material())
    for route in ("first_term", "full", "radial", "at_enstad"):
        e = critical_width_estimates(c.hopper(2.0), c.material(), consolidation=route)
        for t in ("mclean", "jenike", "enstad"):
            assert e[t] == pytest.approx(base[t], rel=1e-9), (route, t)
    fc0 = c.material().fc0
    assert base["mclean"] == pytest.approx(fc0 * 1.15 / (400 * 9.81))
    assert base["jenike"] == pytest.approx(fc0 * math.sin(math.radians(60)) / (400 * 9.81))
    # a material with k = 0 on another hopper: the consolidation field (X, Y) changes nothing
    m = Material(rho=800, phi_deg=35, phi_w_deg=15, k=0.0, fc0=1000.0)
    e1 = critical_width_estimates(Hopper(20, 1.0), m, consolidation="first_term")
    e2 = critical_width_estimates(Hopper(20, 1.0), m, consolidation="full")
    assert e1["jenike"] == pytest.approx(e2["jenike"]) and e1["mclean"] == pytest.approx(e2["mclean"])


@pytest.mark.parametrize("theta", [0.0, 10.0, 30.0, 45.0, 60.0])
def test_mclean_is_jenike_form_with_H_1_plus_theta_over_200(theta):
    assert mclean.mclean_H(theta) == pytest.approx(1 + theta / 200.0)
    fc, rho = 1234.0, 500.0
    assert mclean.critical_width(fc, rho, theta) == pytest.approx(
        jenike.critical_width_closed_form(fc, 0.0, rho, 1 + 0.005 * theta, 1.0))
    for k, S in ((0.2, 1.1), (0.6, 1.3)):
        assert mclean.critical_width_linear(fc, k, rho, theta, S) == pytest.approx(
            jenike.critical_width_closed_form(fc, k, rho, 1 + 0.005 * theta, S))


def test_closed_form_is_the_fixed_point_and_matches_root_finding():
    fc0, k, rho, H, S = 589.5, 0.47, 900.0, 0.998, 1.234
    B = jenike.critical_width_closed_form(fc0, k, rho, H, S)
    assert rho * 9.81 * B == pytest.approx(H * (fc0 + k * S * rho * 9.81 * B))
    Bg = jenike.critical_width_general(lambda s: fc0 + k * s, rho, H, lambda b: S * rho * 9.81 * b)
    assert Bg == pytest.approx(B, rel=1e-9)
    assert math.isinf(jenike.critical_width_closed_form(fc0, 1.0, rho, 1.0, 1.0))


def test_thin_arch_theta_to_zero_is_eq_6_3():
    for beta in (10.0, 25.0, 40.0):
        assert jenike.thin_arch_stress_theta(0.3, 500, 1e-7, beta) == pytest.approx(
            jenike.thin_arch_stress(0.3, 500, beta), rel=1e-5)


def test_jenike_beta_readings_and_case_B():
    # Case B, φ_w = 0: β = ω gives 0 (no arch) while β = θ + ω gives 50.4 cm (docs/theory/hopper_theory.md §c.2)
    e = est("B", 2.0)
    assert e["jenike_by_beta"]["omega"] == 0.0
    assert 100 * e["jenike_by_beta"]["theta_plus_omega"] == pytest.approx(50.4, abs=0.05)
    assert e["assumptions"]["jenike_beta"] == "theta_plus_omega"   # documented default


def test_reference_numbers_i5_mclean_jenike():
    a, b = est("A", 2.0), est("B", 2.0)
    assert 100 * a["mclean"] == pytest.approx(60.2, abs=0.05)
    assert 100 * a["jenike_by_beta"]["omega"] == pytest.approx(35.1, abs=0.05)
    assert 100 * a["jenike_by_beta"]["theta_plus_omega"] == pytest.approx(46.4, abs=0.05)
    assert 100 * b["mclean"] == pytest.approx(67.0, abs=0.05)


def test_reference_numbers_i2_eckhoff_leversen_c0_reading():
    # docs/theory/hopper_theory.md §i.2: the "as documented" recipe
    pol = {H: critical_width_estimates(case("polymer").hopper(H), case("polymer").material("c0"))
           for H in (0.5, 1.0, 2.0)}
    sic = {H: critical_width_estimates(case("sic").hopper(H), case("sic").material("c0"))
           for H in (0.5, 1.0, 2.0)}
    p, s = pol[1.0], sic[1.0]
    assert p["fc0"] == pytest.approx(1952, abs=0.5) and s["fc0"] == pytest.approx(589, abs=0.6)
    assert p["delta_mod_deg"] == pytest.approx(53.71, abs=0.005)
    assert s["delta_mod_deg"] == pytest.approx(43.25, abs=0.005)
    assert p["omega_p_deg"] == pytest.approx(29.47, abs=0.005)
    assert s["omega_p_deg"] == pytest.approx(43.28, abs=0.005)
    assert s["beta_enstad_arch_deg"] == pytest.approx(37.0)
    assert 100 * p["mclean"] == pytest.approx(172.1, abs=0.05)
    assert 100 * p["jenike_by_beta"]["omega"] == pytest.approx(90.9, abs=0.05)
    assert 100 * p["jenike_by_beta"]["theta_plus_omega"] == pytest.approx(136.6, abs=0.05)
    assert 100 * s["mclean"] == pytest.approx(19.3, abs=0.05)
    assert 100 * s["jenike_by_beta"]["omega"] == pytest.approx(15.8, abs=0.05)
    assert 100 * s["jenike_by_beta"]["theta_plus_omega"] == pytest.approx(12.0, abs=0.05)
    assert math.isinf(pol[0.5]["enstad"])
    assert [round(100 * pol[H]["enstad"], 1) for H in (1.0, 2.0)] == [51.4, 91.1]
    assert [round(100 * sic[H]["enstad"], 1) for H in (0.5, 1.0, 2.0)] == [14.8, 15.7, 15.8]


def test_lower_bounds_without_consolidation_exceed_thesis_polymer_values():
    # §i.2: with f_c = f_c0 (k ignored) the polymer already needs 48.5 (McLean) and 38.7 cm (Jenike, β = ω)
    m = case("polymer").material("c0")
    assert 100 * mclean.critical_width(m.fc0, m.rho, 14.5) == pytest.approx(48.5, abs=0.05)
    assert 100 * jenike.critical_width(m.fc0, m.rho, 29.47) == pytest.approx(38.7, abs=0.05)


def test_first_radial_term_factors_and_radial_field():
    # §c.4: S_AM = 1.080 (polymer), 1.294 (SiC, β = ω uncapped), 1.169 (Case A);
    # S_AM/S_J = 1.013, 1.053, 1.053 (Jenike's plane radial field)
    for key, beta_key, s_am, ratio in (("polymer", "omega", 1.080, 1.013),
                                       ("sic", "omega", 1.294, 1.053), ("A", "omega", 1.169, 1.053)):
        c = case(key)
        m = c.material()
        d = delta_mod_deg(m.phi_deg, m.k)
        w = wall_angle_passive_deg(d, m.phi_w_deg)
        S = jenike.S_first_term(c.theta_deg, d, w)
        assert S == pytest.approx(s_am, abs=0.0005)
        assert S / jenike.S_radial(c.theta_deg, d, m.phi_w_deg) == pytest.approx(ratio, abs=0.0015)


def test_table_6_3_cannot_be_matched_by_the_documented_reading():
    # honest check, not a fit: the c0 reading is far from the thesis polymer row
    c = case("polymer")
    e = critical_width_estimates(c.hopper(1.0), c.material("c0"))
    assert e["mclean"] > 3 * 0.35 and e["enstad"] > 1.5 * 0.30
