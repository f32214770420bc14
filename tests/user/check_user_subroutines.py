#!/usr/bin/env python3
"""User subroutines loaded with --user, in the four hosts (tests/user/README.md).

Each case writes its scene, runs the solver with --user on a VUMAT of tests/user/, and checks
the result against a closed form. Usage:

    check_user_subroutines.py CASE --bulkflow BIN --matpoint BIN --work DIR [--abaqus-file F]

Cases
  (the element, MPM and driver probes with *TEMPERATURE, AMPLITUDE=: T = T0 + 400 t, tempOld
  and tempNew checked at both ends of every increment)
  probe_cpe4r_rotation  one CPE4R element: stretch, then a rigid rotation of 50 degrees
  probe_c3d8r_rotation  one C3D8R element: stretch, then a rotation of 40 degrees about (1,2,3)
  probe_cpe4r_block     12 x 12 CPE4R (144 elements: one solver block, two VUMAT calls)
  probe_c3d8r_block     6 x 6 x 4 C3D8R (144 elements)
  probe_cax4r_block     4 x 4 CAX4R from the axis: u_r = a r, u_z = c z (hoop stretch 1 + a in F33, U33)
  probe_mpm             an MPM column settling under gravity (400 particles; temperature and
                        two field variables from *INITIAL CONDITIONS on the material's particles)
  probe_matpoint        bulkflow-matpoint oedometer test in two stages (temperature ramp)
  single_file_elements  our single Abaqus file as --user == the built-in models, bit for bit
  single_file_mpm       the same for an MPM hopper
  bad_compile           a file that does not compile: compiler messages, exit status 2
  bad_no_vumat          a file with neither VUMAT nor VUSDFLD: exit status 2, says so
  bad_nan               a VUMAT returning NaN: exit 2 naming material, element/particle, time

The probe VUMAT (probe_vumat.f) checks every argument itself and stops the run through
xplb_abqerr(-3, ...) on the first that is wrong; this script then checks what it returned: the
stress of a compressible neo-Hookean solid from F, sigma = G/J (B - I) + lambda ln(J)/J I,
and the state variables in which it recorded J, coordMp, charLength, the temperature and the
two field variables.
"""
from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

HERE = Path(__file__).resolve().parent
E, NU, RHO = 1.0e7, 0.3, 2000.0
G = E / (2 * (1 + NU))
LAM = E * NU / ((1 + NU) * (1 - 2 * NU))
T0, F1, F2 = 293.0, 0.25, -1.5
# dT/dt of the probe scenes' *TEMPERATURE, AMPLITUDE= (T = T0 + TRATE t, a linear amplitude)
TRATE = 400.0


class Failed(Exception):
    pass


def run(cmd: list[str], cwd: Path, expect: int = 0) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env.setdefault('OMPI_ALLOW_RUN_AS_ROOT', '1')
    env.setdefault('OMPI_ALLOW_RUN_AS_ROOT_CONFIRM', '1')
    env.setdefault('BULKFLOW_CACHE_DIR', str(cwd / 'cache'))
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=env, timeout=600)
    if proc.returncode != expect:
        sys.stdout.write(proc.stdout)
        sys.stderr.write(proc.stderr)
        raise Failed(f'exit status {proc.returncode}, expected {expect}: {" ".join(cmd)}')
    return proc


def rotation(axis, angle: float) -> np.ndarray:
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def neo_hooke(f: np.ndarray) -> np.ndarray:
    j = np.linalg.det(f)
    return G / j * (f @ f.T - np.eye(3)) + LAM * math.log(j) / j * np.eye(3)


def props_line(xc, check_coord: bool, nfieldv: int, rate: float = 0.0) -> str:
    p = [float(v) for v in (E, NU, RHO, T0, F1, F2, *xc, 1.0 if check_coord else 0.0, nfieldv, rate)]
    return ',\n'.join(', '.join(repr(v) for v in p[i:i + 8]) for i in range(0, len(p), 8))


