#!/usr/bin/env python3
"""Simple shear through bulkflow-matpoint with the mu(I) option at several shear rates.

    check_mu_of_i_shear.py EXE DECK WORKDIR [--inertial I ...] [--tolerance 1e-10]

DECK is a SIMPLE SHEAR deck of our MC VUMAT with the mu(I) block (inputs/matpoint/
simple_shear_mu_of_i.inp: isotropic start, psi = 0). For each inertial number I the deck's
*STAGE TIME is set so that the engineering shear rate is gammadot = I sqrt(p0/rho_s)/d, the
driver runs it, and in the last CSV row tau/p must equal the closed form
mu(I) = mus + (mu2 - mus)/(I0/I + 1), mu = sin(phi) (docs/mu_of_i.md), with I recomputed from
that row's p, within the tolerance; the ratios must rise with I. All constants are read from
the deck. Standard library only.
"""

import argparse
import csv
import math
import re
import subprocess
import sys
from pathlib import Path


def fail(message):
    print(f"check_mu_of_i_shear: FAIL: {message}")
    sys.exit(1)


def deck_constants(text):
    """The *USER MATERIAL constants, the initial p0 and the stage's strain."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.upper().startswith("*USER MATERIAL"))
    n = int(re.search(r"CONSTANTS\s*=\s*(\d+)", lines[start], re.I).group(1))
    values = []
    for line in lines[start + 1:]:
        if line.startswith("*"):
            break
        values += [float(v) for v in line.split(",") if v.strip()]
    if len(values) != n:
        fail(f"deck has {len(values)} constants, CONSTANTS={n}")
    init = next(i for i, line in enumerate(lines) if line.upper().startswith("*INITIAL CONDITIONS"))
    sig = [float(v) for v in lines[init + 1].split(",") if v.strip()]
    stage = next(line for line in lines if line.upper().startswith("*STAGE"))
    gamma = float(re.search(r"STRAIN\s*=\s*([-+0-9.eE]+)", stage, re.I).group(1))
    return values, -sum(sig[:3]) / 3.0, gamma


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("exe")
    parser.add_argument("deck")
    parser.add_argument("workdir")
    parser.add_argument("--inertial", type=float, nargs="+", default=[1.0e-3, 0.05, 1.0])
    parser.add_argument("--tolerance", type=float, default=1.0e-10)
    args = parser.parse_args()

    text = Path(args.deck).read_text()
    props, p0, gamma = deck_constants(text)
    if len(props) < 21 or props[-5] != 1:
        fail("the deck has no mu(I) block (kind 1) after the tables")
    phi_s, (phi2, i0, d, rho_s) = props[2], props[-4:]
    mu_s, mu_2 = math.sin(math.radians(phi_s)), math.sin(math.radians(phi2))
    work = Path(args.workdir)
    work.mkdir(parents=True, exist_ok=True)
    ratios = []
    for inertial in args.inertial:
        rate = inertial * math.sqrt(p0 / rho_s) / d
        time = gamma / rate
        deck = work / f"mu_of_i_shear_I{inertial:g}.inp"
        deck.write_text(re.sub(r"TIME\s*=\s*[-+0-9.eE]+", f"TIME={time!r}", text))
        out = deck.with_suffix(".csv")
        run = subprocess.run([args.exe, str(deck), "-o", str(out)], capture_output=True, text=True)
        if run.returncode != 0:
            fail(f"I = {inertial:g}: exit {run.returncode}: {run.stderr.strip()}")
        with open(out, newline="") as handle:
            last = list(csv.DictReader(handle))[-1]
        tau, p = float(last["tau"]), float(last["p"])
        if not (math.isfinite(tau) and math.isfinite(p) and p > 0):
            fail(f"I = {inertial:g}: tau = {tau}, p = {p}")
        i_row = rate * d / math.sqrt(p / rho_s)
        expected = mu_s + (mu_2 - mu_s) / (i0 / i_row + 1.0)
        ratio = abs(tau) / p
        print(f"I = {i_row:.6g}: gammadot = {rate:.6g} 1/s, tau/p = {ratio:.12f}, "
              f"mu(I) = {expected:.12f}, PHI = {float(last['PHI']):.6f} deg")
        if abs(ratio - expected) > args.tolerance:
            fail(f"I = {inertial:g}: tau/p = {ratio!r} differs from mu(I) = {expected!r} "
                 f"by {abs(ratio - expected):.3g} > {args.tolerance:g}")
        ratios.append(ratio)
    if any(b <= a for a, b in zip(ratios, ratios[1:])):
        fail(f"tau/p does not rise with I: {ratios}")
    print("check_mu_of_i_shear: OK")


if __name__ == "__main__":
    main()
