"""Rewrite a flat bulkflow scene in the layout Abaqus/CAE writes: the mesh in a *PART, an
*ASSEMBLY with one *INSTANCE of it, each analytic rigid wall as an instance of an empty part
holding its reference node, *SURFACE, TYPE=SEGMENTS and *RIGID BODY (as CAE writes analytic
rigid parts), contact surfaces at the assembly level, and every reference to a part's set
qualified with its instance (`FILL-1.AXIS`).

The two decks mean the same model, so bulkflow must give bit-identical results on both
(tests/scenes: scene_cae_layout_wedge). The instances are not moved (a moved instance rounds
coordinates differently). Node numbers come out the same as in the flat deck as long as the
reference nodes follow the mesh nodes, as in the decks bulkflow-make-hopper writes.

    python -m bulkflow.scenes.cae_layout flat.inp cae.inp [--period T] [--instance FILL-1]
"""
from __future__ import annotations

import argparse
import re
from pathlib import Path

PART_KEYWORDS = {'NODE', 'ELEMENT', 'NSET', 'ELSET', 'SOLID SECTION'}


class Block:
    def __init__(self, line: str):
        self.line = line.rstrip('\n')
        head = [f.strip() for f in self.line[1:].split(',')]
        self.name = re.sub(r'\s+', ' ', head[0]).upper()
        self.params: dict[str, str] = {}
        for f in head[1:]:
            if not f:
                continue
            k, _, v = f.partition('=')
            self.params[re.sub(r'\s+', ' ', k).strip().upper()] = v.strip()
        self.data: list[str] = []

    def param(self, key: str, default: str = '') -> str:
        return self.params.get(key, default)

    def text(self, params: dict[str, str] | None = None) -> list[str]:
        if params is None:
            head = [self.line]
        else:
            parts = [self.line[1:].split(',')[0].strip()]
            parts += [k if v == '' else f'{k}={v}' for k, v in params.items()]
            head = ['*' + ', '.join(parts)]
        return head + self.data


def read_blocks(path: Path) -> list[Block]:
    blocks: list[Block] = []
    for raw in path.read_text().splitlines():
        s = raw.strip()
        if not s or s.startswith('**'):
            continue
        if s.startswith('*'):
            blocks.append(Block(s))
        else:
            blocks[-1].data.append(raw.rstrip())
    return blocks


