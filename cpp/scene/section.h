// The generic reader of a scene's TOML: one table read key by key, with
// every refusal one line naming the file and the key; `--set` overrides
// applied to the parsed tree. The scene's schema (which keys, which
// values) is schema.h's and its readers'; this file knows none of it.
#pragma once

#include "scene/expression.h"
#include "scene/input.h"

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <toml++/toml.h>
#include <utility>
#include <vector>

namespace biotcontact
{

/// @brief The scene's named expressions ([expressions], docs/user-guide.md,
/// "Expressions"): each name with its text, the names that text uses
/// already substituted.
using Names = std::map<std::string, std::string>;

/// The identifiers of an expression's text (names, variables, functions),
/// in order, each once; a letter inside a number (the e of 1e9) is none.
std::vector<std::string> identifiers(const std::string& text);

/// `text` with every name of `names` it uses replaced by "(its text)".
std::string substitute_names(const std::string& text, const Names& names);

/// @brief One TOML table of a scene, read key by key. Every key read is
/// marked, so that `finish` can refuse the keys nobody asked for (typos).
/// Every reader throws SceneError "FILE: PATH.KEY: what is wrong".
class Section
{
public:
  /// `table` may be null (an absent optional table): then every key is
  /// absent. `path` is the table's dotted name ("" for the root).
  Section(const toml::table* table, std::string path, const std::string& file);

  [[noreturn]] void fail(const std::string& key, const std::string& message) const;
  /// "missing (WHAT is required)" for `key`, naming the keys the table
  /// has, not read so far, that look like it (misspelt).
  std::string missing(const std::string& key, const std::string& what) const;
  /// The dotted name of `key` in this table.
  std::string name(const std::string& key) const;
  bool has(const std::string& key) const;
  /// The node of `key` (null when absent), marked as read.
  const toml::node* node(const std::string& key);

  /// Tables read from this one on know the mesh's axes (mesh.dimension):
  /// an array of that many values, refused, names it as the cause.
  void set_axes(std::size_t dimension) { _axes = dimension; }
  /// Expressions read from this table, and the tables read from it, on
  /// may use `names`.
  void set_names(std::shared_ptr<const Names> names) { _names = std::move(names); }
  /// A section over `table` (one the scene's reader merged) named as this
  /// one's `key`, knowing the axes and names this one knows.
  Section derived(const toml::table* table, const std::string& key) const;
  Section table(const std::string& key, bool required);
  /// A number, or an expression string without x, y, z and t (one value,
  /// as "2*pi" or "1e9"; docs/user-guide.md, "Expressions").
  double number(const std::string& key, std::optional<double> fallback = std::nullopt);
  int integer(const std::string& key, int fallback);
  bool boolean(const std::string& key, bool fallback);
  std::string string(const std::string& key, std::optional<std::string> fallback = std::nullopt);
  /// A choice by its name (Choices, input.h); the fallback when absent
  /// (without one, `key` is required); refused naming every choice otherwise.
  template <class E>
  E choice(const std::string& key, std::optional<E> fallback = std::nullopt)
  {
    const std::string given
        = string(key, fallback ? std::optional<std::string>(name_of(*fallback)) : std::nullopt);
    for (const auto& [value, text] : Choices<E>::names)
      if (given == text)
        return value;
    std::string list;
    for (std::size_t i = 0; i < Choices<E>::names.size(); ++i)
      list += (i == 0 ? "" : i + 1 == Choices<E>::names.size() ? " or " : ", ") + std::string("\"")
              + Choices<E>::names[i].second + "\"";
    fail(key, "must be " + list + ", got \"" + given + "\"");
  }
  /// A number or an expression string.
  Expression expression(const toml::node* n, const std::string& key) const;
  std::optional<Expression> expression(const std::string& key);
  std::vector<Expression> expression_vector(const std::string& key, std::size_t size);
  /// An array of `size` numbers or constant expressions (any length when
  /// size = 0).
  std::vector<double> number_vector(const std::string& key, std::size_t size);
  std::vector<std::string> keys() const;
  /// Refuses keys that were never read.
  void finish() const;

private:
  /// "must be an array of `size` WHAT", naming mesh.dimension when there
  /// is one value per axis.
  std::string array_of(std::size_t size, const std::string& what) const;
  /// The value of a number or a constant expression (number's rules);
  /// `wanted` says what else `key` must be.
  double constant(const toml::node& n, const std::string& key, const std::string& wanted) const;
  /// The expression of a scene text, its names substituted; throws
  /// std::invalid_argument as Expression does.
  Expression parse(const std::string& text) const;

  const toml::table* _table;
  std::string _path;
  const std::string& _file;
  std::set<std::string> _used;
  std::size_t _axes = 0;
  std::shared_ptr<const Names> _names;
};

/// Applies one "a.b.c=value" override; the value is read as TOML, and taken
/// as a string when it is not valid TOML (so `--set coupling.L=kdr` works).
void apply_override(toml::table& root, const std::string& assignment, const std::string& file);

} // namespace biotcontact
