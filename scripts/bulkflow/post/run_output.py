"""Readers for what a bulkflow run writes: BASE_history.csv, BASE.h5 (field frames), and the few
facts about the scene that post-processing needs from the .inp (densities, gravity, analytic
rigid walls). They read files only, never the solver's stdout.

HDF5 layout (src/output/output_hdf5.f90): /mesh/{coordinates (n, 3), connectivity (m, nen),
node_id, element_id} with attributes element_type, ndim, nen; /frames/NNNNNN/{coordinates
(current, (n, 3)), U, V, A, RF (n, ndim), S, LE (m, ncomp), PEEQ, SDVk (m,)} with attributes
step, step_time, total_time, increment. Stress components 11, 22, 33, 12[, 23, 31], tension positive.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


# ---- history CSV --------------------------------------------------------------------------------
def read_history(path) -> dict[str, np.ndarray]:
    """Columns of BASE_history.csv as 1-D float arrays, in file order."""
    path = Path(path)
    with path.open() as handle:
        names = [n.strip() for n in handle.readline().split(",")]
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: {len(names)} column names but {data.shape[1]} values per row")
    return {name: data[:, i] for i, name in enumerate(names)}


# ---- field frames -------------------------------------------------------------------------------
@dataclass
class Frame:
    step: int
    step_time: float
    total_time: float
    increment: int
    coordinates: np.ndarray                 #: current coordinates (n, 3)
    fields: dict = field(default_factory=dict)


class FieldFile:
    """Mesh and frames of a BASE.h5 (opened lazily with h5py)."""

    def __init__(self, path):
        import h5py

        self.path = Path(path)
        self._h5 = h5py.File(self.path, "r")
        mesh = self._h5["mesh"]
        self.x0 = mesh["coordinates"][:]
        self.connectivity = mesh["connectivity"][:] - self._index_base(mesh)
        self.node_id = mesh["node_id"][:]
        self.element_id = mesh["element_id"][:]
        etype = mesh.attrs.get("element_type", b"")
        self.element_type = etype.decode() if isinstance(etype, bytes) else str(etype)
        self.ndim = int(mesh.attrs.get("ndim", 2))
        self.frame_names = sorted(self._h5["frames"].keys())

    def _index_base(self, mesh) -> int:
        """Connectivity is 0-based in the file (XDMF); keep a check in case that changes."""
        conn = mesh["connectivity"]
        n = mesh["coordinates"].shape[0]
        cmax = int(np.max(conn[:])) if conn.size else 0
        return 1 if cmax == n else 0

    def __len__(self) -> int:
        return len(self.frame_names)

    def frame(self, index: int = -1, names=None) -> Frame:
        g = self._h5["frames"][self.frame_names[index]]
        fields = {k: g[k][:] for k in g.keys() if k != "coordinates" and (names is None or k in names)}
        a = g.attrs
        return Frame(int(a["step"]), float(a["step_time"]), float(a["total_time"]), int(a["increment"]),
                     g["coordinates"][:], fields)

    def close(self):
        self._h5.close()


def element_areas(x: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Areas of quads (first four nodes of each element, in the x-y plane)."""
    p = x[conn[:, :4], :2]
    return 0.5 * np.abs((p[:, 2, 0] - p[:, 0, 0]) * (p[:, 3, 1] - p[:, 1, 1])
                        - (p[:, 2, 1] - p[:, 0, 1]) * (p[:, 3, 0] - p[:, 1, 0]))


