#!/usr/bin/env python3
"""Write the verification scenes of inputs/verification/ (issue 3 items 6-7).

    .venv/bin/python scripts/make_verification_scenes.py [--out inputs/verification]

Every scene is generated here so the meshes are reproducible; the generated .inp files are
committed too. Each scene starts with `** verify:` comment lines holding the parameters its
checker (tests/scenes/check_scene.py) needs: the checker reads them from the scene, so the
closed forms always use the numbers the solver ran with. inputs/verification/README.md lists
the scenes and their closed forms.

Standard library only (the meshes are small and regular, or fixed patch geometries).
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

# One elastic material for all scenes: E = 10 MPa, nu = 0.3, rho = 2000 kg/m^3:
# M = E(1-nu)/((1+nu)(1-2nu)) = 13.46 MPa, c_d = sqrt(M/rho) = 82.04 m/s, K0 = nu/(1-nu) = 0.4286.
RHO = 2000.0
E = 1.0e7
NU = 0.3
G = 9.81

# Stable-increment scale for meshes with free corners. The element increment L_e/c_d (fem_stable_dt,
# L_e = A / longest edge) is the exact limit of a large uniform mesh, but a free one-point element
# has a higher dilatational frequency: with lumped mass and nu = 0.3 the critical increment of a
# single free square is 0.837 h/c_d (cube: 0.734 h/c_d), of a free 2 x 2 block 0.969 h/c_d
# (2 x 2 x 2: 0.939) before the bulk-viscosity damping lowers it further. At SCALE FACTOR = 1 the
# 2 x 2 blocks below blow up from round-off (reported to the lead); 0.8 is stable.
FREE_BLOCK_SCALE = 0.8

# The blocks on the incline carry a moment (friction at the base, weight at the centre): with
# one-point elements part of it goes into the hourglass modes of the base row. With our default
# viscous hourglass control nothing resists a steady hourglass deformation, so a block that
# should stick creeps at a constant rate (2 x 2 block, 20 deg, mu 0.5: 0.5 mm/s, ALLAE 90 % of
# ALLIE) and a sliding one dissipates as much in hourglass as it stores. The stiffness form
# (Abaqus's default is a stiffness form too) holds the mode: ALLAE 3-5 % of ALLIE. Gravity is
# ramped in (smooth step over GRAVITY_RAMP) so the sudden load does not set the block ringing.
# Finer meshes are not better here: a sliding elastic body on a rigid plane with Coulomb friction
# is dynamically unstable (frictional flutter); from 3 x 3 elements up it chatters.
GRAVITY_RAMP = 0.05


def fmt(x: float) -> str:
    """A real for a data line: full precision, always with a dot or exponent."""
    text = repr(float(x))
    return text


class Scene:
    """Accumulates the lines of one .inp file."""

    def __init__(self, name: str, title: str, verify: dict[str, object], comment: list[str]):
        self.name = name
        self.lines: list[str] = []
        for c in comment:
            self.lines.append('** ' + c)
        for key, value in verify.items():
            self.lines.append(f'** verify: {key} = {value}')
        self.lines.append('*HEADING')
        self.lines.append(title)

    def add(self, *lines: str) -> None:
        self.lines.extend(lines)

    def nodes(self, coords: dict[int, tuple[float, ...]], nset: str | None = None) -> None:
        self.add('*NODE' + (f', NSET={nset}' if nset else ''))
        for n in sorted(coords):
            self.add(', '.join([str(n)] + [fmt(c) for c in coords[n]]))

    def elements(self, etype: str, conn: dict[int, tuple[int, ...]], elset: str) -> None:
        self.add(f'*ELEMENT, TYPE={etype}, ELSET={elset}')
        for e in sorted(conn):
            self.add(', '.join(str(v) for v in (e,) + tuple(conn[e])))

    def nset(self, name: str, members: list[int]) -> None:
        self.add(f'*NSET, NSET={name}')
        members = sorted(set(members))
        for i in range(0, len(members), 16):
            self.add(', '.join(str(m) for m in members[i:i + 16]))

    def elset(self, name: str, members: list[int]) -> None:
        self.add(f'*ELSET, ELSET={name}')
        members = sorted(set(members))
        for i in range(0, len(members), 16):
            self.add(', '.join(str(m) for m in members[i:i + 16]))

    def elastic_material(self, elset: str, thickness: float | None = None, name: str = 'SOLID',
                         hourglass: str | None = None) -> None:
        controls = ''
        if hourglass:
            self.add('*SECTION CONTROLS, NAME=HOURGLASS, HOURGLASS=' + hourglass)
            controls = ', CONTROLS=HOURGLASS'
        self.add(f'*SOLID SECTION, ELSET={elset}, MATERIAL={name}{controls}')
        self.add(fmt(thickness) if thickness is not None else ',')
        self.add(f'*MATERIAL, NAME={name}', '*DENSITY', fmt(RHO), '*ELASTIC', f'{fmt(E)}, {fmt(NU)}')

    def write(self, folder: Path) -> Path:
        path = folder / f'{self.name}.inp'
        path.write_text('\n'.join(self.lines) + '\n')
        return path


# ---------------------------------------------------------------------------------------------
# Structured meshes

def grid_2d(nx: int, ny: int, lx: float, ly: float, origin=(0.0, 0.0), frame=((1.0, 0.0), (0.0, 1.0))):
    """CPE4R grid; node (i, j) -> i + j (nx+1) + 1, element (i, j) -> i + j nx + 1, counter-clockwise.
    frame: unit vectors of the local x and y axes (a rotation keeps the node order counter-clockwise)."""
    (ax, ay), (bx, by) = frame
    nodes = {}
    for j in range(ny + 1):
        for i in range(nx + 1):
            xi, eta = lx * i / nx, ly * j / ny
            nodes[i + j * (nx + 1) + 1] = (origin[0] + xi * ax + eta * bx, origin[1] + xi * ay + eta * by)
    conn = {}
    for j in range(ny):
        for i in range(nx):
            n1 = i + j * (nx + 1) + 1
            conn[i + j * nx + 1] = (n1, n1 + 1, n1 + nx + 2, n1 + nx + 1)
    return nodes, conn


def node_2d(i: int, j: int, nx: int) -> int:
    return i + j * (nx + 1) + 1


def grid_3d(nx: int, ny: int, nz: int, lx: float, ly: float, lz: float, frame=None):
    """C3D8R grid; node (i, j, k) -> i + j (nx+1) + k (nx+1)(ny+1) + 1; nodes 1-4 the bottom face
    counter-clockwise seen from +z, 5-8 above. frame: local x, y, z unit vectors (right-handed)."""
    if frame is None:
        frame = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    nodes = {}
    for k in range(nz + 1):
        for j in range(ny + 1):
            for i in range(nx + 1):
                loc = (lx * i / nx, ly * j / ny, lz * k / nz)
                nodes[node_3d(i, j, k, nx, ny)] = tuple(sum(loc[a] * frame[a][d] for a in range(3)) for d in range(3))
    conn = {}
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                b = [node_3d(i, j, k, nx, ny), node_3d(i + 1, j, k, nx, ny), node_3d(i + 1, j + 1, k, nx, ny),
                     node_3d(i, j + 1, k, nx, ny)]
                t = [n + (nx + 1) * (ny + 1) for n in b]
                conn[i + j * nx + k * nx * ny + 1] = tuple(b + t)
    return nodes, conn


def node_3d(i: int, j: int, k: int, nx: int, ny: int) -> int:
    return i + j * (nx + 1) + k * (nx + 1) * (ny + 1) + 1


def wave_speed() -> float:
    m = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU))
    return math.sqrt(m / RHO)


# ---------------------------------------------------------------------------------------------
# 1. Elastic wave in a bar

def wave_bar_2d() -> Scene:
    nx, ny, length, height, v0 = 200, 2, 1.0, 0.01, 0.2
    c = wave_speed()
    h = length / nx
    period = 0.8 * length / c
    stations = (0.2, 0.6)
    s = Scene('wave_bar_2d', 'verification: 1D elastic wave in a plane-strain bar (CPE4R)',
              {'kind': 'wave', 'ndim': 2, 'rho': RHO, 'E': E, 'nu': NU, 'v0': v0, 'length': length,
               'stations': ' '.join(fmt(x) for x in stations), 'axis': 1, 'area': fmt(height * 1.0)},
              ['Plane-strain strip, lateral rollers (u2 = 0 on top and bottom), far end fixed; the',
               'end x = 0 is driven into the bar at v0 from t = 0: a compression front runs at',
               'c_d = sqrt(M/rho) with sigma_11 = -rho c_d v0 and particle velocity v0 behind it.',
               'Generated by scripts/make_verification_scenes.py.'])
    nodes, conn = grid_2d(nx, ny, length, height)
    s.nodes(nodes)
    s.elements('CPE4R', conn, 'BAR')
    s.nset('ALLN', list(nodes))
    s.nset('DRIVEN', [node_2d(0, j, nx) for j in range(ny + 1)])
    s.nset('FAR', [node_2d(nx, j, nx) for j in range(ny + 1)])
    s.nset('SIDES', [node_2d(i, j, nx) for i in range(nx + 1) for j in (0, ny)])
    for k, x in enumerate(stations):
        i = round(x / h)
        s.nset(f'STATION{k + 1}', [node_2d(i, j, nx) for j in range(ny + 1)])
    s.elastic_material('BAR', thickness=1.0)
    s.add('*BOUNDARY', 'SIDES, 2, 2', 'FAR, 1, 1')
    s.add('*STEP, NAME=WAVE', '*DYNAMIC, EXPLICIT', f', {fmt(period)}')
    s.add('*BOUNDARY, TYPE=VELOCITY', f'DRIVEN, 1, 1, {fmt(v0)}')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=4', '*NODE OUTPUT', 'U, V', '*ELEMENT OUTPUT', 'S')
    s.add(f'*OUTPUT, HISTORY, TIME INTERVAL={fmt(0.25 * h / c)}', '*ENERGY OUTPUT')
    s.add('*NODE OUTPUT, NSET=STATION1', 'V1, A1', '*NODE OUTPUT, NSET=STATION2', 'V1')
    s.add('*NODE OUTPUT, NSET=DRIVEN', 'RF1')
    s.add('*END STEP')
    return s


def wave_bar_3d() -> Scene:
    nx, nyz, length, width, v0 = 100, 2, 1.0, 0.02, 0.2
    c = wave_speed()
    h = length / nx
    period = 0.8 * length / c
    stations = (0.2, 0.6)
    s = Scene('wave_bar_3d', 'verification: 1D elastic wave in a bar (C3D8R)',
              {'kind': 'wave', 'ndim': 3, 'rho': RHO, 'E': E, 'nu': NU, 'v0': v0, 'length': length,
               'stations': ' '.join(fmt(x) for x in stations), 'axis': 1, 'area': fmt(width * width)},
              ['Square bar along x, lateral rollers (u2 = 0 on the y faces, u3 = 0 on the z faces), far',
               'end fixed; the end x = 0 is driven into the bar at v0: front at c_d = sqrt(M/rho),',
               'sigma_11 = -rho c_d v0, sigma_22 = sigma_33 = nu/(1-nu) sigma_11.',
               'Generated by scripts/make_verification_scenes.py.'])
    nodes, conn = grid_3d(nx, nyz, nyz, length, width, width)
    s.nodes(nodes)
    s.elements('C3D8R', conn, 'BAR')
    rng = range(nyz + 1)
    s.nset('DRIVEN', [node_3d(0, j, k, nx, nyz) for j in rng for k in rng])
    s.nset('FAR', [node_3d(nx, j, k, nx, nyz) for j in rng for k in rng])
    s.nset('YFACES', [node_3d(i, j, k, nx, nyz) for i in range(nx + 1) for j in (0, nyz) for k in rng])
    s.nset('ZFACES', [node_3d(i, j, k, nx, nyz) for i in range(nx + 1) for j in rng for k in (0, nyz)])
    for n, x in enumerate(stations):
        i = round(x / h)
        s.nset(f'STATION{n + 1}', [node_3d(i, j, k, nx, nyz) for j in rng for k in rng])
    s.elastic_material('BAR')
    s.add('*BOUNDARY', 'YFACES, 2, 2', 'ZFACES, 3, 3', 'FAR, 1, 1')
    s.add('*STEP, NAME=WAVE', '*DYNAMIC, EXPLICIT', f', {fmt(period)}')
    s.add('*BOUNDARY, TYPE=VELOCITY', f'DRIVEN, 1, 1, {fmt(v0)}')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=4', '*NODE OUTPUT', 'U, V', '*ELEMENT OUTPUT', 'S')
    s.add(f'*OUTPUT, HISTORY, TIME INTERVAL={fmt(0.25 * h / c)}', '*ENERGY OUTPUT')
    s.add('*NODE OUTPUT, NSET=STATION1', 'V1, A1', '*NODE OUTPUT, NSET=STATION2', 'V1')
    s.add('*NODE OUTPUT, NSET=DRIVEN', 'RF1')
    s.add('*END STEP')
    return s


# ---------------------------------------------------------------------------------------------
# 2. Gravity-loaded elastic column

def column_2d(name='column_2d', nx=4, ny=20, ramp_periods=10.0, hold_periods=2.0, ramp=True,
              restart=False) -> Scene:
    width, height = 0.2, 1.0
    c = wave_speed()
    t1 = 4 * height / c                      # fundamental period of the column
    t_ramp = ramp_periods * t1
    period = t_ramp + hold_periods * t1
    s = Scene(name, 'verification: gravity-loaded elastic column, plane strain (CPE4R)',
              {'kind': 'column', 'ndim': 2, 'rho': RHO, 'E': E, 'nu': NU, 'g': G, 'height': height,
               'settled': 'yes' if ramp else 'no'},
              ['Plane-strain column, lateral rollers (u1 = 0 on x = 0 and x = W), bottom on rollers',
               '(u2 = 0). Gravity ramped by a smooth step over ten fundamental periods 4H/c_d, then',
               'held: settled state sigma_22 = -rho g (H - y), sigma_11 = sigma_33 = nu/(1-nu) sigma_22.'
               if ramp else 'Gravity applied at once (a dynamic run, for rank and restart comparisons).',
               'Generated by scripts/make_verification_scenes.py.'])
    column_2d_mesh(s, 'CPE4R', nx, ny, width, height)
    s.elastic_material('COLUMN', thickness=1.0)
    if ramp:
        s.add('*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP', f'0., 0., {fmt(t_ramp)}, 1.')
    s.add('*BOUNDARY', 'LEFT, XSYMM', 'RIGHT, XSYMM', 'BOTTOM, YSYMM')
    s.add('*STEP, NAME=GRAVITY', '*DYNAMIC, EXPLICIT', f', {fmt(period)}')
    s.add('*DLOAD' + (', AMPLITUDE=RAMP' if ramp else ''), ', GRAV, 9.81, 0., -1.')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=10', '*NODE OUTPUT', 'U, V, RF', '*ELEMENT OUTPUT', 'S')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=200', '*ENERGY OUTPUT', '*NODE OUTPUT, NSET=TOP', 'U2')
    if restart:
        s.add('*RESTART, WRITE, NUMBER INTERVAL=5')
    s.add('*END STEP')
    return s


def column_2d_mesh(s: Scene, etype: str, nx: int, ny: int, width: float, height: float,
                   sides: tuple[str, str] = ('LEFT', 'RIGHT')) -> dict:
    """The column of column_2d (CPE4R) or column_cax4r (CAX4R): nodes, elements (ELSET COLUMN)
    and the node sets of its two sides, BOTTOM and TOP; returns the connectivity."""
    nodes, conn = grid_2d(nx, ny, width, height)
    s.nodes(nodes)
    s.elements(etype, conn, 'COLUMN')
    s.nset(sides[0], [node_2d(0, j, nx) for j in range(ny + 1)])
    s.nset(sides[1], [node_2d(nx, j, nx) for j in range(ny + 1)])
    s.nset('BOTTOM', [node_2d(i, 0, nx) for i in range(nx + 1)])
    s.nset('TOP', [node_2d(i, ny, nx) for i in range(nx + 1)])
    return conn


def column_3d_mesh(s: Scene, n_lat: int, nz: int, width: float, height: float) -> dict:
    """The square C3D8R column of column_3d: nodes, elements (ELSET COLUMN) and the node sets
    XFACES, YFACES, BOTTOM, TOP; returns the connectivity."""
    nodes, conn = grid_3d(n_lat, n_lat, nz, width, width, height)
    s.nodes(nodes)
    s.elements('C3D8R', conn, 'COLUMN')
    rng = range(n_lat + 1)
    s.nset('XFACES', [node_3d(i, j, k, n_lat, n_lat) for i in (0, n_lat) for j in rng for k in range(nz + 1)])
    s.nset('YFACES', [node_3d(i, j, k, n_lat, n_lat) for i in rng for j in (0, n_lat) for k in range(nz + 1)])
    s.nset('BOTTOM', [node_3d(i, j, 0, n_lat, n_lat) for i in rng for j in rng])
    s.nset('TOP', [node_3d(i, j, nz, n_lat, n_lat) for i in rng for j in rng])
    return conn


def column_3d() -> Scene:
    n_lat, nz, width, height = 2, 10, 0.2, 1.0
    c = wave_speed()
    t1 = 4 * height / c
    t_ramp = 10 * t1
    period = t_ramp + 2 * t1
    s = Scene('column_3d', 'verification: gravity-loaded elastic column (C3D8R)',
              {'kind': 'column', 'ndim': 3, 'rho': RHO, 'E': E, 'nu': NU, 'g': G, 'height': height,
               'settled': 'yes'},
              ['Square column along z, lateral rollers (u1 = 0 on the x faces, u2 = 0 on the y faces),',
               'bottom on rollers (u3 = 0). Gravity -z ramped by a smooth step over ten periods 4H/c_d,',
               'then held: sigma_33 = -rho g (H - z), sigma_11 = sigma_22 = nu/(1-nu) sigma_33.',
               'Generated by scripts/make_verification_scenes.py.'])
    column_3d_mesh(s, n_lat, nz, width, height)
    s.elastic_material('COLUMN')
    ramped_gravity_step(s, t_ramp, period, ['XFACES, XSYMM', 'YFACES, YSYMM', 'BOTTOM, ZSYMM'], 'GRAVITY', 3)
    return s


def ramped_gravity_step(s: Scene, t_ramp: float, period: float, bcs: list[str], step: str, ndim: int,
                        loads: tuple[str, ...] = ()) -> None:
    """The settled-column step: smooth-step amplitude RAMP, the boundary conditions, gravity
    (and `loads`) ramped with it, U, V, RF and S frames, energies and the top's settlement."""
    s.add('*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP', f'0., 0., {fmt(t_ramp)}, 1.')
    s.add('*BOUNDARY', *bcs)
    s.add(f'*STEP, NAME={step}', '*DYNAMIC, EXPLICIT', f', {fmt(period)}')
    s.add('*DLOAD, AMPLITUDE=RAMP', ', GRAV, 9.81, 0., 0., -1.' if ndim == 3 else ', GRAV, 9.81, 0., -1.')
    s.add(*loads)
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=10', '*NODE OUTPUT', 'U, V, RF', '*ELEMENT OUTPUT', 'S')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=200', '*ENERGY OUTPUT', '*NODE OUTPUT, NSET=TOP', f'U{ndim}')
    s.add('*END STEP')


