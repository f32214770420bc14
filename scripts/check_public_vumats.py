#!/usr/bin/env python3
"""Run public third-party VUMATs/VUSDFLDs, unchanged, with --user in the four hosts and check
each against a closed form (docs/user_subroutines.md lists the files and the results). A file
with only a VUSDFLD runs on our *MOHR COULOMB in CPE4R and C3D8R (its fields against the closed
form of what it should write from the stress it reads).

The files are not part of bulkflow: download them first (their repositories are listed in
CASES below and in the docs), into one folder, under the names CASES gives, e.g.

    git clone https://github.com/irfancn/Abaqus-VUMAT-Johnson-Cook /tmp/jc
    cp /tmp/jc/vumat_JC.for /tmp/public_vumats/irfancn_vumat_JC.for
    python3 scripts/check_public_vumats.py --dir /tmp/public_vumats [--build build] [--only NAME ...]

(pantale/abaqusVumat's Sources/VUMAT-NR.f INCLUDEs 'JohnsonCook.f': put that file, unchanged and
under its own name, next to it, as Abaqus users do. afshin6218517/Morteza-Naeij's MC-2D.for goes
in as naeij_MC-2D.for.)

Hosts: C3D8R and CPE4R (a homogeneous stretch, uniaxial-strain compression unless the case gives
another, every node prescribed; with temp_rate a *TEMPERATURE ramp T0 + rate t),
MPM (a 3D column settling under gravity between frictionless walls: sigma_yy = -rho g (H - y)
whatever the material; the 2D column for plane-strain files) and bulkflow-matpoint (an
oedometer test, or the case's own test). A host a file cannot serve (a VUMAT written for 3D
only) is skipped and said so. Each case names the commit its file was checked at.

A file that needs compiler flags of its own (a case with `fflags`: MC-2D.for, whose
vaba_param.inc is commented out) is compiled unchanged by the script into an object file,
which --user links; the docs say why.
"""
from __future__ import annotations

import argparse
import importlib.util
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
spec = importlib.util.spec_from_file_location('user_checks', REPO / 'tests' / 'user' / 'check_user_subroutines.py')
uc = importlib.util.module_from_spec(spec)
spec.loader.exec_module(uc)
spec = importlib.util.spec_from_file_location('vusdfld_builtin', REPO / 'tests' / 'user' / 'check_vusdfld_builtin.py')
vb = importlib.util.module_from_spec(spec)
spec.loader.exec_module(vb)


def jc_check(props):
    """J2 with Johnson-Cook hardening at the reference temperature, no rate term: on yielding,
    the Mises stress equals A + B eps_p^n with eps_p = SDV2."""
    a_, b_, n_ = props[2], props[3], props[5]

    def check(stress6, sdv, ctx=None):
        s = np.asarray(stress6, float)
        p = s[:3].mean()
        d = s.copy()
        d[:3] -= p
        q = math.sqrt(1.5 * (d[0] ** 2 + d[1] ** 2 + d[2] ** 2 + 2 * (d[3] ** 2 + d[4] ** 2 + d[5] ** 2)))
        ep = sdv[1]
        want = a_ + b_ * ep ** n_
        if ep <= 0:
            raise uc.Failed(f'no plastic strain (q = {q:.6e}); the path must yield')
        return q, want
    return check


def ice_check(props):
    """Pressure-dependent (Tsai-Wu) ice: on yielding, J2 = a0 + a1 p + a2 p^2, p = -tr(sigma)/3."""
    a0, a1, a2 = props[2], props[3], props[4]

    def check(stress6, sdv, ctx=None):
        s = np.asarray(stress6, float)
        p = -s[:3].mean()
        d = s.copy()
        d[:3] += p
        j2 = 0.5 * (d[0] ** 2 + d[1] ** 2 + d[2] ** 2) + d[3] ** 2 + d[4] ** 2 + d[5] ** 2
        if sdv[6] <= 0:
            raise uc.Failed(f'no plastic strain (J2 = {j2:.6e}); the path must yield')
        return j2, a0 + a1 * p + a2 * p * p
    return check


def mises(stress6):
    s = np.asarray(stress6, float)
    d = s.copy()
    d[:3] -= s[:3].mean()
    return math.sqrt(1.5 * (d[0] ** 2 + d[1] ** 2 + d[2] ** 2 + 2 * (d[3] ** 2 + d[4] ** 2 + d[5] ** 2)))