def element_scene(path: Path, ndim: int, n: tuple, stretch, axis, angle: float, total: float,
                  temp_rate: float = 0.0, etype: str | None = None):
    """A homogeneous motion x = A(t) X of every node: stretch D over the first half, then the
    rotation R over the second; with temp_rate, *TEMPERATURE, AMPLITUDE= makes the nodes'
    temperature T0 + temp_rate t. Returns the final A and the reference centroids."""
    h = 0.1
    grids = [np.arange(k + 1) * h for k in n]
    coords = np.array(np.meshgrid(*grids, indexing='ij')).reshape(ndim, -1).T
    index = np.arange(coords.shape[0]).reshape([k + 1 for k in n]) + 1
    elems = []
    if ndim == 2:
        for i in range(n[0]):
            for j in range(n[1]):
                elems.append([index[i, j], index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]])
    else:
        for i in range(n[0]):
            for j in range(n[1]):
                for k in range(n[2]):
                    elems.append([index[i, j, k], index[i + 1, j, k], index[i + 1, j + 1, k],
                                  index[i, j + 1, k], index[i, j, k + 1], index[i + 1, j, k + 1],
                                  index[i + 1, j + 1, k + 1], index[i, j + 1, k + 1]])
    elems = np.array(elems)
    d = np.eye(3) + np.diag(stretch)
    r = rotation(axis, angle)
    x3 = np.zeros((coords.shape[0], 3))
    x3[:, :ndim] = coords
    centroids = x3[elems - 1].mean(axis=1)

    def a_of(t):
        if angle == 0:
            return np.eye(3) + (t / total) * (d - np.eye(3))
        s = min(1.0, 2 * t / total)
        th = max(0.0, 2 * t / total - 1) * angle
        return rotation(axis, th) @ (np.eye(3) + s * (d - np.eye(3)))

    lines = ['*HEADING', f'probe VUMAT, {ndim}D, homogeneous motion', '*NODE']
    lines += [f'{k + 1}, ' + ', '.join(repr(float(v)) for v in c) for k, c in enumerate(coords)]
    etype = etype or ('CPE4R' if ndim == 2 else 'C3D8R')
    lines.append(f'*ELEMENT, TYPE={etype}, ELSET=ALL')
    lines += [f'{k + 1}, ' + ', '.join(str(v) for v in e) for k, e in enumerate(elems)]
    lines.append('*NSET, NSET=NALL, GENERATE')
    lines.append(f'1, {coords.shape[0]}, 1')
    lines.append('*SOLID SECTION, ELSET=ALL, MATERIAL=PROBE-NEO')
    if etype == 'CPE4R':
        lines.append('1.0')
    single = len(elems) == 1
    lines += ['*MATERIAL, NAME=probe-neo', '*DENSITY', repr(RHO), '*USER MATERIAL, CONSTANTS=12',
              props_line(centroids[0] if single else [0, 0, 0], single, 2, temp_rate), '*DEPVAR', '10',
              '*INITIAL CONDITIONS, TYPE=TEMPERATURE', f'NALL, {T0}',
              '*INITIAL CONDITIONS, TYPE=FIELD, VARIABLE=1', f'NALL, {F1}',
              '*INITIAL CONDITIONS, TYPE=FIELD, VARIABLE=2', f'NALL, {F2}']
    times = [float(t) for t in np.linspace(0, total, 61)]
    if angle != 0:
        for k in range(coords.shape[0]):
            for i in range(ndim):
                vals = [float((a_of(t) @ x3[k] - x3[k])[i]) for t in times]
                pairs = [f'{t!r}, {v!r}' for t, v in zip(times, vals)]
                lines.append(f'*AMPLITUDE, NAME=A{k + 1}_{i + 1}')
                lines += [', '.join(pairs[m:m + 4]) for m in range(0, len(pairs), 4)]
    lines += ['*AMPLITUDE, NAME=LINEAR', f'0., 0., {total!r}, 1.',
              '*STEP, NAME=MOVE', '*DYNAMIC, EXPLICIT', f', {total!r}', '*BULK VISCOSITY', '0., 0.']
    if temp_rate != 0:
        lines[-5:-5] = ['*AMPLITUDE, NAME=TRAMP', f'0., {T0!r}, {total!r}, {T0 + temp_rate * total!r}']
        lines += ['*TEMPERATURE, AMPLITUDE=TRAMP', 'NALL, 1.0']
    for k in range(coords.shape[0]):
        u = a_of(total) @ x3[k] - x3[k]
        for i in range(ndim):
            if angle != 0:
                lines += [f'*BOUNDARY, AMPLITUDE=A{k + 1}_{i + 1}', f'{k + 1}, {i + 1}, {i + 1}, 1.']
            else:
                lines += ["*BOUNDARY, AMPLITUDE=LINEAR", f"{k + 1}, {i + 1}, {i + 1}, {float(u[i])!r}"]
    lines += ['*OUTPUT, FIELD, NUMBER INTERVAL=2', '*ELEMENT OUTPUT', 'S, SDV',
              '*OUTPUT, HISTORY, NUMBER INTERVAL=10', '*ENERGY OUTPUT', '*END STEP']
    path.write_text('\n'.join(lines) + '\n')
    return a_of(total), centroids