def convert(flat: Path, out: Path, instance: str = 'FILL-1', period: float | None = None,
            walls: str = 'instance') -> Path:
    """walls='instance': each analytic wall in its own instance (names `WALL-1.WALL`);
    walls='assembly': reference nodes, surfaces and rigid bodies at the assembly level (as
    CAE writes reference points made in the assembly), names unchanged."""
    blocks = read_blocks(flat)
    first_step = next(i for i, b in enumerate(blocks) if b.name == 'STEP')
    model, history = blocks[:first_step], blocks[first_step:]
    rigid = {b.param('ANALYTICAL SURFACE').upper(): b.param('REF NODE').upper()
             for b in model if b.name == 'RIGID BODY'}
    ref_sets = set(rigid.values())
    walls = {surf: surf + '-1' for surf in rigid} if walls == 'instance' else {}
    wall_of_ref = {ref: walls[surf] for surf, ref in rigid.items() if surf in walls}
    part_sets: set[str] = set()
    for b in model:
        for key in ('NSET', 'ELSET'):
            if b.name in PART_KEYWORDS and key in b.params and b.param(key).upper() not in ref_sets:
                part_sets.add(b.param(key).upper())

    def qualify(name: str) -> str:
        up = name.strip().upper()
        if up in part_sets:
            return f'{instance}.{name.strip()}'
        if up in wall_of_ref:
            return f'{wall_of_ref[up]}.REF'
        if up in walls:
            return f'{walls[up]}.{name.strip()}'
        return name

    def first_field(line: str, count: int = 1) -> str:
        fields = line.split(',')
        for i in range(min(count, len(fields))):
            fields[i] = ' ' + qualify(fields[i]) if i else qualify(fields[i])
        return ','.join(fields)

    lines: list[str] = []
    heading = [b for b in model if b.name == 'HEADING']
    for b in heading:
        lines += b.text()
    lines += [f'** {flat.name} in the layout Abaqus/CAE writes (parts, an assembly, instances, analytic',
              '** rigid parts); written by bulkflow.scenes.cae_layout: same model, same results.',
              '*Preprint, echo=NO, model=NO, history=NO, contact=NO', '**', '** PARTS', '**',
              f'*Part, name={instance.rsplit("-", 1)[0]}']
    for b in model:
        if b.name in PART_KEYWORDS and not (b.name == 'NODE' and b.param('NSET').upper() in ref_sets):
            lines += b.text()
    lines.append('*End Part')
    for surf in walls:
        lines += [f'*Part, name={surf}', '*End Part']
    asm_nodes = [b for b in model if b.name == 'NODE' and b.param('NSET').upper() in ref_sets and not walls]
    lines += ['**', '** ASSEMBLY', '**', '*Assembly, name=Assembly', f'*Instance, name={instance}, '
              f'part={instance.rsplit("-", 1)[0]}', '*End Instance']
    for surf, inst in walls.items():
        ref_block = next(b for b in model if b.name == 'NODE' and b.param('NSET').upper() == rigid[surf])
        coords = ref_block.data[0].split(',', 1)[1]
        seg = next(b for b in model if b.name == 'SURFACE' and b.param('NAME').upper() == surf)
        lines += [f'*Instance, name={inst}, part={surf}', '*Node', f'1,{coords}',
                  '*Nset, nset=REF, internal', '1,']
        lines += seg.text()
        lines += [f'*Rigid Body, ref node=REF, analytical surface={seg.param("NAME")}', '*End Instance']
    n_ref = 0
    for b in asm_nodes:                       # reference points of the assembly: numbers after the instances
        lines.append(b.line)
        for d in b.data:
            n_ref += 1
            lines.append(f'{n_ref},{d.split(",", 1)[1]}')
    for b in model:
        if b.name == 'SURFACE' and b.param('TYPE', 'ELEMENT').upper() == 'ELEMENT':
            lines += [b.line] + [first_field(d) for d in b.data]
        elif b.name in ('SURFACE', 'RIGID BODY') and not walls:
            lines += b.text()
    lines.append('*End Assembly')
    for b in model:
        if b.name in PART_KEYWORDS or b.name in ('HEADING', 'RIGID BODY', 'SURFACE'):
            continue
        if b.name in ('BOUNDARY', 'INITIAL CONDITIONS'):
            lines += [b.line] + [first_field(d) for d in b.data]
        else:
            lines += b.text()
    for b in history:
        params = {k: (qualify(v) if k in ('NSET', 'ELSET') else v) for k, v in b.params.items()}
        if b.name in ('BOUNDARY', 'DLOAD', 'INITIAL CONDITIONS'):
            lines += b.text(params)[:1] + [first_field(d) for d in b.data]
        elif b.name == 'CONTACT PAIR':
            lines += b.text(params)[:1] + [first_field(d, 2) for d in b.data]
        elif b.name == 'DYNAMIC' and period is not None:
            dt = b.data[0].split(',')[0] if b.data else ''
            lines += b.text(params)[:1] + [f'{dt}, {period!r}']
        else:
            lines += b.text(params)
    out.write_text('\n'.join(lines) + '\n')
    return out


def with_period(flat: Path, out: Path, period: float) -> Path:
    """The flat deck itself with every step's period replaced (the reference run)."""
    text, after_dynamic = [], False
    for raw in flat.read_text().splitlines():
        s = raw.strip()
        if after_dynamic and s and not s.startswith('**'):
            dt = s.split(',')[0]
            raw = f'{dt}, {period!r}'
            after_dynamic = False
        elif s.upper().replace(' ', '').startswith('*DYNAMIC'):
            after_dynamic = True
        text.append(raw)
    out.write_text('\n'.join(text) + '\n')
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    p.add_argument('flat', type=Path)
    p.add_argument('out', type=Path)
    p.add_argument('--period', type=float, help='replace every step period (short test runs)')
    p.add_argument('--instance', default='FILL-1', help='name of the mesh instance (part name: up to the last -)')
    p.add_argument('--flat-out', type=Path, help='also write the flat deck with --period applied here')
    p.add_argument('--walls', choices=('instance', 'assembly'), default='instance',
                   help='analytic walls as instances of their own parts, or at the assembly level')
    a = p.parse_args(argv)
    convert(a.flat, a.out, a.instance, a.period, a.walls)
    if a.flat_out:
        if a.period is None:
            a.flat_out.write_text(a.flat.read_text())
        else:
            with_period(a.flat, a.flat_out, a.period)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
