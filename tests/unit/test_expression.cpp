// Unit tests of the scene's expressions (cpp/scene/expression.h): numbers
// and constant texts are constants, the x/y/z/t dependence flags, values at
// points and times, muparser's syntax (docs/user-guide.md, "Expressions"),
// bad text refused with muparser's message, and the program's own
// functions. The prototype's twin is tests/unit/test_expression.py.
#include "scene/expression.h"

#include <cmath>
#include <gtest/gtest.h>
#include <stdexcept>

using namespace biotcontact;

TEST(Expression, NumbersAndConstantTextsAreConstants)
{
  const Expression number(2.5);
  EXPECT_TRUE(number.is_constant());
  EXPECT_FALSE(number.depends_on_time());
  EXPECT_FALSE(number.depends_on_space());
  EXPECT_EQ(number(1, 2, 3, 4), 2.5);
  EXPECT_EQ(number.text(), "2.5");
  const Expression text("2*3 + 1");
  EXPECT_TRUE(text.is_constant());
  EXPECT_EQ(text(0, 0, 0, 0), 7.0);
  EXPECT_EQ(text(5, -1, 2, 9), 7.0);
  EXPECT_EQ(text.text(), "2*3 + 1") << "the scene's text is kept";
  EXPECT_EQ(Expression("pi")(0, 0, 0, 0), std::acos(-1.0));
  EXPECT_TRUE(Expression("sin(pi/2)").is_constant());
}

TEST(Expression, DependenceFlags)
{
  struct Case
  {
    const char* text;
    bool space, time;
  };
  for (const Case& c : {Case{"x", true, false}, Case{"y + 1", true, false}, Case{"2*z", true, false},
                        Case{"t", false, true}, Case{"x*t", true, true}, Case{"sin(t) + y^2", true, true},
                        Case{"pi * 2", false, false}})
  {
    const Expression e(std::string(c.text));
    EXPECT_EQ(e.depends_on_space(), c.space) << c.text;
    EXPECT_EQ(e.depends_on_time(), c.time) << c.text;
    EXPECT_EQ(e.is_constant(), !c.space and !c.time) << c.text;
  }
}

TEST(Expression, EvaluatesAtPointsAndTimes)
{
  const Expression e(std::string("x + 2*y - z*t"));
  EXPECT_EQ(e(1, 2, 3, 4), -7.0);
  EXPECT_EQ(e(0, 0, 0, 0), 0.0);
  const double point[3] = {-1, 0.5, 2};
  EXPECT_EQ(e(point, 0.25), -0.5);
  // Each evaluation sets every variable: no value is left from the last.
  EXPECT_EQ(e(1, 2, 3, 4), -7.0);
}

TEST(Expression, MuparserSyntax)
{
  struct Case
  {
    const char* text;
    double value;
  };
  for (const Case& c : {Case{"-2^2", -4}, Case{"2^3^2", 512}, Case{"2 * 3 + 4 / 2", 8}, Case{"1e-3 * 1.5e3", 1.5},
                        Case{"1 < 2 ? 3 : 4", 3}, Case{"1 > 2 ? 3 : 4", 4}, Case{"(1 < 2) && (2 < 1)", 0},
                        Case{"(1 < 2) || (2 < 1)", 1}, Case{"2 == 2", 1}, Case{"2 != 2", 0},
                        Case{"log(_e)", 1}, Case{"log10(1000)", 3}, Case{"sqrt(abs(-16))", 4},
                        Case{"min(3, 1, 2)", 1}, Case{"max(3, 1, 2)", 3}, Case{"sum(1, 2, 3)", 6},
                        Case{"avg(1, 2, 3)", 2}, Case{"rint(2.6)", 3}, Case{"exp(0) + cos(0)", 2}})
    EXPECT_DOUBLE_EQ(Expression(std::string(c.text))(0, 0, 0, 0), c.value) << c.text;
  const Expression step(std::string("x > 0.5 ? 1 : 0"));
  EXPECT_EQ(step(1, 0, 0, 0), 1.0);
  EXPECT_EQ(step(0, 0, 0, 0), 0.0);
}

TEST(Expression, BadTextIsRefusedWithAMessage)
{
  for (const std::string text : {"1 +", "foo(x)", "x y", "(x + 1", "sin(x", "2 * * 3", "", "w"})
  {
    try
    {
      Expression e(text);
      ADD_FAILURE() << "accepted \"" << text << "\"";
    }
    catch (const std::invalid_argument& error)
    {
      const std::string message = error.what(), head = "cannot parse expression \"" + text + "\": ";
      EXPECT_EQ(message.rfind(head, 0), 0u) << message;
      EXPECT_GT(message.size(), head.size()) << "muparser's reason follows: " << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
    }
  }
  // An unknown name is named.
  try
  {
    Expression e(std::string("2 * foo"));
    ADD_FAILURE() << "accepted an unknown name";
  }
  catch (const std::invalid_argument& error)
  {
    EXPECT_NE(std::string(error.what()).find("\"foo\""), std::string::npos) << error.what();
  }
}

TEST(Expression, ProgramFunctions)
{
  // A value the program computes (a closed form on a boundary): neither a
  // constant nor a parsed text, taken as time-dependent.
  const Expression e([](double x, double, double, double t) { return x * t + 1; }, "closed form");
  EXPECT_FALSE(e.is_constant());
  EXPECT_TRUE(e.depends_on_time());
  EXPECT_EQ(e(2, 0, 0, 3), 7.0);
  EXPECT_EQ(e.text(), "closed form");
}
