"""bulkflow.arching.decision: flow/no-flow from synthetic history files (no solver needed)."""
import numpy as np
import pytest

from bulkflow.arching.decision import ARREST, FLOW, UNDECIDED, StopParams, decide, read_stop_params

COLUMNS = ["time", "step", "step_time", "increment", "ALLKE", "ALLIE", "ALLVD", "ALLFD", "ALLWK", "ALLAE",
           "ETOTAL", "UMAX_ALLN"]


def _write(path, t, u, ke, step=3, t0=1.0):
    rows = []
    for i, (ti, ui, ki) in enumerate(zip(t, u, ke)):
        rows.append([t0 + ti, step, ti, i, ki, 1.0, 0, 0, 1.0, 0, 0, ui])
    with open(path, "w") as f:
        f.write(",".join(COLUMNS) + "\n")
        for r in rows:
            f.write(",".join(f"{v:.15e}" for v in r) + "\n")
    return path


P = StopParams(nset="ALLN", displacement=1e-3, ke_fraction=0.02, hold=0.05, min_time=0.05, growth=0.05, step=3,
               period=1.0)


def test_flow_when_displacement_exceeds_limit(tmp_path):
    t = np.linspace(0, 0.08, 41)
    u = 0.5 * 9.81 * t ** 2                     # free fall: passes 1 mm at ~14 ms
    ke = 10 * t ** 2
    d = decide(_write(tmp_path / "h.csv", t, u, ke), P)
    assert d.outcome == FLOW and d.umax > P.displacement


def test_arrest_by_kinetic_energy(tmp_path):
    t = np.linspace(0, 0.3, 151)
    ke = np.exp(-t / 0.01)                       # decays to 2 % of its peak by t = 0.04
    u = 2e-4 * (1 - np.exp(-t / 0.01)) + 1e-5 * np.sin(200 * t) ** 2   # keeps wiggling (growth rule fails)
    d = decide(_write(tmp_path / "h.csv", t, u, ke), P)
    assert d.outcome == ARREST and "ALLKE" in d.reason


def test_arrest_by_stalled_displacement_while_vibrating(tmp_path):
    # the material arched before the opening and vibrates: ALLKE never falls to 2 % of its peak,
    # but the largest displacement stops growing
    t = np.linspace(0, 0.2, 101)
    ke = 1e-4 * (1.2 + np.sin(2 * np.pi * t / 0.05))
    u = 2e-5 * np.minimum(t / 0.02, 1.0)
    d = decide(_write(tmp_path / "h.csv", t, u, ke), P)
    assert d.outcome == ARREST and "stopped growing" in d.reason


def test_slow_creep(tmp_path):
    # 0.9 mm in the whole step, steady: below the limit and ALLKE never decays. With the growth
    # rule (0.05 x 1 mm per 0.05 s = 1 mm/s) this creep counts as arrested; without it, undecided.
    import dataclasses
    t = np.linspace(0, 1.0, 201)
    u = 9e-4 * t
    ke = np.full_like(t, 1e-3)
    path = _write(tmp_path / "h.csv", t, u, ke)
    assert decide(path, P).outcome == ARREST
    assert decide(path, dataclasses.replace(P, growth=0.0)).outcome == UNDECIDED
    faster = _write(tmp_path / "h2.csv", t, 0.8e-3 * t + 0.15e-3 * t ** 2, ke)
    assert decide(faster, P).outcome == UNDECIDED


def test_missing_step_is_an_error(tmp_path):
    t = np.linspace(0, 0.1, 11)
    with pytest.raises(ValueError):
        decide(_write(tmp_path / "h.csv", t, t, t, step=2), P)


def test_read_stop_params(tmp_path):
    inp = tmp_path / "s.inp"
    inp.write_text("*HEADING\nx\n*STEP, NAME=A\n*DYNAMIC, EXPLICIT\n, 0.4\n*END STEP\n*STEP, NAME=OPEN\n"
                   "*DYNAMIC, EXPLICIT\n, 0.8\n*STOP CONDITION, NSET=allN, DISPLACEMENT=0.002, "
                   "KINETIC FRACTION=0.03, HOLD=0.06, MIN TIME=0.02, GROWTH=0.1\n*END STEP\n")
    p = read_stop_params(inp)
    assert (p.nset, p.displacement, p.ke_fraction, p.hold, p.min_time, p.growth, p.step, p.period) == \
        ("ALLN", 0.002, 0.03, 0.06, 0.02, 0.1, 2, 0.8)


def test_run_ended_by_distortion_is_undecided_not_arrest(tmp_path):
    # a creeping run that a folded element ends at 0.3 s of a 1 s step, displacement still growing:
    # the early end is the solver's error, not its ARREST rule, so the rows say UNDECIDED
    t = np.linspace(0, 0.3, 61)
    u = 4e-4 * t + 5e-3 * t ** 2
    ke = 1e-4 * (1 + 10 * t ** 2)
    path = _write(tmp_path / "h.csv", t, u, ke)
    assert decide(path, P).outcome == ARREST               # read as the solver's early stop
    d = decide(path, P, ended_by="element 60 tangled at total time 0.9297 s")
    assert d.outcome == UNDECIDED and "element 60 tangled" in d.reason


def test_distortion_end_reads_the_solver_error(tmp_path):
    from bulkflow.arching.runner import distortion_end
    t = np.linspace(0, 0.3, 61)
    path = _write(tmp_path / "h.csv", t, 1e-3 * t, np.full_like(t, 1e-4))
    err = ("bulkflow: error: a.inp: element 60 at total time  9.29744E-01: element tangled: a corner "
           "Jacobian <= 0 (bow-tie or folded element) (increment too large, ...)\n")
    assert distortion_end(err, path, 3) == "element 60 tangled at total time 0.9297 s"
    assert distortion_end(err, path, 2) == ""               # not in the opening step: an error
    assert distortion_end("bulkflow: error: a.inp:12: expected a number\n", path, 3) == ""
    with open(path, "a") as f:                              # a row cut short by the abort
        f.write("1.3,3,0.3")
    assert distortion_end(err, path, 3) == ""
