"""Plots of a bulkflow-matpoint CSV (one row per increment, see inputs/matpoint/README.md).

The kind of test is recognised from the columns the driver writes:

* ``gamma``/``tau``  simple shear: tau-gamma and e22-gamma (dilation) panels;
* ``sv``/``sh``      oedometer: sigma_v-sigma_h (with the elastic K0 line when nu is given);
* ``ea``             triaxial or biaxial: q-(axial strain) and ev-(axial strain) panels;
* otherwise          general path: q-p and ev-time panels.

Axial strain is shown compression positive (-ea) and stresses in the CSV's units.
Usage: ``bulkflow-matpoint-plot run.csv [-o run.png] [--title TEXT] [--nu 0.3]``.
The Agg backend is used, so no display is needed.
"""

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)
import numpy as np  # noqa: E402


def read_matpoint_csv(path):
    """Columns of a bulkflow-matpoint CSV as a dict of 1-D float arrays, in file order."""
    path = Path(path)
    with path.open() as handle:
        header = handle.readline().strip()
    if not header:
        raise ValueError(f"{path}: empty file")
    names = [name.strip() for name in header.split(",")]
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: {len(names)} column names but {data.shape[1]} values per row")
    return {name: data[:, i] for i, name in enumerate(names)}


def test_kind(columns):
    """'simple shear', 'oedometer', 'axial' (triaxial/biaxial) or 'general'."""
    if "gamma" in columns and "tau" in columns:
        return "simple shear"
    if "sv" in columns and "sh" in columns:
        return "oedometer"
    if "ea" in columns:
        return "axial"
    return "general"


def plot_matpoint(columns, title=None, nu=None):
    """A matplotlib Figure with the panels that suit the test."""
    kind = test_kind(columns)
    if kind == "oedometer":
        fig, axes = plt.subplots(1, 1, figsize=(5.5, 4.5))
        axes = [axes]
    else:
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))

    if kind == "simple shear":
        axes[0].plot(columns["gamma"], columns["tau"], "-")
        axes[0].set_xlabel(r"shear strain $\gamma$")
        axes[0].set_ylabel(r"shear stress $\tau$")
        axes[1].plot(columns["gamma"], columns["e22"], "-")
        axes[1].set_xlabel(r"shear strain $\gamma$")
        axes[1].set_ylabel(r"normal strain $\varepsilon_{yy}$ (dilation +)")
    elif kind == "oedometer":
        axes[0].plot(columns["sh"], columns["sv"], "o-", markersize=2, label="driver")
        if nu is not None:
            k0 = nu / (1.0 - nu)
            sv = np.array([0.0, float(np.max(columns["sv"]))])
            axes[0].plot(k0 * sv, sv, "k--", label=rf"$K_0 = \nu/(1-\nu) = {k0:.4f}$")
            axes[0].legend()
        axes[0].set_xlabel(r"horizontal stress $\sigma_h$ (compression +)")
        axes[0].set_ylabel(r"vertical stress $\sigma_v$ (compression +)")
    elif kind == "axial":
        axial = -columns["ea"]
        axes[0].plot(axial, columns["q"], "-")
        axes[0].set_xlabel(r"axial strain $-\varepsilon_a$ (compression +)")
        axes[0].set_ylabel(r"deviator stress $q$")
        axes[1].plot(axial, columns["ev"], "-")
        axes[1].set_xlabel(r"axial strain $-\varepsilon_a$ (compression +)")
        axes[1].set_ylabel(r"volumetric strain $\varepsilon_v$ (dilation +)")
    else:
        axes[0].plot(columns["p"], columns["q"], "-")
        axes[0].set_xlabel(r"mean stress $p$ (compression +)")
        axes[0].set_ylabel(r"deviator stress $q$")
        axes[1].plot(columns["time"], columns["ev"], "-")
        axes[1].set_xlabel("time")
        axes[1].set_ylabel(r"volumetric strain $\varepsilon_v$ (dilation +)")

    for ax in axes:
        ax.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_file(csv_path, png_path=None, title=None, nu=None):
    """Read ``csv_path``, write the PNG (default: same name, .png) and return its path."""
    csv_path = Path(csv_path)
    png_path = Path(png_path) if png_path else csv_path.with_suffix(".png")
    fig = plot_matpoint(read_matpoint_csv(csv_path), title=title or csv_path.stem, nu=nu)
    fig.savefig(png_path, dpi=120)
    plt.close(fig)
    return png_path


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="bulkflow-matpoint-plot",
        description="Plot a bulkflow-matpoint CSV (test kind recognised from its columns).")
    parser.add_argument("csv", nargs="+", help="CSV file(s) written by bulkflow-matpoint")
    parser.add_argument("-o", "--output", help="PNG file (only with a single CSV)")
    parser.add_argument("--title", help="figure title (default: the CSV's name)")
    parser.add_argument("--nu", type=float, help="Poisson's ratio: draw the K0 line (oedometer)")
    args = parser.parse_args(argv)
    if args.output and len(args.csv) > 1:
        parser.error("-o/--output needs exactly one CSV")
    for csv_path in args.csv:
        try:
            png = plot_file(csv_path, args.output, args.title, args.nu)
        except (OSError, ValueError) as exc:
            print(f"bulkflow-matpoint-plot: error: {exc}", file=sys.stderr)
            return 2
        print(png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
