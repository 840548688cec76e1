"""Unit tests of the prototype's scene reader's refusals
(python_prototype/scene/scene.py, read_scene), the twins of
tests/unit/test_scene.cpp: a bad scene raises SceneError with one line
"<file>: <key>: <reason>" naming the key, for unknown keys, wrong types,
values out of range, unknown boundaries and choices, missing keys, bad
expressions, output times off the steps, bad files and bad --set overrides,
faults ([fault.NAME]) and a given pore pressure ([mechanics] pore_pressure
and alpha) where the scene cannot have them or with bad values; the default
scene, a fault's defaults and a given pore pressure are read.
tests/test_bad_scenes.py runs the full catalogue through both tracks'
command lines."""
import math
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402  (the repository on sys.path, a scratch temporary folder)
from python_prototype.scene.input import FaultFlow  # noqa: E402
from python_prototype.scene.scene import SceneError, read_scene  # noqa: E402
from python_prototype.scene.section import identifiers, substitute_names  # noqa: E402

DEFAULT = support.scene("default")
# A gmsh scene without flow (faults need gmsh), and a coupled one.
HERTZ, FRACTURE = support.scene("hertz"), support.scene("fracture")
ELASTIC = support.scene("elastic_contact")  # a built-in mesh without flow
with open(DEFAULT) as f:
    TEXT = f.read()


def refusal(file, overrides=()):
    """The message read_scene refuses the scene with ("" if it accepts it)."""
    try:
        read_scene(file, overrides)
    except SceneError as e:
        return str(e)
    return ""


