"""scripts/sweep_decks.py sorts each deck's outcome right: a stand-in for bulkflow (a small Python
program) behaves as the deck's `** fake-check:` / `** fake-run:` comment says, so every class of
outcome (clean rejection, rejection without file:line, crash, hang, runtime-library message, NaN in
the history, a run stopped with a message, a clean run) is produced on purpose."""
from __future__ import annotations

import stat
import sys
import textwrap
from pathlib import Path

import pytest

import sweep_decks

FAKE = textwrap.dedent('''\
    #!{python}
    import re, sys, time
    from pathlib import Path
    deck = Path(sys.argv[1])
    text = deck.read_text()
    mode = 'check' if '--check' in sys.argv else 'run'
    m = re.search(r'\\*\\* fake-' + mode + r': (\\S+)', text)
    what = m.group(1) if m else 'ok'
    if mode == 'run':
        base = Path(sys.argv[sys.argv.index('--output') + 1])
        rows = 'time,ALLKE\\n0,0\\n1e-5,' + ('nan' if what == 'nan' else '1.5') + '\\n'
        base.with_name(base.name + '_history.csv').write_text(rows)
    if what == 'ok':
        print(f'bulkflow: {{deck}}: OK' if mode == 'check' else '  total    0.01')
        sys.exit(0)
    if what == 'reject':
        print(f'bulkflow: error: {{deck}}:7: *FOO is not simulated by bulkflow; use *BAR', file=sys.stderr)
    elif what == 'reject-unplaced':
        print('bulkflow: error: something is wrong', file=sys.stderr)
    elif what == 'crash':
        print('Program received signal SIGSEGV: Segmentation fault', file=sys.stderr)
        sys.exit(139)
    elif what == 'runtime':
        print('Fortran runtime error: Index 3 of dimension 1 out of bounds', file=sys.stderr)
    elif what == 'hang':
        time.sleep(30)
    elif what == 'nan':
        print('  total    0.01')
        sys.exit(0)
    elif what == 'stop':
        print(f'bulkflow: error: {{deck}}: element 1 at total time 1E-3: element inverted', file=sys.stderr)
    elif what == 'silent':
        pass
    sys.exit(2)
''')


@pytest.fixture()
def fake_bulkflow(tmp_path: Path) -> str:
    exe = tmp_path / 'fake_bulkflow'
    exe.write_text(FAKE.format(python=sys.executable))
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    return str(exe)


def deck(tmp_path: Path, name: str, check: str = 'ok', run: str = 'ok') -> Path:
    path = tmp_path / 'decks' / f'{name}.inp'
    path.parent.mkdir(exist_ok=True)
    path.write_text(f'** fake-check: {check}\n** fake-run: {run}\n*HEADING\n{name}\n')
    return path


@pytest.mark.parametrize('check, run, status, reason', [
    ('ok', 'ok', 'accepted', 'ran'),
    ('reject', 'ok', 'rejected', '*FOO not simulated'),
    ('reject-unplaced', 'ok', 'FAIL', 'rejection without file:line'),
    ('crash', 'ok', 'FAIL', 'runtime-library message'),
    ('runtime', 'ok', 'FAIL', 'runtime-library message'),
    ('hang', 'ok', 'FAIL', 'hang (--check timeout)'),
    ('ok', 'crash', 'FAIL', 'run exit status 139'),
    ('ok', 'hang', 'FAIL', 'hang (run timeout)'),
    ('ok', 'nan', 'FAIL', 'NaN/Inf in the run output'),
    ('ok', 'stop', 'stopped', 'stopped by the run (exit 2)'),
    ('ok', 'silent', 'FAIL', 'run refused without a message'),
])
def test_outcome_is_classified(tmp_path, fake_bulkflow, check, run, status, reason):
    result = sweep_decks.sweep_one(deck(tmp_path, 'd', check, run), fake_bulkflow, timeout=3, increments=5)
    assert (result['status'], result['reason']) == (status, reason)


def test_exit_status_and_report(tmp_path, fake_bulkflow, capsys):
    deck(tmp_path, 'a_good')
    deck(tmp_path, 'b_rejected', check='reject')
    report = tmp_path / 'report.tsv'
    assert sweep_decks.main([str(tmp_path / 'decks'), '--bulkflow', fake_bulkflow, '--report', str(report)]) == 0
    out = capsys.readouterr().out
    assert 'decks: 2   accepted and run: 1' in out and 'rejected (exit 2, file:line): 1' in out
    assert len(report.read_text().splitlines()) == 3
    deck(tmp_path, 'c_crash', run='crash')
    assert sweep_decks.main([str(tmp_path / 'decks'), '--bulkflow', fake_bulkflow]) == 1
    assert 'FAIL' in capsys.readouterr().out


def test_get_writes_listed_files(tmp_path):
    """--get takes each listed file at its commit from a clone (here a local repository)."""
    import subprocess
    repo = tmp_path / 'owner+name'
    repo.mkdir()
    git = ['git', '-C', str(repo), '-c', 'user.name=t', '-c', 'user.email=t@t']
    subprocess.run(git[:3] + ['init', '-q'], check=True)
    (repo / 'sub').mkdir()
    (repo / 'sub' / 'x.inp').write_text('*HEADING\nfirst\n')
    subprocess.run(git + ['add', '.'], check=True)
    subprocess.run(git + ['commit', '-qm', 'one'], check=True)
    first = subprocess.run(git[:3] + ['rev-parse', 'HEAD'], capture_output=True, text=True).stdout.strip()
    (repo / 'sub' / 'x.inp').write_text('*HEADING\nsecond\n')
    subprocess.run(git + ['commit', '-qam', 'two'], check=True)
    sources = tmp_path / 'sources.tsv'
    sources.write_text('set\tlocal\trepository\tpath\tcommit\n'
                       f'abaqus\towner+name/sub/x.inp\towner/name\tsub/x.inp\t{first}\n'
                       f'abaqus\tmissing.inp\towner/name\tnot/there.inp\t{first}\n')
    into = tmp_path / 'into'
    rc = sweep_decks.main(['--get', str(sources), '--into', str(into), '--url', str(tmp_path) + '/{owner}+{name}'])
    assert rc == 1                                   # one listed file is missing
    assert (into / 'abaqus_decks' / 'owner+name' / 'sub' / 'x.inp').read_text() == '*HEADING\nfirst\n'