def jc_thermal_check(props):
    """Johnson-Cook with thermal softening, the temperature from the host (its constant 14 = 1,
    "coupled": T = tempOld), rate term and Taylor-Quinney heating off: on yielding the Mises
    stress is (A + B eps_p^n)(1 - T*^m), T* = (T - T0)/(Tm - T0), eps_p = SDV1, T the host's
    temperature at the start of the increment (the file records the T it used in SDV5)."""
    a_, b_, n_, m_, t0, tm = props[2], props[3], props[4], props[6], props[8], props[9]

    def check(stress6, sdv, ctx):
        ep, t_used, t_old = sdv[0], sdv[4], ctx['temp_old']
        if ep <= 0:
            raise uc.Failed(f'no plastic strain (q = {mises(stress6):.6e}); the path must yield')
        if not abs(t_used - t_old) <= 1e-9 * abs(t_old):
            raise uc.Failed(f'the file used T = {t_used!r} (SDV5); tempOld should be {t_old!r} '
                            f'(tempNew = {ctx["temp_new"]!r})')
        want = (a_ + b_ * ep ** n_) * (1 - ((t_old - t0) / (tm - t0)) ** m_)
        return [('Mises stress', mises(stress6), want), ('T used (SDV5) vs tempOld', t_used, t_old)]
    return check


def evans_skalak_check(props):
    """Evans-Skalak membrane law on the stretches lambda1 = F11, lambda2 = F33 (the file's
    in-plane directions; F22 its thickness direction): tensions T1 = K (l1 l2 - 1) +
    mu (l1^2 - l2^2)/(2 l1^2 l2^2), T2 likewise with 1 and 2 swapped, Cauchy stresses
    s11 = l1 T1 / J, s33 = l2 T2 / J (J = l1 F22 l2), s22 = 0. The file writes the area term
    as K' (1 - l1 l2): its constant 2 is K' = -K (Evans and Skalak 1980, Mechanics and
    Thermodynamics of Biomembranes)."""
    mu, k_area = props[0], -props[1]

    def check(stress6, sdv, ctx):
        f = ctx['F']
        l1, l2, h = f[0, 0], f[2, 2], f[1, 1]
        shear = mu * (l1 ** 2 - l2 ** 2) / (2 * l1 ** 2 * l2 ** 2)
        t1, t2 = k_area * (l1 * l2 - 1) + shear, k_area * (l1 * l2 - 1) - shear
        jac = l1 * l2 * h
        if abs(stress6[1]) > 0:
            raise uc.Failed(f'sigma22 = {stress6[1]!r}; the membrane law writes 0')
        return [('sigma11', stress6[0], l1 * t1 / jac), ('sigma33', stress6[2], l2 * t2 / jac)]
    return check


def ice_vusdfld_check(fields, stress6):
    """NTNU ice VUSDFLD: field 1 = eps0 + (p/(M P2) - N/M)^2 with its constants eps0 = 0.01,
    P2 = 53.2429898, M = 1, N = 0.75 (p = -tr(sigma)/3 in MPa, from vgetvrm('S') at the start of
    the increment); field 2 = 1 while p > Pcut = -2. Returns (got, want) pairs."""
    p = -sum(stress6[:3]) / 3
    return [(fields[0], 0.01 + (p / 53.2429898 - 0.75) ** 2), (fields[1], 1.0 if p > -2.0 else 0.0)]


def mohr_coulomb_check(props):
    """Mohr-Coulomb (Naeij and Javanmardi's MC-2D.for): perfectly plastic, props E, nu, c, phi
    (deg), phi_res and gamma_f (read, unused), psi (deg). On yielding the largest and smallest
    principal stresses (tension positive; sigma33 is a principal stress of the plane-strain
    state) lie on (s_max - s_min)/2 + (s_max + s_min)/2 sin(phi) = c cos(phi), i.e.
    s_max = s_min (1 - sin phi)/(1 + sin phi) + 2 c cos(phi)/(1 + sin phi): in compression
    positive, sigma_3 = sigma_1 K_a - 2 c sqrt(K_a), K_a = (1 - sin phi)/(1 + sin phi). The file
    adds the plastic increments of strainInc(2) to its SDV10, so SDV10 /= 0 says it yielded."""
    c, phi = props[2], math.radians(props[3])
    s = math.sin(phi)

    def check(stress6, sdv, ctx=None):
        s11, s22, s33, s12 = (float(v) for v in stress6[:4])
        mean, radius = 0.5 * (s11 + s22), math.hypot(0.5 * (s11 - s22), s12)
        principal = sorted([mean - radius, mean + radius, s33])
        if sdv[9] == 0:
            raise uc.Failed(f'no plastic increment (SDV10 = 0; principal stresses {principal}); the path must yield')
        want = principal[0] * (1 - s) / (1 + s) + 2 * c * math.cos(phi) / (1 + s)
        return [('largest principal stress on the Mohr-Coulomb line', principal[2], want)]
    return check


