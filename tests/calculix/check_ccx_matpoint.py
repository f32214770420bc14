#!/usr/bin/env python3
"""CalculiX with bulkflow's UMAT against bulkflow-matpoint on one element.

    check_ccx_matpoint.py CASE --prefix build-ccx --matpoint bulkflow-matpoint
                          --standard-file build/abaqus/bulkflow_abaqus_standard.f
                          --include-dir umat/abaqus --work DIR [--tolerance 1e-8]

CASE: oedometer (all strains prescribed) or triaxial (lateral stress held by a pressure, axial
displacement driven; CalculiX's Newton finds the lateral strains). One C3D8 unit cube in
CalculiX, the same material and path in bulkflow-matpoint (AXIS=2). CalculiX prints 7 digits,
so ccx is linked here with a tracing wrapper (umat_trace.f90) around our umat, renamed by
objcopy; the last call per increment and point is the converged stress. Passes when every
converged stress component equals matpoint's to TOLERANCE times the largest stress.
Prints CalculiX's residual sequence of every increment (the Newton rate), and with
--elastic-tangent-too the same run with the elastic DDSDDE ('-ELASTICTANGENT' in the name).
Exit 77 (ctest SKIP) with a plain message when CalculiX with our UMAT is not built.
"""
import argparse
import hashlib
import os
import re
import shutil
import subprocess
import sys

SKIP = 77
E, NU = 20.0e6, 0.3
# MC-SAND: φ 30°, ψ 10°, c 5 kPa, no cut-off, no flow function (umat/README.md layout).
PROPS = [E, NU, 30.0, 10.0, 5.0e3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]
P0 = 100.0e3          # triaxial confining pressure (Pa)
CASES = {
    # name: (axial strain, increments)
    "oedometer": (-0.02, 40),
    "triaxial": (-0.03, 30),
}


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def props_lines(props):
    lines = []
    for i in range(0, len(props), 8):
        lines.append(", ".join(repr(float(x)) for x in props[i:i + 8]))
    return "\n".join(lines)


def matpoint_input(case, strain, incs):
    text = ["*HEADING", f"{case} for the CalculiX comparison", "*MATERIAL, NAME=MC-SAND",
            "*DENSITY", "2000.", f"*USER MATERIAL, CONSTANTS={len(PROPS)}", props_lines(PROPS),
            "*DEPVAR", "8"]
    if case == "triaxial":
        text += ["*INITIAL CONDITIONS, TYPE=STRESS", f"{-P0!r}, {-P0!r}, {-P0!r}, 0., 0., 0.",
                 "*DRIVER CONTROLS, TOLERANCE=1e-14", "*TEST, TYPE=TRIAXIAL, AXIS=2",
                 f"*STAGE, STRAIN={strain!r}, INC={incs}"]
    else:
        text += ["*TEST, TYPE=OEDOMETER, AXIS=3", f"*STAGE, STRAIN={strain!r}, INC={incs}"]
    return "\n".join(text) + "\n"


