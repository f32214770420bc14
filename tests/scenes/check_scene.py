#!/usr/bin/env python3
"""Run a verification scene (inputs/verification/) with bulkflow and check its figures.

    check_scene.py verify   SCENE --bulkflow BIN --workdir DIR
    check_scene.py mpi      SCENE --bulkflow BIN --workdir DIR --mpiexec MPIEXEC --ranks 1 2 3 4
    check_scene.py restart  SCENE --bulkflow BIN --workdir DIR --stop-after N [--ranks R --mpiexec ...]
    check_scene.py inverted SCENE --bulkflow BIN --workdir DIR [--ranks R --mpiexec ...]

verify: one serial run, then the closed-form check of the scene's kind (its `** verify:` lines),
the energy balance (|ETOTAL| <= 1 % of max(ALLKE, ALLIE, |ALLWK|) at the end and on every row of
the second half, ALLAE <= 5 % of ALLIE), no energy-balance warning, no NaN, and the effects line
and timing table against the keywords of the scene. mpi: the same scene on each rank count, final
U and S compared with the 1-rank run (1e-12 relative; bitwise is reported). restart: a run
uninterrupted and one stopped with --stop-after N and continued with --restart: every frame and
the history CSV must be identical. inverted: the run must stop with the element, the time and the
reason, a non-zero exit status and no NaN in what it wrote. Exit status 0 when everything holds.
"""
from __future__ import annotations

import argparse
import math
import re
import shutil
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scene_tools import (CheckFailed, Launcher, Run, check_effects, check_energy, check_no_balance_warning,  # noqa: E402
                         check_no_nan, floats, max_relative_difference, read_fields, read_history, report,
                         scene_parameters)


def moduli(p: dict[str, str]) -> tuple[float, float, float, float]:
    """(lambda, G, M, c_d) of the scene's elastic material."""
    e, nu, rho = float(p['E']), float(p['nu']), float(p['rho'])
    lam = e * nu / ((1 + nu) * (1 - 2 * nu))
    g = e / (2 * (1 + nu))
    m = lam + 2 * g
    return lam, g, m, math.sqrt(m / rho)


def expected_effects(scene: Path) -> tuple[list[str], list[str]]:
    """Effects the scene's keywords call for, and those it must not show (driver_effects rules)."""
    text = scene.read_text().upper()
    keywords = {line.split(',')[0].strip() for line in text.splitlines() if line.startswith('*')
                and not line.startswith('**')}
    present = ['elements', 'material', 'hourglass', 'assembly', 'output']
    absent = []
    for effect, keyword in (('pressure', '*DSLOAD'), ('rigid walls', '*CONTACT PAIR'), ('user field', '*USER DEFINED FIELD'),
                            ('gravity', '*DLOAD'), ('checkpoint', '*RESTART'), ('boundary', '*BOUNDARY')):
        (present if keyword in keywords else absent).append(effect)
    return present, absent


# ---------------------------------------------------------------------------------------------
# Closed forms per kind