# name -> (repository, path in it, file name in --dir, props, depvar, kinds of host, check, comment)
CASES = {
    'johnson_cook': dict(
        repo='irfancn/Abaqus-VUMAT-Johnson-Cook', path='vumat_JC.for', commit='9b99631', file='irfancn_vumat_JC.for',
        # E, nu, A, B, C (rate: 0), n, m, rate0, Tr, Tm, rho, TQ, Cp, WH (heating: 0)
        props=[2.1e11, 0.3, 8e8, 6e8, 0.0, 0.168, 1.1, 1.0, 293.0, 1700.0, 7800.0, 34.0, 460.0, 0.0],
        depvar=6, density=7800.0, hosts=['c3d8r', 'matpoint', 'mpm3d'], check=jc_check, tol=1e-6, strain=-0.02,
        what='J2 plasticity with Johnson-Cook hardening (3D only: it reads stress components 1..6)'),
    'ice_tsai_wu': dict(
        repo='NTNU-IMT/Ice-Elastoplastic-Material-Model', path='src/VUMAT-ICE-Elastoplastic.for', commit='4a2a3e9',
        file='ntnu_imt_VUMAT-ICE-Elastoplastic.for',
        # MPa: E, nu, a0, a1, a2, eps0 (failure strain: 10, no damage), pcut, M, N, Gf1, Gf2, alphad
        props=[9500.0, 0.3, 22.93, 2.06, -0.023, 10.0, -2.0, 1.0, 0.75, 1.0, 1.0, 1.0],
        # units m, MN, s: density in 1e6 kg/m^3 (ice 900 kg/m^3)
        depvar=29, density=9.0e-4, hosts=['cpe4r', 'c3d8r', 'matpoint', 'mpm3d'], check=ice_check, tol=1e-4,
        # far from the cap of the ellipse (p near 100 MPa), where the file's return mapping stops
        # after its 200 iterations without reaching the surface in large increments
        strain=-0.004,
        what='pressure-dependent (Tsai-Wu) plasticity of ice, single-precision locals'),
    'johnson_cook_thermal': dict(
        repo='pantale/abaqusVumat', path='Sources/VUMAT-NR.f (INCLUDEs Sources/JohnsonCook.f)', commit='3be9d7e',
        file='pantale_VUMAT-NR.f', needs=['JohnsonCook.f'],
        # E, nu, A, B, n, C (rate: 0), m, eps0_dot, T0, Tm, Taylor-Quinney (heating: 0), rho0, Cp,
        # coupled = 1 (temperature from the host's tempOld)
        props=[2.0e10, 0.3, 2.0e8, 1.0e8, 0.3, 0.0, 1.2, 1.0, 293.0, 1500.0, 0.0, 7800.0, 460.0, 1.0],
        depvar=7, density=7800.0, hosts=['cpe4r', 'c3d8r', 'matpoint', 'mpm3d'], check=jc_thermal_check,
        tol=1e-6, strain=-0.04,
        # elements: T = 293 + 3e5 t (293 -> 893 K over the 2e-3 s step); driver: constant 700 K
        temp_rate=3.0e5, matpoint_temperature=700.0,
        what='J2 plasticity, Johnson-Cook hardening with thermal softening from tempOld (*TEMPERATURE)'),
    'evans_skalak': dict(
        repo='nima-mostafa-zadeh/Shell-FEM', path='abaqus/models/stretching/evans_skalak/evans_skalak_vumat.f',
        commit='49c4288',
        file='shellfem_evans_skalak_vumat.f',
        # mu, K' (the file's area constant, K' = -K: area modulus K = 2e6)
        props=[1.0e6, -2.0e6], depvar=4, density=1000.0, hosts=['cpe4r', 'c3d8r'], check=evans_skalak_check,
        tol=1e-9, stretch={2: [0.1, -0.02, 0.0], 3: [0.1, -0.02, -0.05]},
        why={'mpm3d': 'a membrane law: sigma22 is 0 whatever F22, so a column loaded in direction 2 cannot stand',
             'matpoint': "the file writes no shear stress: the driver's two-point packaging probe finds "
                         '2G = 0 and stops naming the material'},
        what='hyperelastic membrane (Evans-Skalak) from defgradNew'),
    'mohr_coulomb_2d': dict(
        repo='afshin6218517/Morteza-Naeij', path='MC-2D.for', commit='4f1624c', file='naeij_MC-2D.for',
        # E, nu, c, phi (deg), phi_res (unused), psi (deg), gamma_f (unused); Pa
        props=[1.0e7, 0.1, 2.0e3, 30.0, 30.0, 10.0, 0.2], depvar=13, density=1600.0,
        hosts=['cpe4r', 'mpm2d', 'matpoint'], check=mohr_coulomb_check, tol=1e-6,
        # CPE4R: from an isotropic 100 kPa, compression 4 % in direction 2 with a lateral
        # extension of 0.4 % in direction 1, so that s33 stays the intermediate principal stress
        # (a face of the Mohr-Coulomb pyramid). On the edges (two equal principal stresses:
        # uniaxial strain, equal in-plane compression) the file's corner branches put the
        # stresses back in the wrong places (docs/user_subroutines.md)
        stretch={2: [0.02, -0.02, 0.0]}, element_initial='-1.0e5, -1.0e5, -1.0e5, 0.',
        # the prescribed motion makes the element stress independent of the density: a light
        # one (1e-4 of the soil's) gives the 2 ms step some 200 increments instead of 2. The file
        # returns in one step (no sub-increments); from a 1 % strain increment the return lands
        # in the neighbouring sextant, off the surface (docs/user_subroutines.md)
        element_density=0.16,
        # The file comments out its INCLUDE 'VABA_PARAM.INC': its undeclared variables, the
        # argument arrays among them, are default REAL (single precision) against the host's
        # double-precision arrays. Not patched: compiled here with the promotion the include
        # would have declared (implicit double precision) and given to --user as an object.
        fflags=['-fdefault-real-8', '-fdefault-double-8'],
        # driver: plane-strain biaxial compression from an isotropic 100 kPa, the lateral stress held
        matpoint=dict(test='BIAXIAL, DIMENSION=2', initial='-1.0e5, -1.0e5, -1.0e5, 0.',
                      stage='*STAGE, STRAIN=-0.05, STRESS=-1.0e5, INC=200'),
        # MPM: also the lateral stress of the column, K0 = nu/(1 - nu) above the depth where it
        # yields, on the Mohr-Coulomb line (sigma_h = K_a sigma_v - 2 c sqrt(K_a)) below
        mpm_lateral=True,
        why={'c3d8r': 'a plane-strain model (MC-2D: principal stresses from s11, s22, s12 and s33; s23, s31 '
                      'neither read nor written)',
             'mpm3d': 'a plane-strain model; the 2D column (mpm2d) runs it'},
        what='Mohr-Coulomb, perfectly plastic, non-associated (dilation angle), plane strain; '
             'its vaba_param.inc commented out (single-precision implicit typing)'),
    'ice_vusdfld': dict(
        repo='NTNU-IMT/Ice-Elastoplastic-Material-Model', path='src/VUSDFLD.for', commit='4a2a3e9', file='ntnu_imt_VUSDFLD.for',
        # a VUSDFLD only: on our *MOHR COULOMB (MPa: E, nu; phi, psi; c), which has the PEEQ it reads
        vusdfld=dict(e=9500.0, nu=0.3, c=1.0, density=9.0e-4, strain=-0.004, angles='30., 0.', fields=2),
        hosts=['cpe4r', 'c3d8r'], check=ice_vusdfld_check, tol=1e-6,
        what='VUSDFLD (failure strain from the pressure, read with vgetvrm S and PEEQ) on our *MOHR COULOMB; '
             'single-precision locals'),
}


