"""The prototype mirrors the C++ solver file for file and name for name
(docs/layout.md): every module of cpp/ (a header, a source or both) has a
Python module of the same folder and name in python_prototype/ and back,
and each pair defines the same public names of the same kind (a type, a
function or a constant), except the modules and names listed below with
the reason; a listed difference that no longer exists fails too. C++
names are read from the header (the source without one) at global or
`biotcontact` scope by a small parser whose limits docs/layout.md lists;
Python's by ast (module-level, not starting with "_"; an assigned
CamelCase name is a type alias). Constants pair up to case."""
import ast
import collections
import os
import re
import sys

from support import ROOT, check

# Modules with no twin, and why.
CPP_ONLY = {
    "domain/gmsh_api": "gmsh's C++ functions over a libgmsh opened on the first call; the prototype imports its gmsh "
                       "module where it first reads a mesh (domain/gmsh_mesh), the same deferral",
    "assembly/petsc_error": "checks the error codes PETSc's C calls return (SolverError, check_petsc, warn_petsc); "
                            "petsc4py raises PETSc.Error itself",
}
PROTOTYPE_ONLY = {
    "output/compare": "compares the two tracks' outputs; C++ has nothing to compare with",
}
# The entry points: the same role under each language's name.
ENTRY = {"main": "__main__"}
FOLDERS = ["scene", "domain", "assembly", "time", "solvers", "contact", "steps", "coupling", "output", "diagnostics"]


def private(source):
    """The reason of a helper the C++ keeps private and Python does not."""
    return (f"Python only: to align (issue 36): private to {source} in C++ (its anonymous namespace); "
            "public here, though the prototype marks a private helper with a leading underscore")


