"""bulkflow-accuracy arching-cow's options: the material (--cow-case), Davis's flow rule
(--flow-rule), the criterion and the members (--n-arcs) reach every member's scene and the
family's title; the options are refused for other kinds and with unusable member lists."""
import pytest

from bulkflow.accuracy import arching_cow, cli


@pytest.fixture
def family(monkeypatch):
    """The module's settings, restored after the test."""
    for name in ("N_ARCS", "CRITERION", "FLOW_RULE", "CASE"):
        monkeypatch.setattr(arching_cow, name, getattr(arching_cow, name))
    return arching_cow


def test_members_and_scene_follow_the_settings(family):
    family.N_ARCS, family.FLOW_RULE, family.CASE, family.CRITERION = [16, 30, 60], "davis", "polymer", "half-element"
    ms = family.members(quick=False)
    assert [m["n_arc"] for m in ms] == [16, 30, 60]
    assert all(m["tol"] == 0.002 for m in ms)
    sc = family.member_scene(30)
    assert (sc.n_arc, sc.flow_rule, sc.criterion, sc.height) == (30, "davis", "half-element", 1.0)
    ref = family.member_scene(30)
    family.CASE = "B"
    b = family.member_scene(30)
    assert (b.phi, b.fc0) != (ref.phi, ref.fc0)       # another material, not a relabelled one
    assert "Davis" in family.title() and "half an outlet element" in family.title()
    assert "stops moving" in family.expected_order()


def test_defaults_are_the_thesis_material_and_the_physical_criterion(family):
    sc = family.member_scene(20)
    assert (sc.flow_rule, sc.criterion) == ("nonassociated", "physical")
    assert [m["n_arc"] for m in family.members(quick=True)] == family.QUICK
    assert "ψ = 0" in family.title() and "3 % of the outlet width" in family.title()


@pytest.mark.parametrize("argv, message", [
    (["wave-bar", "--flow-rule", "davis"], "apply to arching-cow only"),
    (["hopper-mdr", "--n-arcs", "10,20,30"], "apply to arching-cow only"),
    (["arching-cow", "--n-arcs", "10,20"], "at least three distinct"),
    (["arching-cow", "--n-arcs", "10,10,20"], "at least three distinct"),
    (["arching-cow", "--n-arcs", "2,10,20"], "at least 4 elements"),
    (["arching-cow", "--n-arcs", "10,a,20"], "whole numbers"),
    (["arching-cow", "--flow-rule", "tresca"], "invalid choice"),
    (["arching-cow", "--cow-case", "A"], "invalid choice"),
])
def test_refused(family, capsys, argv, message):
    with pytest.raises(SystemExit) as exc:
        cli.main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


def test_output_folder_names_the_variant(family, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit):           # nothing measured yet: the folder is named in the error
        cli.main(["arching-cow", "--flow-rule", "davis", "--cow-case", "polymer", "--n-arcs", "16,30,60",
                  "--summarise-only"])
    assert "arching-cow-polymer-davis/arching-cow.json does not exist" in capsys.readouterr().err
    assert family.N_ARCS == [16, 30, 60] and family.FLOW_RULE == "davis" and family.CASE == "polymer"


def test_table_shows_each_search_interval():
    from bulkflow.accuracy.study import _cell_value

    assert _cell_value({"value": 0.33291, "no_flow": 0.33218, "flow": 0.33364}) == "0.33291 (0.33218 .. 0.33364)"
    assert _cell_value({"value": 7.04}) == "7.04"
    assert _cell_value({"value": None, "tss_status": "not reached"}) == "none (not reached)"
