#!/usr/bin/env python3
"""Turn a pFUnit test file (.pf) into plain Fortran for bulkflow's fallback harness.

    pf_preprocess.py tests/unit/test_foo.pf build/.../test_foo.F90

The output holds the test module with every directive expanded, followed by a driver program
that runs each @test between the @before and @after routines (module funit_runner). Only the
subset of pFUnit described in cmake/README.md is accepted; anything else stops with
`file:line: error: ...`, so a .pf file that builds here also builds with real pFUnit.

Standard library only: it runs at build time with whatever Python 3 CMake found.
"""

import re
import sys
from pathlib import Path

# Assertion directive (lower case) -> (Fortran name, required operands, most positional
# arguments, keywords allowed). The Fortran routines live in cmake/funit and take pFUnit's
# argument order; the location argument is always added here.
ASSERTIONS = {
    "equal": ("assertEqual", 2, 4, {"tolerance", "message"}),
    "relativelyequal": ("assertRelativelyEqual", 2, 4, {"tolerance", "message"}),
    "true": ("assertTrue", 1, 2, {"message"}),
    "false": ("assertFalse", 1, 2, {"message"}),
    "lessthan": ("assertLessThan", 2, 3, {"message"}),
    "lessthanorequal": ("assertLessThanOrEqual", 2, 3, {"message"}),
    "greaterthan": ("assertGreaterThan", 2, 3, {"message"}),
    "greaterthanorequal": ("assertGreaterThanOrEqual", 2, 3, {"message"}),
    "isfinite": ("assertIsFinite", 1, 2, {"message"}),
    "isnan": ("assertIsNaN", 1, 2, {"message"}),
    "fail": ("assertFail", 0, 1, {"message"}),
}

# pFUnit features this harness does not implement: named so the error can say so.
UNSUPPORTED = {
    "testcase", "testparameter", "suite", "disable", "mpitest", "mpiassertequal",
    "mpiasserttrue", "mpiassertfalse", "assertnotequal", "assertany", "assertall",
    "assertnone", "assertnotall", "assertsameshape", "assertismemberof", "assertcontains",
    "assertispermutationof", "assertexceptionraised", "assertassociated",
    "assertnotassociated", "assertunassociated", "assertequaluserdefined",
    "assertequivalent", "assertisinfinite", "assertthat",
}

# @test options that would change which tests run or how; all others are ignored.
REJECTED_TEST_OPTIONS = {
    "npes": "MPI tests (npes=) need real pFUnit",
    "ifdef": "conditional tests (ifdef=) need real pFUnit",
    "ifndef": "conditional tests (ifndef=) need real pFUnit",
    "cases": "parameterized tests (cases=) need real pFUnit",
    "testparameters": "parameterized tests (testParameters=) need real pFUnit",
    "type": "custom test types (type=) need real pFUnit",
}

DIRECTIVE_RE = re.compile(r"^(\s*)@(\w+)\s*(.*)$")
SUBROUTINE_RE = re.compile(r"^\s*subroutine\s+(\w+)\s*(\((.*)\))?\s*(!.*)?$", re.IGNORECASE)
MODULE_RE = re.compile(r"^\s*module\s+(\w+)\s*(!.*)?$", re.IGNORECASE)
USE_PFUNIT_RE = re.compile(r"^\s*use\s*(,\s*\w+\s*)?(::)?\s*pfunit\b", re.IGNORECASE)
KEYWORD_RE = re.compile(r"^\s*([A-Za-z]\w*)\s*=(?!=)")
COMMENT_OR_BLANK_RE = re.compile(r"^\s*(!.*)?$")


class PfError(Exception):
    """A problem in the .pf file, reported as file:line: error: message."""

    def __init__(self, line, message):
        super().__init__(message)
        self.line = line
        self.message = message