def check_wave(p, run: Run) -> dict[str, float]:
    lam, g, m, c = moduli(p)
    rho, v0, length = float(p['rho']), float(p['v0']), float(p['length'])
    x1, x2 = floats(p['stations'])
    h = read_history(run.history_csv)
    arrivals = []
    for k in (1, 2):
        t, v = h['time'], h[f'V1_STATION{k}']
        i = int(np.argmax(v >= 0.5 * v0))
        if v[i] < 0.5 * v0 or i == 0:
            raise CheckFailed(f'the front never reached station {k}')
        arrivals.append(t[i - 1] + (0.5 * v0 - v[i - 1]) / (v[i] - v[i - 1]) * (t[i] - t[i - 1]))
    c_measured = (x2 - x1) / (arrivals[1] - arrivals[0])
    figures = {'arrival': c_measured / c - 1}
    # The A history output: its time integral over the front passage is the velocity jump.
    t, a1 = h['time'], h['A1_STATION1']
    dv = float(np.sum(0.5 * (a1[1:] + a1[:-1]) * np.diff(t)))
    figures['a_integral'] = dv / h['V1_STATION1'][-1] - 1
    print(f'  station 1: integral of A1 over time {dv:.5g} m/s, V1 at the end {h["V1_STATION1"][-1]:.5g} m/s')
    report('integral of the A1 history vs the V1 history', 100 * figures['a_integral'], 5.0, ' %')
    print(f'  c_d = {c:.5g} m/s closed form, {c_measured:.5g} m/s from the arrivals at x = {x1:g}, {x2:g}')
    report('front speed error', 100 * figures['arrival'], 1.0, ' %')

    fields = read_fields(run.h5)
    last = fields.frames[-1]
    front = c * last.total_time
    xc = fields.centroids()[:, 0]
    behind = (xc > 0.15 * length) & (xc < front - 0.15 * length)
    if behind.sum() < 5:
        raise CheckFailed('too few elements between the driven end and the front')
    s = last.fields['S'][behind]
    p0 = -s[:, 0].mean()
    xn = fields.x0[:, 0]
    nodes = (xn > 0.15 * length) & (xn < front - 0.15 * length)
    v_plateau = last.fields['V'][nodes, 0].mean()
    k0 = lam / m
    lateral = [s[:, 1].mean() / s[:, 0].mean(), s[:, 2].mean() / s[:, 0].mean()]
    print(f'  plateau at t = {last.total_time:.4g} s: sigma_11 = {-p0:.5g} Pa (closed form {-rho * c * v0:.5g}), '
          f'v = {v_plateau:.5g} m/s, sigma_22/sigma_11 = {lateral[0]:.5f}, sigma_33/sigma_11 = {lateral[1]:.5f} '
          f'(nu/(1-nu) = {k0:.5f})')
    figures['plateau_stress'] = p0 / (rho * c * v0) - 1
    figures['plateau_velocity'] = v_plateau / (p0 / (rho * c)) - 1
    figures['lateral'] = max(abs(x / k0 - 1) for x in lateral)
    report('plateau stress error vs rho c_d v0', 100 * figures['plateau_stress'], 1.0, ' %')
    report('plateau particle velocity error vs p0/(rho c_d)', 100 * figures['plateau_velocity'], 1.0, ' %')
    report('lateral stress ratio error vs nu/(1-nu)', 100 * figures['lateral'], 1.0, ' %')
    if 'RF1_DRIVEN' in h and 'area' in p:
        # The support driving the end pushes with p0 A (RF: the force of the support on the bar).
        late = h['time'] >= 0.5 * h['time'][-1]
        rf = h['RF1_DRIVEN'][late].mean()
        expected = rho * c * v0 * float(p['area'])
        figures['reaction'] = rf / expected - 1
        print(f'  reaction of the driven end {rf:.5g} N (second half mean), rho c_d v0 A = {expected:.5g} N')
        report('reaction force error', 100 * figures['reaction'], 1.0, ' %')
    return figures


def check_column(p, run: Run) -> dict[str, float]:
    lam, g, m, c = moduli(p)
    rho, grav, height = float(p['rho']), float(p['g']), float(p['height'])
    ndim = int(p['ndim'])
    if p.get('settled') != 'yes':
        return {}
    fields = read_fields(run.h5)
    last = fields.frames[-1]
    vert = ndim - 1
    yc = fields.centroids()[:, vert]
    inner = (yc > 0.2 * height) & (yc < 0.8 * height)
    s = last.fields['S'][inner]
    q = float(p.get('surcharge', 0.0))        # *DSLOAD pressure on the top
    sv_exact = -rho * grav * (height - yc[inner]) - q
    sv = s[:, vert]
    horizontal = [0, 2] if ndim == 2 else [0, 1]
    k0 = lam / m
    k0_error = max(np.max(np.abs(s[:, j] / sv / k0 - 1)) for j in horizontal)
    sv_error = np.max(np.abs(sv / sv_exact - 1))
    h = read_history(run.history_csv)
    top = h[f'U{ndim}_TOP'][-1]
    top_exact = -(rho * grav * height ** 2 / 2 + q * height) / m
    print(f'  {inner.sum()} elements with 0.2 H < y < 0.8 H at t = {last.total_time:.4g} s; K0 = {k0:.5f}; '
          f'top settlement {top:.5e} m (closed form {top_exact:.5e})')
    figures = {'k0': float(k0_error), 'sigma_v': float(sv_error), 'settlement': float(top / top_exact - 1)}
    report('K0 error max |sigma_h/sigma_v - nu/(1-nu)|/K0', 100 * figures['k0'], 1.0, ' %')
    report('vertical stress error max |sigma_v/(-rho g (H-y) - q) - 1|', 100 * figures['sigma_v'], 2.0, ' %')
    report('top settlement error vs (rho g H^2/2 + q H)/M', 100 * figures['settlement'], 2.0, ' %')
    return figures


