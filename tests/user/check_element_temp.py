#!/usr/bin/env python3
"""TEMP as an element field output and NT as a node field output (issue 15): every frame's TEMP
dataset holds each element's temperature at the frame's time, the mean of its nodes'
temperatures, and NT those node temperatures (as Abaqus names them: NT for nodes, TEMP for
elements).

    check_element_temp.py CASE --bulkflow BIN --work DIR [--mpiexec MPIEXEC [--mpiexec-flag F]...]

Cases
  builtin_cpe4r  4 x 2 CPE4R, built-in *ELASTIC, every node held. *INITIAL CONDITIONS,
                 TYPE=TEMPERATURE 20 on all nodes; step 1 (0.5 s): *TEMPERATURE, AMPLITUDE=RAMP
                 (0 -> 1 over 0.4 s, then held) 100 on the nodes with x <= 1, so the elements of
                 the first column have four such nodes, those of the second two, the rest none;
                 step 2 (0.2 s): *TEMPERATURE, OP=NEW, all nodes 50. TEMP of element e at a frame
                 of step 1 is (k_e 100 a(t) + (4 - k_e) 20) / 4 (k_e its nodes with x <= 1), 50 in
                 step 2; NT 100 a(t) on those nodes, 20 on the others, 50 in step 2; checked to
                 1e-12 in every frame, with the frame count and the XDMF.
  builtin_c3d8r  the same on 4 x 2 x 1 C3D8R (k_e of 8 nodes).
  builtin_mpi    builtin_cpe4r on 2 ranks (each rank writes its own elements).
  user_probe     the probe VUMAT (probe_vumat.f, --user) in 12 x 12 CPE4R under the temperature
                 ramp T0 + 400 t it checks as tempOld/tempNew on every call: TEMP = T0 + 400 t at
                 every frame, the tempNew of the increment that ended there.
  no_request     builtin_cpe4r without TEMP and NT in the request: no dataset, none in the XDMF.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import check_user_subroutines as uc  # noqa: E402  (the probe's element scene and constants)

T_INITIAL, T_HOT, T_STEP2, RAMP_END = 20.0, 100.0, 50.0, 0.4


class Failed(Exception):
    pass


def ramp(t: float) -> float:
    return min(t / RAMP_END, 1.0)


def grid_scene(ndim: int, with_temp: bool = True) -> tuple[str, np.ndarray, np.ndarray]:
    """The scene text, per element (in file order) how many of its nodes have x <= 1, and those
    nodes' labels."""
    n = (4, 2) if ndim == 2 else (4, 2, 1)
    grids = [np.arange(k + 1, dtype=float) for k in n]
    coords = np.array(np.meshgrid(*grids, indexing='ij')).reshape(ndim, -1).T
    index = np.arange(coords.shape[0]).reshape([k + 1 for k in n]) + 1
    elems = []
    for i in range(n[0]):
        for j in range(n[1]):
            if ndim == 2:
                elems.append([index[i, j], index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]])
            else:
                elems.append([index[i, j, 0], index[i + 1, j, 0], index[i + 1, j + 1, 0], index[i, j + 1, 0],
                              index[i, j, 1], index[i + 1, j, 1], index[i + 1, j + 1, 1], index[i, j + 1, 1]])
    elems = np.array(elems)
    hot_nodes = [k + 1 for k in range(coords.shape[0]) if coords[k, 0] <= 1.0]
    hot_count = np.array([sum(1 for v in e if v in hot_nodes) for e in elems])
    etype = 'CPE4R' if ndim == 2 else 'C3D8R'
    dofs = '1, 2' if ndim == 2 else '1, 3'
    lines = ['*HEADING', f'TEMP element output, {ndim}D', '*NODE']
    lines += [f'{k + 1}, ' + ', '.join(repr(float(v)) for v in c) for k, c in enumerate(coords)]
    lines += [f'*ELEMENT, TYPE={etype}, ELSET=ALLE']
    lines += [f'{k + 1}, ' + ', '.join(str(v) for v in e) for k, e in enumerate(elems)]
    lines += ['*NSET, NSET=ALL, GENERATE', f'1, {coords.shape[0]}, 1', '*NSET, NSET=HOT']
    lines += [', '.join(str(v) for v in hot_nodes[m:m + 8]) for m in range(0, len(hot_nodes), 8)]
    lines += ['*SOLID SECTION, ELSET=ALLE, MATERIAL=SAND']
    if ndim == 2:
        lines.append('1.0')
    lines += ['*MATERIAL, NAME=SAND', '*DENSITY', '2000.', '*ELASTIC', '1.0e7, 0.3',
              '*INITIAL CONDITIONS, TYPE=TEMPERATURE', f'ALL, {T_INITIAL!r}',
              '*AMPLITUDE, NAME=RAMP', f'0., 0., {RAMP_END!r}, 1.',
              '*BOUNDARY', f'ALL, {dofs}']
    request = ['*ELEMENT OUTPUT', 'S, TEMP', '*NODE OUTPUT', 'U, NT'] if with_temp else ['*ELEMENT OUTPUT', 'S']
    lines += ['*STEP, NAME=HEAT', '*DYNAMIC, EXPLICIT', ', 0.5',
              '*TEMPERATURE, AMPLITUDE=RAMP', f'HOT, {T_HOT!r}',
              '*OUTPUT, FIELD, NUMBER INTERVAL=5', *request,
              '*OUTPUT, HISTORY, NUMBER INTERVAL=5', '*ENERGY OUTPUT', '*END STEP',
              '*STEP, NAME=HOLD', '*DYNAMIC, EXPLICIT', ', 0.2',
              '*TEMPERATURE, OP=NEW', f'ALL, {T_STEP2!r}',
              '*OUTPUT, FIELD, NUMBER INTERVAL=2', *request,
              '*OUTPUT, HISTORY, NUMBER INTERVAL=2', '*ENERGY OUTPUT', '*END STEP']
    return '\n'.join(lines) + '\n', hot_count, np.array(hot_nodes)