def host_vusdfld(case, user_file, work: Path, ndim: int):
    """A VUSDFLD-only file on our built-in material: one element compressed and held, so the
    start-of-increment stress the VUSDFLD reads is the final one; its fields are FV1.. of the frames."""
    work.mkdir(parents=True, exist_ok=True)
    scene = work / 'builtin.inp'
    scene.write_text(vb.scene_text(ndim, **case['vusdfld']))
    run([str(BULKFLOW), str(scene), '--quiet', '--user', str(user_file)], work)
    fr = uc.last_frame(work / 'builtin.h5', 'frames')
    s = list(fr['S'][0])
    s6 = s if len(s) == 6 else [s[0], s[1], s[2], s[3], 0.0, 0.0]
    fields = [float(fr[f'FV{j}'][0]) for j in range(1, case['vusdfld']['fields'] + 1)]
    return case['check'](fields, s6)


def run(cmd, cwd):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT='1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM='1')
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=env, timeout=900)
    if proc.returncode != 0:
        raise uc.Failed(f'exit {proc.returncode}: {" ".join(cmd)}\n{proc.stdout[-1500:]}{proc.stderr[-1500:]}')
    return proc


def props_text(props):
    return ',\n'.join(', '.join(repr(float(v)) for v in props[i:i + 8]) for i in range(0, len(props), 8))