# Names one track of a module pair defines and the other does not, by
# module (the Python module's name) and name. Each reason says which side
# has it ("C++ only", "Python only" or "not the same kind") and why; an
# accidental difference says "to align (issue 36)" instead of a reason.
DIFFERENCES = {
    "__main__": {
        "parse": "Python only: to align (issue 36): C++'s parse_arguments, private to main.cpp (its anonymous "
                 "namespace): another name, and public here",
        "compare_main": "Python only: the `compare DIR_A DIR_B` command, which only the prototype has "
                        "(output/compare has no C++ twin)",
    },
    "simulation": {
        "RunControl": "C++ only: run()'s named options (fingerprint, restart) in a struct; Python passes them as "
                      "keyword arguments of run()",
        "Simulation": private("simulation.cpp") + " (tests/test_regions.py imports it)",
    },
    "scene/expression": {
        "ExpressionError": "Python only: the prototype's own expression parser raises this ValueError subclass, "
                           "so that scene.py catches its errors and no other; C++ turns muparser's exception into "
                           "std::invalid_argument",
    },
    "scene/input": {
        "Choices": "C++ only: the names a scene gives a choice's values, in the order its messages list them, "
                   "a traits template (Choices<E>::names) that name_of and Section::choice read; a Python "
                   "enum.Enum holds them itself (its values, in definition order)",
    },
    "scene/scene": {
        "agreed_error": "C++ only: to align (issue 36): the lowest rank's message, which agree_on_error, "
                        "agree_on_output_error and TimeSeries share; Python writes the allreduce and bcast out "
                        "in agree_on_error and agree_on_output_error",
    },
    "solvers/field_split": {
        "own": "C++ only: gives a MatNullSpace a shared_ptr whose deleter calls MatNullSpaceDestroy; petsc4py's "
               "objects free themselves",
    },
    "scene/section": {
        "Names": "C++ only: the type of the names' map; Python passes a dict",
    },
    "solvers/solver": {
        "petsc_error_text": "Python only: PETSc's words for a petsc4py error; C++'s twin, for an error code, is in "
                            "assembly/petsc_error (C++ only)",
        "agreed_error": "Python only: the ranks' agreed error of a call; C++'s twin, agreed_code for an error code, "
                        "is in assembly/petsc_error (C++ only)",
        "MethodChoice": "C++ only: the (method, reason) pair choose_method and set_solver_defaults return; "
                        "Python returns a tuple",
        **{f"crossover_{d}d_{system}": "C++ only: to align (issue 36): Python keeps the six crossovers in one "
                                       "dict, CROSSOVER[(dimension, system)]"
           for d in (2, 3) for system in ("mechanics", "flow", "monolithic")},
        "method_name": "C++ only: the name of a Method; Python's enum has it (Method.name)",
        "SolverError": "Python only: C++ declares it in assembly/petsc_error.h (no Python twin), with check_petsc, "
                       "which throws it for a failed PETSc call in any layer; the prototype raises it from here",
        "option": "C++ only: a PETSc option's value by prefix and name; petsc4py's "
                  "PETSc.Options().getString(prefix + name, \"\") gives it",
        "reason_name": "Python only: a PETSc converged reason's name, which C++ reads from PETSc's "
                       "KSPConvergedReasons and SNESConvergedReasons; petsc4py has no such table (its enums know "
                       "some reasons by other names)",
    },
    "solvers/linear_solver": {
        "factor_package": private("linear_solver.cpp"),
    },
    "assembly/boundary_conditions": {
        "FaceRow": "C++ only: a fault face's row (side, key, DOF, facet flux) as a struct; Python's fault_face_rows "
                   "gives tuples",
        "DisplacementValue": "C++ only: to align (issue 36): Python keeps each prescribed component as an "
                             "(expression, g, dofs, points) tuple, though it has classes for FluxBoundary and "
                             "FluxValues",
        "update_fluxes": "Python only: C++'s update(FluxValues&, t), an overload of update(); Python has no "
                         "overloading",
        "FacetFlux": "C++ only: the type of facet_flux's result, a function of the facets; Python's closures "
                     "need no type",
    },
    "assembly/fault_flow_compliance": {
        "ConduitCompliance": "Python only: the fixed-stress terms of ConduitFaults as its base class, whose "
                             "methods read the faults' cells and open sets; in C++ those members of ConduitFaults "
                             "are defined in fault_flow_compliance.cpp",
    },
    "assembly/fault_flow_jacobian": {
        "ConduitJacobian": "Python only: Newton's term of ConduitFaults as its base class, whose methods read "
                           "the faults' cells, links, ends and junctions; in C++ those members of ConduitFaults "
                           "are defined in fault_flow_jacobian.cpp",
    },
    "assembly/fault_flow_pins": {
        "ConduitPins": "Python only: the pins of ConduitFaults' cells as its base class, whose methods read the "
                       "faults' cells and open sets; in C++ those members of ConduitFaults are defined in "
                       "fault_flow_pins.cpp",
        "CellPins": "Python only: a conduit's per-cell flips, pins and openings as one value (_Conduit.pinning); "
                    "C++'s Conduit holds the three vectors itself",
    },
    "assembly/fault_flow_volumes": {
        "ConduitVolumes": "Python only: the volume bookkeeping of ConduitFaults as its base class, whose methods "
                          "read the faults' cells, faces, wells and junctions; in C++ those members of "
                          "ConduitFaults are defined in fault_flow_volumes.cpp",
    },
    "assembly/forms": {
        "CompiledForms": "C++ only: the forms of forms/biot.py compiled by FFCx at build time, for one cell "
                         "type; the prototype compiles them at run time (Forms, dolfinx's JIT)",
        "compiled_forms": "C++ only: picks the build-time forms of a cell type (triangles or tetrahedra); "
                          "dolfinx's JIT compiles the forms for the mesh at hand",
        "make_form": "C++ only: binds a compiled form to its spaces, coefficients and constants by UFL name; in "
                     "Python the forms hold biot.build's own dolfinx objects and dolfinx's fem.form compiles "
                     "them (Forms.compile)",
        "Forms": "Python only: biot.build's dolfinx objects by UFL name and their compilation by dolfinx's "
                 "JIT (fem.form); C++ has the build-time compiled forms instead (CompiledForms, "
                 "compiled_forms, make_form)",
    },
    "assembly/linear_algebra": {
        "Gathered": "C++ only: every rank's values with their offsets, what all_gather returns; mpi4py's "
                    "allgather returns a list per rank",
        "all_gather": "C++ only: MPI_Allgatherv of int64 values with its counts and offsets; Python calls "
                      "mpi4py's allgather",
        "BCs": "C++ only: a type alias for a vector of DirichletBC pointers; Python's lists need no type",
        "difference": "C++ only: d = a - b on dolfinx vectors; Python subtracts the numpy arrays",
        "wrap": "C++ only: a dolfinx vector as a PETSc Vec sharing its memory; dolfinx's Python API already "
                "provides it (Function.vector)",
        "owned_size": "C++ only: to align (issue 36): the same function is `owned` in Python",
        "values": "C++ only: a copy of a function's or a vector's values (ghosts included); numpy's "
                  "x.array.copy() in Python",
        "assign": "C++ only: sets a function's values (ghosts included) from a span; Python assigns the numpy "
                  "array (f.x.array[:] = x)",
        "owned": "Python only: to align (issue 36): the same function is owned_size in C++",
        "accumulate_ghosts": "Python only: to align (issue 36): a one-line wrapper of "
                             "x.scatter_reverse(ScatterMode.add); C++ calls scatter_rev(std::plus<double>()) "
                             "where it needs it",
        "dof_map": "Python only: the prototype's Q and V are biot.build's own spaces, not the collapsed "
                   "subspaces, so their DOFs reach the mixed space through the collapsed one; C++ uses the "
                   "collapsed space itself and the map collapse() returns",
        "set_lag_preconditioner": "Python only: SNESSetLagPreconditioner, which petsc4py 3.18 does not wrap "
                                  "(called through ctypes); C++ calls PETSc directly",
    },
    "assembly/materials": {
        "on": "Python only: to align (issue 36): in C++ the member Materials::on; here a free function of the "
              "Forms, which hold the coefficients that C++'s Materials holds",
    },
    "assembly/parameters": {
        "Coefficients": "C++ only: the type of the map of Functions by UFL name that make_form binds; Python's "
                        "Forms holds biot.build's own Functions",
        "Constants": "C++ only: the type of the map of Constants by UFL name that make_form binds; Python's "
                     "Forms holds biot.build's own Constants",
        "make_constants": "C++ only: creates the forms' Constants by UFL name; in Python biot.build created "
                          "them (in Forms), and set_constants sets their values",
        "set_constants": "Python only: sets the values of the Constants biot.build created (in Forms); C++ "
                         "creates its own with make_constants",
    },
    "output/keyed_values": {
        "KeyedValues": "C++ only: a field's keys (`width` per entry) and values in flat vectors; Python returns "
                       "(keys, values) as two numpy arrays, the keys' width their second dimension",
    },
    "output/output": {
        "Json": "C++ only: a JSON object built key by key in insertion order; a Python dict is one (to_json "
                "writes it)",
        "to_json": "Python only: writes a dict in the layout of C++'s Json::str (17 significant digits, null for "
                   "NaN and infinity), which json.dumps does not",
        "number": private("output.cpp"),
    },
    "output/progress": {
        "RunStatus": "C++ only: the type of the unscoped enum whose values run_ok, run_not_converged and "
                     "run_output_failed Python holds as plain constants (RUN_OK, ...)",
    },
    "output/time_series": {
        "InputOrder": "C++ only: sends each rank's rows, in the mesh's input order, to the rank that writes "
                      "them (every rank writes its block of the HDF5 datasets); the prototype gathers the rows "
                      "on rank 0, which writes with serial h5py",
        "Fields": "Python only: a reader of a run's output for comparisons (tests/, output/compare); the "
                  "C++ solver only writes",
        "read_time_series": "Python only: a reader of a run's output (tests/support.py, tools/plot_run.py, "
                            "bench/); the C++ solver only writes",
    },
    "output/write_failure": {
        "silence_hdf5_errors": "C++ only: turns off HDF5's printing of its error stack; h5py does so itself on "
                               "import (its __init__ calls _errors.silence_errors())",
        "write_dataset": "Python only: h5py closes a dataset's handle when it is dropped and reports a failed "
                         "close only on stderr, so the prototype flushes while the handle is open; the C++ "
                         "writes through dolfinx's HDF5 interface, whose calls return the failure",
    },
    "contact/change_of_variables": {
        "NodeMatrix": "C++ only: a type alias for a node's d x d matrix (std::array<double, 9>); Python uses "
                      "numpy arrays",
        "inverse": "C++ only: inverts a block of T; Python calls numpy.linalg.inv",
        "node_block": "C++ only: a NodeMatrix as a block's row-major vector; Python's T_node is already an "
                      "array",
    },
    "contact/contact_pins": {
        "ContactPins": "Python only: the pins of ContactSolver's constraints as its base class, whose methods read "
                       "the contact set, the VI and the contact force; in C++ those members of ContactSolver are "
                       "defined in contact_pins.cpp",
    },
    "contact/contact_set": {
        "ContactBlock": "C++ only: a block of the change of variables in V's numbering (DOFs, matrix); Python "
                        "keeps (dofs, T) tuples",
    },
    "coupling/anderson": {
        "State": "C++ only: a type alias for the iterates (a vector of vectors of doubles); Python's lists need "
                 "no type",
    },
    "domain/fault_cells": {
        "WellOnFault": "C++ only: well_cells' result (cells and shares) as a struct; Python returns the two arrays",
        "share_fault_cells": "C++ only: rank 0's cells broadcast field by field; Python's gmsh_mesh.py broadcasts them "
                             "with the faults' pairs (comm.bcast of any object)",
    },
    "domain/wells": {
        "WellCells": "C++ only: the (cells, shares) pair locate_well returns; Python returns a tuple",
    },
}

