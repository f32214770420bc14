"""bulkflow.accuracy.outlet_cell against closed forms: a family made by the model gives back M0 and
κ exactly (any member order), with zero residuals; noise shows in the residuals and the band; the
cells it asks for invert the model; a family whose rate falls with refinement, or with too few
members, is refused."""
import math

import pytest

from bulkflow.accuracy.outlet_cell import describe, fit_outlet_cell

B = 0.0118


def family(m0, kappa, cells, e=1.5):
    return [B / n for n in cells], [m0 * (1 - kappa / n) ** e for n in cells]


@pytest.mark.parametrize("kappa", [0.4, 1.5, 2.5])
def test_exact_family_gives_back_limit_and_narrowing(kappa):
    h, f = family(11.0, kappa, [13, 5, 9, 7])          # unsorted on purpose
    fit = fit_outlet_cell(h, f, B)
    assert fit.limit == pytest.approx(11.0, rel=1e-12)
    assert fit.kappa == pytest.approx(kappa, rel=1e-12)
    assert max(abs(r) for r in fit.residuals) < 1e-12
    assert fit.limit_without_coarsest == pytest.approx(11.0, rel=1e-12)
    assert fit.uncertainty == pytest.approx(0.0, abs=1e-9)
    for x, y in zip(h, f):
        assert fit.rate(x) == pytest.approx(y, rel=1e-12)


def test_other_exponent():
    h, f = family(3.0, 1.2, [3, 5, 7], e=2.5)           # Beverloo's exponent for a round orifice
    fit = fit_outlet_cell(h, f, B, exponent=2.5)
    assert (fit.limit, fit.kappa) == (pytest.approx(3.0, rel=1e-12), pytest.approx(1.2, rel=1e-12))


def test_noise_shows_in_residuals_and_band():
    h, f = family(11.0, 2.5, [7, 9, 11, 13])
    f[1] *= 1.01                                        # one member 1 % high
    fit = fit_outlet_cell(h, f, B)
    assert max(abs(r) for r in fit.residuals) > 2e-3
    assert fit.uncertainty > 0 and math.isfinite(fit.limit_se)
    assert abs(fit.limit - 11.0) < 3 * fit.uncertainty


def test_three_members_have_one_degree_of_freedom():
    h, f = family(11.0, 2.5, [9, 11, 13])
    f[0] *= 0.995
    fit = fit_outlet_cell(h, f, B)
    assert fit.limit_without_coarsest is None            # a line needs two: nothing to leave out
    assert fit.uncertainty == pytest.approx(2 * fit.limit_se)


def test_cells_invert_the_model():
    h, f = family(11.0, 2.5, [7, 9, 11])
    fit = fit_outlet_cell(h, f, B)
    for target in (0.01, 0.02, 0.05):
        hc = fit.cell_for_error(target)
        assert fit.error(hc) == pytest.approx(target, rel=1e-10)
        hs = fit.cell_for_step(target, 1.25)
        assert fit.rate(hs / 1.25) / fit.rate(hs) - 1 == pytest.approx(target, rel=1e-8)
        assert hs > hc                                   # neighbours agree long before the limit is near
    with pytest.raises(ValueError):
        fit.cell_for_step(0.01, 1.0)
    text = "\n".join(describe(fit, ratio=1.25))
    assert "M0 11" in text and "cells across the outlet" in text


def test_refused_inputs():
    h, f = family(11.0, 2.5, [7, 9, 11])
    with pytest.raises(ValueError, match="at least 3"):
        fit_outlet_cell(h[:2], f[:2], B)
    with pytest.raises(ValueError, match="do not rise"):
        fit_outlet_cell(h, list(reversed(f)), B)         # the rate falls as the cell shrinks
    with pytest.raises(ValueError, match="distinct"):
        fit_outlet_cell([h[0], h[0], h[2]], f, B)
    with pytest.raises(ValueError, match="positive"):
        fit_outlet_cell(h, [f[0], -1.0, f[2]], B)
    with pytest.raises(ValueError, match="wider than the outlet at the coarsest"):
        # a steep rise from a coarse member: κ h ≥ b at the coarsest cell
        fit_outlet_cell([B / 1.1, B / 4, B / 5], [0.001, 6.0, 8.0], B)


def test_command_prints_the_fit_and_predictions(capsys):
    from bulkflow.accuracy.outlet_cell import main
    _, f = family(11.0, 2.5, [7, 9, 11])
    assert main(["--width", str(B), "--across", "7", "9", "11", "--values", *map(str, f), "--predict", "13"]) == 0
    out = capsys.readouterr().out
    assert "M0 11 " in out and "κ 2.5 " in out
    assert f"predicted at 13 cells across: {11.0 * (1 - 2.5 / 13) ** 1.5:.6g}" in out
    with pytest.raises(SystemExit):
        main(["--width", str(B), "--across", "7", "9", "--values", "1", "2", "3"])
    assert "one entry per member" in capsys.readouterr().err
