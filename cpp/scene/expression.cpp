#include "scene/expression.h"

#include <cmath>
#include <muParser.h>
#include <sstream>
#include <stdexcept>

namespace biotcontact
{

// The parser binds its variables by address, so it lives on the heap together
// with them; copies of an Expression share it (evaluation is not re-entrant,
// which is fine: the solver is single-threaded per rank).
struct Expression::Parser
{
  mu::Parser parser;
  double x = 0, y = 0, z = 0, t = 0;
};

Expression::Expression(double value) : _value(value)
{
  std::ostringstream s;
  s.precision(17);
  s << value;
  _text = s.str();
}

Expression::Expression(const std::string& text) : Expression(text, text) {}

Expression::Expression(const std::string& text, const std::string& shown) : _text(shown)
{
  auto p = std::make_shared<Parser>();
  try
  {
    p->parser.DefineVar("x", &p->x);
    p->parser.DefineVar("y", &p->y);
    p->parser.DefineVar("z", &p->z);
    p->parser.DefineVar("t", &p->t);
    p->parser.DefineConst("pi", M_PI);
    p->parser.SetExpr(text);
    p->parser.Eval(); // syntax errors surface here
    for (const auto& [name, ptr] : p->parser.GetUsedVar())
    {
      if (name == "t")
        _depends_on_time = true;
      else
        _depends_on_space = true;
    }
  }
  catch (const mu::Parser::exception_type& e)
  {
    throw std::invalid_argument("cannot parse expression \"" + shown + "\": " + e.GetMsg());
  }
  if (!_depends_on_time and !_depends_on_space)
    _value = p->parser.Eval();
  else
    _parser = p;
}

Expression::Expression(std::function<double(double, double, double, double)> f, const std::string& text)
    : _function(std::move(f)), _depends_on_time(true), _text(text)
{
}

double Expression::operator()(double x, double y, double z, double t) const
{
  if (_function)
    return _function(x, y, z, t);
  if (!_parser)
    return _value;
  _parser->x = x;
  _parser->y = y;
  _parser->z = z;
  _parser->t = t;
  return _parser->parser.Eval();
}

} // namespace biotcontact
