#include "scene/section.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace biotcontact
{

Section::Section(const toml::table* table, std::string path, const std::string& file)
    : _table(table), _path(std::move(path)), _file(file)
{
}

void Section::fail(const std::string& key, const std::string& message) const
{
  throw SceneError(_file + ": " + name(key) + ": " + message);
}

namespace
{

/// Whether `given` looks like a misspelling of `key`: one begins the other,
/// or at most 2 letters are changed, added or dropped (Levenshtein).
bool alike(const std::string& key, const std::string& given)
{
  if (given.size() >= 2 and (key.rfind(given, 0) == 0 or given.rfind(key, 0) == 0))
    return true;
  std::vector<std::size_t> row(given.size() + 1);
  for (std::size_t j = 0; j < row.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= key.size(); ++i)
  {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= given.size(); ++j)
    {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (key[i - 1] == given[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row.back() <= 2;
}

} // namespace

std::string Section::missing(const std::string& key, const std::string& what) const
{
  // A key given but not read so far that looks like it: a misspelling.
  std::string given;
  for (const std::string& k : keys())
    if (_used.count(k) == 0 and alike(key, k))
      given += (given.empty() ? "" : ", ") + k;
  return "missing (" + what + " is required" + (given.empty() ? "" : "; the table has " + given + ": misspelt?")
         + ")";
}

std::string Section::name(const std::string& key) const { return _path.empty() ? key : _path + "." + key; }

bool Section::has(const std::string& key) const { return _table and _table->contains(key); }

const toml::node* Section::node(const std::string& key)
{
  _used.insert(key);
  return _table ? _table->get(key) : nullptr;
}

Section Section::table(const std::string& key, bool required)
{
  const toml::node* n = node(key);
  if (!n)
  {
    if (required)
      fail(key, missing(key, "a table"));
    return derived(nullptr, key);
  }
  if (!n->is_table())
    fail(key, "must be a table");
  return derived(n->as_table(), key);
}

Section Section::derived(const toml::table* table, const std::string& key) const
{
  Section child(table, name(key), _file);
  child._axes = _axes;
  child._names = _names;
  return child;
}

Expression Section::parse(const std::string& text) const
{
  return _names ? Expression(substitute_names(text, *_names), text) : Expression(text);
}

namespace
{
bool word_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) or c == '_'; }

/// The end of the identifier that starts at i, or i if none does: a letter
/// or _ not inside a word or a number (the e of 1e9, 1.e9).
std::size_t identifier_end(const std::string& text, std::size_t i)
{
  if (!(std::isalpha(static_cast<unsigned char>(text[i])) or text[i] == '_')
      or (i > 0 and (word_char(text[i - 1]) or text[i - 1] == '.')))
    return i;
  std::size_t end = i + 1;
  while (end < text.size() and word_char(text[end]))
    ++end;
  return end;
}
} // namespace

std::vector<std::string> identifiers(const std::string& text)
{
  std::vector<std::string> found;
  for (std::size_t i = 0; i < text.size();)
  {
    const std::size_t end = identifier_end(text, i);
    if (end > i and std::find(found.begin(), found.end(), text.substr(i, end - i)) == found.end())
      found.push_back(text.substr(i, end - i));
    i = std::max(end, i + 1);
  }
  return found;
}

std::string substitute_names(const std::string& text, const Names& names)
{
  std::string out;
  for (std::size_t i = 0; i < text.size();)
  {
    const std::size_t end = std::max(identifier_end(text, i), i + 1);
    const auto it = names.find(text.substr(i, end - i));
    out += it != names.end() ? "(" + it->second + ")" : text.substr(i, end - i);
    i = end;
  }
  return out;
}

double Section::number(const std::string& key, std::optional<double> fallback)
{
  const toml::node* n = node(key);
  if (!n)
  {
    if (!fallback)
      fail(key, missing(key, "a number"));
    return *fallback;
  }
  return constant(*n, key, "must be a number");
}

std::string Section::array_of(std::size_t size, const std::string& what) const
{
  const std::string text = "must be an array of " + std::to_string(size) + " " + what;
  return size == _axes ? text + ", one per axis (mesh.dimension = " + std::to_string(_axes) + ")" : text;
}

double Section::constant(const toml::node& n, const std::string& key, const std::string& wanted) const
{
  if (n.is_number())
    return n.value<double>().value();
  if (!n.is_string())
    fail(key, wanted);
  Expression e;
  try
  {
    e = parse(n.value<std::string>().value());
  }
  catch (const std::invalid_argument& error)
  {
    fail(key, wanted + " or a constant expression: " + error.what());
  }
  if (e.depends_on_space() or e.depends_on_time())
    fail(key, "\"" + e.text() + "\": one value is wanted here, an expression without x, y, z or t");
  const double value = e(0.0, 0.0, 0.0, 0.0);
  if (!std::isfinite(value))
    fail(key, "\"" + e.text() + "\" gives " + (std::isnan(value) ? "NaN" : "an infinite value"));
  return value;
}

int Section::integer(const std::string& key, int fallback)
{
  const toml::node* n = node(key);
  if (!n)
    return fallback;
  if (!n->is_integer())
    fail(key, "must be an integer");
  return static_cast<int>(n->value<std::int64_t>().value());
}

bool Section::boolean(const std::string& key, bool fallback)
{
  const toml::node* n = node(key);
  if (!n)
    return fallback;
  if (!n->is_boolean())
    fail(key, "must be true or false");
  return n->value<bool>().value();
}

std::string Section::string(const std::string& key, std::optional<std::string> fallback)
{
  const toml::node* n = node(key);
  if (!n)
  {
    if (!fallback)
      fail(key, missing(key, "a string"));
    return *fallback;
  }
  if (!n->is_string())
    fail(key, "must be a string");
  return n->value<std::string>().value();
}

Expression Section::expression(const toml::node* n, const std::string& key) const
{
  if (n->is_number())
    return Expression(n->value<double>().value());
  if (n->is_string())
  {
    try
    {
      return parse(n->value<std::string>().value());
    }
    catch (const std::invalid_argument& e)
    {
      fail(key, e.what());
    }
  }
  fail(key, "must be a number or an expression string");
}

std::optional<Expression> Section::expression(const std::string& key)
{
  const toml::node* n = node(key);
  if (!n)
    return std::nullopt;
  return expression(n, key);
}

std::vector<Expression> Section::expression_vector(const std::string& key, std::size_t size)
{
  const toml::node* n = node(key);
  if (!n or !n->is_array() or n->as_array()->size() != size)
    fail(key, array_of(size, "numbers or expressions"));
  std::vector<Expression> v;
  for (std::size_t i = 0; i < size; ++i)
    v.push_back(expression(n->as_array()->get(i), key));
  return v;
}

std::vector<double> Section::number_vector(const std::string& key, std::size_t size)
{
  const toml::node* n = node(key);
  if (!n or !n->is_array() or (size > 0 and n->as_array()->size() != size))
    fail(key, size > 0 ? array_of(size, "numbers") : "must be an array of numbers");
  std::vector<double> v;
  for (const toml::node& e : *n->as_array())
  {
    v.push_back(constant(e, key, "must be an array of numbers"));
  }
  return v;
}

std::vector<std::string> Section::keys() const
{
  std::vector<std::string> k;
  if (_table)
    for (const auto& [key, value] : *_table)
      k.emplace_back(key.str());
  return k;
}

void Section::finish() const
{
  for (const std::string& key : keys())
    if (_used.count(key) == 0)
      fail(key, "unknown key");
}


void apply_override(toml::table& root, const std::string& assignment, const std::string& file)
{
  const auto eq = assignment.find('=');
  if (eq == std::string::npos or eq == 0)
    throw SceneError(file + ": --set " + assignment + ": expected key.path=value");
  const std::string path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);

  toml::table* table = &root;
  std::string::size_type start = 0, dot;
  while ((dot = path.find('.', start)) != std::string::npos)
  {
    const std::string key = path.substr(start, dot - start);
    if (!table->contains(key))
      table->insert(key, toml::table{});
    toml::node* next = table->get(key);
    if (!next->is_table())
      throw SceneError(file + ": --set " + path + ": " + key + " is not a table");
    table = next->as_table();
    start = dot + 1;
  }
  const std::string key = path.substr(start);
  toml::table parsed;
  try
  {
    parsed = toml::parse("value = " + text);
  }
  catch (const toml::parse_error&)
  {
    parsed.insert("value", text);
  }
  table->insert_or_assign(key, std::move(*parsed.get("value")));
}


} // namespace biotcontact
