#!/usr/bin/env python3
"""*MPM CONTROLS, PIC TIME=tau (docs/keywords.md, docs/mpm.md "PIC/FLIP blend"): the small
eccentric bin (inputs/mpm/bin_small_eccentric_2d.inp) run at CFL 0.3 and at CFL 0.1, once with
its fixed blend FLIP=0.99 and once with PIC TIME=tau, and checked:

- with the fixed blend the discharge depends on the increment: the discharged mass at CFL 0.1 is
  more than 20 % below CFL 0.3's (three times the increments, three times the PIC damping per
  second): the defect the option is for shows in this scene, else the next check could not fail;
- with PIC TIME the two increments discharge the same mass to within 3 %;
- every run keeps the particle and mass balance exact.

    check_pic_time.py <bin.inp> --bulkflow <exe> --workdir <dir> [--tau 0.004]
"""
import argparse
import re
from pathlib import Path

from bin_checks import Checks, balance, run_scene, with_controls


def main():
    p = argparse.ArgumentParser()
    p.add_argument("scene")
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", required=True, type=Path)
    p.add_argument("--tau", type=float, default=0.004, help="PIC TIME [s]")
    a = p.parse_args()
    check = Checks()
    text = Path(a.scene).read_text()
    out = {}
    for blend in ("FLIP=0.99", f"PIC TIME={a.tau:g}"):
        for cfl in (0.3, 0.1):
            def edit(line):
                line = re.sub(r",\s*FLIP=[^,]*", "", line)
                line = re.sub(r",\s*CFL=[^,]*", "", line)
                return line.replace("*MPM CONTROLS", f"*MPM CONTROLS, {blend}, CFL={cfl:g}", 1)
            name = f"{blend.split('=')[0].replace(' ', '_').lower()}_cfl{cfl:g}"
            scene = a.workdir / f"{name}.inp"
            scene.parent.mkdir(parents=True, exist_ok=True)
            scene.write_text(with_controls(text, a.scene, edit))
            stdout, hist = run_scene(a.bulkflow, scene, a.workdir / name)
            balance(check, name, stdout, hist)
            out[blend, cfl] = (float(hist["MASS_OUT"][-1]), int(hist["increment"][-1]))
    (f3, i3), (f1, i1) = out["FLIP=0.99", 0.3], out["FLIP=0.99", 0.1]
    check(f1 < 0.8 * f3, f"FLIP=0.99: CFL 0.1 ({i1} increments) discharges {f1:.4g} kg/m, more than 20 % below "
          f"CFL 0.3's {f3:.4g} ({i3} increments)")
    (p3, i3), (p1, i1) = out[f"PIC TIME={a.tau:g}", 0.3], out[f"PIC TIME={a.tau:g}", 0.1]
    check(abs(p1 - p3) <= 0.03 * p3, f"PIC TIME={a.tau:g}: CFL 0.1 ({i1} increments) discharges {p1:.4g} kg/m, "
          f"CFL 0.3 ({i3} increments) {p3:.4g}: within 3 %")
    check.finish()


if __name__ == "__main__":
    main()