def material_block(name, case, density=None):
    density = case['density'] if density is None else density
    return (f'*MATERIAL, NAME={name}\n*DENSITY\n{density!r}\n'
            f'*USER MATERIAL, CONSTANTS={len(case["props"])}\n{props_text(case["props"])}\n'
            f'*DEPVAR\n{case["depvar"]}\n')


def host_elements(case, user_file, work: Path, ndim: int, check):
    work.mkdir(parents=True, exist_ok=True)
    scene = work / 'compress.inp'
    stretch = case['stretch'][ndim] if 'stretch' in case else [0.0, case['strain'], 0.0]
    rate, total = case.get('temp_rate', 0.0), 2e-3
    f_end, _ = uc.element_scene(scene, ndim, (1,) * ndim, stretch, [0, 0, 1], 0.0, total, temp_rate=rate)
    text = scene.read_text()
    start = text.index('*MATERIAL')
    end = text.index('*INITIAL CONDITIONS')
    text = text[:start] + material_block('PUBLIC', case, case.get('element_density')) + text[end:]
    text = text.replace('MATERIAL=PROBE-NEO', 'MATERIAL=PUBLIC')
    if 'element_initial' in case:
        text = text.replace('*STEP, NAME=MOVE', f'*INITIAL CONDITIONS, TYPE=STRESS\nALL, {case["element_initial"]}\n'
                            '*STEP, NAME=MOVE')
    if rate:
        # every increment in the history: the time at the start of the last one gives its tempOld
        text = text.replace('*OUTPUT, HISTORY, NUMBER INTERVAL=10', '*OUTPUT, HISTORY, FREQUENCY=1')
    scene.write_text(text)
    run([str(BULKFLOW), str(scene), '--quiet', '--user', str(user_file)], work)
    fr = uc.last_frame(work / 'compress.h5', 'frames')
    s = fr['S'][0]
    s6 = list(s) if len(s) == 6 else [s[0], s[1], s[2], s[3], 0.0, 0.0]
    ctx = {'F': f_end}
    if rate:
        times = np.genfromtxt(work / 'compress_history.csv', delimiter=',', names=True)['time']
        if not math.isclose(times[-1], total, rel_tol=1e-12):
            raise uc.Failed(f'the history ends at t = {times[-1]!r}, not at the step end {total!r}')
        ctx['temp_old'], ctx['temp_new'] = uc.T0 + rate * times[-2], uc.T0 + rate * times[-1]
    return check(s6, fr['SDV'][0], ctx)


def host_matpoint(case, user_file, work: Path, check):
    """The driver: an oedometer test (uniaxial strain), or the case's own test (`matpoint`)."""
    work.mkdir(parents=True, exist_ok=True)
    inp = work / 'oedometer.inp'
    temp = case.get('matpoint_temperature')
    extra = f'*INITIAL CONDITIONS, TYPE=TEMPERATURE\n{temp!r}\n' if temp is not None else ''
    if 'matpoint' in case:
        mp = case['matpoint']
        extra += f'*INITIAL CONDITIONS, TYPE=STRESS\n{mp["initial"]}\n' if 'initial' in mp else ''
        test = f'*TEST, TYPE={mp["test"]}\n{mp["stage"]}\n'
    else:
        test = f'*TEST, TYPE=OEDOMETER\n*STAGE, STRAIN={case["strain"]}, INC=100\n'
    inp.write_text('*HEADING\npublic VUMAT, driver\n' + material_block('PUBLIC', case) + extra + test)
    run([str(MATPOINT), str(inp), '-o', 'oedometer.csv', '--user', str(user_file)], work)
    data = np.genfromtxt(work / 'oedometer.csv', delimiter=',', names=True)
    s6 = [data[c][-1] if c in data.dtype.names else 0.0 for c in ('s11', 's22', 's33', 's12', 's23', 's31')]
    sdv = [data[f'SDV{i}'][-1] for i in range(1, case['depvar'] + 1)]
    return check(s6, sdv, {'temp_old': temp, 'temp_new': temp})