def check_incline(p, run: Run) -> dict[str, float]:
    ndim = int(p['ndim'])
    slope = floats(p['slope'])
    alpha = math.radians(float(p['alpha']))
    normal = np.array([math.sin(alpha), math.cos(alpha)]) if ndim == 2 else \
        np.array([math.sin(alpha), 0.0, math.cos(alpha)])
    accel = float(p['accel'])
    grav = float(p['g'])
    h = read_history(run.history_csv)
    t = h['time']
    u = np.stack([h[f'U{i + 1}_BLOCKN'] for i in range(ndim)], axis=1)
    s = u @ slope
    off = u @ normal
    figures = {}
    if accel > 0:
        sel = t >= max(0.25 * t[-1], 2 * float(p.get('ramp', 0)))
        coef = np.polyfit(t[sel], s[sel], 2)
        a_fit = 2 * coef[0]
        print(f'  along the slope: fitted a = {a_fit:.6g} m/s^2, closed form g (sin a - mu cos a) = {accel:.6g}; '
              f'distance {s[-1]:.4g} m')
        figures['acceleration'] = a_fit / accel - 1
        report('acceleration error', 100 * figures['acceleration'], 1.0, ' %')
    else:
        free = 0.5 * grav * math.sin(alpha) * t[-1] ** 2
        print(f'  sticking: largest slip {np.max(np.abs(s)):.3e} m (a frictionless block would go {free:.3g} m)')
        figures['slip'] = float(np.max(np.abs(s)) / free)
        report('slip / frictionless distance', figures['slip'], 1e-3, '', '.3e')
        v = np.stack([h[f'V{i + 1}_BLOCKN'] for i in range(ndim)], axis=1) @ slope
        late = t >= 0.5 * t[-1]
        figures['creep'] = float(abs(s[-1] - s[late][0]))
        report('creep over the second half (m)', figures['creep'], 1e-5, ' m', '.3e')
        print(f'  mean velocity along the slope over the second half {v[late].mean():.3e} m/s')
    figures['normal'] = float(np.max(np.abs(off)))
    report('largest mean displacement off the slope (m)', figures['normal'], 1e-4, ' m', '.3e')
    # The force on the wall (WALLF): the block pushes it with m (g - a t), g pointing down.
    mass = float(p['mass'])
    gvec = np.zeros(ndim)
    gvec[-1] = -grav
    expected = mass * (gvec - accel * slope)
    wall = np.stack([h[f'WALLF{i + 1}_SLOPE'] for i in range(ndim)], axis=1)
    late = t >= 0.5 * t[-1]
    err = np.linalg.norm(wall[late] - expected, axis=1) / (mass * grav)
    print(f'  force on the wall: mean over the second half {np.array2string(wall[late].mean(axis=0), precision=3)} N, '
          f'closed form m (g - a t) = {np.array2string(expected, precision=3)} N; last row '
          f'{np.array2string(wall[-1], precision=3)} N')
    figures['wall_force_mean'] = float(np.linalg.norm(wall[late].mean(axis=0) - expected) / (mass * grav))
    figures['wall_force_last'] = float(err[-1])
    report('wall force error, mean over the second half / mg', 100 * figures['wall_force_mean'], 1.0, ' %')
    report('wall force error of the last row (shortened increment) / mg', 100 * figures['wall_force_last'], 5.0, ' %')
    return figures


