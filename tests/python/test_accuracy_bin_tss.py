"""bulkflow-accuracy bin-tss without a solver: the member's measure on synthetic discharge
histories with a known end of steady discharge, with none (not reached) and with a rate that is
never steady (no steady regime), and the family's summary when a member has no value (no number
is made up, no reference, no recommendation; the outputs are written)."""
import json
import math

import numpy as np
import pytest

from bulkflow.accuracy import bin_tss, study
from bulkflow.mpm.bin_scene import bin_cell


def _mass(t, t_open, pieces):
    """Discharged mass of a piecewise-constant rate: pieces = [(start after opening, rate), ...]."""
    s = np.clip(np.asarray(t) - t_open, 0.0, None)
    m = np.zeros_like(s)
    for i, (start, rate) in enumerate(pieces):
        end = pieces[i + 1][0] if i + 1 < len(pieces) else np.inf
        m += rate * np.clip(np.minimum(s, end) - start, 0.0, None)
    return m


def _write_run(tmp_path, pieces, t_open=0.3, t_end=5.3, m0=216.0, name="run"):
    """A history CSV (the columns the measure reads) and a solver log as run_deck leaves them."""
    t = np.round(np.arange(0.0, t_end + 1e-9, 0.01), 10)
    step = np.where(t < t_open - 1e-12, 1.0, 2.0)
    step_time = np.where(step == 1.0, t, t - t_open)
    out = _mass(t, t_open, pieces)
    base = tmp_path / name
    np.savetxt(f"{base}_history.csv", np.column_stack([t, step, step_time, m0 - out, out]), delimiter=",",
               header="time,step,step_time,MASS,MASS_OUT", comments="")
    (tmp_path / f"{name}.log").write_text("bulkflow: 2400 particles, 1 rank\n")
    return base


def test_steady_then_a_sudden_drop_gives_the_window_end_before_it(tmp_path):
    # 40 kg/s/m steady, a drop to 20 at 3.2 s after opening: the window 3.0-3.5 s sees it, so
    # T_ss = 3.0 s (end of the last steady window), and the MDR up to it is the steady 40
    base = _write_run(tmp_path, [(0.0, 40.0), (3.2, 20.0)])
    res = bin_tss.measure(base, {})
    assert res["tss_status"] == "reached"
    assert res["value"] == pytest.approx(3.0)
    assert res["steady_windows"] == 5                   # windows ending 1.0, 1.5, ..., 3.0
    assert res["mdr"] == pytest.approx(40.0, rel=1e-9)
    assert res["particles"] == 2400
    assert res["discharged"] == pytest.approx((40 * 3.2 + 20 * 1.8) / 216.0, rel=1e-3)


def test_a_run_that_ends_before_the_jump_has_no_value(tmp_path):
    # the drop comes after the run's end: no T_ss and no MDR "up to T_ss", never the run's length
    base = _write_run(tmp_path, [(0.0, 40.0), (6.0, 10.0)])
    res = bin_tss.measure(base, {})
    assert res["tss_status"] == "not reached"
    assert res["value"] is None and res["mdr"] is None and res["tss_rule"] is None
    assert res["steady_windows"] == 9                   # windows ending 1.0 ... 5.0, all within 10 %


def test_a_rate_that_changes_between_the_first_two_windows_is_no_steady_regime(tmp_path):
    # 30 then 40 kg/s/m from 0.9 s: the rule's raw answer is its smallest, 1.0 s, but the rate
    # never held over two windows, so the member has no T_ss
    base = _write_run(tmp_path, [(0.0, 30.0), (1.0, 40.0)])
    res = bin_tss.measure(base, {})
    assert res["tss_status"] == "no steady regime"
    assert res["tss_rule"] == pytest.approx(1.0)
    assert res["value"] is None and res["mdr"] is None


def test_members_keep_the_outlet_edge_on_the_same_grid_position():
    for quick in (True, False):
        rows = bin_tss.members(quick)
        assert len(rows) >= 3
        for r in rows:
            assert r["h"] == pytest.approx(bin_cell(bin_tss.OUTLET, r["edge_cells"]))
            assert bin_tss.OUTLET / r["h"] == pytest.approx(2 * r["edge_cells"] + 1)
        text = bin_tss.scene(rows[0])
        assert f"CELL={rows[0]['h']:.12g}" in text and "NAME=OUTLET, OP=DELETE" in text


