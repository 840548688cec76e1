// A scalar value given in a scene: a number, or an expression of the
// coordinates and time (x, y, z, t) in muparser syntax. The Python prototype
// evaluates the same subset (docs/user-guide.md, "Expressions").
#pragma once

#include <functional>
#include <memory>
#include <string>

namespace biotcontact
{

class Expression
{
public:
  /// A constant.
  explicit Expression(double value = 0.0);
  /// Parses `text`; throws std::invalid_argument with muparser's message.
  explicit Expression(const std::string& text);
  /// Parses `text`, the scene's `shown` with its names substituted
  /// (section.h, substitute_names); text() and messages show `shown`.
  Expression(const std::string& text, const std::string& shown);
  /// A value computed by the program itself (e.g. a closed form imposed on
  /// a boundary); `text` describes it.
  Expression(std::function<double(double, double, double, double)> f, const std::string& text);

  double operator()(double x, double y, double z, double t) const;
  double operator()(const double* x, double t) const { return (*this)(x[0], x[1], x[2], t); }

  bool is_constant() const { return !_parser and !_function; }
  bool depends_on_time() const { return _depends_on_time; }
  bool depends_on_space() const { return _depends_on_space; }
  /// The scene text, or the number printed.
  const std::string& text() const { return _text; }

private:
  struct Parser;
  std::shared_ptr<Parser> _parser;
  std::function<double(double, double, double, double)> _function;
  double _value = 0.0;
  bool _depends_on_time = false;
  bool _depends_on_space = false;
  std::string _text;
};

} // namespace biotcontact