# ---------------------------------------------------------------------------------------------
# 3. Block on a frictional incline

def incline_2d(name: str, alpha_deg: float, mu: float, n=2, period=0.4) -> Scene:
    size = 0.1
    a = math.radians(alpha_deg)
    t = (math.cos(a), -math.sin(a))          # down the slope
    nrm = (math.sin(a), math.cos(a))         # out of the slope, into the material
    accel = max(0.0, G * (math.sin(a) - mu * math.cos(a)))
    s = Scene(name, f'verification: block on a {alpha_deg:g} degree incline, mu = {mu:g} (CPE4R)',
              {'kind': 'incline', 'ndim': 2, 'rho': RHO, 'E': E, 'nu': NU, 'g': G, 'alpha': alpha_deg,
               'mu': mu, 'slope': f'{fmt(t[0])} {fmt(t[1])}', 'accel': fmt(accel), 'ramp': GRAVITY_RAMP,
               'mass': fmt(RHO * size * size)},
              [f'Elastic block, {n} x {n} elements, resting on an analytic rigid line through the origin',
               f'at {alpha_deg:g} degrees (TYPE=SEGMENTS, material on the left of travel), Coulomb',
               f'friction mu = {mu:g}, stiffness hourglass control, gravity -y ramped in over {GRAVITY_RAMP:g} s.',
               'Slides with a = g (sin a - mu cos a)'
               if accel > 0 else 'Sticks: tan(alpha) < mu.',
               'Generated by scripts/make_verification_scenes.py.'])
    nodes, conn = grid_2d(n, n, size, size, frame=(t, nrm))
    s.nodes(nodes)
    s.elements('CPE4R', conn, 'BLOCK')
    s.nset('BLOCKN', list(nodes))
    s.elset('BASE', [i + 1 for i in range(n)])
    s.elastic_material('BLOCK', thickness=1.0, hourglass='STIFFNESS')
    s.add('*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP', f'0., 0., {fmt(GRAVITY_RAMP)}, 1.')
    s.add('*SURFACE, NAME=BOTTOM', 'BASE, S1')
    s.add('*SURFACE, TYPE=SEGMENTS, NAME=SLOPE',
          f'START, {fmt(-0.5 * t[0])}, {fmt(-0.5 * t[1])}', f'LINE, {fmt(2.0 * t[0])}, {fmt(2.0 * t[1])}')
    s.add('*SURFACE INTERACTION, NAME=ROUGH', '*FRICTION', fmt(mu))
    s.add('*CONTACT PAIR, INTERACTION=ROUGH', 'BOTTOM, SLOPE')
    s.add('*STEP, NAME=SLIDE', f'*DYNAMIC, EXPLICIT, SCALE FACTOR={FREE_BLOCK_SCALE}', f', {fmt(period)}')
    s.add('*DLOAD, AMPLITUDE=RAMP', ', GRAV, 9.81, 0., -1.')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=4', '*NODE OUTPUT', 'U, V', '*ELEMENT OUTPUT', 'S')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=200', '*ENERGY OUTPUT', '*NODE OUTPUT, NSET=BLOCKN', 'U, V')
    s.add('*END STEP')
    return s