def run(cmd: list[str], cwd: Path) -> None:
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT='1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM='1')
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=env, timeout=600)
    if r.returncode != 0:
        raise Failed(f'exit {r.returncode}: {" ".join(cmd)}\n{r.stdout[-2000:]}{r.stderr[-2000:]}')


def frames_of(h5: Path, nodes: bool = False):
    """The element ids (with nodes: also the node ids) in dataset order, and (step, step time,
    datasets) of every frame."""
    with h5py.File(h5, 'r') as f:
        ids = f['mesh']['element_id'][()]
        if nodes:
            ids = (ids, f['mesh']['node_id'][()])
        out = []
        for k in sorted(f['frames']):
            g = f['frames'][k]
            out.append((int(np.ravel(g.attrs['step'])[0]), float(np.ravel(g.attrs['step_time'])[0]),
                        {name: g[name][()] for name in g}))
    return ids, out


def check_builtin(a, ndim: int, ranks: int = 1) -> None:
    text, hot_count, hot_nodes = grid_scene(ndim)
    a.work.mkdir(parents=True, exist_ok=True)
    scene = a.work / 'temp.inp'
    scene.write_text(text)
    cmd = [a.bulkflow, str(scene), '--quiet']
    if ranks > 1:
        if not a.mpiexec:
            raise Failed('this case needs --mpiexec')
        cmd = [a.mpiexec, *a.mpiexec_flag, '-n', str(ranks), *cmd]
    run(cmd, a.work)
    (ids, node_ids), frames = frames_of(a.work / 'temp.h5', nodes=True)
    hot = np.isin(node_ids, hot_nodes)
    # 0.5 s in 5 intervals and 0.2 s in 2, each with its start frame: 6 + 2 (the step start of
    # the second is the end of the first, not written twice)
    if len(frames) < 8:
        raise Failed(f'{len(frames)} frames; expected at least 8 (6 in step 1, 2 in step 2)')
    worst = 0.0
    for step, t, data in frames:
        if 'TEMP' not in data:
            raise Failed(f'frame at step {step}, t = {t}: no TEMP dataset ({sorted(data)})')
        temp = np.ravel(data['TEMP'])
        if temp.shape != (len(ids),):
            raise Failed(f'TEMP has shape {data["TEMP"].shape}, expected one value per element ({len(ids)})')
        k = hot_count[ids - 1]
        nen = 4 if ndim == 2 else 8
        if step == 1:
            want = (k * T_HOT * ramp(t) + (nen - k) * T_INITIAL) / nen
        else:
            want = np.full(len(ids), T_STEP2)
        if 'NT' not in data or np.ravel(data['NT']).shape != (len(node_ids),):
            raise Failed(f'frame at step {step}, t = {t}: no NT of {len(node_ids)} nodes')
        nt = np.ravel(data['NT'])
        want_nt = np.where(hot, T_HOT * ramp(t), T_INITIAL) if step == 1 else np.full(len(node_ids), T_STEP2)
        err = max(float(np.max(np.abs(temp - want))), float(np.max(np.abs(nt - want_nt))))
        worst = max(worst, err)
        print(f'  step {step}, t = {t:.4f}: TEMP {np.array2string(temp[:4], precision=6)}..., '
              f'max |TEMP, NT - closed form| = {err:.2e}')
        if err > 1e-12 * max(1.0, float(np.max(np.abs(want)))):
            raise Failed(f'step {step}, t = {t}: TEMP differs from the closed form by {err:.3e}')
    xmf = (a.work / 'temp.xmf').read_text()
    for name in ('TEMP', 'NT'):
        if xmf.count(f'Name="{name}"') != len(frames):
            raise Failed(f'temp.xmf names {name} {xmf.count(f"Name={chr(34)}{name}{chr(34)}")} times for '
                         f'{len(frames)} frames')
    print(f'  {len(frames)} frames, worst |TEMP, NT - closed form| = {worst:.2e} (limit 1e-12 relative); '
          f'XDMF shows TEMP and NT in every frame')


