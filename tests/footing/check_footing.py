#!/usr/bin/env python3
"""Strip footing on weightless c-phi soil against Prandtl's N_c (docs/footing.md).

    check_footing.py bulkflow --bulkflow bin/bulkflow --work DIR
    check_footing.py ccx --ccx-prefix build-ccx --work DIR

bulkflow: phi = 30 deg, CPE4R, 8 elements across the footing half-width (912 elements), the
associated run (psi = phi) and the non-associated one (psi = 0). The associated q_u/c must lie
within 6 % of N_c = 30.14 (measured +3.5 % on this mesh; the error is the mesh's, positive and
falling under refinement: +4.7 % at b/4, +2.9 % at b/16, docs/footing.md); the non-associated
q_u must lie between Davis's reduced-strength estimate (20.08 c) and the associated q_u
(measured 25.2 c). Both runs must stay stable: energy balance within 1 % of the largest energy,
hourglass energy under 2 % of the internal energy, the load's spread over the plateau bounded
(SPREAD), every figure finite.

ccx: phi = psi = 30 deg, CPE8R with 4 elements across b (442 elements, CalculiX with our UMAT):
q_u/c within 5 % of N_c (measured +3.3 %), the push completed. Exit 77 (ctest SKIP) with a plain
message when CalculiX with our UMAT is not built.
"""
import argparse
import math
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import footing_study as fs  # noqa: E402

SKIP = 77
# Largest (max q - min q)/q_u over the last 30 % of the push: associated flow gives a flat plateau
# (measured 1.3 %, the tail of the collapse's overshoot); psi = 0 a load that wanders about its
# limit as shear bands re-form (measured 15.8 %, 8.8 % with a 3x slower push, docs/footing.md).
# A blow-up (hourglass mode, instability) grows without bound; these fluctuations do not.
SPREAD = {True: 0.04, False: 0.25}


def check(name, ok, text):
    print(f"  {'ok  ' if ok else 'FAIL'} {name}: {text}")
    return ok


def stable(r, spread_limit: float) -> bool:
    balance, hourglass, _ = r.energy
    figures = [r.q_u, balance, hourglass, r.spread] + r.curve.pressure + r.curve.settlement
    good = check("finite", all(math.isfinite(x) for x in figures), "every figure of the run")
    good &= check("energy balance", balance <= 0.01, f"max |ETOTAL| / max energy = {100 * balance:.3f} % (limit 1 %)")
    good &= check("hourglass", hourglass <= 0.02, f"ALLAE/ALLIE = {100 * hourglass:.2f} % (limit 2 %)")
    good &= check("steady load", r.spread <= spread_limit,
                  f"(max q - min q)/q_u over the last 30 % of the push = {100 * r.spread:.2f} % "
                  f"(limit {100 * spread_limit:g} %)")
    return good


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("solver", choices=["bulkflow", "ccx"])
    ap.add_argument("--bulkflow")
    ap.add_argument("--ccx-prefix")
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    work = Path(a.work).resolve()
    work.mkdir(parents=True, exist_ok=True)
    phi = 30.0
    nc = fs.prandtl_nc(phi)
    good = True
    if a.solver == "bulkflow":
        args = fs.parser().parse_args(["--nf", "8", "--bulkflow", a.bulkflow])
        mesh = fs.make_mesh(phi, args.nf, args.ratio)
        runs = {}
        for psi in (phi, 0.0):
            r = fs.run_bulkflow(mesh, phi, psi, args, work)
            print(f"bulkflow phi {phi:g} psi {psi:g} ({mesh.describe()}), {r.wall:.1f} s: "
                  f"q_u/c = {r.q_u / fs.COHESION:.3f}, N_c = {nc:.3f}; " + "; ".join(r.notes))
            if not r.ok:
                print("FAIL: the run did not finish")
                return 1
            runs[psi] = r
            good &= stable(r, SPREAD[psi == phi])
        err = runs[phi].q_u / fs.COHESION / nc - 1
        good &= check("associated q_u", abs(err) <= 0.06, f"(q_u/c - N_c)/N_c = {100 * err:+.2f} % (limit 6 %)")
        davis = fs.davis_nc(phi, 0.0)
        q0, q1 = runs[0.0].q_u / fs.COHESION, runs[phi].q_u / fs.COHESION
        good &= check("non-associated q_u", davis <= q0 < q1,
                      f"q_u/c = {q0:.3f}, expected between Davis's {davis:.3f} and the associated {q1:.3f}")
    else:
        ccx = os.path.join(a.ccx_prefix, "bin", "ccx_bulkflow")
        if not os.access(ccx, os.X_OK):
            print(f"SKIPPED: CalculiX with bulkflow's UMAT is not built ({ccx} missing); "
                  "run: bash scripts/build_ccx_umat.sh")
            return SKIP
        args = fs.parser().parse_args(["--nf", "4", "--ccx", ccx])
        mesh = fs.make_mesh(phi, args.nf, args.ratio)
        r = fs.run_ccx(mesh, phi, phi, args, work)
        print(f"ccx phi {phi:g} psi {phi:g} ({r.mesh}), {r.wall:.1f} s: q_u/c = {r.q_u / fs.COHESION:.3f}, "
              f"N_c = {nc:.3f}; " + "; ".join(r.notes))
        if not check("run", r.ok, "ccx completed the push"):
            return 1
        err = r.q_u / fs.COHESION / nc - 1
        good &= check("associated q_u", abs(err) <= 0.05, f"(q_u/c - N_c)/N_c = {100 * err:+.2f} % (limit 5 %)")
    print("PASS" if good else "FAIL")
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main())
