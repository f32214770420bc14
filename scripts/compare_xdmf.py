#!/usr/bin/env python3
"""Two XDMF files describe the same data: the same tree of grids, names, times (as doubles),
topologies, geometries, attributes (name, type, centre) and DataItems (dimensions, number type,
dataset path; inline XML numbers as doubles). Ignored: the XDMF version, layout and number
formatting, and the HDF5 file name before the ':' (two runs' outputs have different names).

    python3 scripts/compare_xdmf.py A.xmf B.xmf      (exit 1 if they differ)

Used for issue 18's move of the MPM's particle XDMF onto output_xdmf (XDMF 3.0 text -> the
element writer's XDMF 2.0 form, the same grids).
"""
import sys
import xml.etree.ElementTree as ET


def described(path):
    out = []

    def walk(e):
        a = dict(e.attrib)
        if e.tag == 'Xdmf':
            a.pop('Version', None)
        if e.tag == 'Time':
            a['Value'] = float(a['Value'])
        text = (e.text or '').strip()
        if e.tag == 'DataItem':
            text = tuple(float(x) for x in text.split()) if a.get('Format') == 'XML' else text.split(':', 1)[-1]
        out.append((e.tag, tuple(sorted(a.items())), text))
        for c in e:
            walk(c)

    walk(ET.parse(path).getroot())
    return out


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    same = described(sys.argv[1]) == described(sys.argv[2])
    print('same data described' if same else 'XDMF files differ')
    return 0 if same else 1


if __name__ == '__main__':
    sys.exit(main())