def check_patch(p, run: Run) -> dict[str, float]:
    lam, g, m, c = moduli(p)
    ndim = int(p['ndim'])
    grad = floats(p['grad']).reshape(ndim, ndim)
    fields = read_fields(run.h5)
    last = fields.frames[-1]
    t = last.total_time
    u_exact = fields.x0 @ grad.T * t
    u = last.fields['U']
    figures = {'displacement': max_relative_difference(u_exact, u)}
    s = last.fields['S']
    mean = s.mean(axis=0)
    figures['uniformity'] = float(np.max(np.abs(s - mean)) / np.max(np.abs(mean)))
    # Exact stress: F = I + L t symmetric positive definite, so R = I and the corotational
    # (logarithmic) strain is log(F); sigma = lambda tr E I + 2 G E.
    f3 = np.eye(3)
    f3[:ndim, :ndim] += grad * t
    if p.get('axisymmetric') == 'yes':
        f3[2, 2] += grad[0, 0] * t              # hoop stretch r/R = 1 + a t of u_r = a r t
    w, q = np.linalg.eigh(f3)
    strain = q @ np.diag(np.log(w)) @ q.T
    sig = lam * np.trace(strain) * np.eye(3) + 2 * g * strain
    order = [(0, 0), (1, 1), (2, 2), (0, 1)] if ndim == 2 else [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)]
    sig_exact = np.array([sig[i, j] for i, j in order])
    figures['stress'] = max_relative_difference(sig_exact, mean)
    le_exact = np.array([strain[i, j] for i, j in order])
    figures['log_strain'] = max(max_relative_difference(le_exact, le) for le in last.fields['LE'])
    print(f'  t = {t:.4g} s, {len(fields.x0)} nodes, {len(s)} elements; stress {np.array2string(mean, precision=6)}')
    report('nodal displacements vs (L t) X, relative', figures['displacement'], 1e-8, '', '.2e')
    report('stress non-uniformity max |S_e - mean|/|mean|', figures['uniformity'], 1e-8, '', '.2e')
    report('stress vs lambda tr(E) I + 2G E, E = log(I + L t)', figures['stress'], 1e-8, '', '.2e')
    report('LE of every element vs log(I + L t)', figures['log_strain'], 1e-8, '', '.2e')
    if 'PE' in last.fields:
        figures['plastic_strain'] = float(np.max(np.abs(last.fields['PE'])))
        report('largest |PE| of the elastic patch', figures['plastic_strain'], 1e-12, '', '.2e')
    if 'A' in last.fields:
        a = np.max(np.abs(last.fields['A']))
        v = np.max(np.abs(last.fields['V']))
        report('largest acceleration x t / largest velocity', a * t / v, 1e-8, '', '.2e')
    return figures


def compliance(stress: np.ndarray, e: float, nu: float) -> np.ndarray:
    """C^-1 sigma of rows of stress components (11, 22, 33, 12[, 23, 31]); tensor shears."""
    eps = np.empty_like(stress)
    trace = stress[:, :3].sum(axis=1)
    eps[:, :3] = ((1 + nu) * stress[:, :3] - nu * trace[:, None]) / e
    eps[:, 3:] = (1 + nu) / e * stress[:, 3:]
    return eps


def check_plastic_patch(p, run: Run) -> dict[str, float]:
    """PE of a homogeneous patch driven through yield: the driver's Δε − C⁻¹Δσ against the
    material's own volumetric plastic strain EVP (SDV2), uniformity, and PE = LE − C⁻¹σ."""
    e, nu = float(p['E']), float(p['nu'])
    last = read_fields(run.h5).frames[-1]
    pe, le, s = last.fields['PE'], last.fields['LE'], last.fields['S']
    peeq, evp = last.fields['PEEQ'].ravel(), last.fields['SDV2'].ravel()
    scale = np.max(np.abs(pe))
    print(f'  t = {last.total_time:.4g} s: PE = {np.array2string(pe.mean(axis=0), precision=6)}, '
          f'PEEQ = {peeq.mean():.5g}, EVP = {evp.mean():.5g}, yield region SDV5 = {last.fields["SDV5"].ravel()}')
    if not (peeq.min() > 1e-4 and evp.min() > 0):
        raise CheckFailed(f'the patch did not flow plastically with dilation (PEEQ {peeq.min():.3g}, EVP {evp.min():.3g})')
    figures = {'trace_vs_evp': float(np.max(np.abs(pe[:, :3].sum(axis=1) - evp)) / np.max(np.abs(evp))),
               'uniformity': float(np.max(np.abs(pe - pe.mean(axis=0))) / scale),
               'decomposition': float(np.max(np.abs(le - compliance(s, e, nu) - pe)) / scale)}
    report('tr PE vs the material\'s EVP (SDV2), relative', figures['trace_vs_evp'], 1e-9, '', '.2e')
    report('PE non-uniformity max |PE_e - mean| / max |PE|', figures['uniformity'], 1e-8, '', '.2e')
    report('PE vs LE - C^-1 S, relative to max |PE|', figures['decomposition'], 1e-8, '', '.2e')
    return figures


