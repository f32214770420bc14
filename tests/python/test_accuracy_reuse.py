"""bulkflow-accuracy --reuse (runs.run_deck_reusing) with a stand-in solver that counts its calls:
a finished member is not run again and keeps the times measured then; a changed deck, rank count
or solver binary runs again; a run that failed leaves nothing to reuse; arching-cow refuses it."""
import json
import os
import stat
import sys

import pytest

from bulkflow.accuracy import cli
from bulkflow.accuracy.runs import deck_key, run_deck_reusing

FAKE_SOLVER = """#!{python}
# a stand-in for bulkflow: counts its calls, writes BASE_history.csv, fails on a deck with FAIL
import sys
from pathlib import Path
deck, base = Path(sys.argv[1]), sys.argv[sys.argv.index("--output") + 1]
with open(Path(deck).parent / "calls.txt", "a") as f:
    f.write(deck.name + "\\n")
if "FAIL" in deck.read_text():
    print("error: told to fail")
    sys.exit(2)
Path(base + "_history.csv").write_text("time,value\\n0,1\\n")
print("bulkflow: done, 7 increments")
"""


@pytest.fixture
def solver(tmp_path):
    exe = tmp_path / "fake_bulkflow"
    exe.write_text(FAKE_SOLVER.format(python=sys.executable))
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    return exe


def calls(workdir):
    f = workdir / "calls.txt"
    return f.read_text().split() if f.exists() else []


def test_a_finished_member_is_not_run_again(tmp_path, solver):
    runs = tmp_path / "runs"
    t1, reused1 = run_deck_reusing("*HEADING\nmember A\n", runs, "fam", solver=str(solver))
    assert not reused1 and len(calls(runs)) == 1 and t1.increments == 7
    t2, reused2 = run_deck_reusing("*HEADING\nmember A\n", runs, "fam", solver=str(solver))
    assert reused2 and len(calls(runs)) == 1
    # the times measured by the run itself, not the (near zero) time of the reuse
    assert (t2.wall, t2.cpu, t2.increments, t2.base) == (t1.wall, t1.cpu, t1.increments, t1.base)
    done = json.loads((runs / f"{t1.base.name}.done.json").read_text())
    assert done["key"] == deck_key("*HEADING\nmember A\n", 1, str(solver))


def test_deck_ranks_and_binary_are_part_of_the_key(tmp_path, solver):
    runs = tmp_path / "runs"
    run_deck_reusing("deck 1\n", runs, "fam", solver=str(solver))
    run_deck_reusing("deck 2\n", runs, "fam", solver=str(solver))
    assert len(calls(runs)) == 2
    key_1 = deck_key("deck 1\n", 1, str(solver))
    assert deck_key("deck 1\n", 2, str(solver)) != key_1
    # the same path with other bytes (a rebuilt solver) is another binary
    solver.write_text(solver.read_text() + "# rebuilt\n")
    os.utime(solver, ns=(solver.stat().st_atime_ns, solver.stat().st_mtime_ns + 10**9))
    assert deck_key("deck 1\n", 1, str(solver)) != key_1
    _, reused = run_deck_reusing("deck 1\n", runs, "fam", solver=str(solver))
    assert not reused and len(calls(runs)) == 3


def test_a_failed_run_leaves_nothing_to_reuse(tmp_path, solver):
    runs = tmp_path / "runs"
    for attempt in (1, 2):
        with pytest.raises(RuntimeError, match="told to fail"):
            run_deck_reusing("FAIL\n", runs, "fam", solver=str(solver))
        assert len(calls(runs)) == attempt
    assert not list(runs.glob("*.done.json"))


def test_cli_refuses_reuse_for_searches(capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["arching-cow", "--reuse", "--quick"])
    assert exc.value.code == 2
    assert "--reuse" in capsys.readouterr().err
