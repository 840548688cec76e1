// Unit tests of the scene reader's refusals (cpp/scene/scene.h, read_scene):
// a bad scene raises SceneError with one line "<file>: <key>: <reason>"
// naming the key, for unknown keys, wrong types, values out of range,
// unknown boundaries and choices, missing keys, bad expressions, output
// times off the steps, bad files and bad --set overrides, faults
// ([fault.NAME]) and a given pore pressure ([mechanics] pore_pressure and
// alpha) where the scene cannot have them or with bad values; the default
// scene, a fault's defaults and a given pore pressure are read. tests/test_bad_scenes.py runs the full catalogue
// through the binary. The prototype's twin is tests/unit/test_scene.py.
#include "scene/scene.h"
#include "scene/section.h"

#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>

using namespace biotcontact;

namespace
{
const std::string default_scene = std::string(BIOTCONTACT_SOURCE_DIR) + "/scenes/default.toml";
// A gmsh scene without flow (faults need gmsh), and a coupled one.
const std::string hertz_scene = std::string(BIOTCONTACT_SOURCE_DIR) + "/scenes/hertz.toml";
const std::string fracture_scene = std::string(BIOTCONTACT_SOURCE_DIR) + "/scenes/fracture.toml";
// A built-in mesh without flow.
const std::string elastic_scene = std::string(BIOTCONTACT_SOURCE_DIR) + "/scenes/elastic_contact.toml";

/// The message read_scene refuses the scene with ("" if it accepts it).
std::string refusal(const std::string& file, const std::vector<std::string>& overrides = {})
{
  try
  {
    read_scene(file, overrides);
  }
  catch (const SceneError& e)
  {
    return e.what();
  }
  return "";
}

/// The scene `file` with `overrides` is refused with one line
/// "<file>: <key>: ..." whose reason holds `reason`.
void expect_refused_in(const std::string& file, const std::vector<std::string>& overrides, const std::string& key,
                       const std::string& reason)
{
  const std::string message = refusal(file, overrides), head = file + ": " + key + ": ";
  EXPECT_EQ(message.rfind(head, 0), 0u) << "--set " << overrides.front() << ": \"" << message << "\"";
  EXPECT_NE(message.find(reason, head.size()), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
}

/// The same for the default scene.
void expect_refused(const std::vector<std::string>& overrides, const std::string& key, const std::string& reason)
{
  expect_refused_in(default_scene, overrides, key, reason);
}

/// A scratch folder for scene files, removed at the end of the test.
struct SceneFiles : testing::Test
{
  std::filesystem::path folder;
  void SetUp() override
  {
    char name[] = "/tmp/biotcontact-unit-XXXXXX";
    folder = mkdtemp(name);
  }
  void TearDown() override { std::filesystem::remove_all(folder); }
  std::string written(const std::string& text) const
  {
    const std::string path = folder / "scene.toml";
    std::ofstream(path) << text;
    return path;
  }
  /// The default scene without the line that sets `key`.
  std::string without(const std::string& key) const
  {
    std::ifstream in(default_scene);
    std::ostringstream out;
    for (std::string line; std::getline(in, line);)
      if (line.rfind(key + " ", 0) != 0)
        out << line << "\n";
    return written(out.str());
  }
};
} // namespace

TEST(SceneReader, ReadsTheDefaultScene)
{
  const Scene s = read_scene(default_scene);
  EXPECT_EQ(s.name, "default");
  EXPECT_EQ(s.num_steps(), 48) << "time.end = 9.6, time.dt = 0.2";
  ASSERT_TRUE(s.mechanics);
  // E = 1e9, nu = 0.2: G = E / (2 (1 + nu)), lambda = E nu / ((1 + nu) (1 - 2 nu)).
  EXPECT_DOUBLE_EQ(s.mechanics->G, 1e9 / 2.4);
  EXPECT_DOUBLE_EQ(s.mechanics->lambda, 1e9 * 0.2 / (1.2 * 0.6));
  ASSERT_TRUE(s.has_contact());
  const ContactSpec& c = s.boundaries.at("bottom").contact.value();
  EXPECT_EQ(c.gap(0, 0, 0, 0), 0.0012);
  EXPECT_EQ(c.normal.at(1)(0, 0, 0, 0), -1.0);
  EXPECT_EQ(refusal(default_scene, {"time.dt=0.4"}), "") << "another whole number of steps";
}

TEST(SceneReader, ReadsConstantExpressionsWhereANumberIsWanted)
{
  const Scene s = read_scene(default_scene, {"mechanics.E='2 * 5e8'", "mesh.upper=['5 * 2', '1']"});
  EXPECT_DOUBLE_EQ(s.mechanics->G, 1e9 / 2.4) << "E = \"2 * 5e8\" is E = 1e9";
  EXPECT_EQ(s.mesh.upper, (std::vector<double>{10.0, 1.0}));
  expect_refused({"mechanics.E='1e9 * t'"}, "mechanics.E", "one value is wanted here");
}

TEST(SceneReader, NamedExpressionsAreSubstituted)
{
  EXPECT_EQ(identifiers("2.5e-3*x + sin(a1) - 1e9*b_2"), (std::vector<std::string>{"x", "sin", "a1", "b_2"}));
  EXPECT_EQ(substitute_names("a*ab + a", {{"a", "1+x"}}), "(1+x)*ab + (1+x)");
  // Names in any order, one using another, where a number or an expression is wanted.
  const Scene s = read_scene(default_scene, {"expressions.young='2*half'", "expressions.half=5e8",
                                             "mechanics.E='young'", "boundary.top.traction=[0.0, '-half*(1 + y)']"});
  EXPECT_DOUBLE_EQ(s.mechanics->G, 1e9 / 2.4) << "E = young = 2 half = 1e9";
  const Expression& traction = s.boundaries.at("top").traction.at(1);
  EXPECT_DOUBLE_EQ(traction(0.0, 1.0, 0.0, 0.0), -1e9);
  EXPECT_EQ(traction.text(), "-half*(1 + y)") << "messages show the scene's text";
  expect_refused({"expressions.a='b'", "expressions.b='a + 1'"}, "expressions.a", "cycle (a -> b -> a)");
  expect_refused({"expressions.sin=1.0"}, "expressions.sin", "not a name");
  expect_refused({"expressions.a='1 +'"}, "expressions.a", "cannot parse");
  expect_refused({"expressions.a=[1.0]"}, "expressions.a", "must be a number or an expression string");
}

TEST(SceneReader, UnknownKeysAreRefused)
{
  expect_refused({"mechanics.Ee=1.0"}, "mechanics.Ee", "unknown key");
  expect_refused({"boundary.top.tracton=[0.0, 1.0]"}, "boundary.top.tracton", "unknown key");
  expect_refused({"nosuch.key=1"}, "nosuch", "unknown key");
}

TEST(SceneReader, WrongTypesAreRefused)
{
  expect_refused({"mechanics.E='abc'"}, "mechanics.E", "must be a number");
  expect_refused({"output.xdmf=3"}, "output.xdmf", "must be true or false");
  expect_refused({"scene.name=[1, 2]"}, "scene.name", "must be a string");
  expect_refused({"coupling.max_iterations=2.5"}, "coupling.max_iterations", "must be an integer");
  expect_refused({"mesh.upper=[1.0]"}, "mesh.upper", "must be an array of 2 numbers");
}

TEST(SceneReader, OutOfRangeValuesAreRefused)
{
  expect_refused({"mechanics.nu=0.5"}, "mechanics.nu", "must lie in (-1, 0.5)");
  expect_refused({"mechanics.E=-1.0"}, "mechanics.E", "must be a positive finite number");
  expect_refused({"time.dt=0.0"}, "time.dt", "must be a positive finite number");
  expect_refused({"flow.phi0=1.5"}, "flow.phi0", "must lie in [0, 1]");
  expect_refused({"coupling.alpha=1.5"}, "coupling.alpha", "must lie in [0, 1]");
  expect_refused({"time.retry=21"}, "time.retry", "must lie in [0, 20]");
  expect_refused({"time.dt=0.7"}, "time.dt", "time.end must be a whole number of steps dt");
}

TEST(SceneReader, UnknownBoundariesAndChoicesAreRefused)
{
  expect_refused({"boundary.middle.pressure=0.0"}, "boundary.middle", "unknown boundary name");
  expect_refused({"coupling.scheme=undrained"}, "coupling.scheme", "undrained");
  expect_refused({"mesh.type=sphere"}, "mesh.type", "sphere");
  expect_refused({"time.scheme=rk4"}, "time.scheme", "rk4");
}

TEST(SceneReader, BadExpressionIsRefused)
{
  expect_refused({"boundary.top.pressure='1 +'"}, "boundary.top.pressure", "cannot parse expression \"1 +\"");
}

TEST(SceneReader, OutputTimeOffTheStepsIsRefused)
{
  expect_refused({"output.times=[0.3]"}, "output.times", "0.3 is not the end of a step");
  expect_refused({"output.times=[2.0, 1.0]"}, "output.times", "must increase strictly");
  expect_refused({"output.times=[1.0]", "output.every=2.0"}, "output.every", "not both");
}

TEST_F(SceneFiles, MissingKeyIsRefused)
{
  const std::string file = without("mu_f");
  const std::string message = refusal(file);
  EXPECT_EQ(message, file + ": flow.mu_f: missing (a number is required)");
}

TEST_F(SceneFiles, MissingTableIsRefused)
{
  std::ifstream in(default_scene);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  text.replace(text.find("[time]"), 6, "[tiem]");
  const std::string file = written(text);
  EXPECT_EQ(refusal(file), file + ": time: missing (a table is required; the table has tiem: misspelt?)");
}

TEST_F(SceneFiles, MisspeltKeyIsNamed)
{
  expect_refused({"time.adaptive={ tol = 1e-3 }"}, "time.adaptive.tolerance",
                 "missing (a number is required; the table has tol: misspelt?)");
}

TEST_F(SceneFiles, BadFilesAreRefused)
{
  const std::string absent = (folder / "no" / "scene.toml").string();
  EXPECT_EQ(refusal(absent), absent + ": scene file not found");
  EXPECT_EQ(refusal(folder.string()), folder.string() + ": scene file not found") << "a directory";
  const std::string broken = written("[mesh\ntype = 1\n");
  const std::string message = refusal(broken);
  EXPECT_EQ(message.rfind(broken + ":", 0), 0u) << message;
  EXPECT_NE(message.find("invalid TOML"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(SceneReader, BadOverrideIsRefused)
{
  EXPECT_EQ(refusal(default_scene, {"mechanics"}), default_scene + ": --set mechanics: expected key.path=value");
  EXPECT_EQ(refusal(default_scene, {"=1"}), default_scene + ": --set =1: expected key.path=value");
  EXPECT_EQ(refusal(default_scene, {"mesh.type.x=1"}), default_scene + ": --set mesh.type.x: type is not a table");
}

TEST(SceneReader, ReadsFaults)
{
  const Scene plain = read_scene(hertz_scene, {"fault.f.flow='transparent'"});
  const FaultSpec& f = plain.faults.at("f");
  EXPECT_EQ(f.gap(0, 0, 0, 0), 0.0) << "gap 0 by default";
  EXPECT_FALSE(f.pressure);
  EXPECT_FALSE(f.pore_pressure_load);
  EXPECT_EQ(f.flow, FaultFlow::transparent);
  EXPECT_EQ(f.normal, (std::vector<double>{0.0, 1.0})) << "[0, 1] in 2D";
  const Scene given = read_scene(fracture_scene, {"fault.f.gap='1e-3*x'", "fault.f.pressure='1e5*t'",
                                                  "fault.f.flow='pressure'", "fault.f.normal=[1, 1]"});
  const FaultSpec& g = given.faults.at("f");
  EXPECT_EQ(g.gap(2, 0, 0, 0), 2e-3);
  EXPECT_EQ((*g.pressure)(0, 0, 0, 3), 3e5);
  EXPECT_EQ(g.flow, FaultFlow::pressure);
  EXPECT_EQ(g.normal, (std::vector<double>{1.0, 1.0}));
  const Scene loaded = read_scene(fracture_scene, {"fault.f.pore_pressure_load=true", "fault.f.flow='sealing'"});
  EXPECT_TRUE(loaded.faults.at("f").pore_pressure_load);
}

TEST(SceneReader, FaultsWhereTheSceneCannotHaveThemAreRefused)
{
  expect_refused({"fault.f.gap=0.0"}, "fault.f", "a fault is an interior physical group of a gmsh mesh");
  expect_refused_in(hertz_scene, {"fault.top.gap=0.0"}, "fault.top",
                    "also given as [boundary.top]: a physical group is a boundary or a fault, not both");
  expect_refused_in(hertz_scene, {"fault.f.pore_pressure_load=true"}, "fault.f.pore_pressure_load",
                    "needs a pore pressure: [flow], or mechanics.pore_pressure");
  expect_refused_in(hertz_scene, {"fault.f.flow='sealing'"}, "fault.f.flow", "\"sealing\" in a scene without [flow]");
  // With [flow] a fault is transparent by default (its flux tied across it).
  EXPECT_EQ(read_scene(fracture_scene, {"fault.f.gap=0.0"}).faults.at("f").flow, FaultFlow::transparent);
}

TEST(SceneReader, BadFaultValuesAreRefused)
{
  expect_refused_in(hertz_scene, {"fault.f.gap='1e-3*t'"}, "fault.f.gap", "must not depend on t");
  expect_refused_in(fracture_scene, {"fault.f.pressure=1e5", "fault.f.pore_pressure_load=true"},
                    "fault.f.pore_pressure_load", "give pressure or pore_pressure_load, not both");
  expect_refused_in(hertz_scene, {"fault.f.flow='leaky'"}, "fault.f.flow",
                    "must be \"transparent\", \"sealing\", \"pressure\" or \"conduit\", got \"leaky\"");
  expect_refused_in(fracture_scene, {"fault.f.flow='pressure'"}, "fault.f.pressure",
                    "missing (flow = \"pressure\" holds the fault at this pressure)");
  expect_refused_in(hertz_scene, {"fault.f.normal=[0, 0]"}, "fault.f.normal", "must be a non-zero finite vector");
  expect_refused_in(hertz_scene, {"fault.f.normal=[inf, 1]"}, "fault.f.normal", "must be a non-zero finite vector");
  expect_refused_in(hertz_scene, {"fault.f.normal=[0, 0, 1]"}, "fault.f.normal", "must be an array of 2 numbers");
  expect_refused_in(hertz_scene, {"fault.f.aperture=1e-3"}, "fault.f.aperture", "unknown key");
}

TEST(SceneReader, ReadsAGivenPorePressure)
{
  const Scene s = read_scene(elastic_scene, {"mechanics.pore_pressure='-1e6*t'", "mechanics.alpha=0.8",
                                             "boundary.bottom.pore_pressure_load=true"});
  ASSERT_TRUE(s.mechanics->pore_pressure);
  EXPECT_EQ((*s.mechanics->pore_pressure)(0, 0, 0, 2), -2e6);
  EXPECT_EQ(s.mechanics->alpha, 0.8);
  EXPECT_TRUE(s.boundaries.at("bottom").pore_pressure_load) << "the face takes the given pressure";
}

TEST(SceneReader, BadGivenPorePressureIsRefused)
{
  expect_refused({"mechanics.pore_pressure=1e5", "mechanics.alpha=1.0"}, "mechanics.pore_pressure",
                 "a given pore pressure is for a scene without [flow] (here the flow computes it)");
  expect_refused_in(elastic_scene, {"mechanics.pore_pressure=1e5"}, "mechanics.alpha",
                    "missing (the Biot coefficient of mechanics.pore_pressure)");
  expect_refused_in(elastic_scene, {"mechanics.alpha=0.8"}, "mechanics.alpha",
                    "needs mechanics.pore_pressure (a coupled scene gives coupling.alpha)");
  for (const char* alpha : {"mechanics.alpha=0.0", "mechanics.alpha=1.5"})
    expect_refused_in(elastic_scene, {"mechanics.pore_pressure=1e5", alpha}, "mechanics.alpha",
                      "the Biot coefficient must lie in (0, 1]");
  expect_refused_in(elastic_scene, {"boundary.bottom.pore_pressure_load=true"}, "boundary.bottom.pore_pressure_load",
                    "needs a pore pressure: a coupled scene, or mechanics.pore_pressure");
}
