"""scripts/check_standalone_docs.py finds every kind of outside citation, with file:line, and
accepts citations of docs/theory/ (standard library only: unittest)."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir,
                      "scripts", "check_standalone_docs.py")

#: One line per kind of outside citation the check must refuse.
BAD = [
    "! formulas: numerics.md §4.2",
    "# see hopper_theory.md §c.2",
    "    # β = θ + ω gives 50.4 cm (hopper_theory §c.2)",
    "!> (abaqus_interfaces.md §0 item 2)",
    "notes in anchors.md",
    "the architecture of design.md",
    "as in thesis.md eq. 6.8",
    "from reference/numerics.md 5.7",
    "`/work/shared/reference/hopper_theory.md` §d",
    "see ../shared/seed for the cases",
    "a file in /work/tmp",
]

GOOD = [
    "! formulas: docs/theory/mpm.md §4.2",
    "# see docs/theory/hopper_theory.md §c.2 (Enstad 1975, Chem. Eng. Sci. 30)",
    "!> [docs/theory/abaqus_contract.md](../../docs/theory/abaqus_contract.md) §0",
    "thesis eq. 6.8 (Pardikar, FEM Modeling of Hopper Flow)",
    "Abaqus Analysis User's Guide, Mohr-Coulomb plasticity",
]


def run(root, *files):
    return subprocess.run([sys.executable, SCRIPT, "--root", root, *files],
                          capture_output=True, text=True)


class CheckStandaloneDocs(unittest.TestCase):
    def test_each_outside_citation_is_reported_with_file_and_line(self):
        with tempfile.TemporaryDirectory() as root:
            with open(os.path.join(root, "notes.f90"), "w", encoding="utf-8") as fh:
                fh.write("\n".join(["program p"] + BAD + ["end program"]) + "\n")
            result = run(root)
            self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
            reported = [line for line in result.stdout.splitlines() if line.startswith("notes.f90:")]
            self.assertEqual([int(line.split(":")[1]) for line in reported],
                             list(range(2, 2 + len(BAD))), result.stdout)

    def test_citations_of_our_docs_and_primary_sources_pass(self):
        with tempfile.TemporaryDirectory() as root:
            os.makedirs(os.path.join(root, "docs", "theory"))
            with open(os.path.join(root, "code.py"), "w", encoding="utf-8") as fh:
                fh.write("\n".join(GOOD) + "\n")
            # a sibling link inside docs/theory is a link within the repository
            for name, text in (("hopper_theory.md", "# ours\n## (c) Jenike\n### c.2 Arch\n## (f) Janssen\n"),
                               ("abaqus_contract.md", "# ours\n## 0. What the host must do\n"),
                               ("mpm.md", "## 4. MPM\n### 4.2 GIMP\nJanssen saturation "
                                          "(`hopper_theory.md §f`)\n")):
                with open(os.path.join(root, "docs", "theory", name), "w", encoding="utf-8") as fh:
                    fh.write(text)
            result = run(root)
            self.assertEqual(result.returncode, 0, result.stdout + result.stderr)

    def test_a_bare_note_name_with_no_sibling_file_is_refused(self):
        with tempfile.TemporaryDirectory() as root:
            os.makedirs(os.path.join(root, "docs"))
            with open(os.path.join(root, "docs", "x.md"), "w", encoding="utf-8") as fh:
                fh.write("intro\nsee numerics.md\n")
            result = run(root, "docs/x.md")
            self.assertEqual(result.returncode, 1)
            self.assertIn("docs/x.md:2:", result.stdout)

    def test_a_citation_of_a_missing_section_is_refused(self):
        with tempfile.TemporaryDirectory() as root:
            os.makedirs(os.path.join(root, "docs", "theory"))
            with open(os.path.join(root, "docs", "theory", "mpm.md"), "w", encoding="utf-8") as fh:
                fh.write("# MPM\n\n## 4. MPM\n\n### 4.2 GIMP\n\nsee `mpm.md §4.3`\n")
            with open(os.path.join(root, "a.f90"), "w", encoding="utf-8") as fh:
                fh.write("! docs/theory/mpm.md §4.2 exists\n! docs/theory/mpm.md §4, §4.7 does not\n"
                         "! docs/theory/nothing.md §1\n")
            result = run(root)
            self.assertEqual(result.returncode, 1)
            lines = sorted(line.split(": ")[0] for line in result.stdout.splitlines())
            self.assertEqual(lines, ["a.f90:2", "a.f90:3", "docs/theory/mpm.md:7"], result.stdout)
            self.assertIn("mpm.md §4.7", result.stdout)

    def test_missing_root_is_a_usage_error(self):
        self.assertEqual(run("/nonexistent-bulkflow-root").returncode, 2)


if __name__ == "__main__":
    unittest.main()
