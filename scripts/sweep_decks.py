#!/usr/bin/env python3
"""Sweep public Abaqus / CalculiX input decks through bulkflow, as a new user would try them.

    python3 scripts/sweep_decks.py --bulkflow build/bin/bulkflow DIR_OR_DECK... [--report out.tsv]
                                   [--timeout 60] [--run-increments 20] [--jobs 2]
    python3 scripts/sweep_decks.py --get docs/deck_sweep_sources.tsv --into /tmp   # fetch the decks first

For every *.inp found (directories are searched recursively), `bulkflow DECK --check` runs
(timeout). A deck it accepts is also run, unchanged, for a few increments
(`--stop-after N`, outputs in a scratch directory). The sweep fails (exit 1) on:
  * a crash, a hang (timeout) or an exit status other than 0 and 2;
  * a runtime-library message (gfortran "Fortran runtime error", "Backtrace", a signal, MPI abort)
    in any output, or NaN/Inf in what a run printed or wrote to its history;
  * a rejection (exit 2) whose message does not name `file:line`;
  * an accepted deck whose short run crashes, hangs, prints NaN/Inf or exits 2 without an error
    message (a run that stops with exit 2 and `bulkflow: error: ...`, e.g. an element inverting,
    is counted apart as "run stopped cleanly").
It prints the counts: accepted (and run), rejected by reason (the keyword or the feature the
message names), failures. The decks themselves are not part of the repository: the sources
are listed in docs/deck_sweep_sources.tsv (set, local name, repository, path, commit) and
docs/deck_sweep.md gives the counts of the last sweep. `--get` clones each listed repository
(blobless, from github.com) and writes every listed file, at its commit, to
INTO/<set>_decks/<local name>.
"""
from __future__ import annotations

import argparse
import collections
import concurrent.futures
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

RUNTIME_NOISE = re.compile(r'Fortran runtime error|Backtrace for this error|Program received signal|'
                           r'Segmentation fault|MPI_ABORT|forrtl:|malloc\(\)|double free|core dumped', re.I)
NONFINITE = re.compile(r'(?<![A-Za-z])(nan|[+-]?inf(inity)?)(?![A-Za-z])', re.I)
WHERE = re.compile(r'error: (?P<file>[^:\n]+):(?P<line>\d+): (?P<msg>.*)')


def decks_of(paths: list[Path]) -> list[Path]:
    found: list[Path] = []
    for p in paths:
        if p.is_dir():
            found += sorted(q for q in p.rglob('*') if q.suffix.lower() == '.inp' and q.is_file())
        elif p.is_file():
            found.append(p)
    return found


def reason_of(message: str) -> str:
    """The keyword or feature a rejection names, normalised for counting."""
    m = re.match(r'unknown keyword (\*[A-Z0-9 \-_]+)', message)
    if m:
        return f'unknown keyword {m.group(1).strip()}'
    m = re.match(r'(\*[A-Z0-9 \-_]+?)(,.*?)? is not (simulated|supported)', message)
    if m:
        return f'{m.group(1).strip()} not simulated'
    m = re.match(r'unknown parameter ([A-Z0-9 \-_]+) on (\*[A-Z0-9 \-_]+)', message)
    if m:
        return f'parameter {m.group(1).strip()} on {m.group(2).strip()}'
    m = re.search(r'element type "?([A-Z0-9]+)"?', message)
    if m and 'element type' in message:
        return f'element type {m.group(1)}'
    m = re.match(r'(\*[A-Z0-9 \-_]+?)[:,;]', message)
    if m:
        return f'{m.group(1).strip()}: ' + re.sub(r'[0-9.eE+-]+|"[^"]*"', '#', message[m.end():].split(';')[0]).strip()[:60]
    return re.sub(r'\b\d+\b|"[^"]*"', '#', message.split(';')[0])[:70]


def run(cmd: list[str], timeout: float, cwd: Path) -> tuple[int | None, str]:
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=cwd,
                           errors='replace')
        return p.returncode, p.stdout + p.stderr
    except subprocess.TimeoutExpired as e:
        out = (e.stdout or b'') + (e.stderr or b'')
        return None, out.decode(errors='replace') if isinstance(out, bytes) else str(out)


