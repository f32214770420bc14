#!/usr/bin/env python3
"""Run bulkflow-matpoint (or a build with a user VUMAT) on an input and check the outcome.

    check_matpoint_run.py EXE INPUT CSV [--k0 NU] [--expect-error TEXT] [--same-csv-as INPUT2]
                          [--user FILE] [--last-row NAME=VALUE]...

--k0 NU            the run must succeed; in stage 1 every row must have sh/sv = NU/(1-NU)
                   (relative 1e-10) and, when there is a stage 2, the last row must be back
                   at zero stress (1e-9 of the largest vertical stress).
--expect-error T   the run must fail with exit status 2 and stderr must be the single line
                   "bulkflow: error: <INPUT>:T" (T starts with the line number), with no
                   backtrace and no NaN.
--user FILE        run with --user FILE (a user's VUMAT compiled and loaded at run time)
--last-row N=V     the run must succeed and column N of the last row must be V (relative 1e-12)
--same-csv-as I2   the run must succeed, and running EXE on I2 must write the same CSV, byte
                   for byte (the same material written two ways, e.g. *MOHR COULOMB keywords
                   and the equivalent *USER MATERIAL constants); the path must reach plastic
                   flow (PEEQ > 0 in the last row), so the material model was exercised.
Standard library only: CTest runs it with the interpreter CMake found.
"""

import argparse
import csv
import subprocess
import sys


def fail(message):
    print(f"check_matpoint_run: FAIL: {message}")
    sys.exit(1)


def check_k0(csv_path, nu):
    with open(csv_path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    if not rows:
        fail(f"{csv_path}: no rows")
    k0 = nu / (1.0 - nu)
    loading = [r for r in rows if r["stage"] == "1"]
    for r in loading:
        sv, sh = float(r["sv"]), float(r["sh"])
        if abs(sh / sv - k0) > 1e-10 * k0:
            fail(f"stage 1, time {r['time']}: sh/sv = {sh / sv!r}, expected K0 = {k0!r}")
    print(f"K0: {len(loading)} loading rows with sh/sv = {k0:.12g}")
    if any(r["stage"] == "2" for r in rows):
        peak = max(abs(float(r["sv"])) for r in rows)
        last = rows[-1]
        back = max(abs(float(last[key])) for key in last if key.startswith("s") and key[1:].isdigit())
        if back > 1e-9 * peak:
            fail(f"unloading ends at stress {back!r}, not zero (peak {peak!r})")
        print(f"unloading back to zero stress: {back:.3e} of peak {peak:.6g}")


def check_same_csv(exe, csv_path, other_input):
    other_csv = csv_path + ".other.csv"
    run = subprocess.run([exe, other_input, "-o", other_csv], capture_output=True, text=True)
    if run.returncode != 0:
        fail(f"{other_input}: exit status {run.returncode}: {run.stderr.strip()}")
    with open(csv_path, "rb") as a, open(other_csv, "rb") as b:
        first, second = a.read(), b.read()
    if first != second:
        fail(f"{csv_path} and {other_csv} differ")
    with open(csv_path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    if not float(rows[-1]["PEEQ"]) > 0.0:
        fail("no plastic flow in the last row (PEEQ = 0): the comparison does not exercise plasticity")
    print(f"same CSV, byte for byte, as {other_input}: {len(rows)} rows, final PEEQ {rows[-1]['PEEQ']}")


def check_last_row(csv_path, expectations):
    with open(csv_path, newline="") as handle:
        last = list(csv.DictReader(handle))[-1]
    for item in expectations:
        name, value = item.split("=", 1)
        if name not in last:
            fail(f"no column {name!r} in {csv_path}")
        got, want = float(last[name]), float(value)
        if abs(got - want) > 1e-12 * max(abs(want), 1.0):
            fail(f"last row: {name} = {got!r}, expected {want!r}")
        print(f"last row: {name} = {got!r} as expected")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("exe")
    parser.add_argument("input")
    parser.add_argument("csv")
    parser.add_argument("--k0", type=float)
    parser.add_argument("--expect-error")
    parser.add_argument("--same-csv-as")
    parser.add_argument("--user")
    parser.add_argument("--last-row", action="append", default=[])
    args = parser.parse_args()

    user = ["--user", args.user] if args.user else []
    run = subprocess.run([args.exe, args.input, "-o", args.csv] + user, capture_output=True, text=True)
    print(run.stdout, end="")
    print(run.stderr, end="", file=sys.stderr)
    if args.expect_error is not None:
        if run.returncode != 2:
            fail(f"exit status {run.returncode}, expected 2")
        expected = f"bulkflow: error: {args.input}:{args.expect_error}"
        lines = [line for line in run.stderr.splitlines() if line.strip()]
        if not lines or not lines[0].startswith(expected):
            fail(f"stderr does not start with {expected!r}")
        if "Backtrace" in run.stderr or "nan" in run.stderr.lower().split():
            fail("stderr has a backtrace or a NaN")
        print("error reported as expected")
        return
    if run.returncode != 0:
        fail(f"exit status {run.returncode}")
    if args.k0 is not None:
        check_k0(args.csv, args.k0)
    if args.same_csv_as is not None:
        check_same_csv(args.exe, args.csv, args.same_csv_as)
    if args.last_row:
        check_last_row(args.csv, args.last_row)


if __name__ == "__main__":
    main()