def scan_parenthesized(text, line):
    """Split `(a, b(c, d), 'e,f')...` into (inside of the first parenthesis, rest after it).

    Nesting counts (), [] and (/ /) (the latter is parentheses); quotes may contain anything,
    with '' or "" standing for a quote character.
    """
    if not text.startswith("("):
        raise PfError(line, "expected '(' after the directive name")
    depth = 0
    quote = None
    i = 0
    while i < len(text):
        ch = text[i]
        if quote:
            if ch == quote:
                if i + 1 < len(text) and text[i + 1] == quote:
                    i += 1
                else:
                    quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in "([":
            depth += 1
        elif ch in ")]":
            depth -= 1
            if depth < 0:
                raise PfError(line, f"unbalanced '{ch}'")
            if depth == 0:
                if ch != ")":
                    raise PfError(line, "unbalanced '['")
                return text[1:i], text[i + 1:]
        elif ch == "!":
            raise PfError(line, "unbalanced parentheses before '!'")
        i += 1
    if quote:
        raise PfError(line, "unterminated character string")
    raise PfError(line, "missing ')': a directive must be on one line (no '&' continuation)")


def split_arguments(text, line):
    """Split an argument list at top-level commas (not inside (), [], or quotes)."""
    args = []
    depth = 0
    quote = None
    start = 0
    i = 0
    while i < len(text):
        ch = text[i]
        if quote:
            if ch == quote:
                if i + 1 < len(text) and text[i + 1] == quote:
                    i += 1
                else:
                    quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in "([":
            depth += 1
        elif ch in ")]":
            depth -= 1
            if depth < 0:
                raise PfError(line, f"unbalanced '{ch}' in the arguments")
        elif ch == "," and depth == 0:
            args.append(text[start:i].strip())
            start = i + 1
        i += 1
    if quote:
        raise PfError(line, "unterminated character string in the arguments")
    if depth != 0:
        raise PfError(line, "unbalanced brackets in the arguments")
    last = text[start:].strip()
    if last or args:
        args.append(last)
    if any(not a for a in args):
        raise PfError(line, "empty argument")
    return args


def check_rest_of_line(rest, line, what):
    """Nothing may follow a directive: pFUnit's parser would not recognise the line."""
    rest = rest.strip()
    if not rest:
        return
    if rest.startswith("!"):
        raise PfError(line, f"trailing comment after {what}: pFUnit cannot parse it; "
                            "put the comment on its own line")
    if rest.startswith("&"):
        raise PfError(line, f"{what} continued with '&': pFUnit cannot parse it; keep it on "
                            "one line and compute long expressions into locals first")
    raise PfError(line, f"unexpected text after {what}: {rest!r}")


def expand_assertion(kind, indent, rest, line, file_name):
    """@assertX(args) -> the call with the .pf location, then return on failure (as pFUnit)."""
    name, required, max_positional, keywords = ASSERTIONS[kind]
    inside, after = scan_parenthesized(rest, line)
    check_rest_of_line(after, line, f"@{name}(...)")
    args = split_arguments(inside, line)
    positional = 0
    seen_keywords = set()
    for arg in args:
        match = KEYWORD_RE.match(arg)
        if match:
            keyword = match.group(1).lower()
            if keyword not in keywords:
                allowed = ", ".join(sorted(k + "=" for k in keywords))
                raise PfError(line, f"@{name} does not take {keyword}= (allowed: {allowed})")
            if keyword in seen_keywords:
                raise PfError(line, f"{keyword}= given twice")
            seen_keywords.add(keyword)
        else:
            if seen_keywords:
                raise PfError(line, "positional argument after a keyword argument")
            positional += 1
    operands = positional + (1 if kind == "relativelyequal" and "tolerance" in seen_keywords else 0)
    if kind == "relativelyequal":
        required = 3  # pFUnit has no tolerance-free assertRelativelyEqual
    if operands < required:
        raise PfError(line, f"@{name} needs at least {required} argument(s), got {operands}")
    if positional > max_positional:
        raise PfError(line, f"@{name} takes at most {max_positional} positional arguments")
    location = f"location=SourceLocation('{file_name}', {line})"
    call_args = ", ".join(args + [location])
    return [f"{indent}call {name}({call_args})", f"{indent}if (anyExceptions()) return"]


def parse_test_options(rest, line):
    """@test or @test(options): reject the options that need real pFUnit, ignore the others."""
    if not rest.strip():
        return
    inside, after = scan_parenthesized(rest.strip(), line)
    check_rest_of_line(after, line, "@test(...)")
    for option in split_arguments(inside, line):
        key = option.split("=", 1)[0].strip().lower()
        if key in REJECTED_TEST_OPTIONS:
            raise PfError(line, f"@test({option}): {REJECTED_TEST_OPTIONS[key]}; "
                                "bulkflow's fallback harness runs serial tests only")


