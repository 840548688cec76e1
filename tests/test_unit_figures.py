"""The unit tests' figures in docs/verification.md ("Unit tests") are the
suite's (issue 51): the sentence "runs them alone: N ctest tests (S
GoogleTest suites holding T TESTs, one of P Python modules, one on two
ranks and the source checks C)" is read and each count compared with the sources and with
`ctest -N -L unit` of this build. The time quoted beside it is measured by
the command the page gives, not here (no timed test)."""
import glob
import os
import re
import subprocess

from support import BINARY, ROOT, check

SENTENCE = re.compile(r"runs them alone: (\d+) ctest tests \((\d+) GoogleTest suites holding (\d+) TESTs, "
                      r"one of (\d+) Python modules, one on two ranks and the source checks ([^)]*)\)")


def documented():
    with open(os.path.join(ROOT, "docs", "verification.md")) as f:
        text = " ".join(f.read().split())
    m = SENTENCE.search(text)
    check(m is not None, "docs/verification.md states the unit tests' counts in the expected sentence")
    checks = re.findall(r"`(\w+)`", m.group(5))
    return [int(g) for g in m.groups()[:4]], checks


def counted():
    tests = []
    for path in glob.glob(os.path.join(ROOT, "tests", "unit", "test_*.cpp")):
        with open(path) as f:
            tests += re.findall(r"^TEST(?:_F)?\((\w+),", f.read(), re.M)
    modules = glob.glob(os.path.join(ROOT, "tests", "unit", "test_*.py"))
    with open(os.path.join(ROOT, "tests", "CMakeLists.txt")) as f:
        m = re.search(r"set_tests_properties\(([\w ]+) PROPERTIES LABELS unit\)", f.read())
    return len(set(tests)), len(tests), len(modules), m.group(1).split()


def main():
    (total, suites, tests, modules), checks = documented()
    s, t, p, c = counted()
    check((suites, tests, modules) == (s, t, p),
          f"suites, TESTs and Python modules as documented: {suites}, {tests}, {modules} (counted {s}, {t}, {p})")
    check(sorted(checks) == sorted(c), f"the source checks as documented: {checks} (CMake: {c})")
    # The Python modules run in one ctest test (unit.prototype), what needs
    # two ranks in another (unit.two_ranks).
    check(total == suites + 2 + len(checks), f"{total} ctest tests = the sum of the documented parts")
    listing = subprocess.run(["ctest", "-N", "-L", "unit"], cwd=os.path.dirname(BINARY), capture_output=True,
                             text=True, check=True).stdout
    m = re.search(r"Total Tests: (\d+)", listing)
    check(m and int(m.group(1)) == total, f"ctest -N -L unit lists {m and m.group(1)} tests, documented {total}")
    print("PASS")


if __name__ == "__main__":
    main()