def last_frame(h5: Path, group: str):
    with h5py.File(h5, 'r') as f:
        g = f[group]
        k = sorted(g)[-1]
        out = {name: g[k][name][()] for name in g[k]}
    sdv = sorted((int(n[3:]), v) for n, v in out.items() if n.startswith('SDV') and n[3:].isdigit())
    if sdv:
        out['SDV'] = np.column_stack([v for _, v in sdv])
    return out


def stress_matrix(s: np.ndarray) -> np.ndarray:
    m = np.zeros((3, 3))
    m[0, 0], m[1, 1], m[2, 2], m[0, 1] = s[0], s[1], s[2], s[3]
    if len(s) == 6:
        m[1, 2], m[0, 2] = s[4], s[5]
    return m + np.triu(m, 1).T


def check_close(name: str, got, want, tol: float):
    err = float(np.max(np.abs(np.asarray(got) - np.asarray(want))))
    print(f'  {name}: max error {err:.3e} (limit {tol:.1e})')
    if not err <= tol:
        raise Failed(f'{name}: error {err:.3e} above {tol:.1e}')


def probe_elements(a, ndim: int, n: tuple, stretch, axis, angle: float, etype: str | None = None):
    work = a.work
    work.mkdir(parents=True, exist_ok=True)
    scene = work / 'probe.inp'
    total = 0.05
    f, centroids = element_scene(scene, ndim, n, stretch, axis, angle, total, temp_rate=TRATE, etype=etype)
    run([a.bulkflow, str(scene), '--quiet', '--user', str(HERE / 'probe_vumat.f')], work)
    fr = last_frame(work / 'probe.h5', 'frames')
    s_want = neo_hooke(f)
    smax = np.max(np.abs(s_want))
    for e, s in enumerate(fr['S']):
        check_close(f'S element {e + 1}', stress_matrix(s), s_want, 1e-7 * smax) if e < 2 else \
            check_close_quiet(stress_matrix(s), s_want, 1e-7 * smax, f'S element {e + 1}')
    sdv = fr['SDV']
    check_close('SDV1 = J', sdv[:, 0], np.linalg.det(f), 1e-12)
    check_close('SDV2-4 = coordMp = F X_c', sdv[:, 1:4], centroids @ f.T, 1e-12)
    check_close('SDV6 = tempNew = T0 + rate t (*TEMPERATURE, AMPLITUDE=) at the end', sdv[:, 5],
                T0 + TRATE * total, 1e-9 * T0)
    check_close('SDV7, SDV8 = field 1, field 2', sdv[:, 6:8], [F1, F2], 0)
    sizes = sorted(set(sdv[:, 8].astype(int)))
    print(f'  nblock seen: {sizes}')
    if max(sizes) > 136:
        raise Failed(f'nblock {max(sizes)} above 136')
    if len(sdv) > 136 and 136 not in sizes:
        raise Failed('a block of more than 136 points was not cut at 136')
    if not np.all(sdv[:, 4] > 0):
        raise Failed('charLength not positive')