def written(text):
    path = os.path.join(tempfile.mkdtemp(), "scene.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


class SceneReader(unittest.TestCase):
    def expect_refused_in(self, file, overrides, key, reason):
        """The scene `file` with `overrides` is refused with one line
        "<file>: <key>: ..." whose reason holds `reason`."""
        message, head = refusal(file, overrides), f"{file}: {key}: "
        self.assertTrue(message.startswith(head), f"--set {overrides[0]}: {message!r}")
        self.assertIn(reason, message[len(head):])
        self.assertNotIn("\n", message, "one line")

    def expect_refused(self, overrides, key, reason):
        """The same for the default scene."""
        self.expect_refused_in(DEFAULT, overrides, key, reason)

    def test_reads_the_default_scene(self):
        s = read_scene(DEFAULT)
        self.assertEqual(s.name, "default")
        self.assertEqual(s.num_steps(), 48, "time.end = 9.6, time.dt = 0.2")
        # E = 1e9, nu = 0.2: G = E / (2 (1 + nu)), lambda = E nu / ((1 + nu) (1 - 2 nu)).
        self.assertAlmostEqual(s.mechanics.G, 1e9 / 2.4, delta=4 * math.ulp(s.mechanics.G))
        self.assertAlmostEqual(s.mechanics.lmbda, 1e9 * 0.2 / (1.2 * 0.6), delta=4 * math.ulp(s.mechanics.lmbda))
        self.assertTrue(s.has_contact())
        c = s.boundaries["bottom"].contact
        self.assertEqual(c.gap(0, 0, 0, 0), 0.0012)
        self.assertEqual(c.normal[1](0, 0, 0, 0), -1.0)
        self.assertEqual(refusal(DEFAULT, ["time.dt=0.4"]), "", "another whole number of steps")

    def test_reads_constant_expressions_where_a_number_is_wanted(self):
        s = read_scene(DEFAULT, ["mechanics.E='2 * 5e8'", "mesh.upper=['5 * 2', '1']"])
        self.assertAlmostEqual(s.mechanics.G, 1e9 / 2.4, delta=4 * math.ulp(s.mechanics.G), msg='E = "2 * 5e8"')
        self.assertEqual(list(s.mesh.upper), [10.0, 1.0])
        self.expect_refused(["mechanics.E='1e9 * t'"], "mechanics.E", "one value is wanted here")

    def test_unknown_keys_are_refused(self):
        self.expect_refused(["mechanics.Ee=1.0"], "mechanics.Ee", "unknown key")
        self.expect_refused(["boundary.top.tracton=[0.0, 1.0]"], "boundary.top.tracton", "unknown key")
        self.expect_refused(["nosuch.key=1"], "nosuch", "unknown key")

    def test_named_expressions_are_substituted(self):
        self.assertEqual(identifiers("2.5e-3*x + sin(a1) - 1e9*b_2"), ["x", "sin", "a1", "b_2"])
        self.assertEqual(substitute_names("a*ab + a", {"a": "1+x"}), "(1+x)*ab + (1+x)")
        # Names in any order, one using another, where a number or an expression is wanted.
        s = read_scene(DEFAULT, ["expressions.young='2*half'", "expressions.half=5e8", "mechanics.E='young'",
                                 "boundary.top.traction=[0.0, '-half*(1 + y)']"])
        self.assertAlmostEqual(s.mechanics.G, 1e9 / 2.4, delta=4 * math.ulp(s.mechanics.G), msg="E = 2 half = 1e9")
        traction = s.boundaries["top"].traction[1]
        self.assertEqual(traction(0.0, 1.0, 0.0, 0.0), -1e9)
        self.assertEqual(traction.text, "-half*(1 + y)", "messages show the scene's text")
        self.expect_refused(["expressions.a='b'", "expressions.b='a + 1'"], "expressions.a", "cycle (a -> b -> a)")
        self.expect_refused(["expressions.sin=1.0"], "expressions.sin", "not a name")
        self.expect_refused(["expressions.a='1 +'"], "expressions.a", "cannot parse")
        self.expect_refused(["expressions.a=[1.0]"], "expressions.a", "must be a number or an expression string")

    def test_wrong_types_are_refused(self):
        self.expect_refused(["mechanics.E='abc'"], "mechanics.E", "must be a number")
        self.expect_refused(["output.xdmf=3"], "output.xdmf", "must be true or false")
        self.expect_refused(["scene.name=[1, 2]"], "scene.name", "must be a string")
        self.expect_refused(["coupling.max_iterations=2.5"], "coupling.max_iterations", "must be an integer")
        self.expect_refused(["mesh.upper=[1.0]"], "mesh.upper", "must be an array of 2 numbers")

    def test_out_of_range_values_are_refused(self):
        self.expect_refused(["mechanics.nu=0.5"], "mechanics.nu", "must lie in (-1, 0.5)")
        self.expect_refused(["mechanics.E=-1.0"], "mechanics.E", "must be a positive finite number")
        self.expect_refused(["time.dt=0.0"], "time.dt", "must be a positive finite number")
        self.expect_refused(["flow.phi0=1.5"], "flow.phi0", "must lie in [0, 1]")
        self.expect_refused(["coupling.alpha=1.5"], "coupling.alpha", "must lie in [0, 1]")
        self.expect_refused(["time.retry=21"], "time.retry", "must lie in [0, 20]")
        self.expect_refused(["time.dt=0.7"], "time.dt", "time.end must be a whole number of steps dt")

    def test_unknown_boundaries_and_choices_are_refused(self):
        self.expect_refused(["boundary.middle.pressure=0.0"], "boundary.middle", "unknown boundary name")
        self.expect_refused(["coupling.scheme=undrained"], "coupling.scheme", "undrained")
        self.expect_refused(["mesh.type=sphere"], "mesh.type", "sphere")
        self.expect_refused(["time.scheme=rk4"], "time.scheme", "rk4")

    def test_bad_expression_is_refused(self):
        self.expect_refused(["boundary.top.pressure='1 +'"], "boundary.top.pressure", 'cannot parse expression "1 +"')

    def test_output_time_off_the_steps_is_refused(self):
        self.expect_refused(["output.times=[0.3]"], "output.times", "0.3 is not the end of a step")
        self.expect_refused(["output.times=[2.0, 1.0]"], "output.times", "must increase strictly")
        self.expect_refused(["output.times=[1.0]", "output.every=2.0"], "output.every", "not both")

    def test_missing_key_is_refused(self):
        file = written("\n".join(line for line in TEXT.splitlines() if not line.startswith("mu_f ")))
        self.assertEqual(refusal(file), f"{file}: flow.mu_f: missing (a number is required)")

    def test_missing_table_is_refused(self):
        file = written(TEXT.replace("[time]", "[tiem]"))
        self.assertEqual(refusal(file), f"{file}: time: missing (a table is required; the table has tiem: misspelt?)")

    def test_misspelt_key_is_named(self):
        self.expect_refused(["time.adaptive={ tol = 1e-3 }"], "time.adaptive.tolerance",
                            "missing (a number is required; the table has tol: misspelt?)")

    def test_bad_files_are_refused(self):
        folder = tempfile.mkdtemp()
        absent = os.path.join(folder, "no", "scene.toml")
        self.assertEqual(refusal(absent), f"{absent}: scene file not found")
        self.assertEqual(refusal(folder), f"{folder}: scene file not found", "a directory")
        broken = written("[mesh\ntype = 1\n")
        message = refusal(broken)
        self.assertTrue(message.startswith(broken + ":"), message)
        self.assertIn("invalid TOML", message)
        self.assertNotIn("\n", message)

    def test_bad_override_is_refused(self):
        self.assertEqual(refusal(DEFAULT, ["mechanics"]), f"{DEFAULT}: --set mechanics: expected key.path=value")
        self.assertEqual(refusal(DEFAULT, ["=1"]), f"{DEFAULT}: --set =1: expected key.path=value")
        self.assertEqual(refusal(DEFAULT, ["mesh.type.x=1"]), f"{DEFAULT}: --set mesh.type.x: type is not a table")

    def test_reads_faults(self):
        f = read_scene(HERTZ, ["fault.f.flow='transparent'"]).faults["f"]
        self.assertEqual(f.gap(0, 0, 0, 0), 0.0, "gap 0 by default")
        self.assertIsNone(f.pressure)
        self.assertFalse(f.pore_pressure_load)
        self.assertEqual(f.flow, FaultFlow.transparent)
        self.assertEqual(f.normal, [0.0, 1.0], "[0, 1] in 2D")
        g = read_scene(FRACTURE, ["fault.f.gap='1e-3*x'", "fault.f.pressure='1e5*t'", "fault.f.flow='pressure'",
                                  "fault.f.normal=[1, 1]"]).faults["f"]
        self.assertEqual(g.gap(2, 0, 0, 0), 2e-3)
        self.assertEqual(g.pressure(0, 0, 0, 3), 3e5)
        self.assertEqual(g.flow, FaultFlow.pressure)
        self.assertEqual(g.normal, [1.0, 1.0])
        self.assertTrue(read_scene(FRACTURE, ["fault.f.pore_pressure_load=true", "fault.f.flow='sealing'"])
                        .faults["f"].pore_pressure_load)

    def test_faults_where_the_scene_cannot_have_them_are_refused(self):
        self.expect_refused(["fault.f.gap=0.0"], "fault.f", "a fault is an interior physical group of a gmsh mesh")
        self.expect_refused_in(HERTZ, ["fault.top.gap=0.0"], "fault.top",
                               "also given as [boundary.top]: a physical group is a boundary or a fault, not both")
        self.expect_refused_in(HERTZ, ["fault.f.pore_pressure_load=true"], "fault.f.pore_pressure_load",
                               "needs a pore pressure: [flow], or mechanics.pore_pressure")
        self.expect_refused_in(HERTZ, ["fault.f.flow='sealing'"], "fault.f.flow", '"sealing" in a scene without [flow]')
        # With [flow] a fault is transparent by default (its flux tied across it).
        self.assertEqual(read_scene(FRACTURE, ["fault.f.gap=0.0"]).faults["f"].flow, FaultFlow.transparent)

    def test_bad_fault_values_are_refused(self):
        self.expect_refused_in(HERTZ, ["fault.f.gap='1e-3*t'"], "fault.f.gap", "must not depend on t")
        self.expect_refused_in(FRACTURE, ["fault.f.pressure=1e5", "fault.f.pore_pressure_load=true"],
                               "fault.f.pore_pressure_load", "give pressure or pore_pressure_load, not both")
        self.expect_refused_in(HERTZ, ["fault.f.flow='leaky'"], "fault.f.flow",
                               'must be "transparent", "sealing", "pressure" or "conduit", got "leaky"')
        self.expect_refused_in(FRACTURE, ["fault.f.flow='pressure'"], "fault.f.pressure",
                               'missing (flow = "pressure" holds the fault at this pressure)')
        self.expect_refused_in(HERTZ, ["fault.f.normal=[0, 0]"], "fault.f.normal", "must be a non-zero finite vector")
        self.expect_refused_in(HERTZ, ["fault.f.normal=[inf, 1]"], "fault.f.normal",
                               "must be a non-zero finite vector")
        self.expect_refused_in(HERTZ, ["fault.f.normal=[0, 0, 1]"], "fault.f.normal", "must be an array of 2 numbers")
        self.expect_refused_in(HERTZ, ["fault.f.aperture=1e-3"], "fault.f.aperture", "unknown key")

    def test_reads_a_given_pore_pressure(self):
        s = read_scene(ELASTIC, ["mechanics.pore_pressure='-1e6*t'", "mechanics.alpha=0.8",
                                 "boundary.bottom.pore_pressure_load=true"])
        self.assertEqual(s.mechanics.pore_pressure(0, 0, 0, 2), -2e6)
        self.assertEqual(s.mechanics.alpha, 0.8)
        self.assertTrue(s.boundaries["bottom"].pore_pressure_load, "the face takes the given pressure")

    def test_bad_given_pore_pressure_is_refused(self):
        self.expect_refused(["mechanics.pore_pressure=1e5", "mechanics.alpha=1.0"], "mechanics.pore_pressure",
                            "a given pore pressure is for a scene without [flow] (here the flow computes it)")
        self.expect_refused_in(ELASTIC, ["mechanics.pore_pressure=1e5"], "mechanics.alpha",
                               "missing (the Biot coefficient of mechanics.pore_pressure)")
        self.expect_refused_in(ELASTIC, ["mechanics.alpha=0.8"], "mechanics.alpha",
                               "needs mechanics.pore_pressure (a coupled scene gives coupling.alpha)")
        for alpha in ("mechanics.alpha=0.0", "mechanics.alpha=1.5"):
            self.expect_refused_in(ELASTIC, ["mechanics.pore_pressure=1e5", alpha], "mechanics.alpha",
                                   "the Biot coefficient must lie in (0, 1]")
        self.expect_refused_in(ELASTIC, ["boundary.bottom.pore_pressure_load=true"],
                               "boundary.bottom.pore_pressure_load",
                               "needs a pore pressure: a coupled scene, or mechanics.pore_pressure")


if __name__ == "__main__":
    unittest.main()