def check_rotation(p, run: Run) -> dict[str, float]:
    """After the stretch along x and the rigid 90 degree rotation the stretch lies along y."""
    lam, g, m, c = moduli(p)
    ndim = int(p['ndim'])
    e = math.log(1 + float(p['stretch']))
    fields = read_fields(run.h5)
    order = [(0, 0), (1, 1), (2, 2), (0, 1)] if ndim == 2 else [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)]
    strain = np.zeros((3, 3))
    strain[1, 1] = e
    sig = lam * e * np.eye(3) + 2 * g * strain
    le_exact = np.array([strain[i, j] for i, j in order])
    s_exact = np.array([sig[i, j] for i, j in order])
    mid = [f for f in fields.frames if f.step == 1][-1]
    last = fields.frames[-1]
    print(f'  after the stretch (t = {mid.total_time:.4g} s): S = {np.array2string(mid.fields["S"][0], precision=2)}')
    print(f'  after the rotation (t = {last.total_time:.4g} s): S = {np.array2string(last.fields["S"][0], precision=2)}, '
          f'LE = {np.array2string(last.fields["LE"][0], precision=6)}')
    figures = {'stress': max_relative_difference(s_exact, last.fields['S'][0]),
               'log_strain': max_relative_difference(le_exact, last.fields['LE'][0])}
    report('S after the rotation vs the rotated closed form', figures['stress'], 1e-3, '', '.2e')
    report('LE after the rotation vs log(1 + stretch) e_y e_y', figures['log_strain'], 1e-3, '', '.2e')
    return figures


def check_dynamic(p, run: Run) -> dict[str, float]:
    return {}


def check_sections(p, run: Run) -> dict[str, float]:
    """The element with the stiffness section rings in its hourglass mode: ALLAE (stored) rises
    and falls again. With the viscous form (the first section's) it could only grow."""
    h = read_history(run.history_csv)
    a = h['ALLAE']
    peak = int(np.argmax(a))
    ke0 = h['ALLKE'][0]
    drop = (a[peak] - a[peak:].min()) / a[peak]
    print(f'  initial hourglass kinetic energy {ke0:.4g} J; ALLAE peaks at {a[peak]:.4g} J '
          f'(t = {h["time"][peak]:.4g} s), then falls by {100 * drop:.3g} %')
    if a[peak] < 0.5 * ke0:
        raise CheckFailed('the hourglass mode stored less than half its kinetic energy')
    report('share of the peak ALLAE not given back afterwards', 1 - drop, 0.8, '', '.3g')
    return {'returned': float(drop)}


def check_lame(p, run: Run) -> dict[str, float]:
    """Thick-walled cylinder, plane strain, internal pressure p, outer surface free (Lame;
    docs/theory/elements.md §3.10): u = A r + B/r, sigma_r = 2(lam+G)A - 2G B/r^2,
    sigma_theta = 2(lam+G)A + 2G B/r^2, sigma_z = 2 lam A; sigma_r(a) = -p, sigma_r(b) = 0:
    A = p a^2 / (2 (lam+G)(b^2 - a^2)), B = p a^2 b^2 / (2 G (b^2 - a^2))."""
    lam, g, m, c = moduli(p)
    a, b, pressure = float(p['inner']), float(p['outer']), float(p['pressure'])
    big_a = pressure * a ** 2 / (2 * (lam + g) * (b ** 2 - a ** 2))
    big_b = pressure * a ** 2 * b ** 2 / (2 * g * (b ** 2 - a ** 2))
    u_a = big_a * a + big_b / a
    fields = read_fields(run.h5)
    last = fields.frames[-1]
    r = fields.centroids()[:, 0]
    s = last.fields['S']
    sr_exact = 2 * (lam + g) * big_a - 2 * g * big_b / r ** 2
    st_exact = 2 * (lam + g) * big_a + 2 * g * big_b / r ** 2
    rn = fields.x0[:, 0]
    u_exact = big_a * rn + big_b / rn
    figures = {'sigma_r': float(np.max(np.abs(s[:, 0] - sr_exact)) / pressure),
               'sigma_theta': float(np.max(np.abs(s[:, 2] - st_exact)) / pressure),
               'sigma_z': float(np.max(np.abs(s[:, 1] - 2 * lam * big_a)) / pressure),
               'u_r': float(np.max(np.abs(last.fields['U'][:, 0] - u_exact)) / u_a)}
    print(f'  {len(s)} elements, bore pressure p = {pressure:.5e} Pa, hoop stress at the bore '
          f'{st_exact.max():.5e} Pa, t = {last.total_time:.4g} s')
    report('radial stress error max |sigma_r - Lame| / p', 100 * figures['sigma_r'], 1.0, ' %')
    report('hoop stress error max |sigma_theta - Lame| / p', 100 * figures['sigma_theta'], 1.0, ' %')
    report('axial stress error max |sigma_z - 2 lam A| / p', 100 * figures['sigma_z'], 1.0, ' %')
    report('radial displacement error max |u_r - (A r + B/r)| / u_a', 100 * figures['u_r'], 1.0, ' %')
    return figures


