"""Unit tests of cmake/pf_preprocess.py (run by CTest as pf_preprocess_pytest)."""

import importlib.util
import os
from pathlib import Path

import pytest

_SCRIPT = Path(os.environ.get(
    "BULKFLOW_PF_PREPROCESSOR",
    Path(__file__).resolve().parents[2] / "cmake" / "pf_preprocess.py"))
_SPEC = importlib.util.spec_from_file_location("pf_preprocess", _SCRIPT)
pf = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(pf)


def module_text(*body, name="test_demo"):
    """A minimal .pf module with the given lines inside `contains`."""
    return "\n".join([f"module {name}", "  use funit", "  implicit none", "contains",
                      *body, f"end module {name}", ""])


def one_test(*lines):
    return module_text("  @test", "  subroutine test_one()", *lines, "  end subroutine test_one")


def error_of(text, name="test_demo.pf"):
    with pytest.raises(pf.PfError) as caught:
        pf.preprocess(text, name)
    return caught.value


@pytest.mark.parametrize("text, expected", [
    ("a, b", ["a", "b"]),
    ("f(x, y), [1, 2], (/ 3, 4 /)", ["f(x, y)", "[1, 2]", "(/ 3, 4 /)"]),
    ("'a, (b', \"c, d)\"", ["'a, (b'", "\"c, d)\""]),
    ("'it''s, here', x", ["'it''s, here'", "x"]),
    ("a(b(c, d), [e, f(g, h)]), tolerance=t(1, 2)", ["a(b(c, d), [e, f(g, h)])", "tolerance=t(1, 2)"]),
    ("", []),
])
def test_split_arguments(text, expected):
    assert pf.split_arguments(text, 1) == expected


@pytest.mark.parametrize("text", ["a, (b", "a), b", "'open, b", "a, , b"])
def test_split_arguments_rejects_malformed(text):
    with pytest.raises(pf.PfError):
        pf.split_arguments(text, 1)


def test_assertion_expands_with_pf_location_and_early_return():
    out = pf.preprocess(one_test("    @assertEqual(1.0_dp, x, tolerance=1.0e-3_dp, message='a, b')"),
                        "test_demo.pf").splitlines()
    call = "    call assertEqual(1.0_dp, x, tolerance=1.0e-3_dp, message='a, b', " \
           "location=SourceLocation('test_demo.pf', 7))"
    index = out.index(call)
    assert out[index + 1] == "    if (anyExceptions()) return"


@pytest.mark.parametrize("directive, routine", [
    ("@assertTrue(x)", "assertTrue"), ("@assertFalse(x)", "assertFalse"),
    ("@ASSERTEQUAL(1, 2)", "assertEqual"), ("@assertLessThan(1, 2)", "assertLessThan"),
    ("@assertLessThanOrEqual(1, 2)", "assertLessThanOrEqual"),
    ("@assertGreaterThan(2, 1)", "assertGreaterThan"),
    ("@assertGreaterThanOrEqual(2, 1)", "assertGreaterThanOrEqual"),
    ("@assertIsFinite(x)", "assertIsFinite"), ("@assertIsNaN(x)", "assertIsNaN"),
    ("@assertRelativelyEqual(1.0, x, 1.0e-6)", "assertRelativelyEqual"),
    ("@assertRelativelyEqual(1.0, x, tolerance=1.0e-6)", "assertRelativelyEqual"),
])
def test_every_supported_assertion_expands(directive, routine):
    out = pf.preprocess(one_test("    " + directive), "test_demo.pf")
    assert f"call {routine}(" in out


def test_assert_fail_without_arguments():
    out = pf.preprocess(one_test("    @assertFail()"), "test_demo.pf")
    assert "call assertFail(location=SourceLocation('test_demo.pf', 7))" in out


def test_driver_runs_every_test_between_before_and_after():
    text = module_text(
        "  @before", "  subroutine set_up()", "  end subroutine set_up",
        "  @after", "  subroutine tear_down()", "  end subroutine tear_down",
        "  @test", "  ! a comment between directive and subroutine", "",
        "  subroutine test_a()", "  end subroutine test_a",
        "  @test(description='ignored option')", "  subroutine test_b", "  end subroutine test_b")
    out = pf.preprocess(text, "test_demo.pf")
    assert "program test_demo_driver" in out
    assert "call funit_run_test('test_demo', 'test_a', test_a, set_up=set_up, tear_down=tear_down)" in out
    assert out.index("'test_a'") < out.index("'test_b'")
    assert "  !@test" in out and "  !@before" in out


@pytest.mark.parametrize("line, words", [
    ("    @assertTrue(x) ! why", "trailing comment"),
    ("    @assertEqual(a, &", "'&'"),
    ("    @assertRelativelyEqual(1.0, x)", "at least 3"),
    ("    @assertEqual(1.0, x, tol=1.0)", "does not take tol="),
    ("    @assertEqual(1.0, message='m', x)", "positional argument after a keyword"),
    ("    @assertEqual(1.0)", "at least 2"),
    ("    @assertTrue(x, 'm', y)", "at most 2"),
    ("    @assertEqual(1.0, x, location=here)", "does not take location="),
    ("    @assertNotEqual(1, 2)", "not supported"),
    ("    @mpiAssertEqual(1, 2)", "not supported"),
    ("    @frobnicate", "unknown directive"),
])
def test_bad_directives_are_reported_with_their_line(line, words):
    error = error_of(one_test(line))
    assert error.line == 7
    assert words in error.message


@pytest.mark.parametrize("option", ["npes=[1, 2]", "ifdef=USE_MPI", "cases=[1, 2]"])
def test_options_that_need_real_pfunit_are_rejected(option):
    text = module_text(f"  @test({option})", "  subroutine test_one()", "  end subroutine test_one")
    error = error_of(text)
    assert error.line == 5 and "real pFUnit" in error.message


def test_test_procedure_with_argument_is_rejected():
    text = module_text("  @test", "  subroutine test_one(this)", "  end subroutine test_one")
    assert "arguments" in error_of(text).message


def test_module_must_be_named_after_the_file():
    error = error_of(one_test("    @assertTrue(.true.)"), "test_other.pf")
    assert error.line == 1 and "test_other" in error.message


def test_use_pfunit_is_rejected():
    text = one_test("    @assertTrue(.true.)").replace("use funit", "use pfunit")
    assert "use pfunit" in error_of(text).message


def test_directive_without_subroutine_and_file_without_tests():
    assert "must be followed by" in error_of(module_text("  @test")).message
    assert "without a following subroutine" in error_of("module test_demo\n  @after\n").message
    assert "no @test" in error_of(module_text()).message


def test_main_writes_output_or_reports_file_and_line(tmp_path, capsys):
    good = tmp_path / "test_demo.pf"
    good.write_text(one_test("    @assertTrue(.true.)"))
    generated = tmp_path / "out" / "test_demo.f90"
    assert pf.main(["pf_preprocess.py", str(good), str(generated)]) == 0
    assert "end program test_demo_driver" in generated.read_text()

    bad = tmp_path / "test_bad.pf"
    bad.write_text(one_test("    @assertTrue(.true.)").replace("test_demo", "test_bad")
                   .replace("@assertTrue(.true.)", "@assertTrue(.true.) ! no"))
    assert pf.main(["pf_preprocess.py", str(bad), str(tmp_path / "bad.f90")]) == 1
    assert f"{bad}:7: error: trailing comment" in capsys.readouterr().err