def incline_3d(name: str, alpha_deg: float, mu: float, n=2, period=0.4) -> Scene:
    size = 0.1
    a = math.radians(alpha_deg)
    t = (math.cos(a), 0.0, -math.sin(a))
    nrm = (math.sin(a), 0.0, math.cos(a))
    accel = max(0.0, G * (math.sin(a) - mu * math.cos(a)))
    s = Scene(name, f'verification: block on a {alpha_deg:g} degree incline, mu = {mu:g} (C3D8R)',
              {'kind': 'incline', 'ndim': 3, 'rho': RHO, 'E': E, 'nu': NU, 'g': G, 'alpha': alpha_deg,
               'mu': mu, 'slope': ' '.join(fmt(x) for x in t), 'accel': fmt(accel), 'ramp': GRAVITY_RAMP,
               'mass': fmt(RHO * size ** 3)},
              [f'Elastic cube, {n}^3 elements, on the analytic rigid plane through the origin with',
               f'normal (sin a, 0, cos a), a = {alpha_deg:g} degrees (TYPE=PLANE), Coulomb friction',
               f'mu = {mu:g}, stiffness hourglass control, gravity -z ramped in over {GRAVITY_RAMP:g} s:',
               'a = g (sin a - mu cos a) down the fall line.' if accel > 0 else 'sticks: tan(alpha) < mu.',
               'Generated by scripts/make_verification_scenes.py.'])
    nodes, conn = grid_3d(n, n, n, size, size, size, frame=(t, (0.0, 1.0, 0.0), nrm))
    s.nodes(nodes)
    s.elements('C3D8R', conn, 'BLOCK')
    s.nset('BLOCKN', list(nodes))
    s.elset('BASE', [i + 1 for i in range(n * n)])
    s.elastic_material('BLOCK', hourglass='STIFFNESS')
    s.add('*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP', f'0., 0., {fmt(GRAVITY_RAMP)}, 1.')
    s.add('*SURFACE, NAME=BOTTOM', 'BASE, S1')
    s.add('*SURFACE, TYPE=PLANE, NAME=SLOPE', '0., 0., 0.', ', '.join(fmt(x) for x in nrm))
    s.add('*SURFACE INTERACTION, NAME=ROUGH', '*FRICTION', fmt(mu))
    s.add('*CONTACT PAIR, INTERACTION=ROUGH', 'BOTTOM, SLOPE')
    s.add('*STEP, NAME=SLIDE', f'*DYNAMIC, EXPLICIT, SCALE FACTOR={FREE_BLOCK_SCALE}', f', {fmt(period)}')
    s.add('*DLOAD, AMPLITUDE=RAMP', ', GRAV, 9.81, 0., 0., -1.')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=4', '*NODE OUTPUT', 'U, V', '*ELEMENT OUTPUT', 'S')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=200', '*ENERGY OUTPUT', '*NODE OUTPUT, NSET=BLOCKN', 'U, V')
    s.add('*END STEP')
    return s