def check_floor(p, run: Run) -> dict[str, float]:
    """A body at rest on a rigid floor after the gravity ramp: the floor carries its weight m g
    (the second half of the history rows after the ramp)."""
    mass, grav, ramp = float(p['mass']), float(p['g']), float(p['ramp'])
    h = read_history(run.history_csv)
    wall = [k for k in h if k.startswith('WALLF2_')][0]
    t = h['time']
    settled = t > ramp + 0.5 * (t[-1] - ramp)
    force = h[wall][settled]
    figures = {'weight': float(np.max(np.abs(force / (-mass * grav) - 1)))}
    print(f'  {wall}: mean {force.mean():.6e} N over {settled.sum()} rows; weight m g = {mass * grav:.6e} N')
    report('floor force vs the weight of the full ring, worst row', 100 * figures['weight'], 1.0, ' %')
    return figures


CHECKS = {'floor': check_floor, 'lame': check_lame, 'wave': check_wave, 'column': check_column, 'incline': check_incline, 'patch': check_patch,
          'dynamic': check_dynamic, 'sections': check_sections, 'rotation': check_rotation,
          'plastic_patch': check_plastic_patch}


# ---------------------------------------------------------------------------------------------
# Commands

def cmd_verify(args, launcher: Launcher) -> None:
    p = scene_parameters(args.scene)
    kind = p.get('kind')
    if kind not in CHECKS:
        raise CheckFailed(f'{args.scene}: no "** verify: kind = ..." line with a known kind')
    print(f'{args.scene.name}: {kind}, {p.get("ndim")}D')
    run = launcher.run(args.scene, args.workdir / args.scene.stem)
    CHECKS[kind](p, run)
    check_plastic_strain_trace(run)
    # The hourglass share is meaningless where the hourglass mode is the point of the scene.
    check_energy(read_history(run.history_csv), check_artificial=kind != 'sections')
    check_no_balance_warning(run)
    check_no_nan(run)
    present, absent = expected_effects(args.scene)
    check_effects(run, present, absent)


def check_plastic_strain_trace(run: Run) -> None:
    """Wherever a scene writes PE and the state variables, tr PE (the driver's) equals EVP = SDV2
    (the material's) in every frame; elements of a material without SDVs write SDV2 = 0, and
    their PE must stay zero too."""
    fields = read_fields(run.h5)
    frames = [f for f in fields.frames if 'PE' in f.fields and 'SDV2' in f.fields]
    if not frames:
        return
    worst = max(float(np.max(np.abs(f.fields['PE'][:, :3].sum(axis=1) - f.fields['SDV2'].ravel()))) for f in frames)
    scale = max(float(np.max(np.abs(f.fields['PE']))) for f in frames) + 1e-30
    report(f'tr PE vs SDV2 over {len(frames)} frames, relative to max |PE|', worst / scale, 1e-9, '', '.2e')


def final_arrays(run: Run) -> dict[str, np.ndarray]:
    fields = read_fields(run.h5)
    last = fields.frames[-1]
    return {'U': last.fields['U'], 'S': last.fields['S'], 'time': np.array([last.total_time])}


def cmd_mpi(args, launcher: Launcher) -> None:
    print(f'{args.scene.name}: final U and S on {", ".join(map(str, args.ranks))} ranks')
    reference = None
    worst = 0.0
    for n in args.ranks:
        run = launcher.run(args.scene, args.workdir / f'{args.scene.stem}_np{n}', ranks=n)
        check_no_nan(run)
        arrays = final_arrays(run)
        if reference is None:
            reference = arrays
            continue
        for name in ('U', 'S'):
            d = max_relative_difference(reference[name], arrays[name])
            bitwise = np.array_equal(reference[name], arrays[name])
            print(f'  {n} ranks: {name} max relative difference {d:.3e}{" (bitwise identical)" if bitwise else ""}')
            worst = max(worst, d)
        if reference['time'][0] != arrays['time'][0]:
            raise CheckFailed(f'{n} ranks end at t = {arrays["time"][0]!r}, 1 rank at {reference["time"][0]!r}')
    report('MPI agreement, max relative difference of U and S', worst, 1e-12, '', '.3e')


