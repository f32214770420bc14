#!/usr/bin/env python3
"""Run `bulkflow-accuracy KIND --quick` against a given solver and check what it wrote.

    check_accuracy.py wave-bar --bulkflow build/bin/bulkflow --workdir /tmp/acc

Checks: KIND.csv, KIND.png and KIND.json exist; the JSON's members are the CSV's rows; the error
falls strictly with every refinement; the observed order of the three finest is within
[1.7, 2.6] (both kinds are second order: docs/accuracy.md says why); and every recommendation
is a member within its target with no member of less work also within it. Exit status 1 with the
failed checks listed.

bin-tss (a Richardson family of an MPM bin, no exact solution and no expected order) is checked
for what the command promises instead: every member has either a T_ss (a positive multiple of the
0.5 s window, with an MDR) or no value, no error and no MDR with the reason in `tss_status`; the
summary extrapolates only when the three finest have a value, and recommends nothing without a
reference.
"""
import argparse
import csv
import json
import shutil
import subprocess
import sys
from pathlib import Path

ORDER_RANGE = (1.7, 2.6)


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("kind")
    p.add_argument("--bulkflow", required=True)
    p.add_argument("--workdir", required=True, type=Path)
    a = p.parse_args()
    out = a.workdir
    cmd = [sys.executable, "-m", "bulkflow.accuracy.cli", a.kind, "--quick", "--out", str(out),
           "--solver", a.bulkflow]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    print(proc.stdout + proc.stderr)
    if proc.returncode != 0:
        print(f"FAIL: {' '.join(cmd)} exited with {proc.returncode}")
        return 1
    failures = []

    def check(ok, what):
        print(("ok    " if ok else "FAIL  ") + what)
        if not ok:
            failures.append(what)

    files = [out / f"{a.kind}.{ext}" for ext in ("csv", "png", "json")]
    for f in files:
        check(f.exists() and f.stat().st_size > 0, f"{f} written")
    if failures:
        return 1
    summary = json.loads(files[2].read_text())
    rows = list(csv.DictReader(files[0].open()))
    members = summary["members"]
    check(len(rows) == len(members) >= (3 if a.kind == "bin-tss" else 4), f"{len(rows)} CSV rows = {len(members)} JSON members (at least 4)")
    members = sorted(members, key=lambda m: -m["h"])          # coarse to fine
    if a.kind == "bin-tss":
        check_bin_tss(summary, members, check)
        print(f"{len(failures)} check(s) failed" if failures else "all checks passed")
        return 1 if failures else 0
    errors = [m["error"] for m in members]
    check(all(e2 < e1 for e1, e2 in zip(errors, errors[1:])),
          "error falls with every refinement: " + ", ".join(f"h {m['h']:.4g}: {100 * m['error']:.3g} %" for m in members))
    p_obs = summary["observed_order"]
    check(p_obs is not None and ORDER_RANGE[0] <= p_obs <= ORDER_RANGE[1],
          f"observed order {p_obs} within {ORDER_RANGE}")
    for rec in summary["recommendations"]:
        target = rec["target"]
        within = [m for m in members if m["error"] <= target]
        if not within:
            check(rec["label"] is None, f"±{100 * target:g} %: no member within it, none recommended")
            continue
        best = min(within, key=lambda m: m["work"])
        check(rec["label"] == best["label"], f"±{100 * target:g} %: recommended '{rec['label']}' is the "
                                             f"least-work member within it ('{best['label']}')")
        check(rec["line"].startswith(f"for ±{100 * target:g} %"), f"recommendation line: {rec['line']}")
    for m in members:
        check(m["wall"] > 0 and m["cpu"] > 0 and m["increments"] > 0,
              f"{m['label']}: measured wall {m['wall']:.3g} s, CPU {m['cpu']:.3g} s, {m['increments']} increments")
    if a.kind == "wave-bar":
        check_reuse(cmd, out / "reuse", members, check)
    print(f"{len(failures)} check(s) failed" if failures else "all checks passed")
    return 1 if failures else 0


def check_reuse(cmd, out, members, check) -> None:
    """--reuse twice into a fresh folder: the first runs every member, the second none (each line
    says it was reused, no new solver log) and writes the same values and measured times."""
    cmd = [c if c != str(cmd[cmd.index("--out") + 1]) else str(out) for c in cmd] + ["--reuse"]
    shutil.rmtree(out, ignore_errors=True)     # a fresh folder: runs of an earlier ctest would be reused
    found = []
    for attempt in (1, 2):
        proc = subprocess.run(cmd, capture_output=True, text=True)
        print(proc.stdout + proc.stderr)
        if proc.returncode != 0:
            check(False, f"--reuse run {attempt} exited with {proc.returncode}")
            return
        logs = sorted(p.stat().st_mtime_ns for p in (out / "runs").glob("*.log"))
        found.append((proc.stdout.count("reused: measured by an earlier run"), logs,
                      json.loads((out / "wave-bar.json").read_text())["members"]))
    (n1, logs1, m1), (n2, logs2, m2) = found
    check(n1 == 0 and len(logs1) == len(members), f"--reuse, first: {len(logs1)} runs, none reused")
    check(n2 == len(members) and logs2 == logs1, f"--reuse, second: {n2} of {len(members)} reused, no new run")
    check([(m["value"], m["wall"], m["cpu"]) for m in m1] == [(m["value"], m["wall"], m["cpu"]) for m in m2],
          "--reuse, second: the same values and measured times")
    check(all(m["reused"] for m in m2) and not any(m["reused"] for m in m1), "--reuse: the rows say which were reused")


def check_bin_tss(summary, members, check) -> None:
    """The promises of bulkflow.accuracy.bin_tss: no made-up T_ss, and a summary that says so."""
    statuses = ("reached", "not reached", "no steady regime")
    for m in members:
        v = m["value"]
        if v is None:
            check(m["tss_status"] in statuses[1:] and m["error"] is None and m["mdr"] is None,
                  f"{m['label']}: no T_ss ({m['tss_status']}), no error, no MDR")
        else:
            check(m["tss_status"] == "reached" and v >= 1.0 and abs(v / 0.5 - round(v / 0.5)) < 1e-9
                  and m["mdr"] > 0, f"{m['label']}: T_ss {v} s, a multiple of 0.5 s, MDR {m['mdr']:.4g} kg/s/m")
        check(m["wall"] > 0 and m["increments"] > 0, f"{m['label']}: {m['increments']} increments, "
                                                      f"{m['wall']:.3g} s wall")
    finest3 = sorted(members, key=lambda m: m["h"])[:3]
    if any(m["value"] is None for m in finest3):
        check(summary["reference"] is None and all(r["label"] is None for r in summary["recommendations"]),
              "a finest member without T_ss: no reference, no recommendation")
    else:
        check("reference_note" in summary or summary["reference"] is not None,
              f"three finest with T_ss: a reference ({summary['reference']}) or the reason for none")


if __name__ == "__main__":
    sys.exit(main())