# ---------------------------------------------------------------------------------------------
# 4. Patch tests

PATCH_2D_NODES = {1: (0.0, 0.0), 2: (0.24, 0.0), 3: (0.24, 0.12), 4: (0.0, 0.12),
                  5: (0.04, 0.02), 6: (0.18, 0.03), 7: (0.16, 0.08), 8: (0.08, 0.08)}
PATCH_2D_CONN = {1: (1, 2, 6, 5), 2: (2, 3, 7, 6), 3: (3, 4, 8, 7), 4: (4, 1, 5, 8), 5: (5, 6, 7, 8)}

# MacNeal & Harder (1985) 3D patch geometry: unit cube, seven hexahedra around an irregular inner
# one. Their inner nodes (MH below) leave a corner Jacobian of the y = 0 side element slightly
# negative (-0.013 at node 13), which our inversion check rightly rejects; the inner nodes here
# are moved halfway towards the regular cube [0.25, 0.75]^3 (smallest corner Jacobian 0.025).
_MH_INNER = {9: (0.249, 0.342, 0.192), 10: (0.826, 0.288, 0.288), 11: (0.850, 0.649, 0.263),
             12: (0.273, 0.750, 0.230), 13: (0.320, 0.186, 0.643), 14: (0.677, 0.305, 0.683),
             15: (0.788, 0.693, 0.644), 16: (0.165, 0.745, 0.702)}
_REGULAR_INNER = {9: (0.25, 0.25, 0.25), 10: (0.75, 0.25, 0.25), 11: (0.75, 0.75, 0.25),
                  12: (0.25, 0.75, 0.25), 13: (0.25, 0.25, 0.75), 14: (0.75, 0.25, 0.75),
                  15: (0.75, 0.75, 0.75), 16: (0.25, 0.75, 0.75)}
PATCH_3D_NODES = {1: (0.0, 0.0, 0.0), 2: (1.0, 0.0, 0.0), 3: (1.0, 1.0, 0.0), 4: (0.0, 1.0, 0.0),
                  5: (0.0, 0.0, 1.0), 6: (1.0, 0.0, 1.0), 7: (1.0, 1.0, 1.0), 8: (0.0, 1.0, 1.0)}
PATCH_3D_NODES.update({n: tuple(round(0.5 * (a + b), 4) for a, b in zip(_MH_INNER[n], _REGULAR_INNER[n]))
                       for n in _MH_INNER})
PATCH_3D_CONN = {1: (9, 10, 11, 12, 13, 14, 15, 16),      # inner
                 2: (1, 2, 3, 4, 9, 10, 11, 12),          # bottom
                 3: (13, 14, 15, 16, 5, 6, 7, 8),         # top
                 4: (1, 2, 10, 9, 5, 6, 14, 13),          # y = 0 side
                 5: (2, 3, 11, 10, 6, 7, 15, 14),         # x = 1 side
                 6: (3, 4, 12, 11, 7, 8, 16, 15),         # y = 1 side
                 7: (4, 1, 9, 12, 8, 5, 13, 16)}          # x = 0 side


def quad_area(p):
    return 0.5 * ((p[2][0] - p[0][0]) * (p[3][1] - p[1][1]) - (p[3][0] - p[1][0]) * (p[2][1] - p[0][1]))


def hex_corner_jacobians(p):
    """det of the three edges at each corner (positive for a valid Abaqus-ordered hexahedron)."""
    nbr = {0: (1, 3, 4), 1: (2, 0, 5), 2: (3, 1, 6), 3: (0, 2, 7), 4: (7, 5, 0), 5: (4, 6, 1), 6: (5, 7, 2),
           7: (6, 4, 3)}
    dets = []
    for i, (a, b, c) in nbr.items():
        u = [p[a][d] - p[i][d] for d in range(3)]
        v = [p[b][d] - p[i][d] for d in range(3)]
        w = [p[c][d] - p[i][d] for d in range(3)]
        dets.append(u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                    + u[2] * (v[0] * w[1] - v[1] * w[0]))
    return dets


def fix_hex_orientation(conn, nodes):
    out = {}
    for e, c in conn.items():
        dets = hex_corner_jacobians([nodes[n] for n in c])
        if min(dets) < 0:
            c = c[4:] + c[:4]            # swap the two faces: reverses the orientation
            dets = hex_corner_jacobians([nodes[n] for n in c])
        if min(dets) <= 0:
            raise ValueError(f'patch element {e} is not a valid hexahedron: {dets}')
        out[e] = c
    return out