def cmd_restart(args, launcher: Launcher) -> None:
    n = args.ranks[0]
    print(f'{args.scene.name}: restart after increment {args.stop_after} on {n} rank(s)')
    full = launcher.run(args.scene, args.workdir / f'{args.scene.stem}_full_np{n}', ranks=n)
    base = args.workdir / f'{args.scene.stem}_restarted_np{n}'
    first = launcher.run(args.scene, base, ranks=n, extra=['--stop-after', str(args.stop_after)])
    if f'stopped after increment {args.stop_after}' not in first.stdout:
        raise CheckFailed('the interrupted run did not report its stop')
    second = launcher.run(args.scene, base, ranks=n, extra=['--restart'])
    a, b = read_fields(full.h5), read_fields(second.h5)
    if len(a.frames) != len(b.frames):
        raise CheckFailed(f'{len(a.frames)} frames uninterrupted, {len(b.frames)} restarted')
    differing = []
    for fa, fb in zip(a.frames, b.frames):
        if (fa.total_time, fa.increment, fa.step) != (fb.total_time, fb.increment, fb.step):
            differing.append(f'frame header at t = {fa.total_time}')
        for name in fa.fields:
            if name not in fb.fields or not np.array_equal(fa.fields[name], fb.fields[name]):
                differing.append(f'{name} at t = {fa.total_time:.6g}')
    ta, tb = full.history_csv.read_text(), second.history_csv.read_text()
    rows_a, rows_b = ta.splitlines(), tb.splitlines()
    print(f'  {len(a.frames)} frames, {len(rows_a) - 1} history rows; the interrupted run stopped at '
          f'increment {args.stop_after}')
    if differing:
        raise CheckFailed('restarted run differs: ' + ', '.join(differing[:8]))
    print('  ok   every frame identical bit for bit (U, S and all other fields)')
    if ta != tb:
        bad = next((i for i, (x, y) in enumerate(zip(rows_a, rows_b)) if x != y), min(len(rows_a), len(rows_b)))
        raise CheckFailed(f'history CSV differs from row {bad}: {len(rows_a)} vs {len(rows_b)} lines')
    print('  ok   history CSV identical')
    check_refused_restarts(args, launcher, base, n)


def check_refused_restarts(args, launcher: Launcher, saved: Path, n: int) -> None:
    """Restarts that cannot continue are refused cleanly — exit status 2, the reason once (rank
    0) with what was expected, no backtrace, no MPI_Abort: no checkpoint, another rank count, an
    edited scene (the message names the edited line). A comment added to the scene is no edit."""
    import shutil
    wd = args.workdir

    def copy_outputs(to: Path) -> None:
        for f in saved.parent.glob(saved.name + '.rst.*'):
            shutil.copy(f, str(to) + f.name[len(saved.name):])
        for suffix in ('.h5', '.xmf', '_history.csv'):
            if Path(str(saved) + suffix).exists():
                shutil.copy(str(saved) + suffix, str(to) + suffix)

    def refused(run: Run, what: str, needles: list[str]) -> None:
        msg = next((l for l in run.stderr.splitlines() if l.startswith('bulkflow: error:')), '')
        text = run.stdout + run.stderr
        print(f'  {what}: exit status {run.returncode}: {msg}')
        problems = []
        if run.returncode != 2:
            problems.append(f'exit status {run.returncode}, expected 2')
        if run.stderr.count('bulkflow: error:') != 1:
            problems.append(f'the error is said {run.stderr.count("bulkflow: error:")} times, expected once')
        if not all(nd in msg for nd in needles) or 'expected' not in msg:
            problems.append(f'the message lacks {needles} or what was expected')
        if 'Backtrace' in text or 'MPI_ABORT' in text or 'Error termination' in text:
            problems.append('a backtrace or MPI_Abort')
        if problems:
            raise CheckFailed(f'{what}: ' + '; '.join(problems))

    refused(launcher.run(args.scene, wd / 'none', ranks=n, extra=['--restart'], expect_success=False),
            'no checkpoint', ['none.rst.0: cannot open the file'])
    # (another rank count: the multi-rank tests restart on 1 rank; a 1-rank test has no mpiexec)
    if n > 1:
        refused(launcher.run(args.scene, saved, ranks=1, extra=['--restart'], expect_success=False),
                f'restart on 1 rank of a {n}-rank checkpoint', [f'written by a run on {n} ranks, this run has 1'])

    lines = args.scene.read_text().splitlines()
    at = next(i for i, l in enumerate(lines) if l.upper().startswith('*DENSITY')) + 1
    fields = lines[at].split(',')
    fields[0] = repr(float(fields[0]) * 1.01)
    edited = wd / f'{args.scene.stem}_edited.inp'
    edited.write_text('\n'.join(lines[:at] + [','.join(fields)] + lines[at + 1:]) + '\n')
    copy_outputs(wd / 'edited')
    refused(launcher.run(edited, wd / 'edited', ranks=n, extra=['--restart'], expect_success=False),
            f'edited scene (density on line {at + 1})',
            [f'{edited.name}:{at + 1}: differs from the scene the checkpoint was written for'])

    commented = wd / f'{args.scene.stem}_commented.inp'
    commented.write_text('** a comment added after the checkpoint\n\n' + args.scene.read_text())
    copy_outputs(wd / 'commented')
    run = launcher.run(commented, wd / 'commented', ranks=n, extra=['--restart'], expect_success=False)
    if run.returncode != 0:
        sys.stderr.write(run.stderr)
        raise CheckFailed(f'a comment added to the scene stopped the restart (exit status {run.returncode})')
    print('  ok   refused restarts: clean, said once, with what was expected; a comment added is no edit')


