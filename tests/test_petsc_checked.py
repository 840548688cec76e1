"""Every PETSc call in cpp/ has its error code checked (issue 51): main.cpp
makes PETSc return its codes instead of aborting, so a call whose code is
dropped lets a run go on with garbage. A call is checked when its value is
passed on: inside PetscCall (functions returning PetscErrorCode),
check_petsc (throws the project's one-line error), warn_petsc (destructors,
which cannot throw), or assigned or returned. What this test refuses is a
PETSc call standing alone as a statement: after `;`, `{`, `}`, `)` (the
body of an if or a for) or `else`; and a code kept in a variable for a
later test (`PetscErrorCode ierr = VecSet(...);`), which a change between
them can leave untested: `if (const PetscErrorCode ierr = ...; ierr != 0)`
tests it where it is made. Comments and strings are blanked first.
It also checks that the scan sees the calls it should (a planted call)."""
import os
import re
import sys

from support import ROOT, check

# PETSc's function families; names that are macros handling their own codes
# or that return no error code are exempt.
CALL = re.compile(r"\b((?:Vec|Mat|KSP|PC|SNES|IS|DM|Petsc)[A-Z]\w*)\s*\(")
EXEMPT = {"PetscCall", "PetscCallMPI", "PetscCallVoid", "PetscFunctionBeginUser", "PetscFunctionBegin",
          "PetscFunctionReturn", "PetscOptionsBegin", "PetscOptionsEnd", "PetscObjectComm"}
STATEMENT_START = re.compile(r"(?:[;{})]|\belse)$")
KEPT = re.compile(r"^\s*(?:const\s+)?(?:PetscErrorCode\s+)?\w+\s*=\s*$")


def blank_comments_and_strings(text):
    """The text with comments and string/char literals replaced by spaces
    (newlines kept, so line numbers stay)."""
    token = re.compile(r'//[^\n]*|/\*.*?\*/|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', re.S)
    return token.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)


def unchecked_calls(text):
    """(line, name) of every PETSc call standing alone as a statement."""
    code = blank_comments_and_strings(text)
    found = []
    for m in CALL.finditer(code):
        name = m.group(1)
        before = code[:m.start()].rstrip()
        statement = code[max(code.rfind(c, 0, m.start()) for c in ";{}") + 1:m.start()]
        if name in EXEMPT or not before or not (STATEMENT_START.search(before[-8:]) or KEPT.match(statement)):
            continue
        found.append((code.count("\n", 0, m.start()) + 1, name))
    return found


def main():
    planted = ("void f(Vec v)\n{\n  VecSet(v, 0.0);\n  if (v) VecDestroy(&v);\n  check_petsc(VecSet(v, 1.0), \"x\");\n"
               + "  // " + "a long comment " * 30 + "\n  VecZeroEntries(v);\n  PetscErrorCode ierr = VecSet(v, 2.0);\n"
               + "  if (const PetscErrorCode e = VecSet(v, 3.0); e != 0) check_petsc(e, \"y\");\n}\n")
    check(unchecked_calls(planted) == [(3, "VecSet"), (4, "VecDestroy"), (7, "VecZeroEntries"), (8, "VecSet")],
          f"the scan finds the planted unchecked calls: {unchecked_calls(planted)}")
    failures = []
    for folder, _, files in os.walk(os.path.join(ROOT, "cpp")):
        for name in sorted(files):
            if name.endswith((".cpp", ".h")):
                path = os.path.join(folder, name)
                with open(path) as f:
                    for line, call in unchecked_calls(f.read()):
                        failures.append(f"{os.path.relpath(path, ROOT)}:{line}: {call}")
    for failure in failures:
        print("unchecked:", failure)
    check(not failures, f"every PETSc call's error code is checked ({len(failures)} unchecked)")
    print("PASS")


if __name__ == "__main__":
    sys.exit(main())