def ccx_input(case, strain, incs, name):
    if case == "oedometer":
        # Two C3D8 stacked along z (the axis): the middle nodes' uz are the unknowns (with
        # every displacement prescribed ccx would have no equation to solve).
        layers = [0.0, 0.5, 1.0]
        text = ["*HEADING", f"{case}, two C3D8, bulkflow UMAT", "*NODE, NSET=NALL"]
        for l, z in enumerate(layers):
            for j, (x, y) in enumerate([(0, 0), (1, 0), (1, 1), (0, 1)]):
                text.append(f"{4 * l + j + 1}, {x}., {y}., {z!r}")
        text += ["*ELEMENT, TYPE=C3D8, ELSET=EALL", "1, 1, 2, 3, 4, 5, 6, 7, 8",
                 "2, 5, 6, 7, 8, 9, 10, 11, 12", "*NSET, NSET=Z0", "1, 2, 3, 4",
                 "*NSET, NSET=TOP", "9, 10, 11, 12"]
    else:
        nodes = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
        text = ["*HEADING", f"{case}, one C3D8, bulkflow UMAT", "*NODE, NSET=NALL"]
        text += [f"{i + 1}, {x}., {y}., {z}." for i, (x, y, z) in enumerate(nodes)]
        text += ["*ELEMENT, TYPE=C3D8, ELSET=EALL", "1, 1, 2, 3, 4, 5, 6, 7, 8",
                 "*NSET, NSET=X0", "1, 4, 5, 8", "*NSET, NSET=Y0", "1, 2, 5, 6",
                 "*NSET, NSET=Z0", "1, 2, 3, 4", "*NSET, NSET=TOP", "3, 4, 7, 8"]
    text += [f"*MATERIAL, NAME={name}", f"*USER MATERIAL, CONSTANTS={len(PROPS)}",
             # CalculiX reads the constants 8 a line and then the temperature.
             props_lines(PROPS + [0.0]), "*DEPVAR", "8",
             f"*SOLID SECTION, ELSET=EALL, MATERIAL={name}",
             "*AMPLITUDE, NAME=HOLD", "0., 1., 1., 1."]
    if case == "triaxial":
        text += ["*INITIAL CONDITIONS, TYPE=STRESS"]
        text += [f"1, {ip}, {-P0!r}, {-P0!r}, {-P0!r}, 0., 0., 0." for ip in range(1, 9)]
    text += ["*STEP, INC=1000", "*STATIC, DIRECT", f"{1.0 / incs!r}, 1.",
             "*CONTROLS, PARAMETERS=FIELD", "1.e-13, 1.e-13, 0., 0., 0.02, 1.e-5, 1.e-3, 1.e-8"]
    if case == "oedometer":
        text += ["*BOUNDARY", "NALL, 1, 2", "Z0, 3, 3", f"TOP, 3, 3, {strain!r}"]
    else:
        text += ["*BOUNDARY", "X0, 1, 1", "Y0, 2, 2", "Z0, 3, 3", f"TOP, 2, 2, {strain!r}"]
        # S4: x = 1 face, S2: z = 1 face (C3D8 face numbering), the confining pressure held.
        text += ["*DLOAD, AMPLITUDE=HOLD", f"1, P4, {P0!r}", f"1, P2, {P0!r}"]
    text += ["*EL PRINT, ELSET=EALL", "S", "*END STEP"]
    return "\n".join(text) + "\n"


def build_traced_ccx(args, work):
    """ccx linked with umat_trace.f90 around our umat; cached by the inputs' hash."""
    lib = os.path.join(args.prefix, "lib")
    here = os.path.dirname(os.path.abspath(__file__))
    wrapper = os.path.join(here, "umat_trace.f90")
    host = os.path.join(args.include_dir, "standard_host.f90")
    digest = hashlib.sha256()
    for path in (args.standard_file, wrapper, host, os.path.join(lib, "libccx_no_umat.a")):
        with open(path, "rb") as f:
            digest.update(f.read())
    exe = os.path.join(work, "ccx_traced")
    stamp = exe + ".sha256"
    if os.path.exists(exe) and os.path.exists(stamp) and open(stamp).read() == digest.hexdigest():
        return exe
    run = lambda cmd: subprocess.run(cmd, cwd=work, check=True)
    run(["gfortran", "-O2", "-ffree-form", "-ffree-line-length-none", "-I", args.include_dir, "-c",
         args.standard_file, "-o", "bulkflow_umat.o"])
    run(["objcopy", "--redefine-sym", "umat_=bulkflow_umat_traced_", "bulkflow_umat.o"])
    run(["gfortran", "-O2", "-c", wrapper, "-o", "umat_trace.o"])
    run(["gfortran", "-O2", "-c", host, "-o", "host.o"])
    libs = open(os.path.join(lib, "ccx_link_libraries.txt")).read().split()
    run(["gfortran", "-O2", "-o", exe, os.path.join(lib, "ccx_main.o"), "umat_trace.o",
         "bulkflow_umat.o", "host.o", os.path.join(lib, "libccx_no_umat.a")] + libs)
    with open(stamp, "w") as f:
        f.write(digest.hexdigest())
    return exe


def run_ccx(exe, work, job, deck):
    with open(os.path.join(work, job + ".inp"), "w") as f:
        f.write(deck)
    trace = os.path.join(work, "umat_trace.txt")
    if os.path.exists(trace):
        os.remove(trace)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_RESULTS="1", CCX_NPROC_STIFFNESS="1")
    out = subprocess.run([exe, job], cwd=work, env=env, capture_output=True, text=True)
    with open(os.path.join(work, job + ".log"), "w") as f:
        f.write(out.stdout + out.stderr)
    if out.returncode != 0 or "*ERROR" in out.stdout:
        fail(f"ccx {job} failed (log {os.path.join(work, job + '.log')}):\n" + out.stdout[-2000:])
    converged = {}
    for line in open(trace):
        parts = line.split()
        noel, npt, t = int(parts[0]), int(parts[1]), float(parts[2])
        converged[(round(t, 9), noel, npt)] = [float(x) for x in parts[3:9]]
    return converged, residual_sequences(out.stdout)


