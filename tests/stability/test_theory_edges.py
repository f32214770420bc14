"""Stability suite, theory part: bulkflow.theory at the edges of its inputs (issue 21 point 4).

"Stable" here means: every estimate is a width >= 0, inf (no arch-free width) or nan with a note
saying why, never an exception or a negative width, for c = 0, theta -> 0, phi_w = 0,
phi_w >= phi and k = 0 with every flow function; a hopper the theories cannot describe
(theta = 0) is refused with a message (CLI: exit 2), not a division by zero.
"""
import io
import math
from contextlib import redirect_stderr, redirect_stdout

import pytest

from bulkflow.theory import Hopper, Material, critical_width_estimates
from bulkflow.theory import cli
from bulkflow.theory.flow_function import BilinearFlowFunction, LinearFlowFunction

FLOWS = ("linear", "bilinear")
WIDTHS = ("mclean", "jenike", "enstad")
BASE = dict(rho=400.0, phi_deg=40.0, phi_w_deg=20.0, k=0.2, fc0=800.0)


def _estimates(theta=30.0, **material):
    m = Material(**{**BASE, **material})
    return critical_width_estimates(Hopper(theta_deg=theta, height=2.0, outlet_width=0.3), m)


def _assert_widths_sane(est):
    for key in WIDTHS:
        B = est[key]
        if math.isnan(B):
            assert any(n.startswith(key) for n in est["notes"]), (key, est["notes"])
        else:
            assert B >= 0.0, (key, B)
    for reading, B in est["jenike_by_beta"].items():
        assert math.isnan(B) or B >= 0.0, (reading, B)


@pytest.mark.parametrize("flow", FLOWS)
@pytest.mark.parametrize("k", (0.0, 0.2, 0.6))
def test_cohesionless_never_arches(flow, k):
    """c = 0 (f_c0 = 0): the issue's division by zero with the bilinear function. A cohesionless
    material has f_c = k sigma1 and no theory gives it a positive critical width."""
    est = _estimates(fc0=0.0, k=k, flow=flow)
    _assert_widths_sane(est)
    for key in WIDTHS:
        assert est[key] == 0.0 or math.isinf(est[key]), (key, est[key])
    assert est["mclean"] == 0.0 and est["enstad"] == 0.0


@pytest.mark.parametrize("k", (0.0, 0.2, 0.9))
def test_bilinear_flow_function_edges(k):
    """The bilinear function is continuous at sigma1* and, for f_c0 = 0, is the linear k sigma1."""
    lin, bil = LinearFlowFunction(800.0, k), BilinearFlowFunction(800.0, k)
    s = bil.sigma_merge
    assert float(bil(s * (1 - 1e-12))) == pytest.approx(float(lin(s)), rel=1e-9)
    assert float(bil(0.0)) == pytest.approx(400.0)
    zero = BilinearFlowFunction(0.0, k)
    assert math.isfinite(zero.k_low)
    sig = [0.0, 1.0, 1e3, 1e6]
    assert list(zero(sig)) == pytest.approx(list(LinearFlowFunction(0.0, k)(sig)))
    with pytest.raises(ValueError):
        BilinearFlowFunction(800.0, 1.0).k_low


@pytest.mark.parametrize("flow", FLOWS)
def test_k_zero_every_flow_function(flow):
    """k = 0: a constant f_c; linear and bilinear give finite positive widths."""
    est = _estimates(k=0.0, flow=flow)
    _assert_widths_sane(est)
    for key in WIDTHS:
        assert 0.0 < est[key] < math.inf, (key, est[key])


@pytest.mark.parametrize("flow", FLOWS)
def test_smooth_wall(flow):
    """phi_w = 0: beta = 0 for Enstad (arcs centred on the apex), every width finite."""
    est = _estimates(phi_w_deg=0.0, flow=flow)
    _assert_widths_sane(est)
    assert est["beta_enstad_arch_deg"] == 0.0
    assert all(0.0 < est[key] < math.inf for key in WIDTHS)


@pytest.mark.parametrize("flow", FLOWS)
@pytest.mark.parametrize("phi_w", (40.0, 45.0, 60.0))
@pytest.mark.parametrize("theta", (1.0, 30.0, 89.0))
def test_wall_rougher_than_material(flow, phi_w, theta):
    """phi_w >= phi: Jenike's beta = theta + omega_p can pass 90 deg; the width is then nan with a
    note (before: a negative width), never an exception."""
    est = _estimates(theta=theta, phi_w_deg=phi_w, flow=flow)
    _assert_widths_sane(est)


@pytest.mark.parametrize("flow", FLOWS)
@pytest.mark.parametrize("theta", (1.0, 0.5))
def test_steep_hopper_limit(flow, theta):
    """theta -> 0: the estimates exist (Enstad may be inf: no arch-free width in a near channel)."""
    est = _estimates(theta=theta, flow=flow)
    _assert_widths_sane(est)
    assert 0.0 < est["jenike"] < math.inf


@pytest.mark.parametrize("theta", (0.0, -5.0, 90.0))
def test_no_wedge_is_refused(theta):
    with pytest.raises(ValueError, match="0 < theta < 90"):
        Hopper(theta_deg=theta, height=2.0)


def _cli(*args):
    """bulkflow-theory in this process (a subprocess pays the scipy import again): (exit, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        try:
            code = cli.main(list(args))
        except SystemExit as stop:
            code = stop.code
    return code, err.getvalue()


def test_cli_cohesionless_bilinear_runs():
    """The command of issue 21: a cohesionless material with the bilinear flow function."""
    r = _cli("--theta", "30", "--height", "2", "--rho", "400", "--phi", "40", "--phi-w", "20",
             "--k", "0.3", "--fc0", "0", "--flow", "bilinear")
    code, err = r
    assert code == 0, err


def test_cli_theta_zero_is_a_usage_error():
    r = _cli("--theta", "0", "--height", "2", "--rho", "400", "--phi", "40", "--phi-w", "20",
             "--k", "0.3", "--fc0", "800")
    code, err = r
    assert code == 2
    assert "0 < theta < 90" in err
