// Unit tests of the mesh cache's key (cpp/domain/mesh_cache.h,
// mesh_cache_key): 16 hex digits, the same for the same inputs, another
// for each input the mesh depends on (the .geo's text, gmsh's version,
// mesh.size_factor, mesh.refine, a fault's tip_size and tip_grading), the
// same for a fault setting that does not change the mesh (friction, a
// fault without tip_size). tests/test_cached_meshes.py runs the cache through
// both tracks. The prototype's twin is tests/unit/test_mesh_cache.py.
#include "domain/mesh_cache.h"
#include "scene/scene.h"

#include <gtest/gtest.h>
#include <regex>
#include <set>

using namespace biotcontact;

namespace
{
// A gmsh scene; its fault f names no group, which only the mesh checks.
const std::string hertz_scene = std::string(BIOTCONTACT_SOURCE_DIR) + "/scenes/hertz.toml";
const std::string text = "Point(1) = {0, 0, 0};\n", version = "4.8.4";

std::string key(std::vector<std::string> overrides, const std::string& geo = text, const std::string& gmsh = version)
{
  overrides.insert(overrides.begin(), "fault.f.gap=0.0");
  return mesh_cache_key(read_scene(hertz_scene, overrides), geo, gmsh);
}
} // namespace

TEST(MeshCacheKey, IsSixteenHexDigitsAndTheSameForTheSameInputs)
{
  EXPECT_TRUE(std::regex_match(key({}), std::regex("[0-9a-f]{16}")));
  EXPECT_EQ(key({}), key({}));
}

TEST(MeshCacheKey, ChangesWithEachInputOfTheMesh)
{
  const std::set<std::string> keys{key({}),
                                   key({}, text + "// more\n"),
                                   key({}, text, "4.8.5"),
                                   key({"mesh.size_factor=0.5"}),
                                   key({"mesh.refine=1"}),
                                   key({"fault.f.tip_size=0.01"}),
                                   key({"fault.f.tip_size=0.01", "fault.f.tip_grading=0.3"})};
  EXPECT_EQ(keys.size(), 7u);
}

TEST(MeshCacheKey, IgnoresWhatDoesNotChangeTheMesh)
{
  EXPECT_EQ(key({"fault.f.friction=0.3"}), key({}));
  EXPECT_EQ(key({"fault.g.gap=0.0"}), key({})); // a fault without tip_size
}