def check_close_quiet(got, want, tol, name):
    if not float(np.max(np.abs(np.asarray(got) - np.asarray(want)))) <= tol:
        check_close(name, got, want, tol)


def probe_mpm(a):
    work = a.work
    work.mkdir(parents=True, exist_ok=True)
    scene = work / 'probe_mpm.inp'
    total = 0.8
    height = 1.0
    g = 9.81
    scene.write_text(f"""*HEADING
probe VUMAT in MPM: a column settling under gravity on rollers
*MPM GRID, CELL=0.05, SHAPE=GIMP
-0.2, -0.2
0.4, 1.4
*MPM CONTROLS, FLIP=0.99, CFL=0.3, DAMPING=0.2
*MATERIAL, NAME=Probe-MPM
*DENSITY
{RHO}
*USER MATERIAL, CONSTANTS=12
{props_line([0, 0, 0], False, 2, TRATE)}
*DEPVAR
10
*INITIAL CONDITIONS, TYPE=TEMPERATURE
PROBE-MPM, {T0!r}
*INITIAL CONDITIONS, TYPE=FIELD, VARIABLE=1
PROBE-MPM, {F1!r}
*INITIAL CONDITIONS, TYPE=FIELD, VARIABLE=2
PROBE-MPM, {F2!r}
*PARTICLES, MATERIAL=PROBE-MPM, PPC=2
0., 0.
0.25, {height}
*MPM WALL, NAME=AXIS, TYPE=SYMMETRY
0., 1.4, 0., -0.2
*MPM WALL, NAME=SIDE, TYPE=SYMMETRY
0.25, -0.2, 0.25, 1.4
*MPM WALL, NAME=FLOOR, TYPE=SYMMETRY
-0.2, 0., 0.4, 0.
*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP
0., 0., 0.3, 1.
*AMPLITUDE, NAME=TRAMP
0., {T0!r}, {total!r}, {T0 + TRATE * total!r}
*STEP, NAME=SETTLE
*DYNAMIC, EXPLICIT
, {total!r}
*DLOAD, AMPLITUDE=RAMP
, GRAV, {g}, 0., -1.
*TEMPERATURE, AMPLITUDE=TRAMP
PROBE-MPM, 1.0
*OUTPUT, FIELD, NUMBER INTERVAL=2
*ELEMENT OUTPUT
S, SDV
*OUTPUT, HISTORY, NUMBER INTERVAL=80
*ENERGY OUTPUT
*END STEP
""".replace('T0_PLACEHOLDER', ''))
    run([a.bulkflow, str(scene), '--quiet', '--user', str(HERE / 'probe_vumat.f')], work)
    fr = last_frame(work / 'probe_mpm.h5', 'particles')
    x = fr['coordinates']
    sdv = fr['SDV']
    check_close('SDV2-3 = coordMp = particle position', sdv[:, 1:3], x[:, 0:2], 1e-9)
    check_close('SDV6 = tempNew = T0 + rate t (*TEMPERATURE on the particles) at the end', sdv[:, 5],
                T0 + TRATE * total, 1e-9 * T0)
    check_close('SDV7, SDV8 = field 1, field 2 (*INITIAL CONDITIONS on the particles)', sdv[:, 6:8], [F1, F2], 0)
    sizes = sorted(set(sdv[:, 8].astype(int)))
    print(f'  particles {len(x)}, nblock seen: {sizes}')
    if max(sizes) > 136:
        raise Failed(f'nblock {max(sizes)} above 136')
    # Vertical stress of the settled column: the weight above, rho g (H - y) (to the damping
    # and the particle discretisation: 5 % of the bottom value).
    top = x[:, 1].max() + 0.5 * np.median(sdv[:, 4])
    want = -RHO * g * (top - x[:, 1]) * 1.0
    s_yy = fr['S'][:, 1]
    # mass is conserved: rho0 H g at the bottom whatever the compression
    bottom = RHO * g * height
    check_close('S22 = -rho g (H - y) (per particle)', s_yy, want * (RHO * g * height) / (RHO * g * top),
                0.05 * bottom)