def preprocess(source_text, pf_name):
    """Return the generated Fortran for the .pf text; pf_name is its file name."""
    stem = Path(pf_name).stem
    out = [f"! Generated by cmake/pf_preprocess.py from {pf_name}. Do not edit: edit the .pf file.",
           ""]
    module = None
    tests, set_up, tear_down = [], None, None
    pending = None  # (directive, line) waiting for its subroutine

    lines = source_text.splitlines()
    for number, text in enumerate(lines, start=1):
        directive = DIRECTIVE_RE.match(text)
        if directive:
            indent, word, rest = directive.groups()
            word_lower = word.lower()
            if pending:
                raise PfError(number, f"@{word} follows @{pending[0]} (line {pending[1]}) "
                                      "before its subroutine")
            if word_lower == "test":
                parse_test_options(rest, number)
                pending = ("test", number)
                out.append(f"{indent}!@{word}{rest}")
            elif word_lower in ("before", "after"):
                check_rest_of_line(rest, number, f"@{word}")
                pending = (word_lower, number)
                out.append(f"{indent}!@{word}")
            elif word_lower.startswith("assert") and word_lower[6:] in ASSERTIONS:
                out.extend(expand_assertion(word_lower[6:], indent, rest.strip(), number, pf_name))
            elif word_lower in UNSUPPORTED:
                raise PfError(number, f"@{word} is not supported by bulkflow's fallback harness "
                                      "(see cmake/README.md); it needs real pFUnit")
            else:
                raise PfError(number, f"unknown directive @{word}")
            continue

        if pending and not COMMENT_OR_BLANK_RE.match(text):
            kind, directive_line = pending
            sub = SUBROUTINE_RE.match(text)
            if not sub:
                raise PfError(number, f"@{kind} (line {directive_line}) must be followed by "
                                      "`subroutine name()`")
            name, arguments = sub.group(1), (sub.group(3) or "").strip()
            if arguments:
                raise PfError(number, f"subroutine {name}({arguments}): test procedures with "
                                      "arguments (@TestCase, MPI) need real pFUnit")
            if kind == "test":
                if name.lower() in (t.lower() for t in tests):
                    raise PfError(number, f"test {name} defined twice")
                tests.append(name)
            elif kind == "before":
                if set_up:
                    raise PfError(number, f"second @before ({name}); there is already {set_up}")
                set_up = name
            else:
                if tear_down:
                    raise PfError(number, f"second @after ({name}); there is already {tear_down}")
                tear_down = name
            pending = None

        if module is None:
            mod = MODULE_RE.match(text)
            if mod and mod.group(1).lower() != "procedure":
                module = mod.group(1)
                if module.lower() != stem.lower():
                    raise PfError(number, f"module {module} in {pf_name}: pFUnit needs the "
                                          f"module to be named after the file ({stem})")
        if USE_PFUNIT_RE.match(text):
            raise PfError(number, "`use pfunit` (MPI tests) needs real pFUnit; serial tests "
                                  "`use funit`")
        out.append(text)

    if pending:
        raise PfError(pending[1], f"@{pending[0]} without a following subroutine")
    if module is None:
        raise PfError(1, f"no `module {stem}` found: a .pf file is a Fortran module")
    if not tests:
        raise PfError(1, "no @test in this file")

    out += ["", f"program {stem}_driver"]
    out.append("  use funit_runner, only: funit_run_test, funit_suite_end")
    for name in [n for n in (set_up, tear_down) if n] + tests:
        out.append(f"  use {module}, only: {name}")
    out.append("  implicit none")
    fixtures = ""
    if set_up:
        fixtures += f", set_up={set_up}"
    if tear_down:
        fixtures += f", tear_down={tear_down}"
    for name in tests:
        out.append(f"  call funit_run_test('{stem}', '{name}', {name}{fixtures})")
    out.append(f"  call funit_suite_end('{stem}')")
    out.append(f"end program {stem}_driver")
    return "\n".join(out) + "\n"


def main(argv):
    if len(argv) != 3:
        print(f"usage: {Path(argv[0]).name} INPUT.pf OUTPUT.F90", file=sys.stderr)
        return 2
    source, target = Path(argv[1]), Path(argv[2])
    try:
        generated = preprocess(source.read_text(), source.name)
    except PfError as error:
        print(f"{source}:{error.line}: error: {error.message}", file=sys.stderr)
        return 1
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(generated)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