# What each module pair defines, by name. C++: the declarations at global or
# `biotcontact` scope of the header (of the source when a module has none),
# read by the small parser below. Python: the module-level names not
# starting with "_" (ast).
CPP_SKIPPED = re.compile(r'//[^\n]*|/\*.*?\*/|^[ \t]*#(?:\\\n|[^\n])*|\b(?:u8|u|U|L)?R"([^(\s]*)\(.*?\)\1"'
                         r'|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', re.S | re.M)
TYPE_HEAD = re.compile(r"(class|struct|union|enum)\b(?:\s+(?:class|struct)\b)?\s*(\w*)")
NOT_NAMES = {"decltype", "alignas", "noexcept", "sizeof", "static_assert", "__attribute__"}
CATEGORY = {"class": "type", "struct": "type", "union": "type", "enum": "type", "alias": "type",
            "function": "function", "constant": "constant", "variable": "constant"}


def blanked(text):
    """C++ text without its comments and preprocessor lines, and with its
    string and character literals emptied (braces in them do not count)."""
    def blank(m):
        s = m.group(0)
        return " " if s.startswith(("//", "/*")) or s.lstrip().startswith("#") else '""'
    return CPP_SKIPPED.sub(blank, text)


def closing(text, i):
    """The index of the brace that closes the one at text[i]."""
    depth = 0
    for j in range(i, len(text)):
        depth += {"{": 1, "}": -1}.get(text[j], 0)
        if depth == 0:
            return j
    sys.exit(f"FAIL: test_mirror cannot read C++: unbalanced braces after {text[max(0, i - 80):i]!r}")