def probe_matpoint(a):
    """The driver's oedometer with *TEMPERATURE, AMPLITUDE= as the element and MPM probes: the
    probe checks tempOld/tempNew = T0 + TRATE t at both ends of every increment, and records
    tempNew in SDV6, checked here row by row."""
    work = a.work
    work.mkdir(parents=True, exist_ok=True)
    inp = work / 'probe_oedometer.inp'
    total = 0.5
    inp.write_text(f"""*HEADING
probe VUMAT in the material-point driver: oedometer, temperature ramp
*MATERIAL, NAME=PROBE-POINT
*DENSITY
{RHO}
*USER MATERIAL, CONSTANTS=12
{props_line([0, 0, 0], False, 0, TRATE)}
*DEPVAR
10
*INITIAL CONDITIONS, TYPE=TEMPERATURE
{T0!r}
*AMPLITUDE, NAME=TRAMP
0., {T0!r}, {total!r}, {T0 + TRATE * total!r}
*TEMPERATURE, AMPLITUDE=TRAMP
PROBE-POINT, 1.0
*TEST, TYPE=OEDOMETER
*STAGE, STRAIN=-0.03, INC=30, TIME={total / 2!r}
*STAGE, STRAIN=-0.02, INC=20, TIME={total / 2!r}
""")
    run([a.matpoint, str(inp), '-o', str(work / 'probe.csv'), '--user', str(HERE / 'probe_vumat.f')], work)
    data = np.genfromtxt(work / 'probe.csv', delimiter=',', names=True)
    # axis 2 (the default): F = diag(1, exp(e22), 1), e22 the logarithmic strain
    f = np.diag([1.0, math.exp(data['e22'][-1]), 1.0])
    want = neo_hooke(f)
    check_close('s22, s11 at the end (oedometer)', [data['s22'][-1], data['s11'][-1]],
                [want[1, 1], want[0, 0]], 1e-6 * abs(want[1, 1]))
    rows = data[1:]
    check_close('SDV6 = tempNew = T0 + rate t, every increment (*TEMPERATURE, AMPLITUDE=)', rows['SDV6'],
                T0 + TRATE * rows['time'], 1e-9 * T0)
    check_close('SDV10 = increments seen by point 1', rows['SDV10'][-1], len(rows), 0)
    print(f'  {len(rows)} increments, T from {T0} to {rows["SDV6"][-1]:.6f}')


def same_files(a_dir: Path, b_dir: Path, base: str, group: str):
    ha = (a_dir / f'{base}_history.csv').read_bytes()
    hb = (b_dir / f'{base}_history.csv').read_bytes()
    if ha != hb:
        raise Failed(f'{base}_history.csv differs')
    with h5py.File(a_dir / f'{base}.h5', 'r') as fa, h5py.File(b_dir / f'{base}.h5', 'r') as fb:
        names = []
        fa.visit(lambda n: names.append(n) if isinstance(fa[n], h5py.Dataset) else None)
        for n in names:
            if fa[n][()].tobytes() != fb[n][()].tobytes():
                raise Failed(f'{base}.h5 {n} differs')
    print(f'  {base}: history and {len(names)} datasets identical')


def single_file(a, scene_text: str, base: str, group: str):
    work = a.work
    for sub in ('builtin', 'user'):
        (work / sub).mkdir(parents=True, exist_ok=True)
        (work / sub / f'{base}.inp').write_text(scene_text)
    run([a.bulkflow, f'{base}.inp', '--quiet'], work / 'builtin')
    run([a.bulkflow, f'{base}.inp', '--quiet', '--user', a.abaqus_file], work / 'user')
    same_files(work / 'builtin', work / 'user', base, group)


