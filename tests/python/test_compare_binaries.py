"""scripts/compare_binaries.py: two runs that both fail without output prove nothing and must not
be reported as identical; two identical fake solvers must be."""
from __future__ import annotations

import importlib.util
import stat
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def _module():
    spec = importlib.util.spec_from_file_location("compare_binaries", REPO / "scripts" / "compare_binaries.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _fake_solver(path: Path, body: str) -> str:
    """A shell script taking the solver's arguments (DECK --output BASE ...)."""
    path.write_text("#!/bin/sh\nbase=$3\n" + body + "\n")
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return str(path)


def test_both_failing_is_not_compared(tmp_path, capsys):
    deck = tmp_path / "d.inp"
    deck.write_text("*HEADING\n")
    fail = _fake_solver(tmp_path / "fail.sh", "echo 'mpirun refused' >&2; exit 1")
    rc = _module().main([fail, fail, str(deck), "--workdir", str(tmp_path / "w")])
    out = capsys.readouterr().out
    assert rc == 1
    assert "NOT COMPARED" in out and "mpirun refused" in out
    assert "all identical" not in out


def test_identical_outputs_are_same(tmp_path, capsys):
    deck = tmp_path / "d.inp"
    deck.write_text("*HEADING\n")
    ok = _fake_solver(tmp_path / "ok.sh", "printf 't,ALLKE\\n0,1\\n' > ${base}_history.csv")
    rc = _module().main([ok, ok, str(deck), "--workdir", str(tmp_path / "w")])
    assert rc == 0
    assert "all identical" in capsys.readouterr().out


def test_different_histories_differ(tmp_path, capsys):
    deck = tmp_path / "d.inp"
    deck.write_text("*HEADING\n")
    a = _fake_solver(tmp_path / "a.sh", "printf 't,ALLKE\\n0,1\\n' > ${base}_history.csv")
    b = _fake_solver(tmp_path / "b.sh", "printf 't,ALLKE\\n0,2\\n' > ${base}_history.csv")
    rc = _module().main([a, b, str(deck), "--workdir", str(tmp_path / "w")])
    assert rc == 1
    assert "DIFFERS" in capsys.readouterr().out
