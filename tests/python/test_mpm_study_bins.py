"""bulkflow-mpm-study bins: the runs it asks for (no solver; run_bin is replaced by a recorder).
--open-edge opens the floor and the outlet plate at the outlet's edge in every case (OPEN= in the
scene text), and without it no wall is open."""
import argparse

import pytest

from bulkflow.mpm import bin_run, study_bins
from bulkflow.mpm.bin_scene import bin_scene


def parse(argv):
    p = argparse.ArgumentParser()
    study_bins.add_arguments(p)
    p.add_argument("--runs", default="runs")
    p.add_argument("--bulkflow", default="bulkflow")
    p.add_argument("--no-reuse", action="store_true")
    return p.parse_args(argv)


@pytest.mark.parametrize("open_edge", [False, True])
def test_open_edge_reaches_every_case(monkeypatch, open_edge):
    asked = []

    def record(exe, runs, reuse=True, **scene):
        asked.append(scene)
        return dict(base="unused", geometry=dict(half=scene["case"] == "concentric"), particles=1, wall=1.0)

    monkeypatch.setattr(bin_run, "run_bin", record)
    monkeypatch.setattr(bin_run, "discharge_figures", lambda *a, **k: {})
    monkeypatch.setattr(study_bins.np, "genfromtxt", lambda *a, **k: None)
    argv = ["--edge-cells", "1", "--discharge", "0.5"] + (["--open-edge"] if open_edge else [])
    rows = study_bins._runs(parse(argv))
    assert [(s["case"], s["sand"]) for s in asked] == list(study_bins.CASES)
    assert len(rows) == 4
    for scene in asked:
        text = bin_scene(**scene)
        opened = [line for line in text.splitlines() if line.startswith("*MPM WALL") and "OPEN=" in line]
        if open_edge:
            assert scene["open_edge"] is True
            assert len(opened) == 2, text
        else:
            assert "open_edge" not in scene
            assert opened == []