def host_mpm(case, user_file, work: Path, ndim: int = 3):
    """Vertical equilibrium of a column between frictionless walls, any material (3D:
    inputs/mpm/column_k0_3d.inp, 2D: column_k0_2d.inp, with the case's material). With
    `mpm_lateral`, also the Mohr-Coulomb column's lateral stress (mohr_coulomb_lateral)."""
    work.mkdir(parents=True, exist_ok=True)
    text = (REPO / 'inputs' / 'mpm' / f'column_k0_{ndim}d.inp').read_text()
    start = text.index('*MATERIAL')
    end = text.index('*PARTICLES')
    text = text[:start] + material_block('SOIL', case) + text[end:]
    text = text.replace('*ELEMENT OUTPUT\nS\n', '*ELEMENT OUTPUT\nS, SDV\n')
    scene = work / 'column.inp'
    scene.write_text(text)
    run([str(BULKFLOW), str(scene), '--quiet', '--user', str(user_file)], work)
    fr = uc.last_frame(work / 'column.h5', 'particles')
    y = fr['coordinates'][:, 1]
    rho, g, height = case['density'], 9.81, 1.0
    # the top of the column: half a particle spacing above the highest particle (2D: cell 0.05,
    # 2 particles per cell; the 3D figure is the one this check has always used)
    top = y.max() + (0.05 if ndim == 3 else 0.0125)
    want = -rho * g * height * (top - y) / top
    err = float(np.max(np.abs(fr['S'][:, 1] - want)))
    results = [('sigma_yy vs -rho g (H - y)', err, 0.05 * rho * g * height)]
    if case.get('mpm_lateral'):
        for k, name in ((0, 'sigma_xx'), (2, 'sigma_zz')):
            results.append(mohr_coulomb_lateral(case, name, fr['S'][:, k], fr['S'][:, 1], 0.05 * rho * g * height))
    return results


def mohr_coulomb_lateral(case, name, s_h, s_v, tol):
    """A Mohr-Coulomb column at rest between frictionless walls, loaded monotonically in uniaxial
    strain (compression positive): sigma_h = K0 sigma_v while elastic, K0 = nu/(1 - nu); on the
    line sigma_h = K_a sigma_v - 2 c sqrt(K_a) (K_a = (1 - sin phi)/(1 + sin phi)) where that is
    larger, i.e. once K0 sigma_v would fall below it: sigma_h = max of the two."""
    nu, c, phi = case['props'][1], case['props'][2], math.radians(case['props'][3])
    k0, ka = nu / (1 - nu), (1 - math.sin(phi)) / (1 + math.sin(phi))
    sv = -np.asarray(s_v)
    want = np.maximum(k0 * sv, ka * sv - 2 * c * math.sqrt(ka))
    yielded = int(np.count_nonzero(ka * sv - 2 * c * math.sqrt(ka) > k0 * sv))
    err = float(np.max(np.abs(-np.asarray(s_h) - want)))
    return (f'{name} vs max(K0 sigma_v, K_a sigma_v - 2c sqrt(K_a)) ({yielded} of {len(sv)} particles '
            f'on the line)', err, tol)


def compile_object(case, source: Path, work: Path, build: Path) -> Path:
    """A file that needs compiler flags of its own (`fflags`) is compiled here, unchanged, by the
    build's Fortran compiler with the flags --user uses for fixed form plus those, into an
    object file that --user links (docs/user_subroutines.md: `.o` files)."""
    work.mkdir(parents=True, exist_ok=True)
    compiler = 'gfortran'
    cache = build / 'CMakeCache.txt'
    if cache.exists():
        for line in cache.read_text().splitlines():
            if line.startswith('CMAKE_Fortran_COMPILER:'):
                compiler = line.split('=', 1)[1]
    obj = work / (source.stem + '.o')
    cmd = [compiler, '-c', '-fPIC', '-O2', '-ffixed-form', '-ffixed-line-length-132', *case['fflags'],
           '-I', str(source.parent), '-I', str(build / 'abaqus_include'), str(source), '-o', str(obj)]
    print(f'  compiled unchanged: {" ".join(cmd)}')
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise uc.Failed(f'{" ".join(cmd)}\n{proc.stderr[-2000:]}')
    return obj


