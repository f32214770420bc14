"""pytest for scripts/bulkflow/post/matpoint_plot.py on small CSV files made here."""

import numpy as np
import pytest

from bulkflow.post import matpoint_plot


def write_csv(path, columns):
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    np.savetxt(path, data, delimiter=",", header=",".join(names), comments="")


def triaxial_columns(n=21):
    ea = np.linspace(0.0, -0.05, n)
    q = np.minimum(-ea * 4.0e6, 2.0e5)
    return {"time": np.linspace(0, 1, n), "stage": np.ones(n), "e11": -0.3 * ea, "e22": ea,
            "e33": -0.3 * ea, "e12": 0 * ea, "s11": -1e5 + 0 * ea, "s22": -1e5 - q,
            "s33": -1e5 + 0 * ea, "s12": 0 * ea, "p": 1e5 + q / 3, "q": q, "ev": 0.4 * ea,
            "ea": ea, "PEEQ": 0 * ea, "ener_intern": 0 * ea, "ener_inelas": 0 * ea}


@pytest.mark.parametrize("kind", ["axial", "simple shear", "oedometer", "general"])
def test_each_kind_makes_a_png(tmp_path, kind):
    cols = triaxial_columns()
    if kind == "simple shear":
        del cols["ea"]
        cols["gamma"] = np.linspace(0, 1, 21)
        cols["tau"] = np.tanh(cols["gamma"] * 10) * 5e4
    elif kind == "oedometer":
        cols["sv"] = np.linspace(0, 1e5, 21)
        cols["sh"] = cols["sv"] * 0.3 / 0.7
    elif kind == "general":
        del cols["ea"]
    csv_path = tmp_path / "run.csv"
    write_csv(csv_path, cols)
    assert matpoint_plot.test_kind(matpoint_plot.read_matpoint_csv(csv_path)) == kind
    png = matpoint_plot.plot_file(csv_path, nu=0.3)
    assert png == tmp_path / "run.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_reads_columns_by_name(tmp_path):
    csv_path = tmp_path / "t.csv"
    write_csv(csv_path, triaxial_columns(5))
    cols = matpoint_plot.read_matpoint_csv(csv_path)
    assert list(cols)[:3] == ["time", "stage", "e11"]
    assert cols["q"].shape == (5,)
    assert cols["ea"][-1] == pytest.approx(-0.05)


def test_main_with_output_name_and_errors(tmp_path, capsys):
    csv_path = tmp_path / "a.csv"
    write_csv(csv_path, triaxial_columns())
    out = tmp_path / "figure.png"
    assert matpoint_plot.main([str(csv_path), "-o", str(out), "--title", "triaxial"]) == 0
    assert out.exists()
    bad = tmp_path / "bad.csv"
    bad.write_text("time,q\n1,2,3\n")
    assert matpoint_plot.main([str(bad)]) == 2
    assert "bulkflow-matpoint-plot: error:" in capsys.readouterr().err