def cmd_inverted(args, launcher: Launcher) -> None:
    p = scene_parameters(args.scene)
    n = args.ranks[0]
    run = launcher.run(args.scene, args.workdir / f'{args.scene.stem}_np{n}', ranks=n, expect_success=False)
    text = run.stdout + run.stderr
    print(f'{args.scene.name} on {n} rank(s): exit status {run.returncode}')
    if run.returncode == 0:
        raise CheckFailed('the run finished although an element inverts')
    m = re.search(r'element (\d+) at total time\s+([-+0-9.Ee]+): (.*)', text)
    if not m:
        sys.stdout.write(text)
        raise CheckFailed('no "element N at total time T: reason" message')
    elem, when, reason = int(m.group(1)), float(m.group(2)), m.group(3)
    print(f'  message: element {elem} at t = {when:.5e}: {reason.strip()}')
    if 'element' not in p or elem < 1:
        raise CheckFailed('bad element number in the message')
    if not (when > 0 and math.isfinite(when)):
        raise CheckFailed('the time in the message is not a positive number')
    if 'inverted' not in reason and 'collapse' not in reason:
        raise CheckFailed(f'the reason does not say what happened: {reason}')
    if re.search(r'\bnan\b', text, re.IGNORECASE):
        raise CheckFailed('NaN in the messages')
    check_no_nan(run)
    print('  ok   stopped with the element, the time and the reason; no NaN')


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('command', choices=['verify', 'mpi', 'restart', 'inverted'])
    parser.add_argument('scene', type=Path)
    parser.add_argument('--bulkflow', required=True)
    parser.add_argument('--workdir', type=Path, required=True)
    parser.add_argument('--mpiexec', default=None)
    parser.add_argument('--numproc-flag', default='-n')
    parser.add_argument('--mpiexec-flag', action='append', default=[],
                        help='one extra mpiexec argument (repeat)')
    parser.add_argument('--ranks', type=int, nargs='+', default=[1])
    parser.add_argument('--stop-after', type=int, default=10)
    args = parser.parse_args()
    args.scene = args.scene.resolve()
    args.workdir = args.workdir.resolve()
    # The runs start in the work directory: a relative binary path must not depend on it.
    if Path(args.bulkflow).exists():
        args.bulkflow = str(Path(args.bulkflow).resolve())
    if args.workdir.exists():
        shutil.rmtree(args.workdir)
    args.workdir.mkdir(parents=True)
    launcher = Launcher(args.bulkflow, args.mpiexec, args.mpiexec_flag, args.numproc_flag)
    try:
        {'verify': cmd_verify, 'mpi': cmd_mpi, 'restart': cmd_restart, 'inverted': cmd_inverted}[args.command](
            args, launcher)
    except CheckFailed as exc:
        print(f'FAILED: {exc}')
        return 1
    print('PASSED')
    return 0


if __name__ == '__main__':
    sys.exit(main())
