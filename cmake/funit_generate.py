#!/usr/bin/env python3
"""Write the typed assertion interfaces of bulkflow's fallback .pf harness.

    funit_generate.py OUTPUT.f90 [--max-rank N]

pFUnit 4 declares its assertions as generic interfaces with one specific procedure per
accepted combination of types, kinds and ranks, so a call that matches none of them does not
compile. The fallback must be exactly that strict (a .pf file that builds here must build with
pFUnit), so its generics are written out the same way: this script lists the combinations that
pFUnit 4's documented interface accepts (see cmake/README.md, "How strict the fallback is") and
writes one thin wrapper per combination. Every wrapper hands its operands to the shared checks of
funit_assert_equal and funit_assert_compare, which do the comparing and reporting.

The rules, for gfortran's default kinds (integer = int32, real = real32):
  * assertEqual on integers: expected and actual of the same kind, or expected default integer;
    no tolerance.
  * assertEqual on reals: actual of kind K; expected a default integer, a default real or a real
    of kind K (never a wider real than actual); tolerance, when given, default real or kind K.
  * assertRelativelyEqual: the real combinations, tolerance required; fails when an expected
    value is zero (pFUnit reports a zero denominator).
  * expected has the rank of actual or is a scalar.
  * assertLessThan and the other orderings: the same type/kind pairs as assertEqual, without a
    tolerance; scalars only here (pFUnit also takes arrays: the fallback is stricter there).
  * assertEqual on logicals (default kind) and on character scalars (pFUnit also compares
    string arrays: the fallback is stricter there).
  * assertIsNaN, assertIsFinite: real scalars only.
Standard library only: it runs at build time with whatever Python 3 CMake found.
"""

import argparse
from pathlib import Path

INTEGER_KINDS = ["int8", "int16", "int32", "int64"]
REAL_KINDS = ["real32", "real64"]
DEFAULT_INTEGER = "int32"
DEFAULT_REAL = "real32"

ORDERINGS = {
    "assertLessThan": "order_less",
    "assertLessThanOrEqual": "order_less_or_equal",
    "assertGreaterThan": "order_greater",
    "assertGreaterThanOrEqual": "order_greater_or_equal",
}


def decl(type_kind, name, rank, intent="in"):
    """Fortran declaration of a dummy of `type_kind` ('integer:int32', 'real:real64',
    'logical', 'character') and rank."""
    dims = "" if rank == 0 else "(" + ", ".join([":"] * rank) + ")"
    if type_kind == "logical":
        spec = "logical"
    elif type_kind == "character":
        spec = "character(len=*)"
    else:
        base, kind = type_kind.split(":")
        spec = f"{base}({kind})"
    return f"    {spec}, intent({intent}) :: {name}{dims}"


def short(type_kind):
    if type_kind in ("logical", "character"):
        return type_kind[0]
    base, kind = type_kind.split(":")
    return base[0] + kind.replace("int", "").replace("real", "")


def integer_pairs():
    pairs = [(k, k) for k in INTEGER_KINDS]
    pairs += [(DEFAULT_INTEGER, k) for k in INTEGER_KINDS if k != DEFAULT_INTEGER]
    return [(f"integer:{e}", f"integer:{a}") for e, a in pairs]


def real_pairs():
    """(expected, actual, [tolerance kinds]) for every real actual kind."""
    out = []
    for k in REAL_KINDS:
        expected = [f"integer:{DEFAULT_INTEGER}", f"real:{DEFAULT_REAL}", f"real:{k}"]
        tolerances = sorted({DEFAULT_REAL, k})
        for e in dict.fromkeys(expected):
            out.append((e, f"real:{k}", [f"real:{t}" for t in tolerances]))
    return out


def rank_forms(max_rank):
    """(rank of expected, rank of actual): equal ranks, or a scalar expected."""
    forms = [(0, 0)]
    for r in range(1, max_rank + 1):
        forms += [(0, r), (r, r)]
    return forms


def flat(name, rank):
    """The flattened operand handed to the shared checks (funit_core's flat_value)."""
    if rank <= 2:
        return f"flatten({name})"
    return f"flatten_shaped(reshape({name}, [size({name})]), shape({name}))"