def patch(ndim: int, plastic: bool = False) -> Scene:
    # A symmetric velocity gradient L: the motion x = (I + L t) X is homogeneous, F = I + L t is
    # symmetric positive definite, so R = I and the corotational strain is log(I + L t).
    if ndim == 2:
        nodes, conn = PATCH_2D_NODES, PATCH_2D_CONN
        for e, c in conn.items():
            if quad_area([nodes[n] for n in c]) <= 0:
                raise ValueError(f'patch element {e} is clockwise')
        grad = [[0.010, 0.004], [0.004, -0.006]]
        etype, name, boundary_nodes = 'CPE4R', 'patch_2d', [1, 2, 3, 4]
        if plastic:
            grad = [[0.004, 0.006], [0.006, -0.012]]
    else:
        nodes, conn = PATCH_3D_NODES, fix_hex_orientation(PATCH_3D_CONN, PATCH_3D_NODES)
        grad = [[0.010, 0.004, -0.002], [0.004, -0.006, 0.003], [-0.002, 0.003, 0.005]]
        etype, name, boundary_nodes = 'C3D8R', 'patch_3d', list(range(1, 9))
        if plastic:
            grad = [[0.004, 0.006, -0.002], [0.006, -0.012, 0.003], [-0.002, 0.003, 0.003]]
    if plastic:
        name = name.replace('patch', 'patch_plastic')
    # Strains of ~2e-3 over ~70 (3D) to ~800 (2D) increments: the midpoint rule of the strain
    # increments differs from log(I + L t) by ~(L dt)^2/24 relative, ~1e-11 here.
    period = 0.2
    flat = ' '.join(fmt(grad[i][j]) for i in range(ndim) for j in range(ndim))
    if plastic:
        s = Scene(name, f'verification: plastic strain PE in a yielding patch, distorted {etype} mesh',
                  {'kind': 'plastic_patch', 'ndim': ndim, 'rho': RHO, 'E': E, 'nu': NU, 'grad': flat,
                   'period': period, 'boundary': ' '.join(str(n) for n in boundary_nodes)},
                  ['The patch of patch_2d/3d in Mohr-Coulomb with cohesion and dilation (phi 30, psi 10,',
                   'c 5 kPa), driven by a homogeneous motion that compresses and shears it through yield.',
                   'PE is integrated by the driver as de - C^-1 dsigma; the material integrates its own',
                   'volumetric plastic strain EVP (SDV2) inside the return: tr PE must equal SDV2, PE must',
                   'be uniform and equal LE - C^-1 sigma (no initial stress), and PEEQ > 0.',
                   'Generated by scripts/make_verification_scenes.py.'])
    else:
        s = Scene(name, f'verification: constant-strain patch test, distorted {etype} mesh',
                  {'kind': 'patch', 'ndim': ndim, 'rho': RHO, 'E': E, 'nu': NU, 'grad': flat, 'period': period,
                   'boundary': ' '.join(str(n) for n in boundary_nodes)},
                  ['Distorted patch (MacNeal-Harder geometry); every node starts with v = L X and the',
                   'boundary nodes keep it (velocity BCs): the exact motion is homogeneous, x = (I + L t) X,',
                   'with uniform stress sigma = lambda tr(E) I + 2 G E, E = log(I + L t) (L symmetric, so',
                   'R = I). Bulk viscosity off: its pressure depends on the element length, not uniform.',
                   'Generated by scripts/make_verification_scenes.py.'])
    s.nodes(nodes)
    s.elements(etype, conn, 'PATCH')
    if plastic:
        s.add('*SOLID SECTION, ELSET=PATCH, MATERIAL=SAND', fmt(1.0) if ndim == 2 else ',')
        s.add('*MATERIAL, NAME=SAND', '*DENSITY', fmt(RHO), '*ELASTIC', f'{fmt(E)}, {fmt(NU)}',
              '*MOHR COULOMB', '30., 10.', '*MOHR COULOMB HARDENING', '5000., 0.', '*DEPVAR', '8')
    else:
        s.elastic_material('PATCH', thickness=1.0 if ndim == 2 else None)
    s.add('*INITIAL CONDITIONS, TYPE=VELOCITY')
    vel = {}
    for n in sorted(nodes):
        x = nodes[n]
        vel[n] = [sum(grad[i][j] * x[j] for j in range(ndim)) for i in range(ndim)]
        for i in range(ndim):
            s.add(f'{n}, {i + 1}, {fmt(vel[n][i])}')
    s.add('*STEP, NAME=STRETCH', '*DYNAMIC, EXPLICIT', f', {fmt(period)}')
    s.add('*BULK VISCOSITY', '0., 0.')
    s.add('*BOUNDARY, TYPE=VELOCITY')
    for n in boundary_nodes:
        for i in range(ndim):
            s.add(f'{n}, {i + 1}, {i + 1}, {fmt(vel[n][i])}')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=2', '*NODE OUTPUT', 'U, V, A', '*ELEMENT OUTPUT',
          'S, LE, PE, PEEQ, SDV' if plastic else 'S, LE, PE')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=50', '*ENERGY OUTPUT')
    s.add('*END STEP')
    return s


# ---------------------------------------------------------------------------------------------
# 8. Inverted element

def inverted_2d() -> Scene:
    s = Scene('inverted_2d', 'verification: an element crushed against a rigid floor',
              {'kind': 'inverted', 'ndim': 2, 'element': 2},
              ['Two elements thrown at 2000 m/s onto a rigid floor: the bottom nodes stop on the floor,',
               'the top ones do not, so the elements invert within an increment or two. The run must',
               'stop with the element, the time and the reason, a non-zero exit status and no NaN.',
               'Generated by scripts/make_verification_scenes.py.'])
    nodes, conn = grid_2d(2, 1, 0.2, 0.1)
    s.nodes(nodes)
    s.elements('CPE4R', conn, 'BLOCK')
    s.nset('ALLN', list(nodes))
    s.elastic_material('BLOCK', thickness=1.0)
    s.add('*SURFACE, NAME=BOTTOM', 'BLOCK, S1')
    s.add('*SURFACE, TYPE=SEGMENTS, NAME=FLOOR', 'START, -1., 0.', 'LINE, 1., 0.')
    s.add('*SURFACE INTERACTION, NAME=SMOOTH')
    s.add('*CONTACT PAIR, INTERACTION=SMOOTH', 'BOTTOM, FLOOR')
    s.add('*INITIAL CONDITIONS, TYPE=VELOCITY', 'ALLN, 2, -2000.')
    s.add('*STEP, NAME=CRASH', '*DYNAMIC, EXPLICIT', ', 0.01')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=10', '*NODE OUTPUT', 'U, V', '*ELEMENT OUTPUT', 'S')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=100', '*ENERGY OUTPUT')
    s.add('*END STEP')
    return s


# ---------------------------------------------------------------------------------------------
# Rigid rotation of a stretched element (corotational stress update and output frames)

def rotation(ndim: int) -> Scene:
    """One element, every node prescribed: step 1 stretches it along x by STRETCH (linear ramp),
    step 2 rotates it rigidly by 90 degrees about z (per-node tabular amplitudes, 201 points).
    The stretch then lies along y: LE = log(1 + STRETCH) e_y (x) e_y, sigma = lambda tr LE I +
    2 G LE, in global components."""
    # The last increment of step 1 is shortened to end the step, and the supports change speed
    # there: the scene also checks the energy balance across a change of increment.
    stretch, t_stretch, t_rotate, points = 0.01, 0.01, 0.2, 201
    size = 0.1
    if ndim == 2:
        nodes, conn = grid_2d(1, 1, size, size)
        etype = 'CPE4R'
    else:
        nodes, conn = grid_3d(1, 1, 1, size, size, size)
        etype = 'C3D8R'
    name = f'rotation_{ndim}d'
    s = Scene(name, f'verification: stretch, then a rigid 90 degree rotation ({etype})',
              {'kind': 'rotation', 'ndim': ndim, 'rho': RHO, 'E': E, 'nu': NU, 'stretch': stretch},
              [f'One {etype} element, all nodes prescribed. Step 1: stretch 1 + {stretch:g} along x;',
               'step 2: rigid rotation by 90 degrees about z (tabular amplitude per node and dof).',
               'Afterwards LE = log(1 + stretch) along y and sigma = lambda tr LE I + 2 G LE, both in',
               'global components: checks the corotational stress update and the output frames.',
               'Generated by scripts/make_verification_scenes.py.'])
    s.nodes(nodes)
    s.elements(etype, conn, 'ONE')
    s.elastic_material('ONE', thickness=1.0 if ndim == 2 else None)
    s.add('*AMPLITUDE, NAME=LINEAR', f'0., 0., {fmt(t_stretch)}, 1.')
    for n in sorted(nodes):
        x, y = nodes[n][0], nodes[n][1]
        for d in (1, 2):
            values = []
            for k in range(points):
                th = 0.5 * math.pi * k / (points - 1)
                xs = (1 + stretch) * x
                pos = (math.cos(th) * xs - math.sin(th) * y, math.sin(th) * xs + math.cos(th) * y)
                values.append((t_rotate * k / (points - 1), pos[d - 1] - (x, y)[d - 1]))
            s.add(f'*AMPLITUDE, NAME=R{n}_{d}')
            for i in range(0, points, 4):
                s.add(', '.join(f'{fmt(t)}, {fmt(v)}' for t, v in values[i:i + 4]))
    s.add('*STEP, NAME=STRETCH', '*DYNAMIC, EXPLICIT', f', {fmt(t_stretch)}')
    s.add('*BOUNDARY, AMPLITUDE=LINEAR')
    for n in sorted(nodes):
        s.add(f'{n}, 1, 1, {fmt(stretch * nodes[n][0])}', f'{n}, 2, 2, 0.')
        if ndim == 3:
            s.add(f'{n}, 3, 3, 0.')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=2', '*NODE OUTPUT', 'U', '*ELEMENT OUTPUT', 'S, LE')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=20', '*ENERGY OUTPUT')
    s.add('*END STEP')
    s.add('*STEP, NAME=ROTATE', '*DYNAMIC, EXPLICIT', f', {fmt(t_rotate)}')
    for n in sorted(nodes):
        for d in (1, 2):
            s.add(f'*BOUNDARY, AMPLITUDE=R{n}_{d}', f'{n}, {d}, {d}, 1.')
    s.add('*END STEP')
    return s