def top_level(head):
    """The indices of the '(', '=' and ',' of a declaration outside (), [],
    {} and, before an initialiser's '=', template arguments <>."""
    depth, angles, initialiser, found = 0, 0, False, []
    for i, c in enumerate(head):
        if depth == 0 and angles == 0 and c in "(=,":
            found.append(i)
            initialiser = c == "=" or (initialiser and c != ",")
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif depth == 0 and not initialiser and c in "<>":
            angles = max(angles + (1 if c == "<" else -1), 0)
    return found


def declaration(head):
    """The declaration without template parameters and attributes."""
    head = re.sub(r"\[\[.*?\]\]", " ", head).strip()
    while re.match(r"template\s*<", head):
        depth, parentheses = 0, 0  # a '>' in parentheses is a comparison
        for j in range(head.index("<"), len(head)):
            parentheses += {"(": 1, ")": -1}.get(head[j], 0)
            depth += {"<": 1, ">": -1}.get(head[j], 0) if parentheses == 0 else 0
            if depth == 0:
                break
        head = head[j + 1:].strip()
    return head


def shape(head):
    """What a declaration is: namespace, type, alias, function or variable
    (or None: nothing it names counts, such as a using-directive)."""
    if re.match(r"(inline\s+)?namespace\b", head) or re.match(r'extern\s*""$', head):
        return "namespace"
    if re.match(r"(using\s+namespace|static_assert|friend)\b", head) or head == "":
        return None
    if re.match(r"(using\s+\w+\s*=|typedef\b)", head):
        return "alias"
    if head.startswith("using"):  # a using-declaration names something of elsewhere
        return None
    if TYPE_HEAD.match(head):
        return "type"
    if re.search(r"\boperator\b", head):
        return "function"
    tops = [i for i in top_level(head) if head[i] != ","]
    pointer = tops and re.match(r"\(\s*[*&]", head[tops[0]:])  # a pointer to a function
    return "function" if tops and head[tops[0]] == "(" and not pointer else "variable"