def check_user_probe(a) -> None:
    a.work.mkdir(parents=True, exist_ok=True)
    scene = a.work / 'probe.inp'
    total = 2e-3
    uc.element_scene(scene, 2, (12, 12), [0.05, -0.03, 0.0], [0, 0, 1], 0.0, total, temp_rate=uc.TRATE)
    text = scene.read_text().replace('*ELEMENT OUTPUT\nS, SDV\n', '*ELEMENT OUTPUT\nS, SDV, TEMP\n')
    scene.write_text(text)
    env_cache = a.work / 'cache'
    os.environ.setdefault('BULKFLOW_CACHE_DIR', str(env_cache))
    run([a.bulkflow, str(scene), '--quiet', '--user', str(HERE / 'probe_vumat.f')], a.work)
    ids, frames = frames_of(a.work / 'probe.h5')
    if len(frames) < 3:
        raise Failed(f'{len(frames)} frames')
    worst = 0.0
    for step, t, data in frames:
        temp = np.ravel(data['TEMP'])
        want = uc.T0 + uc.TRATE * t
        err = float(np.max(np.abs(temp - want)))
        worst = max(worst, err)
        if err > 1e-12 * want:
            raise Failed(f't = {t}: TEMP {temp[:3]} against T0 + 400 t = {want!r}')
    print(f'  {len(frames)} frames of 144 elements: TEMP = T0 + 400 t (the probe\'s tempNew), worst error '
          f'{worst:.2e} (limit 1e-12 relative)')


def check_no_request(a) -> None:
    text, _, _ = grid_scene(2, with_temp=False)
    a.work.mkdir(parents=True, exist_ok=True)
    scene = a.work / 'plain.inp'
    scene.write_text(text)
    run([a.bulkflow, str(scene), '--quiet'], a.work)
    _, frames = frames_of(a.work / 'plain.h5')
    xmf = (a.work / 'plain.xmf').read_text()
    if any('TEMP' in data or 'NT' in data for _, _, data in frames) or 'TEMP' in xmf or '"NT"' in xmf:
        raise Failed('TEMP or NT written although no request names them')
    print(f'  {len(frames)} frames without TEMP and NT (not requested)')


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('case', choices=['builtin_cpe4r', 'builtin_c3d8r', 'builtin_mpi', 'user_probe', 'no_request'])
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--work', type=Path, required=True)
    p.add_argument('--mpiexec')
    p.add_argument('--mpiexec-flag', action='append', default=[])
    a = p.parse_args()
    try:
        if a.case == 'builtin_cpe4r':
            check_builtin(a, 2)
        elif a.case == 'builtin_c3d8r':
            check_builtin(a, 3)
        elif a.case == 'builtin_mpi':
            check_builtin(a, 2, ranks=2)
        elif a.case == 'user_probe':
            check_user_probe(a)
        else:
            check_no_request(a)
    except (Failed, uc.Failed) as exc:
        print(f'FAIL {a.case}: {exc}')
        return 1
    print(f'PASS {a.case}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