class Writer:
    def __init__(self):
        self.generics = {}
        self.bodies = []

    def add(self, generic, specific, lines):
        self.generics.setdefault(generic, []).append(specific)
        self.bodies.append("\n".join(lines))

    def equal(self, generic, check, e, a, re, ra, tol=None, relative=False):
        name = f"{check}_{short(e)}{re}_{short(a)}{ra}" + (f"_t{short(tol)}" if tol else "")
        args = "expected, actual" + (", tolerance" if tol else "") + ", message, location"
        lines = [f"  subroutine {name}({args})", decl(e, "expected", re), decl(a, "actual", ra)]
        if tol:
            lines.append(decl(tol, "tolerance", 0))
        lines += ["    character(len=*), intent(in), optional :: message",
                  "    type(SourceLocation), intent(in), optional :: location"]
        tol_arg = ", real(tolerance, dp)" if tol else ""
        rel_arg = ", relative=.true." if relative else ""
        lines.append(f"    call check_equal('{generic}', {flat('expected', re)}, {flat('actual', ra)}"
                     f"{tol_arg}{rel_arg}, message=message, location=location)")
        lines.append(f"  end subroutine {name}")
        self.add(generic, name, lines)

    def order(self, generic, e, a):
        name = f"{ORDERINGS[generic]}_{short(e)}_{short(a)}"
        lines = [f"  subroutine {name}(lhs, rhs, message, location)", decl(e, "lhs", 0), decl(a, "rhs", 0),
                 "    character(len=*), intent(in), optional :: message",
                 "    type(SourceLocation), intent(in), optional :: location",
                 f"    call check_order('{generic}', {ORDERINGS[generic]}, flatten(lhs), flatten(rhs), "
                 "message, location)",
                 f"  end subroutine {name}"]
        self.add(generic, name, lines)

    def ieee_class(self, generic, kind):
        want_finite = ".true." if generic == "assertIsFinite" else ".false."
        name = f"{'is_finite' if want_finite == '.true.' else 'is_nan'}_{short(kind)}"
        lines = [f"  subroutine {name}(x, message, location)", decl(kind, "x", 0),
                 "    character(len=*), intent(in), optional :: message",
                 "    type(SourceLocation), intent(in), optional :: location",
                 f"    call check_class('{generic}', {want_finite}, flatten(x), message, location)",
                 f"  end subroutine {name}"]
        self.add(generic, name, lines)


def generate(max_rank):
    w = Writer()
    forms = rank_forms(max_rank)
    for re, ra in forms:
        for e, a in integer_pairs():
            w.equal("assertEqual", "equal", e, a, re, ra)
        for e, a, tolerances in real_pairs():
            w.equal("assertEqual", "equal", e, a, re, ra)
            for t in tolerances:
                w.equal("assertEqual", "equal", e, a, re, ra, tol=t)
                w.equal("assertRelativelyEqual", "relative", e, a, re, ra, tol=t, relative=True)
        w.equal("assertEqual", "equal", "logical", "logical", re, ra)
        if ra == 0:
            w.equal("assertEqual", "equal", "character", "character", re, ra)
    for generic in ORDERINGS:
        for e, a in integer_pairs():
            w.order(generic, e, a)
        for e, a, _ in real_pairs():
            w.order(generic, e, a)
    for generic in ("assertIsNaN", "assertIsFinite"):
        for k in REAL_KINDS:
            w.ieee_class(generic, f"real:{k}")

    kinds = ", ".join(INTEGER_KINDS + REAL_KINDS)
    out = ["! Generated by cmake/funit_generate.py: do not edit.",
           "!> The assertions of bulkflow's fallback .pf harness as generic interfaces with one",
           "!> specific per (type, kind, rank) combination that pFUnit 4 accepts, so a call pFUnit",
           "!> rejects at compile time is rejected here too.",
           "module funit_assert_typed",
           f"  use, intrinsic :: iso_fortran_env, only: {kinds}",
           "  use funit_core, only: dp, SourceLocation, flatten, flatten_shaped",
           "  use funit_assert_equal, only: check_equal",
           "  use funit_assert_compare, only: check_order, check_class, " + ", ".join(ORDERINGS.values()),
           "  implicit none",
           "  private", ""]
    for generic in w.generics:
        out.append(f"  public :: {generic}")
    out.append("")
    for generic, specifics in w.generics.items():
        out.append(f"  interface {generic}")
        for s in specifics:
            out.append(f"    module procedure {s}")
        out.append(f"  end interface {generic}")
        out.append("")
    out.append("contains")
    out.append("")
    out.append("\n\n".join(w.bodies))
    out.append("")
    out.append("end module funit_assert_typed")
    return "\n".join(out) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", type=Path)
    parser.add_argument("--max-rank", type=int, default=3)
    args = parser.parse_args()
    text = generate(args.max_rank)
    # Rewrite only when the text changes, so a re-run does not rebuild every test.
    if not args.output.exists() or args.output.read_text() != text:
        args.output.parent.mkdir(parents=True, exist_ok=True)
        args.output.write_text(text)


if __name__ == "__main__":
    main()