# ---------------------------------------------------------------------------------------------
# Hourglass control per section

def hourglass_sections_2d() -> Scene:
    """Two separate elements with different section controls: the first section (viscous, the
    default) on an element at rest, the second (stiffness) on an element whose nodes start in the
    hourglass mode h = (1, -1, 1, -1). Stiffness control stores the mode's energy and gives it
    back (ALLAE rises and falls); had the first section's form been used for both (the driver
    did that), ALLAE would only grow."""
    v0 = 0.1
    s = Scene('hourglass_sections_2d', 'verification: hourglass control taken from each element\'s section',
              {'kind': 'sections', 'ndim': 2, 'v0': v0},
              ['Element 1 (viscous hourglass, the first section) at rest; element 2 (stiffness',
               'hourglass, the second section) with its nodes moving in the hourglass mode',
               'h = (1, -1, 1, -1) along x: the mode oscillates, ALLAE rises and falls.',
               'Generated by scripts/make_verification_scenes.py.'])
    nodes = {1: (0.0, 0.0), 2: (0.1, 0.0), 3: (0.1, 0.1), 4: (0.0, 0.1),
             5: (1.0, 0.0), 6: (1.1, 0.0), 7: (1.1, 0.1), 8: (1.0, 0.1)}
    s.nodes(nodes)
    s.elements('CPE4R', {1: (1, 2, 3, 4), 2: (5, 6, 7, 8)}, 'ALLE')
    s.elset('VISCOUS', [1])
    s.elset('STIFF', [2])
    s.add('*SOLID SECTION, ELSET=VISCOUS, MATERIAL=SOLID', '1.0')
    s.add('*SECTION CONTROLS, NAME=HGSTIFF, HOURGLASS=STIFFNESS')
    s.add('*SOLID SECTION, ELSET=STIFF, MATERIAL=SOLID, CONTROLS=HGSTIFF', '1.0')
    s.add('*MATERIAL, NAME=SOLID', '*DENSITY', fmt(RHO), '*ELASTIC', f'{fmt(E)}, {fmt(NU)}')
    s.add('*INITIAL CONDITIONS, TYPE=VELOCITY')
    for n, sign in zip((5, 6, 7, 8), (1, -1, 1, -1)):
        s.add(f'{n}, 1, {fmt(sign * v0)}')
    # Single free elements: critical increment 0.837 h/c_d (see FREE_BLOCK_SCALE), hence 0.7.
    s.add('*STEP, NAME=RING', '*DYNAMIC, EXPLICIT, SCALE FACTOR=0.7', ', 0.02')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=4', '*NODE OUTPUT', 'U, V', '*ELEMENT OUTPUT', 'S')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=400', '*ENERGY OUTPUT')
    s.add('*END STEP')
    return s


# ---------------------------------------------------------------------------------------------
# 6.-7. Rank agreement and restart: dynamic scenes with every kind of state

def restart_2d() -> Scene:
    """Mohr-Coulomb sand (angle table on a user field: VUSDFLD + state variables) on a rough
    floor driven by a moving rigid body, gravity, a lid pushed by a velocity BC; checkpoints."""
    nx, ny, size = 4, 4, 0.2
    s = Scene('restart_2d', 'verification: restart and rank agreement, MC sand on a moving rough floor',
              {'kind': 'dynamic', 'ndim': 2},
              ['Mohr-Coulomb block (friction angle table against the VUSDFLD field) under an elastic top',
               'row (a second material, without state variables), with initial stress on',
               'a rough rigid floor. Step 1: gravity ramped in; step 2: the floor (a rigid body) is moved',
               'sideways and the lid pushed down: plastic flow, sliding and state variables, to compare',
               'runs on 1-4 ranks and runs interrupted and restarted (also across the step boundary).',
               'Generated by scripts/make_verification_scenes.py.'])
    nodes, conn = grid_2d(nx, ny, size, size)
    nodes[1000] = (0.1, -0.1)
    s.nodes(nodes)
    s.elements('CPE4R', conn, 'SAND')
    s.nset('LID', [node_2d(i, ny, nx) for i in range(nx + 1)])
    s.nset('ALLN', [n for n in nodes if n != 1000])
    s.elset('BASE', [i + 1 for i in range(nx)])
    # The top row is a second, elastic material without state variables: blocks of two
    # materials with different *DEPVAR counts (8 and none).
    s.elset('CAP', [i + 1 + nx * (ny - 1) for i in range(nx)])
    s.elset('BELOW', [i + 1 for i in range(nx * (ny - 1))])
    s.add('*SOLID SECTION, ELSET=BELOW, MATERIAL=SAND', '1.0')
    s.add('*SOLID SECTION, ELSET=CAP, MATERIAL=CAP', '1.0')
    s.add('*MATERIAL, NAME=CAP', '*DENSITY', fmt(RHO), '*ELASTIC', f'{fmt(2 * E)}, {fmt(NU)}')
    s.add('*MATERIAL, NAME=SAND', '*DENSITY', fmt(RHO), '*ELASTIC', f'{fmt(E)}, {fmt(NU)}',
          '*MOHR COULOMB, DEPENDENCIES=1', '30., 5., , -0.01', '35., 8., , 0.', '40., 10., , 0.01',
          '*MOHR COULOMB HARDENING', '2000., 0.', '*DEPVAR', '8', '*USER DEFINED FIELD')
    s.add('*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP, TIME=TOTAL TIME', '0., 0., 0.01, 1.')
    s.add('*AMPLITUDE, NAME=PUSH, DEFINITION=SMOOTH STEP, TIME=STEP TIME', '0., 0., 0.005, 1.')
    s.add('*SURFACE, NAME=BOTTOM', 'BASE, S1')
    s.add('*SURFACE, TYPE=SEGMENTS, NAME=FLOOR', 'START, -1., 0.', 'LINE, 1., 0.')
    s.add('*RIGID BODY, REF NODE=1000, ANALYTICAL SURFACE=FLOOR')
    s.add('*SURFACE INTERACTION, NAME=ROUGH', '*FRICTION', '0.4')
    s.add('*CONTACT PAIR, INTERACTION=ROUGH', 'BOTTOM, FLOOR')
    s.add('*INITIAL CONDITIONS, TYPE=STRESS', 'SAND, -2000., -4000., -2000., 0.')
    s.add('*STEP, NAME=SETTLE', f'*DYNAMIC, EXPLICIT, SCALE FACTOR={FREE_BLOCK_SCALE}', ', 0.02')
    s.add('*BOUNDARY', '1000, 1, 2')
    s.add('*DLOAD, AMPLITUDE=RAMP', ', GRAV, 9.81, 0., -1.')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=4', '*NODE OUTPUT', 'U, V, A, RF', '*ELEMENT OUTPUT', 'S, SDV, FV, PE')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=20', '*ENERGY OUTPUT', '*NODE OUTPUT, NSET=LID', 'RF2, U2')
    s.add('*RESTART, WRITE, NUMBER INTERVAL=4')
    s.add('*END STEP')
    s.add('*STEP, NAME=PUSH', f'*DYNAMIC, EXPLICIT, SCALE FACTOR={FREE_BLOCK_SCALE}', ', 0.03')
    s.add('*BOUNDARY, TYPE=VELOCITY, AMPLITUDE=PUSH', '1000, 1, 1, 0.5', 'LID, 2, 2, -0.3')
    s.add('*END STEP')
    return s