def single_file_elements(a):
    # A Mohr-Coulomb column of CPE4R under gravity, as *USER MATERIAL MC-... (our model by name).
    lines = ['*HEADING', 'MC column (CPE4R) through *USER MATERIAL', '*NODE']
    nx, ny, h = 4, 40, 0.05
    for j in range(ny + 1):
        for i in range(nx + 1):
            lines.append(f'{j * (nx + 1) + i + 1}, {i * h!r}, {j * h!r}')
    lines.append('*ELEMENT, TYPE=CPE4R, ELSET=ALL')
    k = 0
    for j in range(ny):
        for i in range(nx):
            k += 1
            n1 = j * (nx + 1) + i + 1
            lines.append(f'{k}, {n1}, {n1 + 1}, {n1 + nx + 2}, {n1 + nx + 1}')
    lines += ['*NSET, NSET=BOTTOM, GENERATE', f'1, {nx + 1}, 1', '*NSET, NSET=SIDES, GENERATE',
              f'1, {ny * (nx + 1) + 1}, {nx + 1}',
              '*NSET, NSET=RIGHT, GENERATE', f'{nx + 1}, {(ny + 1) * (nx + 1)}, {nx + 1}',
              '*SOLID SECTION, ELSET=ALL, MATERIAL=MC-SAND', '1.0',
              '*MATERIAL, NAME=MC-SAND', '*DENSITY', '1600.', '*USER MATERIAL, CONSTANTS=16',
              '1.0e7, 0.25, 30., 0., 1000., 0., 0., 0.', '0., 0., 0., 0., 0., 0., 0., 0.',
              '*DEPVAR', '8', '*STEP', '*DYNAMIC, EXPLICIT', ', 0.1', '*BOUNDARY',
              'BOTTOM, 2, 2', 'SIDES, 1, 1', 'RIGHT, 1, 1', '*DLOAD', ', GRAV, 9.81, 0., -1.',
              '*OUTPUT, FIELD, NUMBER INTERVAL=2', '*ELEMENT OUTPUT', 'S, LE, SDV',
              '*NODE OUTPUT', 'U, V', '*OUTPUT, HISTORY, NUMBER INTERVAL=20', '*ENERGY OUTPUT', '*END STEP']
    single_file(a, '\n'.join(lines) + '\n', 'mc_column', 'frames')


def single_file_mpm(a):
    text = (HERE.parent.parent / 'inputs' / 'mpm' / 'hopper_small_2d.inp').read_text()
    single_file(a, text, 'hopper_small_2d', 'particles')


def bad(a, source: str, name: str, must: list[str], scene: Path | None = None):
    work = a.work
    work.mkdir(parents=True, exist_ok=True)
    (work / name).write_text(source)
    if scene is None:
        scene = HERE.parent.parent / 'inputs' / 'mpm' / 'hopper_small_2d.inp'
    proc = run([a.bulkflow, str(scene), '--quiet', '--user', name], work, expect=2)
    text = proc.stdout + proc.stderr
    print('  ' + '\n  '.join(text.strip().splitlines()[-6:]))
    for m in must:
        if m not in text:
            raise Failed(f'the message does not contain "{m}"')


def nan_scene(a, elements: bool = False) -> Path:
    """A column of material SOIL (*USER MATERIAL) for the NaN VUMAT: MPM or CPE4R."""
    a.work.mkdir(parents=True, exist_ok=True)
    path = a.work / ('nan_elements.inp' if elements else 'nan_mpm.inp')
    if elements:
        element_scene(path, 2, (2, 2), [0.02, -0.01, 0], [0, 0, 1], 0.0, 0.05)
        text = path.read_text().replace('probe-neo', 'soil').replace('PROBE-NEO', 'SOIL')
    else:
        text = (HERE.parent.parent / 'inputs' / 'mpm' / 'column_k0_2d.inp').read_text()
        text = text.replace('*ELASTIC\n1.0e7, 0.2', '*USER MATERIAL, CONSTANTS=2\n1.0e7, 0.2')
    path.write_text(text)
    return path