def sweep_one(deck: Path, bulkflow: str, timeout: float, increments: int) -> dict:
    result = {'deck': str(deck), 'status': '', 'reason': '', 'detail': ''}
    with tempfile.TemporaryDirectory(prefix='bulkflow_sweep_') as tmp:
        tmp_path = Path(tmp)
        rc, out = run([bulkflow, str(deck.resolve()), '--check'], timeout, tmp_path)
        if rc is None:
            return {**result, 'status': 'FAIL', 'reason': 'hang (--check timeout)'}
        if RUNTIME_NOISE.search(out):
            return {**result, 'status': 'FAIL', 'reason': 'runtime-library message', 'detail': out[-300:]}
        if rc == 2:
            m = WHERE.search(out)
            if not m:
                return {**result, 'status': 'FAIL', 'reason': 'rejection without file:line', 'detail': out[-300:]}
            return {**result, 'status': 'rejected', 'reason': reason_of(m.group('msg')),
                    'detail': f'{Path(m.group("file")).name}:{m.group("line")}: {m.group("msg")[:200]}'}
        if rc != 0:
            return {**result, 'status': 'FAIL', 'reason': f'--check exit status {rc}', 'detail': out[-300:]}
        base = tmp_path / 'run'
        rc, out = run([bulkflow, str(deck.resolve()), '--output', str(base), '--stop-after', str(increments),
                       '--quiet'], timeout, tmp_path)
        history = base.with_name('run_history.csv')
        text = out + (history.read_text(errors='replace') if history.exists() else '')
        if rc is None:
            return {**result, 'status': 'FAIL', 'reason': 'hang (run timeout)'}
        if RUNTIME_NOISE.search(out) or rc not in (0, 2):
            return {**result, 'status': 'FAIL', 'reason': f'run exit status {rc}', 'detail': out[-300:]}
        if NONFINITE.search(text):
            return {**result, 'status': 'FAIL', 'reason': 'NaN/Inf in the run output', 'detail': out[-300:]}
        if rc == 2:
            # A run may stop on what only the run can find (an element inverting, NaN forces): clean
            # if the message says what and where, and --check found nothing wrong with the input.
            m = re.search(r'bulkflow: error: (?P<msg>.*)', out)
            if not m:
                return {**result, 'status': 'FAIL', 'reason': 'run refused without a message', 'detail': out[-300:]}
            return {**result, 'status': 'stopped', 'reason': 'stopped by the run (exit 2)',
                    'detail': m.group('msg').replace(str(deck.resolve()), deck.name)[:200]}
        return {**result, 'status': 'accepted', 'reason': 'ran', 'detail': out.strip().splitlines()[-1][:120] if out.strip() else ''}


def get_decks(sources: Path, into: Path, url: str = 'https://github.com/{repo}.git') -> int:
    """Fetch the decks listed in SOURCES (TSV: set, local, repository, path, commit) into INTO."""
    rows = [line.split('\t') for line in sources.read_text().splitlines()[1:] if line.strip()]
    by_repo: dict[str, list[list[str]]] = collections.defaultdict(list)
    for row in rows:
        by_repo[row[2]].append(row)
    missing = 0
    with tempfile.TemporaryDirectory(prefix='bulkflow_decks_') as tmp:
        for repo, items in sorted(by_repo.items()):
            clone = Path(tmp) / repo.replace('/', '+')
            p = subprocess.run(['git', 'clone', '--quiet', '--filter=blob:none', '--no-checkout',
                                url.format(repo=repo, owner=repo.split('/')[0], name=repo.split('/')[1]), str(clone)], capture_output=True, text=True)
            if p.returncode != 0:
                print(f'cannot clone {repo}: {p.stderr.strip()}')
                missing += len(items)
                continue
            for kind, local, _, path, commit in items:
                out = into / f'{kind}_decks' / local
                out.parent.mkdir(parents=True, exist_ok=True)
                blob = subprocess.run(['git', '-C', str(clone), 'show', f'{commit}:{path}'], capture_output=True)
                if blob.returncode != 0:
                    print(f'missing {repo} {commit[:10]} {path}')
                    missing += 1
                    continue
                out.write_bytes(blob.stdout)
    print(f'{len(rows) - missing} of {len(rows)} decks written under {into}')
    return 1 if missing else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('paths', nargs='*', type=Path)
    ap.add_argument('--bulkflow')
    ap.add_argument('--get', type=Path, metavar='SOURCES', help='fetch the decks listed in SOURCES (TSV) and stop')
    ap.add_argument('--into', type=Path, default=Path('/tmp'), help='with --get: where <set>_decks/ go')
    ap.add_argument('--url', default='https://github.com/{repo}.git',
                    help='with --get: where to clone from ({repo}, {owner}, {name} are replaced)')
    ap.add_argument('--timeout', type=float, default=60)
    ap.add_argument('--run-increments', type=int, default=20)
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--report', type=Path, help='write one line per deck (TSV)')
    a = ap.parse_args(argv)
    if a.get:
        return get_decks(a.get, a.into, a.url)
    if not a.paths or not a.bulkflow:
        ap.error('give --bulkflow and at least one deck or directory (or --get SOURCES)')
    a.bulkflow = str(Path(a.bulkflow).resolve()) if os.sep in a.bulkflow else a.bulkflow
    decks = decks_of(a.paths)
    if not decks:
        print('no decks found')
        return 1
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        results = list(pool.map(lambda d: sweep_one(d, a.bulkflow, a.timeout, a.run_increments), decks))
    by_status = collections.Counter(r['status'] for r in results)
    reasons = collections.Counter(r['reason'] for r in results if r['status'] == 'rejected')
    print(f'decks: {len(results)}   accepted and run: {by_status["accepted"]}   accepted, run stopped cleanly '
          f'(exit 2): {by_status["stopped"]}   rejected (exit 2, file:line): {by_status["rejected"]}   '
          f'failures: {by_status["FAIL"]}')
    print('rejections by reason:')
    for reason, n in reasons.most_common():
        print(f'  {n:5d}  {reason}')
    for r in results:
        if r['status'] == 'FAIL':
            print(f'FAIL {r["deck"]}: {r["reason"]} {r["detail"]!r}')
        elif r['status'] == 'accepted':
            print(f'ran  {r["deck"]}: {r["detail"]}')
        elif r['status'] == 'stopped':
            print(f'stop {r["deck"]}: {r["detail"]}')
    if a.report:
        with open(a.report, 'w') as f:
            f.write('deck\tstatus\treason\tdetail\n')
            for r in results:
                f.write('\t'.join(r[k].replace('\t', ' ').replace('\n', ' ') for k in
                                  ('deck', 'status', 'reason', 'detail')) + '\n')
    return 1 if by_status['FAIL'] else 0


if __name__ == '__main__':
    sys.exit(main())