def verdict(ok: bool) -> str:
    return 'PASS' if ok else 'FAIL'


def run_host(case, host, user_file, work, check):
    """One host of one case: prints its lines, returns the number of failures."""
    if check is None:
        pairs = host_vusdfld(case, user_file, work, 2 if host == 'cpe4r' else 3)
        ok = all(abs(g - w) <= case['tol'] * max(1.0, abs(w)) for g, w in pairs)
        print(f'  {host:9s} fields ' + ', '.join(f'{g:.9e} (closed form {w:.9e})' for g, w in pairs)
              + f' {verdict(ok)}')
        return 0 if ok else 1
    if host in ('mpm2d', 'mpm3d'):
        failures = 0
        for label, err, tol in host_mpm(case, user_file, work, 2 if host == 'mpm2d' else 3):
            print(f'  {host:9s} {label}: max error {err:.3e} (limit {tol:.1e}) {verdict(err <= tol)}')
            failures += 0 if err <= tol else 1
        return failures
    if host == 'matpoint':
        result = host_matpoint(case, user_file, work, check)
    else:
        result = host_elements(case, user_file, work, 2 if host == 'cpe4r' else 3, check)
    if isinstance(result, tuple):
        result = [('yield measure', *result)]
    failures = 0
    for label, got, want in result:
        rel = abs(got - want) / abs(want)
        ok = rel <= case['tol']
        failures += 0 if ok else 1
        print(f'  {host:9s} {label} {got:.9e}, closed form {want:.9e}, relative error {rel:.2e} {verdict(ok)}')
    return failures


def main() -> int:
    global BULKFLOW, MATPOINT
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--dir', type=Path, required=True, help='folder with the downloaded files')
    p.add_argument('--build', type=Path, default=REPO / 'build')
    p.add_argument('--work', type=Path, default=Path('/tmp/bulkflow_public_vumats'))
    p.add_argument('--only', nargs='+', choices=sorted(CASES), help='run these cases only')
    a = p.parse_args()
    a.build, a.dir = a.build.resolve(), a.dir.resolve()   # the hosts run in their own folders
    BULKFLOW = a.build / 'bin' / 'bulkflow'
    MATPOINT = a.build / 'bin' / 'bulkflow-matpoint'
    os.environ.setdefault('BULKFLOW_CACHE_DIR', str(a.work / 'cache'))
    failures = 0
    for name, case in CASES.items():
        if a.only and name not in a.only:
            continue
        user_file = a.dir / case['file']
        print(f'{name}: {case["repo"]} {case["path"]} (commit {case["commit"]}; {case["what"]})')
        missing = [f for f in [case['file'], *case.get('needs', [])] if not (a.dir / f).exists()]
        if missing:
            print(f'  missing {", ".join(str(a.dir / f) for f in missing)}: download first  FAIL')
            failures += 1
            continue
        check = case['check'](case['props']) if 'props' in case else None
        if 'fflags' in case:
            try:
                user_file = compile_object(case, user_file, a.work / name, a.build)
            except uc.Failed as exc:
                print(f'  compile  FAIL: {exc}')
                failures += 1
                continue
        for host in ('cpe4r', 'c3d8r', 'mpm2d', 'mpm3d', 'matpoint'):
            if host not in case['hosts']:
                if host == 'mpm2d' and 'mpm2d' not in case.get('why', {}):
                    continue   # the 2D column is run for plane-strain-only files
                why = {'mpm3d': 'particles write no FV', 'matpoint': 'the driver keeps its own VUSDFLD door'}
                reason = why[host] if check is None else case.get('why', {}).get(host, 'the file does not serve it')
                print(f'  {host:9s} skipped ({reason})')
                continue
            try:
                failures += run_host(case, host, user_file, a.work / name / host, check)
            except uc.Failed as exc:
                print(f'  {host:9s} FAIL: {exc}')
                failures += 1
    print('all passed' if failures == 0 else f'{failures} failure(s)')
    return 0 if failures == 0 else 1


if __name__ == '__main__':
    sys.exit(main())