BROKEN = """      subroutine vumat(nblock, ndir)
      include 'vaba_param.inc'
      x = = 1
      end
"""
NO_VUMAT = """      subroutine vumat_helper(nblock)
      include 'vaba_param.inc'
      return
      end
"""
NAN_VUMAT = """      subroutine vumat(nblock, ndir, nshr, nstatev, nfieldv, nprops,
     1  lanneal, stepTime, totalTime, dt, cmname, coordMp, charLength,
     2  props, density, strainInc, relSpinInc, tempOld, stretchOld,
     3  defgradOld, fieldOld, stressOld, stateOld, enerInternOld,
     4  enerInelasOld, tempNew, stretchNew, defgradNew, fieldNew,
     5  stressNew, stateNew, enerInternNew, enerInelasNew)
      include 'vaba_param.inc'
      dimension strainInc(nblock,*), stressOld(nblock,*),
     1  stressNew(nblock,*)
      character*80 cmname
c     elastic, until t = 0.01: then a quiet NaN (its bit pattern: no
c     floating-point exception, so debug builds reach the host's check)
      integer*8 nanbits
      parameter (nanbits = -2251799813685248_8)
      do k = 1, nblock
         do j = 1, ndir + nshr
            stressNew(k,j) = stressOld(k,j) + 1.d7 * strainInc(k,j)
            if (totalTime .gt. 0.01d0) stressNew(k,j) =
     1         transfer(nanbits, 1.d0)
         end do
      end do
      return
      end
"""


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('case')
    p.add_argument('--bulkflow', required=True)
    p.add_argument('--matpoint', required=True)
    p.add_argument('--work', type=Path, required=True)
    p.add_argument('--abaqus-file')
    a = p.parse_args()
    if a.work.exists():
        shutil.rmtree(a.work)
    a.work.mkdir(parents=True)
    cases = {
        'probe_cpe4r_rotation': lambda: probe_elements(a, 2, (1, 1), [0.02, -0.01, 0], [0, 0, 1],
                                                       math.radians(50)),
        'probe_c3d8r_rotation': lambda: probe_elements(a, 3, (1, 1, 1), [0.02, -0.01, 0.015], [1, 2, 3],
                                                       math.radians(40)),
        'probe_cpe4r_block': lambda: probe_elements(a, 2, (12, 12), [0.02, -0.01, 0], [0, 0, 1], 0.0),
        'probe_c3d8r_block': lambda: probe_elements(a, 3, (6, 6, 4), [0.02, -0.01, 0.015], [0, 0, 1], 0.0),
        # CAX4R (x = r): the stretch's third entry is the hoop stretch u_r/r = a of u_r = a r
        'probe_cax4r_block': lambda: probe_elements(a, 2, (4, 4), [0.02, -0.01, 0.02], [0, 0, 1], 0.0, 'CAX4R'),
        'probe_mpm': lambda: probe_mpm(a),
        'probe_matpoint': lambda: probe_matpoint(a),
        'single_file_elements': lambda: single_file_elements(a),
        'single_file_mpm': lambda: single_file_mpm(a),
        'bad_compile': lambda: bad(a, BROKEN, 'broken.f', ['broken.f:3', 'did not compile']),
        'bad_no_vumat': lambda: bad(a, NO_VUMAT, 'no_vumat.f', ['defines no subroutine VUMAT']),
        'bad_nan': lambda: bad(a, NAN_VUMAT, 'nan_vumat.f', ['material SOIL', 'particle ', 'total time'],
                               scene=nan_scene(a)),
        'bad_nan_elements': lambda: bad(a, NAN_VUMAT, 'nan_vumat.f', ['material SOIL', 'element ', 'total time'],
                                        scene=nan_scene(a, elements=True)),
    }
    if a.case not in cases:
        p.error(f'unknown case {a.case}; expected one of {", ".join(cases)}')
    try:
        cases[a.case]()
    except Failed as exc:
        print(f'FAILED: {a.case}: {exc}')
        return 1
    print(f'OK: {a.case}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