def residual_sequences(stdout):
    """Largest residual force of each iteration, per increment (ccx's own printout)."""
    sequences, current = [], None
    for line in stdout.splitlines():
        if re.match(r"\s*increment \d+ attempt", line):
            current = []
            sequences.append(current)
        m = re.match(r"\s*largest residual force=\s*(\S+)", line)
        if m and current is not None:
            current.append(float(m.group(1)))
    return sequences


def read_matpoint(csv):
    lines = open(csv).read().split("\n")
    head = lines[0].split(",")
    rows = [[float(x) for x in l.split(",")] for l in lines[1:] if l.strip()]
    col = {h.strip(): i for i, h in enumerate(head)}
    # Standard order 11, 22, 33, 12, 13, 23 from the VUMAT order 11, 22, 33, 12, 23, 31.
    keys = ["s11", "s22", "s33", "s12", "s31", "s23"]
    return {round(r[col["time"]], 9): [r[col[k]] for k in keys] for r in rows[1:]}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=sorted(CASES))
    ap.add_argument("--prefix", required=True)
    ap.add_argument("--matpoint", required=True)
    ap.add_argument("--standard-file", required=True)
    ap.add_argument("--include-dir", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--tolerance", type=float, default=1e-8)
    ap.add_argument("--elastic-tangent-too", action="store_true")
    args = ap.parse_args()
    args.prefix = os.path.abspath(args.prefix)
    args.standard_file = os.path.abspath(args.standard_file)
    args.include_dir = os.path.abspath(args.include_dir)
    args.matpoint = os.path.abspath(args.matpoint)
    needed = [os.path.join(args.prefix, "lib", f) for f in
              ("ccx_main.o", "libccx_no_umat.a", "ccx_link_libraries.txt")]
    missing = [p for p in needed if not os.path.exists(p)]
    if missing or shutil.which("objcopy") is None:
        print("SKIPPED: CalculiX with bulkflow's UMAT is not built (" + (missing[0] if missing else
              "objcopy missing") + "); run: bash scripts/build_ccx_umat.sh")
        sys.exit(SKIP)
    work = os.path.abspath(os.path.join(args.work, args.case))
    os.makedirs(work, exist_ok=True)
    exe = build_traced_ccx(args, work)

    strain, incs = CASES[args.case]
    inp = os.path.join(work, "matpoint.inp")
    with open(inp, "w") as f:
        f.write(matpoint_input(args.case, strain, incs))
    csv = os.path.join(work, "matpoint.csv")
    subprocess.run([args.matpoint, inp, "-o", csv], check=True, capture_output=True)
    reference = read_matpoint(csv)

    converged, residuals = run_ccx(exe, work, args.case, ccx_input(args.case, strain, incs,
                                                                   "ABAQUS_MC-SAND"))
    scale = max(abs(x) for s in reference.values() for x in s)
    worst, count = 0.0, 0
    for (t, _, _), s in converged.items():
        if t not in reference:
            fail(f"ccx converged at time {t}, which matpoint does not have")
        worst = max(worst, max(abs(a - b) for a, b in zip(s, reference[t])) / scale)
        count += 1
    if count < 8 * incs:
        fail(f"only {count} converged point states from ccx, expected {8 * incs}")
    print(f"{args.case}: {incs} increments x {count // incs} points, max |sigma_ccx - sigma_matpoint| / max|sigma|"
          f" = {worst:.2e} (tolerance {args.tolerance:.0e})")
    print("consistent tangent: largest residual force per iteration, increments with > 1 iteration:")
    for i, seq in enumerate(residuals, 1):
        if len(seq) > 1 and max(seq) > 0:
            print(f"  increment {i}: " + ", ".join(f"{r:.3e}" for r in seq))
    if args.elastic_tangent_too:
        _, res_el = run_ccx(exe, work, args.case + "_elastic_tangent",
                            ccx_input(args.case, strain, incs, "ABAQUS_MC-SAND-ELASTICTANGENT"))
        print("elastic tangent: largest residual force per iteration:")
        for i, seq in enumerate(res_el, 1):
            if len(seq) > 1 and max(seq) > 0:
                print(f"  increment {i}: " + ", ".join(f"{r:.3e}" for r in seq))
        print("iterations in total: consistent", sum(map(len, residuals)), "elastic",
              sum(map(len, res_el)))
    if not worst <= args.tolerance:
        fail(f"{args.case}: ccx and matpoint differ by {worst:.2e} > {args.tolerance:.0e}")
    print("PASS")


if __name__ == "__main__":
    main()