def mpi_column_2d() -> Scene:
    return column_2d(name='mpi_column_2d', nx=6, ny=16, ramp=False, ramp_periods=0.0, hold_periods=1.0)


def mpi_column_3d() -> Scene:
    s = column_3d()
    return s


# ---------------------------------------------------------------------------------------------
# 10. CAX4R axisymmetric elements (x = r, y = z; docs/theory/elements.md §3.10)

def lame_cax4r(nr=24, inner=0.1, outer=0.2, ramp_periods=20.0, hold_periods=4.0) -> Scene:
    # Thick-walled cylinder in plane strain (top and bottom on rollers, u_z = 0), internal
    # pressure p on the bore (*DSLOAD on the S4 edges, smooth step), outer surface free. Lame:
    # u = A r + B/r, sigma_r = 2(lam+G)A - 2G B/r^2, sigma_theta = 2(lam+G)A + 2G B/r^2.
    c = wave_speed()
    t1 = 4 * (outer - inner) / c
    t_ramp = ramp_periods * t1
    period = t_ramp + hold_periods * t1
    pressure = 1.0e3
    height = (outer - inner) / nr
    s = Scene('lame_cax4r', 'verification: pressurised thick-walled cylinder (Lame), CAX4R',
              {'kind': 'lame', 'ndim': 2, 'rho': RHO, 'E': E, 'nu': NU, 'inner': inner, 'outer': outer,
               'pressure': pressure},
              ['Thick-walled cylinder a < r < b, one row of CAX4R elements, top and bottom on rollers',
               '(plane strain along z), internal pressure p on the bore (*DSLOAD, smooth step over twenty',
               'periods 4(b-a)/c_d, then held), outer surface free: Lame.',
               'Generated by scripts/make_verification_scenes.py.'])
    nodes, conn = grid_2d(nr, 1, outer - inner, height, origin=(inner, 0.0))
    s.nodes(nodes)
    s.elements('CAX4R', conn, 'WALL')
    s.add('*SURFACE, TYPE=ELEMENT, NAME=BORE', '1, S4')
    s.nset('OUTSIDE', [node_2d(nr, j, nr) for j in range(2)])
    s.nset('BOTTOM', [node_2d(i, 0, nr) for i in range(nr + 1)])
    s.nset('TOP', [node_2d(i, 1, nr) for i in range(nr + 1)])
    s.elastic_material('WALL')
    s.add('*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP', f'0., 0., {fmt(t_ramp)}, 1.')
    s.add('*BOUNDARY', 'BOTTOM, YSYMM', 'TOP, YSYMM')
    s.add('*STEP, NAME=PRESSURISE', '*DYNAMIC, EXPLICIT', f', {fmt(period)}')
    s.add('*DSLOAD, AMPLITUDE=RAMP', f'BORE, P, {fmt(pressure)}')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=10', '*NODE OUTPUT', 'U, RF', '*ELEMENT OUTPUT', 'S')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=50', '*ENERGY OUTPUT', '*NODE OUTPUT, NSET=OUTSIDE', 'U1')
    s.add('*END STEP')
    return s


def column_cax4r(name='column_cax4r', mohr_coulomb=False, nr=4, nz=20) -> Scene:
    radius, height = 0.2, 1.0
    c = wave_speed()
    t1 = 4 * height / c
    t_ramp = 10 * t1
    period = t_ramp + 2 * t1
    material = 'Mohr-Coulomb (phi 30, psi 0, c 1 kPa: K0 stays above the active limit)' if mohr_coulomb \
        else 'elastic'
    s = Scene(name, f'verification: gravity-loaded axisymmetric column (CAX4R), {material}',
              {'kind': 'column', 'ndim': 2, 'rho': RHO, 'E': E, 'nu': NU, 'g': G, 'height': height,
               'settled': 'yes'},
              ['Axisymmetric column 0 < r < R, nodes on the axis and on r = R on radial rollers, bottom on',
               'rollers. Gravity ramped by a smooth step over ten periods 4H/c_d, then held: settled state',
               'sigma_z = -rho g (H - z), sigma_r = sigma_theta = nu/(1-nu) sigma_z (K0).',
               f'Material: {material}' + ('; stiffness hourglass control.' if mohr_coulomb else '.'),
               'Generated by scripts/make_verification_scenes.py.'])
    column_2d_mesh(s, 'CAX4R', nr, nz, radius, height, sides=('AXIS', 'WALL'))
    if mohr_coulomb:
        # the stiffness hourglass form of *SECTION CONTROLS (the elastic column has the viscous default)
        s.add('*SECTION CONTROLS, NAME=HOURGLASS, HOURGLASS=STIFFNESS')
        s.add('*SOLID SECTION, ELSET=COLUMN, MATERIAL=SAND, CONTROLS=HOURGLASS', ',')
        s.add('*MATERIAL, NAME=SAND', '*DENSITY', fmt(RHO), '*ELASTIC', f'{fmt(E)}, {fmt(NU)}',
              '*MOHR COULOMB', '30., 0.', '*MOHR COULOMB HARDENING', '1000., 0.', '*DEPVAR', '8')
    else:
        s.elastic_material('COLUMN')
    ramped_gravity_step(s, t_ramp, period, ['AXIS, XSYMM', 'WALL, XSYMM', 'BOTTOM, YSYMM'], 'GRAVITY', 2)
    return s


def patch_cax4r() -> Scene:
    # u_r = a r, u_z = c z: the only linear fields with a uniform axisymmetric strain (a shear
    # u_z = d r would be uniform too, but its uniform stress is not in equilibrium: d(sigma_rz)/dr
    # + sigma_rz / r != 0). Nodes 1 and 4 lie on the axis.
    nodes, conn = PATCH_2D_NODES, PATCH_2D_CONN
    grad = [[0.010, 0.0], [0.0, -0.006]]
    period = 0.2
    flat = ' '.join(fmt(grad[i][j]) for i in range(2) for j in range(2))
    boundary_nodes = [1, 2, 3, 4]
    s = Scene('patch_cax4r', 'verification: constant-strain axisymmetric patch test, distorted CAX4R mesh',
              {'kind': 'patch', 'ndim': 2, 'axisymmetric': 'yes', 'rho': RHO, 'E': E, 'nu': NU, 'grad': flat,
               'period': period, 'boundary': ' '.join(str(n) for n in boundary_nodes)},
              ['The distorted patch of patch_2d as a CAX4R ring section (x = r, nodes 1 and 4 on the axis);',
               'every node starts with v_r = a r, v_z = c z and the corners keep it: the exact motion is',
               'homogeneous with E = diag(log(1 + a t), log(1 + c t), log(1 + a t)) (rr, zz, theta theta),',
               'sigma_rr = sigma_theta theta, uniform. Bulk viscosity off (its pressure depends on L_e).',
               'Generated by scripts/make_verification_scenes.py.'])
    s.nodes(nodes)
    s.elements('CAX4R', conn, 'PATCH')
    s.elastic_material('PATCH')
    s.add('*INITIAL CONDITIONS, TYPE=VELOCITY')
    vel = {}
    for n in sorted(nodes):
        x = nodes[n]
        vel[n] = [sum(grad[i][j] * x[j] for j in range(2)) for i in range(2)]
        for i in range(2):
            s.add(f'{n}, {i + 1}, {fmt(vel[n][i])}')
    s.add('*STEP, NAME=STRETCH', '*DYNAMIC, EXPLICIT', f', {fmt(period)}')
    s.add('*BULK VISCOSITY', '0., 0.')
    s.add('*BOUNDARY, TYPE=VELOCITY')
    for n in boundary_nodes:
        for i in range(2):
            s.add(f'{n}, {i + 1}, {i + 1}, {fmt(vel[n][i])}')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=2', '*NODE OUTPUT', 'U, V, A', '*ELEMENT OUTPUT', 'S, LE, PE')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=50', '*ENERGY OUTPUT')
    s.add('*END STEP')
    return s