def function_name(head):
    """The unqualified name a function declaration declares, or None when it
    defines a name declared elsewhere (a member, another namespace's)."""
    m = re.search(r"(::\s*)?\boperator\s*(\(\)|\[\]|[^\s\w(]+|\w[\w\s:*&<>]*?)\s*\(", head)
    if m:
        return None if m.group(1) else "operator" + re.sub(r"\s", "", m.group(2))
    for i in top_level(head):
        if head[i] != "(":
            continue
        name = re.search(r"(~?[\w:]+)\s*$", head[:i])
        if name and name.group(1) not in NOT_NAMES:
            return None if "::" in name.group(1) else name.group(1)
    return None


def variable_names(head):
    """The names a variable declaration declares, one per declarator."""
    names, start = [], 0
    for end in [i for i in top_level(head) if head[i] == ","] + [len(head)]:
        part = head[start:end]
        part = part[:min([i for i in top_level(part) if part[i] == "="], default=len(part))]
        name = re.search(r"(\w+)\s*(\[[^\]]*\]\s*)*$", part)
        if name and "::" not in part[max(name.start() - 2, 0):name.start()]:
            names.append(name.group(1))
        start = end + 1
    return names


def declared(head, body):
    """{name: kind} of what one declaration at namespace scope defines
    (kind: class, struct, union, enum, alias, function, constant, variable);
    `body`: whether braces follow it (a type without them is only declared
    here, and defined elsewhere)."""
    head = declaration(head)
    kind = shape(head)
    if kind == "alias":
        m = re.match(r"using\s+(\w+)", head) or re.search(r"(\w+)\s*(\[[^\]]*\]\s*)*$", head)
        return {m.group(1): "alias"}
    if kind == "type":
        m = TYPE_HEAD.match(head)
        return {m.group(2): m.group(1)} if m.group(2) and body else {}
    if kind == "function":
        name = function_name(head)
        return {name: "function"} if name else {}
    if kind == "variable":
        kind = "constant" if re.search(r"\b(const|constexpr)\b", head) else "variable"
        pointer = re.match(r"[^(]*\(\s*[*&]+\s*(\w+)\s*\)\s*\(", head)  # to a function
        return {pointer.group(1): kind} if pointer else {name: kind for name in variable_names(head)}
    return {}


def enumerators(head, body):
    """The values of an unscoped enum, which lie at the enclosing
    namespace's scope like constants (those of an enum class do not)."""
    if not re.match(r"enum\s+(?!class\b|struct\b)", head):
        return {}
    return {m.group(1): "constant" for m in (re.match(r"\s*(\w+)", part) for part in body.split(",")) if m}


def cpp_names(text, path):
    """{name: kind} of the declarations at global or biotcontact scope of
    the C++ `text` of file `path`, outside anonymous and `detail` namespaces."""
    text, names, head, tail, i = blanked(text), {}, "", False, 0
    while i < len(text):
        c = text[i]
        if c == "{":
            h = declaration(head)
            kind = shape(h)
            if kind == "namespace":
                inner = re.match(r"(?:inline\s+)?namespace\s*([\w:]*)", h)
                name = inner.group(1) if inner else "biotcontact"  # extern "C" is transparent
                if name.split("::")[-1] not in ("", "detail", "biotcontact"):
                    sys.exit(f"FAIL: test_mirror does not read namespace {name} ({path}): extend its parser")
                i = i + 1 if name == "biotcontact" else closing(text, i) + 1
                head = ""
                continue
            end = closing(text, i)
            names.update(declared(head, True))
            names.update(enumerators(h, text[i + 1:end]))
            # After a type's or a variable's braces, the rest up to ';' is theirs.
            i, head, tail = end + 1, "", kind in ("type", "variable")
            continue
        if c == "}":
            head = ""
        elif c == ";":
            if not tail:
                names.update(declared(head, False))
            head, tail = "", False
        else:
            head += c
        i += 1
    return names


