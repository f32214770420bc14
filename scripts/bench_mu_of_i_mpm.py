#!/usr/bin/env python3
"""MPM throughput with and without the mu(I) option (docs/mu_of_i.md); prints figures, not a test.

    python3 scripts/bench_mu_of_i_mpm.py [--bulkflow build/bin/bulkflow] [--rounds 3]
                                         [--stop-after 0] [--cell H --discharge S]

Runs the small hopper inputs/mpm/hopper_small_2d.inp (static MC) and
inputs/mpm/hopper_small_mu_of_i_2d.inp (the same with the mu(I) block) alternately, --rounds
times each, one process at a time, and prints for each run the solver's particle-steps per second
of its time loop and the user CPU seconds, then the medians and the ratio (mu(I) / static).
--stop-after N stops each run after N increments (0: the whole fill and discharge).
--cell H: instead of the small hopper, the ch. 4 hopper of bulkflow.mpm.hopper_scene at cell H
(1 s fill, --discharge S s with inflow), without and with the mu(I) block of
bulkflow.mpm.study_mu_of_i.
"""
import argparse
import re
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DECKS = {"static": ROOT / "inputs/mpm/hopper_small_2d.inp",
         "mu(I)": ROOT / "inputs/mpm/hopper_small_mu_of_i_2d.inp"}


def one_run(binary, deck, out, stop_after):
    cmd = [str(binary), str(deck), "--output", str(out), "--quiet"]
    if stop_after > 0:
        cmd += ["--stop-after", str(stop_after)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    r = subprocess.run(cmd, capture_output=True, text=True)
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before
    m = re.search(r"throughput (\d+) particle-steps,\s+([0-9.E+-]+) per second", r.stdout)
    if r.returncode != 0 or not m:
        sys.exit(f"{deck.name}: exit {r.returncode}\n{r.stdout}\n{r.stderr}")
    steps = int(m.group(1))
    return steps, float(m.group(2)), cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bulkflow", default=str(ROOT / "build/bin/bulkflow"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--stop-after", type=int, default=0)
    ap.add_argument("--cell", type=float, default=0.0)
    ap.add_argument("--discharge", type=float, default=1.5)
    a = ap.parse_args()
    rates = {k: [] for k in DECKS}
    cpu_rates = {k: [] for k in DECKS}
    with tempfile.TemporaryDirectory() as tmp:
        decks = DECKS
        if a.cell > 0:
            sys.path.insert(0, str(ROOT / "scripts"))
            from bulkflow.mpm.hopper_scene import hopper_scene, with_mu_of_i
            from bulkflow.mpm.study_mu_of_i import MU_OF_I_BLOCK
            text = hopper_scene(cell=a.cell, discharge_time=a.discharge, field_frames=2)
            decks = {"static": Path(tmp) / "hopper_mc.inp", "mu(I)": Path(tmp) / "hopper_mui.inp"}
            decks["static"].write_text(text)
            decks["mu(I)"].write_text(with_mu_of_i(text, MU_OF_I_BLOCK))
        for rnd in range(a.rounds):
            for name, deck in decks.items():
                steps, rate, cpu = one_run(a.bulkflow, deck, Path(tmp) / f"{rnd}_{deck.stem}", a.stop_after)
                rates[name].append(rate)
                cpu_rates[name].append(steps / cpu)
                print(f"round {rnd + 1} {name:6s}: {steps} particle-steps, {rate:.4e}/s (time loop), "
                      f"{steps / cpu:.4e}/s (user CPU {cpu:.2f} s)")
    med = {k: statistics.median(v) for k, v in rates.items()}
    medc = {k: statistics.median(v) for k, v in cpu_rates.items()}
    print(f"median particle-steps/s: static {med['static']:.4e}, mu(I) {med['mu(I)']:.4e}, "
          f"ratio mu(I)/static {med['mu(I)'] / med['static']:.3f} (time loop); "
          f"{medc['mu(I)'] / medc['static']:.3f} (user CPU)")


if __name__ == "__main__":
    main()
