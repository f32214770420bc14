#!/usr/bin/env python3
"""Reader benchmark (issue 16, point 5): time and peak memory of `bulkflow --check` on large
and long-lined decks. A benchmark script that prints figures, not a test.

  .venv/bin/python scripts/bench_reader.py [--build build] [--baseline PATH] [--cells 1000]
                                           [--fields 100000] [--params 10000] [--only big,line,keyword]

Cases (decks written to a temporary directory under /tmp, removed at the end):
  big      an n x n CPE4R plane-strain block (--cells 1000: 1 002 001 nodes, 1 000 000 elements,
           one *NODE and one *ELEMENT line per node/element, a material, a section, a step):
           read and checked completely (exit 0). Target: < 10 s and < 600 MB on one core.
  line     the 2 x 1 control scene with an *NSET whose one data line has --fields node numbers
           (the 6 nodes repeated): read and checked (exit 0).
  keyword  a *HEADING line with --params parameters P1, P2, ...: read, then refused at its
           first parameter (exit 2, "unknown parameter P1") - the time is the reader's.
Each case runs in its own process; wall time from the parent, CPU time (user + system) and max
RSS from wait4's rusage. On a shared machine the wall time includes waiting for a core: the CPU
time is the reader's cost (with one core to itself the two agree).
With --baseline another bulkflow binary (e.g. the main branch's) runs the same decks, in
turn with this build's, and the ratios are printed.
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)

MODEL_TAIL = """*SOLID SECTION, ELSET=SOLID, MATERIAL=SAND
1.0
*MATERIAL, NAME=SAND
*DENSITY
1500.
*ELASTIC
1.0e7, 0.3
*STEP, NAME=SETTLE
*DYNAMIC, EXPLICIT
, 0.01
*BOUNDARY
BOTTOM, 1, 2
*DLOAD
SOLID, GRAV, 9.81, 0., -1.
*OUTPUT, HISTORY
*ENERGY OUTPUT
*END STEP
"""


def write_big(path, n):
    """n x n CPE4R elements of side 0.01, nodes numbered row by row from 1."""
    m = n + 1
    h = 0.01
    with open(path, "w") as f:
        f.write("*HEADING\nreader benchmark: %d x %d CPE4R elements\n*NODE\n" % (n, n))
        lines = []
        for j in range(m):
            y = j * h
            for i in range(m):
                lines.append("%d, %.6f, %.6f\n" % (1 + i + j * m, i * h, y))
            if len(lines) > 100000:
                f.writelines(lines)
                lines = []
        f.writelines(lines)
        f.write("*ELEMENT, TYPE=CPE4R, ELSET=SOLID\n")
        lines = []
        e = 0
        for j in range(n):
            for i in range(n):
                e += 1
                a = 1 + i + j * m
                lines.append("%d, %d, %d, %d, %d\n" % (e, a, a + 1, a + 1 + m, a + m))
            if len(lines) > 100000:
                f.writelines(lines)
                lines = []
        f.writelines(lines)
        f.write("*NSET, NSET=BOTTOM, GENERATE\n1, %d, 1\n" % m)
        f.write(MODEL_TAIL)


SMALL_MESH = """*NODE
1, 0., 0.
2, 1., 0.
3, 2., 0.
4, 0., 1.
5, 1., 1.
6, 2., 1.
*ELEMENT, TYPE=CPE4R, ELSET=SOLID
1, 1, 2, 5, 4
2, 2, 3, 6, 5
*NSET, NSET=BOTTOM
1, 2, 3
"""


def write_long_line(path, fields):
    with open(path, "w") as f:
        f.write("*HEADING\nreader benchmark: one data line of %d fields\n" % fields)
        f.write(SMALL_MESH)
        f.write("*NSET, NSET=MANY\n")
        f.write(", ".join(str(1 + k % 6) for k in range(fields)) + "\n")
        f.write(MODEL_TAIL)


def write_long_keyword(path, params):
    with open(path, "w") as f:
        f.write("*HEADING, " + ", ".join("P%d" % k for k in range(1, params + 1)) + "\n")
        f.write("reader benchmark: a keyword line of %d parameters\n" % params)
        f.write(SMALL_MESH)
        f.write(MODEL_TAIL)


def run(binary, deck):
    """(wall s, CPU s, max RSS in MB, exit status, last line of output) of `binary --check deck`."""
    t0 = time.perf_counter()
    p = subprocess.Popen([binary, "--check", deck], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         cwd=os.path.dirname(deck))
    out = p.stdout.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    text = out.decode(errors="replace").strip().splitlines()
    cpu = usage.ru_utime + usage.ru_stime
    return wall, cpu, usage.ru_maxrss / 1024.0, p.returncode, (text[-1] if text else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--baseline", help="another bulkflow binary to compare with")
    ap.add_argument("--cells", type=int, default=1000)
    ap.add_argument("--fields", type=int, default=100000)
    ap.add_argument("--params", type=int, default=10000)
    ap.add_argument("--only", default="big,line,keyword")
    args = ap.parse_args()
    binary = os.path.join(args.build, "bin", "bulkflow")
    if not os.access(binary, os.X_OK):
        sys.exit("bench_reader: no %s; build first (scripts/build.sh release)" % binary)
    cases = [c.strip() for c in args.only.split(",") if c.strip()]
    with tempfile.TemporaryDirectory(prefix="bench_reader_", dir="/tmp") as tmp:
        decks = []
        if "big" in cases:
            path = os.path.join(tmp, "big_cpe4r.inp")
            write_big(path, args.cells)
            decks.append(("big", "%d nodes, %d CPE4R elements, %.0f MB" % (
                (args.cells + 1) ** 2, args.cells ** 2, os.path.getsize(path) / 1e6), path))
        if "line" in cases:
            path = os.path.join(tmp, "long_line.inp")
            write_long_line(path, args.fields)
            decks.append(("line", "one data line of %d fields" % args.fields, path))
        if "keyword" in cases:
            path = os.path.join(tmp, "long_keyword.inp")
            write_long_keyword(path, args.params)
            decks.append(("keyword", "one keyword line of %d parameters" % args.params, path))
        print("bench_reader: %s --check (one process per case, 1 core)" % binary)
        print("  %-8s %-44s %9s %9s %11s" % ("case", "deck", "wall", "CPU", "max RSS"))
        row = "  %-8s %-44s"
        figures = "%7.2f s %7.2f s %8.1f MB  exit %d"
        for name, what, path in decks:
            ours = run(binary, path)
            print(row % (name, what) + figures % ours[:4] + " | " + ours[4][:80])
            if args.baseline:
                base = run(args.baseline, path)
                print(row % ("", "baseline") + figures % base[:4] + " | " + base[4][:80])
                print(row % ("", "ratio baseline / this build") + "%7.1fx %7.1fx %8.1fx" % (
                    base[0] / max(ours[0], 1e-9), base[1] / max(ours[1], 1e-9), base[2] / max(ours[2], 1e-9)))


if __name__ == "__main__":
    main()