def python_names(text, path):
    """{name: kind} of the module-level definitions of the Python `text` of
    file `path` not starting with "_": classes, functions, and assigned
    names, CamelCase ones as type aliases, the others as constants; also
    under a module-level if or try (imported names are not its own)."""
    found = {}

    def visit(body):
        for node in body:
            if isinstance(node, ast.ClassDef):
                found[node.name] = "class"
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                found[node.name] = "function"
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                for target in node.targets if isinstance(node, ast.Assign) else [node.target]:
                    for name in target.elts if isinstance(target, ast.Tuple) else [target]:
                        if isinstance(name, ast.Name):
                            camel = re.fullmatch(r"[A-Z]\w*[a-z]\w*", name.id)
                            found[name.id] = "alias" if camel else "constant"
            elif isinstance(node, (ast.If, ast.Try)):
                visit(node.body + node.orelse + getattr(node, "finalbody", [])
                      + [s for h in getattr(node, "handlers", []) for s in h.body])
    visit(ast.parse(text, path).body)
    return {name: kind for name, kind in found.items() if not name.startswith("_")}


def differences(cpp_side, python_side):
    """{name: "C++ only" | "Python only" | "not the same kind"} of one pair,
    and the number of names compared. A C++ constant has its Python twin in
    the UPPER_CASE of its name; a Python constant counts only then."""
    constants = {name.lower(): name for name, kind in python_side.items() if kind == "constant"}
    python_side = {name: kind for name, kind in python_side.items() if kind != "constant"}
    found = {}
    for name, kind in cpp_side.items():
        if CATEGORY[kind] == "constant":
            if name.lower() not in constants:
                found[name] = "C++ only"
        elif name not in python_side:
            found[name] = "C++ only"
        elif CATEGORY[kind] != CATEGORY[python_side[name]]:
            found[name] = "not the same kind"
    found.update({name: "Python only" for name in python_side if name not in cpp_side})
    return found, len(set(cpp_side) | set(python_side))


def modules(top, suffixes):
    found = set()
    for folder, _, files in os.walk(top):
        for f in files:
            stem, suffix = os.path.splitext(f)
            if suffix in suffixes and stem != "__init__":
                found.add(os.path.relpath(os.path.join(folder, stem), top))
    return found


cpp = {ENTRY.get(m, m) for m in modules(os.path.join(ROOT, "cpp"), {".h", ".cpp"})}
prototype = modules(os.path.join(ROOT, "python_prototype"), {".py"})

for folder in FOLDERS:
    check(os.path.isdir(os.path.join(ROOT, "cpp", folder))
          and os.path.isdir(os.path.join(ROOT, "python_prototype", folder)), f"{folder}/ on both tracks")
missing = sorted(cpp - prototype - set(CPP_ONLY))
check(not missing, f"every C++ module has a Python twin (missing: {missing})")
extra = sorted(prototype - cpp - set(PROTOTYPE_ONLY))
check(not extra, f"every Python module has a C++ twin (missing: {extra})")
stale = sorted((set(CPP_ONLY) - cpp) | (set(PROTOTYPE_ONLY) - prototype) | (set(CPP_ONLY) & prototype)
               | (set(PROTOTYPE_ONLY) & cpp))
check(not stale, f"the lists of modules without a twin are current (stale: {stale})")
outside = sorted(m for m in cpp | prototype if os.path.dirname(m) not in FOLDERS + [""])
check(not outside, f"every module lies in a folder of the data flow (outside: {outside})")


def cpp_source(module):
    """The C++ file whose declarations a pair compares: the header, or the
    source of a module without one (main.cpp)."""
    stem = os.path.join(ROOT, "cpp", {v: k for k, v in ENTRY.items()}.get(module, module))
    return stem + ".h" if os.path.exists(stem + ".h") else stem + ".cpp"


def compare_pairs(pairs):
    """{(module, name): kind of difference} over the module pairs, and
    Counters of the names compared by category and by track."""
    found, compared = {}, collections.Counter()
    for module in pairs:
        path = cpp_source(module)
        cpp_side = cpp_names(open(path).read(), path)
        path = os.path.join(ROOT, "python_prototype", module + ".py")
        python_side = python_names(open(path).read(), path)
        differ, names = differences(cpp_side, python_side)
        found.update({(module, name): kind for name, kind in differ.items()})
        compared["names"] += names
        compared.update(f"C++ {CATEGORY[kind]}" for kind in cpp_side.values())
        constants = {name.lower() for name, kind in cpp_side.items() if CATEGORY[kind] == "constant"}
        compared.update(f"Python {CATEGORY[kind]}" for name, kind in python_side.items()
                        if kind != "constant" or name.lower() in constants)
    return found, compared


