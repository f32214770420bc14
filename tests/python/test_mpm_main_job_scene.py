"""The main job's MPM scene (inputs/demo/wedge_hopper_mpm_discharge.inp) is what the generator
writes: its header names the command, and that command run again gives the file byte for byte.
Also: the generator's defaults are unchanged by the header and discharge-frames options (the ch. 4
studies name their cached runs by the scene text), and the scene's geometry reads back."""
import shlex
from pathlib import Path

from bulkflow.mpm import hopper_scene
from bulkflow.post.mpm_scene import hopper_geometry, read_mpm_scene

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "inputs" / "demo" / "wedge_hopper_mpm_discharge.inp"


def _command(text):
    lines = [x for x in text.splitlines() if x.startswith("** command: ")]
    assert len(lines) == 1, "the header names the generator's command once"
    args = shlex.split(lines[0][len("** command: "):])
    assert args[0] == "bulkflow-make-mpm-hopper" and args[-2:] == ["-o", "FILE"]
    return args[1:-2]


def test_generator_reproduces_the_committed_scene(tmp_path):
    text = SCENE.read_text()
    out = tmp_path / "scene.inp"
    assert hopper_scene.main(_command(text) + ["-o", str(out)]) == 0
    assert out.read_bytes() == SCENE.read_bytes()


def test_the_scene_is_the_default_hopper_without_inflow():
    text = SCENE.read_text()
    args = _command(text)
    assert "--no-inflow" in args
    for option in ("--theta", "--outlet", "--height", "--wall-friction", "--phi"):
        assert option not in args, f"{option}: the default hopper's geometry and Table 4.2 material"
    g = hopper_geometry(read_mpm_scene(SCENE))
    assert abs(g["theta"] - 30.0) < 1e-6 and abs(g["outlet"] - 0.25) < 1e-9
    assert "*INFLOW" not in text and "*MPM WALL, NAME=OUTLET, OP=DELETE" in text


def test_defaults_unchanged_by_the_new_options():
    base = hopper_scene.hopper_scene()
    assert "** command:" not in base
    assert hopper_scene.hopper_scene(discharge_frames=10) == base
    assert base.count("*OUTPUT, FIELD, NUMBER INTERVAL=10") == 2
    two = hopper_scene.hopper_scene(discharge_frames=40)
    assert two.count("NUMBER INTERVAL=10") == 1 and two.count("NUMBER INTERVAL=40") == 1


def test_command_line_hides_the_output_path():
    cmd = hopper_scene.command_line(["-o", "/tmp/x.inp", "--cell", "0.05", "--output=y", "--no-inflow"])
    assert cmd == "bulkflow-make-mpm-hopper --cell 0.05 --no-inflow -o FILE"