def _row(label, h, value, mdr):
    return {"label": label, "h": h, "value": value, "mdr": mdr, "wall": 1.0, "cpu": 1.0, "increments": 10,
            "ranks": 1, "work": 1.0 / h ** 3, "tss_status": "reached" if value is not None else "not reached"}


def test_summary_with_a_member_not_reached_makes_no_number(tmp_path):
    rows = [_row("k1", 0.4, None, None), _row("k2", 0.2, 3.5, 36.0), _row("k3", 0.1, 3.1, 39.0),
            _row("k4", 0.05, 3.0, 40.0)]
    # complete family: a Richardson reference exists
    s = study.summarise(bin_tss.KIND, [dict(r) for r in rows[1:]])
    assert s["reference"] is not None and s["observed_order"] > 0
    # the finest is not reached: no order, no reference, no recommendation, no error for it
    rows[3] = _row("k4", 0.05, None, None)
    s = study.summarise(bin_tss.KIND, rows)
    assert s["reference"] is None and math.isnan(s["observed_order"])
    assert "k4" in s["reference_note"] and "k1" in s["reference_note"]
    assert all(r["label"] is None for r in s["recommendations"])
    errors = {r["label"]: r["error"] for r in s["members"]}
    assert errors["k4"] is None and errors["k1"] is None and errors["k3"] == 0.0
    assert errors["k2"] == pytest.approx(3.5 / 3.1 - 1)
    assert s["also"]["mdr"]["reference"] is None
    s["total_wall"], s["quick"] = 1.0, True
    study.write_outputs(bin_tss.KIND, rows, s, tmp_path)
    md = (tmp_path / "bin-tss.md").read_text()
    assert "none (not reached)" in md and "no recommendation" in md
    saved = json.loads((tmp_path / "bin-tss.json").read_text())
    assert [m["value"] for m in saved["members"]] == [None, 3.5, 3.1, None]
    assert (tmp_path / "bin-tss.png").stat().st_size > 0


def test_a_coarse_member_without_a_value_leaves_the_extrapolation_of_the_three_finest():
    # T_ss = 2 + 8 h (order 1) on the three finest; the coarsest has none and gets no error
    rows = [_row("k1", 0.4, None, None)] + [_row(f"k{i}", h, 2.0 + 8.0 * h, 50.0 - 40.0 * h)
                                            for i, h in ((2, 0.2), (3, 0.1), (4, 0.05))]
    s = study.summarise(bin_tss.KIND, rows)
    assert s["observed_order"] == pytest.approx(1.0, rel=1e-9)
    assert s["reference"] == pytest.approx(2.0, rel=1e-9)
    assert s["members"][0]["error"] is None
    assert s["members"][3]["error"] == pytest.approx(0.4 / 2.0)
    assert s["also"]["mdr"]["reference"] == pytest.approx(50.0, rel=1e-9)


def test_equal_t_ss_of_the_finest_members_gives_no_order_and_no_reference():
    # T_ss is a multiple of the 0.5 s window: members that agree to it show no convergence rate
    rows = [_row("k1", 0.4, None, None), _row("k2", 0.2, 3.0, 38.0), _row("k3", 0.1, 3.0, 51.0),
            _row("k4", 0.05, 3.0, 55.0)]
    s = study.summarise(bin_tss.KIND, rows)
    assert s["reference"] is None and "no observed order" in s["reference_note"]
    assert "values are equal" in s["reference_note"] and "oscillatory" not in s["reference_note"]
    assert all(r["label"] is None for r in s["recommendations"])
    assert [r["error"] for r in s["members"]] == [None, 0.0, 0.0, 0.0]
    # one repeated value is not called oscillatory either
    rows = [_row("k2", 0.2, 3.5, 38.0), _row("k3", 0.1, 3.0, 51.0), _row("k4", 0.05, 3.0, 55.0)]
    s = study.summarise(bin_tss.KIND, rows)
    assert "a value repeats" in s["reference_note"]
    assert [r["error"] for r in s["members"]] == [pytest.approx(3.5 / 3.0 - 1), 0.0, 0.0]
