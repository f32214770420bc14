"""Pure logic of bulkflow.accuracy.convergence against closed forms: f = f0 + C h^p gives back p
and f0 exactly (constant and varying refinement ratios), the GCI formula, oscillatory input is
refused, and the recommendation picks the cheapest member within the target."""
import math

import pytest

from bulkflow.accuracy.convergence import (order_from_errors, order_from_values, recommend,
                                           richardson)


@pytest.mark.parametrize("p", [1.0, 1.5, 2.0, 3.0])
def test_order_and_extrapolation_constant_ratio(p):
    h = [0.4, 0.2, 0.1, 0.05]
    f = [3.0 + 0.7 * x ** p for x in h]
    assert order_from_values(h, f) == pytest.approx(p, rel=1e-10)
    rich = richardson(h, f)
    assert rich.value == pytest.approx(3.0, rel=1e-12)
    # GCI = 1.25 |(f2 - f1)/f1| / (r^p - 1) with r = 2 on the two finest
    f1, f2 = f[3], f[2]
    assert rich.gci == pytest.approx(1.25 * abs((f2 - f1) / f1) / (2 ** p - 1), rel=1e-12)
    assert rich.uncertainty == pytest.approx(abs(f1) * rich.gci, rel=1e-12)


def test_order_varying_ratio_and_unsorted_input():
    h = [0.03, 0.1, 0.045, 0.5]            # finest three: 0.03, 0.045, 0.1 (ratios 1.5 and 2.22)
    f = [-2.0 + 5.0 * x ** 1.7 for x in h]
    assert order_from_values(h, f) == pytest.approx(1.7, rel=1e-8)
    assert richardson(h, f).value == pytest.approx(-2.0, rel=1e-8)


def test_order_from_errors_power_law_and_decreasing_values():
    h = [0.2, 0.1, 0.05, 0.025]
    assert order_from_errors(h, [4 * x ** 2 for x in h]) == pytest.approx(2.0, rel=1e-12)
    # decreasing towards the limit works the same (f0 - C h^p)
    assert order_from_values(h, [1 - x ** 1.25 for x in h]) == pytest.approx(1.25, rel=1e-10)


def test_oscillatory_convergence_is_refused():
    h = [0.4, 0.2, 0.1]
    f = [1.0, 1.2, 1.1]
    assert math.isnan(order_from_values(h, f))
    with pytest.raises(ValueError, match="oscillatory"):
        richardson(h, f)
    # with a given order it extrapolates anyway: f1 + (f1 - f2)/(2^2 - 1)
    assert richardson(h, f, order=2.0).value == pytest.approx(1.1 + (1.1 - 1.2) / 3)


def test_too_few_or_repeated_sizes():
    with pytest.raises(ValueError, match="at least three"):
        order_from_values([0.1, 0.2], [1.0, 2.0])
    with pytest.raises(ValueError, match="distinct"):
        order_from_values([0.1, 0.1, 0.2], [1.0, 2.0, 3.0])


def test_recommend_picks_cheapest_within_target():
    members = [
        {"label": "coarse", "error": 0.08, "wall": 1.0},
        {"label": "medium", "error": -0.018, "wall": 4.0},
        {"label": "odd", "error": 0.009, "wall": 3.0},       # cheaper and better: picked for 2 %
        {"label": "fine", "error": 0.004, "wall": 16.0},
        {"label": "broken", "error": float("nan"), "wall": 0.1},
    ]
    assert recommend(members, 0.10)["label"] == "coarse"
    assert recommend(members, 0.02)["label"] == "odd"
    assert recommend(members, 0.005)["label"] == "fine"
    assert recommend(members, 0.001) is None


def test_recommend_needs_the_costlier_members_within_the_target_too():
    # a coarse member on the reference by chance, a finer one off it: not recommended
    members = [
        {"label": "lucky", "error": 0.001, "wall": 1.0},
        {"label": "off", "error": -0.03, "wall": 4.0},
        {"label": "no value", "error": float("nan"), "wall": 6.0},
        {"label": "settled", "error": 0.008, "wall": 9.0},
        {"label": "finest", "error": 0.004, "wall": 30.0},
    ]
    assert recommend(members, 0.01)["label"] == "settled"
    assert recommend(members, 0.05)["label"] == "lucky"
    assert recommend(members, 0.005)["label"] == "finest"


def test_differences_growing_with_refinement_have_no_order():
    # monotone values whose differences grow as h falls (a drift, not convergence): no p > 0
    h = [0.1, 0.07, 0.05]
    f = [0.3746, 0.3716, 0.3658]
    assert math.isnan(order_from_values(h, f))
    with pytest.raises(ValueError, match="asymptotic range"):
        richardson(h, f)


def test_low_observed_order_is_not_extrapolated():
    # f = f0 + C h^0.2: a positive order, but too low to trust (the correction would be ~9x the
    # last difference at r = 1.25): refused unless the order is given
    h = [0.05, 0.04, 0.032]
    f = [1.0 + x ** 0.2 for x in h]
    assert order_from_values(h, f) == pytest.approx(0.2, rel=1e-8)
    with pytest.raises(ValueError, match="below 0.5"):
        richardson(h, f)
    assert richardson(h, f, min_order=0.1).value == pytest.approx(1.0, rel=1e-8)