def column_surcharge(etype: str, q=5.0e3) -> Scene:
    # A column of column_2d/3d/cax4r under gravity and a surcharge pressure q on its top
    # (*DSLOAD on the top faces, the same smooth step): sigma_v = -rho g (H - y) - q, K0 as before.
    # CPE4R with thickness 0.5 (the pressure forces scale with it like the masses); CAX4R needs
    # the 2 pi r weighting along the top edges for a sigma_z uniform in r.
    height = 1.0
    c = wave_speed()
    t1 = 4 * height / c
    t_ramp = 10 * t1
    period = t_ramp + 2 * t1
    name = {'CPE4R': 'column_surcharge_2d', 'C3D8R': 'column_surcharge_3d', 'CAX4R': 'column_surcharge_cax4r'}[etype]
    ndim = 3 if etype == 'C3D8R' else 2
    s = Scene(name, f'verification: gravity and a top surcharge pressure on an elastic column ({etype})',
              {'kind': 'column', 'ndim': ndim, 'rho': RHO, 'E': E, 'nu': NU, 'g': G, 'height': height,
               'settled': 'yes', 'surcharge': q},
              [f'The column of column_{"3d" if ndim == 3 else ("cax4r" if etype == "CAX4R" else "2d")} with a '
               'pressure q on its top faces (*DSLOAD, P) ramped with gravity:',
               'sigma_v = -rho g (H - y) - q, horizontal stresses nu/(1-nu) sigma_v, top settlement',
               '(rho g H^2/2 + q H)/M. Generated by scripts/make_verification_scenes.py.'])
    if ndim == 2:
        nx, ny, width = 4, 20, 0.2
        column_2d_mesh(s, etype, nx, ny, width, height)
        s.elset('TOPROW', [i + (ny - 1) * nx + 1 for i in range(nx)])
        s.elastic_material('COLUMN', thickness=0.5 if etype == 'CPE4R' else None)
        s.add('*SURFACE, TYPE=ELEMENT, NAME=LID', 'TOPROW, S3')
        bcs = ['LEFT, XSYMM', 'RIGHT, XSYMM', 'BOTTOM, YSYMM']
    else:
        n_lat, nz, width = 2, 10, 0.2
        conn = column_3d_mesh(s, n_lat, nz, width, height)
        s.elset('TOPROW', [e for e in conn if e > (nz - 1) * n_lat * n_lat])
        s.elastic_material('COLUMN')
        s.add('*SURFACE, TYPE=ELEMENT, NAME=LID', 'TOPROW, S2')
        bcs = ['XFACES, XSYMM', 'YFACES, YSYMM', 'BOTTOM, ZSYMM']
    ramped_gravity_step(s, t_ramp, period, bcs, 'LOAD', ndim, ('*DSLOAD, AMPLITUDE=RAMP', f'LID, P, {fmt(q)}'))
    return s


def floor_cax4r(n=4, radius=0.2, height=0.2, mu=0.3, period=0.3) -> Scene:
    # A solid cylinder (CAX4R, full ring) standing on an analytic rigid floor with friction: once
    # the gravity ramp has settled, the floor carries the weight of the whole cylinder,
    # rho g pi R^2 H — the check of the ring convention of masses and contact forces.
    mass = RHO * math.pi * radius ** 2 * height
    s = Scene('floor_cax4r', 'verification: axisymmetric cylinder (CAX4R) resting on a rigid floor',
              {'kind': 'floor', 'ndim': 2, 'rho': RHO, 'E': E, 'nu': NU, 'g': G, 'mass': fmt(mass),
               'ramp': GRAVITY_RAMP},
              ['Solid cylinder 0 < r < R, 0 < z < H of CAX4R elements, axis nodes on radial rollers, on an',
               f'analytic rigid line z = 0 (TYPE=SEGMENTS) with friction mu = {mu:g}; gravity -z ramped in',
               f'over {GRAVITY_RAMP:g} s. The floor force WALLF2 is the weight of the full ring, rho g pi R^2 H.',
               'Generated by scripts/make_verification_scenes.py.'])
    nodes, conn = grid_2d(n, n, radius, height)
    s.nodes(nodes)
    s.elements('CAX4R', conn, 'CYLINDER')
    s.nset('AXIS', [node_2d(0, j, n) for j in range(n + 1)])
    s.elset('BASE', [i + 1 for i in range(n)])
    s.elastic_material('CYLINDER')
    s.add('*AMPLITUDE, NAME=RAMP, DEFINITION=SMOOTH STEP', f'0., 0., {fmt(GRAVITY_RAMP)}, 1.')
    s.add('*SURFACE, NAME=BOTTOM', 'BASE, S1')
    s.add('*SURFACE, TYPE=SEGMENTS, NAME=FLOOR', f'START, {fmt(-0.5 * radius)}, 0.', f'LINE, {fmt(2.0 * radius)}, 0.')
    s.add('*SURFACE INTERACTION, NAME=ROUGH', '*FRICTION', fmt(mu))
    s.add('*CONTACT PAIR, INTERACTION=ROUGH', 'BOTTOM, FLOOR')
    s.add('*BOUNDARY', 'AXIS, XSYMM')
    s.add('*STEP, NAME=SETTLE', '*DYNAMIC, EXPLICIT', f', {fmt(period)}')
    s.add('*DLOAD, AMPLITUDE=RAMP', ', GRAV, 9.81, 0., -1.')
    s.add('*OUTPUT, FIELD, NUMBER INTERVAL=50', '*NODE OUTPUT', 'U, V', '*ELEMENT OUTPUT', 'S')
    s.add('*OUTPUT, HISTORY, NUMBER INTERVAL=20', '*ENERGY OUTPUT')
    s.add('*END STEP')
    return s


def all_scenes() -> list[Scene]:
    return [wave_bar_2d(), wave_bar_3d(), column_2d(), column_3d(),
            incline_2d('incline_slide_2d', 30.0, 0.3), incline_2d('incline_stick_2d', 20.0, 0.5),
            incline_3d('incline_slide_3d', 30.0, 0.3), incline_3d('incline_stick_3d', 20.0, 0.5, n=3),
            patch(2), patch(3), patch(2, plastic=True), patch(3, plastic=True), rotation(2), rotation(3), hourglass_sections_2d(), inverted_2d(), restart_2d(), mpi_column_2d(),
            incline_2d('mpi_incline_2d', 30.0, 0.3, n=4, period=0.1),
            lame_cax4r(), column_cax4r(), column_cax4r('column_mc_cax4r', mohr_coulomb=True), patch_cax4r(),
            column_surcharge('CPE4R'), column_surcharge('C3D8R'), column_surcharge('CAX4R'), floor_cax4r()]


def main() -> None:
    repo = Path(__file__).resolve().parent.parent
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--out', type=Path, default=repo / 'inputs' / 'verification')
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for scene in all_scenes():
        path = scene.write(args.out)
        print(path)


if __name__ == '__main__':
    main()