def hex_volumes(x: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Volumes of 8-node hexes (Abaqus node order) as five tetrahedra: exact when the faces are
    planar (as in the extruded meshes of our generators), close otherwise."""
    p = x[conn]
    tets = [(0, 1, 3, 4), (1, 2, 3, 6), (1, 4, 5, 6), (3, 4, 6, 7), (1, 3, 4, 6)]
    vol = np.zeros(len(conn))
    for a, b, c, d in tets:
        vol += np.abs(np.einsum("ij,ij->i", p[:, b] - p[:, a], np.cross(p[:, c] - p[:, a], p[:, d] - p[:, a]))) / 6
    return vol


# ---- the scene file -----------------------------------------------------------------------------
@dataclass
class Segment:
    kind: str                 #: "LINE" or "CIRCL"
    p0: tuple
    p1: tuple
    centre: tuple | None = None

    def points(self, n: int = 40) -> np.ndarray:
        """Points along the segment (2, k)."""
        if self.kind == "LINE":
            return np.array([self.p0, self.p1]).T
        c = np.array(self.centre)
        a0 = math.atan2(self.p0[1] - c[1], self.p0[0] - c[0])
        a1 = math.atan2(self.p1[1] - c[1], self.p1[0] - c[0])
        da = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi        # the short way (< 180°)
        r = math.hypot(self.p0[0] - c[0], self.p0[1] - c[1])
        t = a0 + da * np.linspace(0, 1, n)
        return np.array([c[0] + r * np.cos(t), c[1] + r * np.sin(t)])

    def material_normal(self) -> np.ndarray | None:
        """Unit normal into the material (left of the direction of travel), straight lines only."""
        if self.kind != "LINE":
            return None
        d = np.subtract(self.p1, self.p0)
        d = d / np.linalg.norm(d)
        return np.array([-d[1], d[0]])


@dataclass
class SceneFacts:
    heading: str = ""
    densities: dict = field(default_factory=dict)          #: material name -> ρ
    section_material: dict = field(default_factory=dict)   #: element set -> material name
    thickness: dict = field(default_factory=dict)          #: element set -> 2D thickness
    gravity: float = 0.0                                   #: |g| of the first GRAV load
    gravity_direction: tuple = (0.0, -1.0, 0.0)
    walls: dict = field(default_factory=dict)              #: name -> [Segment] (TYPE=SEGMENTS)
    planes: dict = field(default_factory=dict)             #: name -> (point, normal) (TYPE=PLANE)
    user_field: bool = False


def _lines(path: Path):
    """Logical lines of an .inp with *INCLUDE followed; comments and blank lines dropped."""
    for raw in path.read_text().splitlines():
        s = raw.strip()
        if not s or s.startswith("**"):
            continue
        m = re.match(r"\*INCLUDE\s*,\s*INPUT\s*=\s*(.+)$", s, re.I)
        if m:
            yield from _lines(path.parent / m.group(1).strip().strip('"'))
            continue
        yield s


def _params(line: str) -> tuple[str, dict]:
    parts = [p.strip() for p in line[1:].split(",")]
    kw = parts[0].upper()
    params = {}
    for p in parts[1:]:
        if "=" in p:
            k, v = p.split("=", 1)
            params[k.strip().upper()] = v.strip().strip('"').upper()
        elif p:
            params[p.upper()] = ""
    return kw, params


def read_scene_facts(path) -> SceneFacts:
    """The facts post-processing needs from a scene (not a full reader: the solver checks scenes)."""
    facts = SceneFacts()
    kw, params, material = "", {}, None
    surface = None
    data_count = 0
    for line in _lines(Path(path)):
        if line.startswith("*"):
            kw, params = _params(line)
            data_count = 0
            surface = None
            if kw == "MATERIAL":
                material = params.get("NAME")
            elif kw == "USER DEFINED FIELD":
                facts.user_field = True
            elif kw == "SOLID SECTION":
                facts.section_material[params.get("ELSET")] = params.get("MATERIAL")
            elif kw == "SURFACE" and params.get("TYPE") in ("SEGMENTS", "PLANE"):
                surface = params.get("NAME")
                if params["TYPE"] == "SEGMENTS":
                    facts.walls[surface] = []
                else:
                    facts.planes[surface] = []
            continue
        data_count += 1
        fields = [f.strip() for f in line.split(",")]
        if kw == "HEADING" and data_count == 1:
            facts.heading = line
        elif kw == "DENSITY" and material and data_count == 1:
            facts.densities[material] = float(fields[0])
        elif kw == "SOLID SECTION" and data_count == 1 and fields[0]:
            facts.thickness[params.get("ELSET")] = float(fields[0])
        elif kw == "DLOAD" and len(fields) > 2 and fields[1].upper() == "GRAV" and facts.gravity == 0:
            facts.gravity = float(fields[2])
            d = [float(f) if f else 0.0 for f in fields[3:6]] + [0.0] * 3
            n = math.sqrt(sum(v * v for v in d[:3])) or 1.0
            facts.gravity_direction = tuple(v / n for v in d[:3])
        elif surface is not None and surface in facts.walls:
            segs = facts.walls[surface]
            tag = fields[0].upper()
            nums = [float(f) for f in fields[1:] if f]
            if tag == "START":
                segs.append(Segment("START", tuple(nums[:2]), tuple(nums[:2])))
            else:
                p0 = segs[-1].p1
                if tag == "LINE":
                    segs.append(Segment("LINE", p0, tuple(nums[:2])))
                elif tag == "CIRCL":
                    segs.append(Segment("CIRCL", p0, tuple(nums[:2]), tuple(nums[2:4])))
        elif surface is not None and surface in facts.planes:
            facts.planes[surface].append(tuple(float(f) for f in fields[:3]))
    for name in facts.walls:
        facts.walls[name] = [s for s in facts.walls[name] if s.kind != "START"]
    return facts


def scene_weight(facts: SceneFacts, fields_file: FieldFile) -> float:
    """Weight of the deformable material (per unit depth × thickness in 2D): Σ ρ V₀ |g|, for a
    scene with one material (the density of the first material is used for all elements)."""
    if not facts.densities:
        raise ValueError("no *DENSITY in the scene")
    rho = next(iter(facts.densities.values()))
    if fields_file.element_type.upper().startswith("C3D"):
        volume = hex_volumes(fields_file.x0, fields_file.connectivity).sum()
    else:
        t = next(iter(facts.thickness.values()), 1.0)
        volume = t * element_areas(fields_file.x0, fields_file.connectivity).sum()
    return rho * volume * facts.gravity
