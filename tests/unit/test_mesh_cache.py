"""Unit tests of the mesh cache's key (python_prototype/domain/mesh_cache.py,
mesh_cache_key), the twins of tests/unit/test_mesh_cache.cpp: 16 hex
digits, the same for the same inputs, another for each input the mesh
depends on (the .geo's text, gmsh's version, mesh.size_factor,
mesh.refine, a fault's tip_size and tip_grading), the same for a fault
setting that does not change the mesh (friction, a fault without
tip_size). tests/test_cached_meshes.py runs the cache through both tracks."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402  (the repository on sys.path, a scratch temporary folder)
from python_prototype.domain.mesh_cache import mesh_cache_key  # noqa: E402
from python_prototype.scene.scene import read_scene  # noqa: E402

HERTZ = support.scene("hertz")  # a gmsh scene; its fault f below names no group, which only the mesh checks
TEXT, VERSION = b"Point(1) = {0, 0, 0};\n", "4.8.4"


def key(*overrides, text=TEXT, version=VERSION):
    return mesh_cache_key(read_scene(HERTZ, ["fault.f.gap=0.0", *overrides]), text, version)


class MeshCacheKey(unittest.TestCase):
    def test_is_sixteen_hex_digits_and_the_same_for_the_same_inputs(self):
        self.assertRegex(key(), "^[0-9a-f]{16}$")
        self.assertEqual(key(), key())

    def test_changes_with_each_input_of_the_mesh(self):
        keys = {key(), key(text=TEXT + b"// more\n"), key(version="4.8.5"), key("mesh.size_factor=0.5"),
                key("mesh.refine=1"), key("fault.f.tip_size=0.01"),
                key("fault.f.tip_size=0.01", "fault.f.tip_grading=0.3")}
        self.assertEqual(len(keys), 7)

    def test_ignores_what_does_not_change_the_mesh(self):
        self.assertEqual(key("fault.f.friction=0.3"), key())
        self.assertEqual(key("fault.g.gap=0.0"), key())  # a fault without tip_size


if __name__ == "__main__":
    unittest.main()