# The readers read what the docstring says they read.
CPP_SAMPLE = r'''// A { in a comment
#include <map>
#define TWICE(x) \
  ((x) * 2)
namespace biotcontact
{
class Later;  /* a forward declaration { */
enum Status { ok = 0, failed = 3 };
enum class Mode : int { fast, slow };
using Table = std::map<std::string, std::pair<int, double>>;
typedef double Real;
const char* text = "a } in a string", *raw = R"x(a } ")x";
constexpr int small_size = 4, large_size = 8;
inline constexpr std::array<std::pair<const char*, int>, 2> counts{{{"a", 1}, {"b", 2}}};
template <class T, int N = (1 > 0)>
struct Box final : public Base<T>
{
  void member();
  int value = 0;
};
template <class F>
void visit(const Box<int>& b, F&& f)
{
  f(b.value);
}
std::function<void(int)> make_callback(std::map<int, int> m = {});
bool operator<(const Box<int>& a, const Box<int>& b);
void (*handler)(int);
void Box<int>::member() { }
Table::Table(int x) : size{x} { }
namespace detail { int hidden(); }
namespace
{
int private_helper() { return 1; }
}
} // namespace biotcontact
int main(int argc, char* argv[]) { return 0; }
'''
PYTHON_SAMPLE = """import os
from x import Imported
LIMIT, other = 1, 2
Alias = dict
_hidden = 3
class Box:
    def member(self):
        pass
def visit(b):
    pass
async def wait():
    pass
def _helper():
    pass
if os.name:
    def chosen():
        pass
"""
expected = {"Status": "enum", "ok": "constant", "failed": "constant", "Mode": "enum", "Table": "alias",
            "Real": "alias", "text": "constant", "raw": "constant", "small_size": "constant",
            "large_size": "constant", "counts": "constant", "Box": "struct", "visit": "function",
            "make_callback": "function", "operator<": "function", "handler": "variable", "main": "function"}
got = cpp_names(CPP_SAMPLE, "sample.h")
check(got == expected, "the C++ reader reads a sample as documented"
      + (f" (read: {sorted(got.items())})" if got != expected else ""))
expected = {"LIMIT": "constant", "other": "constant", "Alias": "alias", "Box": "class", "visit": "function",
            "wait": "function", "chosen": "function"}
got = python_names(PYTHON_SAMPLE, "sample.py")
check(got == expected, "the Python reader reads a sample as documented"
      + (f" (read: {sorted(got.items())})" if got != expected else ""))

REASON = re.compile(r"(C\+\+ only|Python only|not the same kind): (to align \(issue 36\): )?\S.{20,}")
pairs = sorted(cpp & prototype)
found, compared = compare_pairs(pairs)
listed = {(module, name): reason for module, names in DIFFERENCES.items() for name, reason in names.items()}
vague = sorted(f"{module}: {name}" for (module, name), reason in listed.items() if not REASON.fullmatch(reason))
check(not vague, "every listed difference says its side and why" + (f" (not: {vague})" if vague else ""))
unlisted = [f"{module}: {name} ({kind})" for (module, name), kind in sorted(found.items())
            if (module, name) not in listed]
check(not unlisted, "what each module pair defines is the same on both tracks, or listed in DIFFERENCES with "
      "the reason" + (f" (not listed: {'; '.join(unlisted)})" if unlisted else ""))
stale = [f"{module}: {name} (listed {reason.split(':')[0]}, now "
         f"{found.get((module, name), 'the same on both tracks or on neither')})"
         for (module, name), reason in sorted(listed.items()) if found.get((module, name)) != reason.split(":")[0]]
check(not stale, "DIFFERENCES is current" + (f" (stale: {'; '.join(stale)})" if stale else ""))
counts = collections.Counter((kind, "to align" if "to align (issue 36)" in listed[key] else "must stay")
                             for key, kind in found.items())
print(f"{len(pairs)} module pairs, {compared['names']} names compared (C++: "
      + ", ".join(f"{compared['C++ ' + c]} {c}s" for c in ("type", "function", "constant")) + "; Python: "
      + ", ".join(f"{compared['Python ' + c]} {c}s" for c in ("type", "function", "constant")) + ")")
for kind in ("C++ only", "Python only", "not the same kind"):
    print(f"{kind}: {counts[kind, 'to align'] + counts[kind, 'must stay']} "
          f"({counts[kind, 'to align']} to align, {counts[kind, 'must stay']} must stay)")
