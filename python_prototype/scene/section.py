"""The generic reader of a scene's TOML (cpp/scene/section.h): one table read
key by key, with every refusal one line naming the file and the key;
`--set` overrides applied to the parsed tree. The scene's schema (which
keys, which values) is schema.py's and its readers'; this file knows none of it.

Tables are read in sorted key order, as toml++ (a sorted map) does, so the
first unknown key named is the same on both tracks."""
import math
import tomllib

from .expression import Expression, ExpressionError
from .input import SceneError, name_of


def _identifier_end(text, i):
    """The end of the identifier that starts at i, or i if none does: a
    letter or _ not inside a word or a number (the e of 1e9, 1.e9)."""
    if not (text[i].isalpha() or text[i] == "_") or (i > 0 and (text[i - 1].isalnum() or text[i - 1] in "_.")):
        return i
    end = i + 1
    while end < len(text) and (text[end].isalnum() or text[end] == "_"):
        end += 1
    return end


def identifiers(text):
    """The identifiers of an expression's text (names, variables,
    functions), in order, each once; a letter inside a number (the e of
    1e9) is none."""
    found, i = [], 0
    while i < len(text):
        end = _identifier_end(text, i)
        if end > i and text[i:end] not in found:
            found.append(text[i:end])
        i = max(end, i + 1)
    return found


def substitute_names(text, names):
    """`text` with every name of `names` it uses replaced by "(its text)"."""
    out, i = [], 0
    while i < len(text):
        end = max(_identifier_end(text, i), i + 1)
        word = text[i:end]
        out.append(f"({names[word]})" if word in names else word)
        i = end
    return "".join(out)


class Section:
    """One TOML table of a scene (a dict, or None for an absent optional
    table: then every key is absent; `path` its dotted name, "" for the
    root), read key by key. Every key read is marked, so that `finish` can
    refuse the keys nobody asked for (typos). Every reader raises SceneError
    "FILE: PATH.KEY: what is wrong"."""

    def __init__(self, table, path, file):
        self.table, self.path, self.file, self.used = table, path, file, set()
        self.axes = 0  # set_axes
        self.names = None  # set_names

    def set_axes(self, dimension):
        """Tables read from this one on know the mesh's axes
        (mesh.dimension): an array of that many values, refused, names it
        as the cause."""
        self.axes = dimension

    def set_names(self, names):
        """Expressions read from this table, and the tables read from it, on
        may use `names` (a dict: each name's text, the names it uses
        substituted)."""
        self.names = names

    def derived(self, table, key):
        """A section over `table` (one the scene's reader merged) named as
        this one's `key`, knowing the axes and names this one knows."""
        child = Section(table, self.name(key), self.file)
        child.axes, child.names = self.axes, self.names
        return child

    def parse(self, text):
        """The expression of a scene text, its names substituted; raises
        ExpressionError as Expression does."""
        return Expression(substitute_names(text, self.names), text) if self.names else Expression(text)

    @staticmethod
    def is_number(value):
        """Whether a TOML value is a number (an integer or a float, not a
        boolean, which Python counts as an integer)."""
        return isinstance(value, (int, float)) and not isinstance(value, bool)

    @staticmethod
    def is_integer(value):
        return isinstance(value, int) and not isinstance(value, bool)

    def fail(self, key, message):
        raise SceneError(f"{self.file}: {self.name(key)}: {message}")

    def missing(self, key, what):
        """"missing (WHAT is required)" for `key`, naming the keys the table
        has, not read so far, that look like it (misspelt)."""
        given = ", ".join(k for k in self.keys() if k not in self.used and _alike(key, k))
        return f"missing ({what} is required" + (f"; the table has {given}: misspelt?" if given else "") + ")"

    def name(self, key):
        """The dotted name of `key` in this table."""
        return f"{self.path}.{key}" if self.path else key

    def has(self, key):
        return self.table is not None and key in self.table

    def node(self, key):
        """The value of `key` (None when absent), marked as read."""
        self.used.add(key)
        return None if self.table is None else self.table.get(key)

    def section(self, key, required):
        """The table `key` (C++'s Section::table; `table` is this one's dict here)."""
        n = self.node(key)
        if n is None and required:
            self.fail(key, self.missing(key, "a table"))
        if n is not None and not isinstance(n, dict):
            self.fail(key, "must be a table")
        return self.derived(n, key)

    def _array_of(self, size, what):
        """"must be an array of `size` WHAT", naming mesh.dimension when
        there is one value per axis."""
        text = f"must be an array of {size} {what}"
        return text + f", one per axis (mesh.dimension = {self.axes})" if size == self.axes else text

    def number(self, key, fallback=None):
        n = self.node(key)
        if n is None:
            if fallback is None:
                self.fail(key, self.missing(key, "a number"))
            return fallback
        return self._constant(n, key, "must be a number")

    def _constant(self, n, key, wanted):
        """A number, or an expression string without x, y, z and t (C++'s
        Section::constant); `wanted` says what else `key` must be."""
        if self.is_number(n):
            return float(n)
        if not isinstance(n, str):
            self.fail(key, wanted)
        try:
            e = self.parse(n)
        except ExpressionError as error:
            self.fail(key, f"{wanted} or a constant expression: {error}")
        if e.depends_on_space or e.depends_on_time:
            self.fail(key, f'"{e.text}": one value is wanted here, an expression without x, y, z or t')
        value = e(0.0, 0.0, 0.0, 0.0)
        if not math.isfinite(value):
            self.fail(key, f'"{e.text}" gives ' + ("NaN" if math.isnan(value) else "an infinite value"))
        return float(value)

    def integer(self, key, fallback):
        n = self.node(key)
        if n is None:
            return fallback
        if not self.is_integer(n):
            self.fail(key, "must be an integer")
        return int(n)

    def boolean(self, key, fallback):
        n = self.node(key)
        if n is None:
            return fallback
        if not isinstance(n, bool):
            self.fail(key, "must be true or false")
        return n

    def string(self, key, fallback=None):
        n = self.node(key)
        if n is None:
            if fallback is None:
                self.fail(key, self.missing(key, "a string"))
            return fallback
        if not isinstance(n, str):
            self.fail(key, "must be a string")
        return n

    def choice(self, key, kind, fallback=None):
        """A value of the choice `kind` (an enum of input.py) by its name; the
        fallback when absent (without one, `key` is required); refused naming
        every choice otherwise. `kind` is C++'s template argument."""
        given = self.string(key, None if fallback is None else name_of(fallback))
        for value in kind:
            if given == name_of(value):
                return value
        names = [f'"{name_of(value)}"' for value in kind]
        self.fail(key, f"must be {', '.join(names[:-1])} or {names[-1]}, got \"{given}\"")

    def to_expression(self, n, key):
        """A number or an expression string (C++'s expression(node, key))."""
        if self.is_number(n):
            return Expression(float(n))
        if isinstance(n, str):
            try:
                return self.parse(n)
            except ExpressionError as e:
                self.fail(key, str(e))
        self.fail(key, "must be a number or an expression string")

    def expression(self, key):
        n = self.node(key)
        return None if n is None else self.to_expression(n, key)

    def expression_vector(self, key, size):
        n = self.node(key)
        if not isinstance(n, list) or len(n) != size:
            self.fail(key, self._array_of(size, "numbers or expressions"))
        return [self.to_expression(e, key) for e in n]

    def number_vector(self, key, size):
        """An array of `size` numbers or constant expressions (any length
        when size = 0)."""
        n = self.node(key)
        if not isinstance(n, list) or (size > 0 and len(n) != size):
            self.fail(key, self._array_of(size, "numbers") if size > 0 else "must be an array of numbers")
        return [self._constant(e, key, "must be an array of numbers") for e in n]

    def keys(self):
        return sorted(self.table) if self.table is not None else []

    def finish(self):
        """Refuses keys that were never read."""
        for key in self.keys():
            if key not in self.used:
                self.fail(key, "unknown key")


def _alike(key, given):
    """Whether `given` looks like a misspelling of `key`: one begins the
    other, or at most 2 letters are changed, added or dropped (Levenshtein)."""
    if len(given) >= 2 and (key.startswith(given) or given.startswith(key)):
        return True
    row = list(range(len(given) + 1))
    for i in range(1, len(key) + 1):
        diagonal, row[0] = row[0], i
        for j in range(1, len(given) + 1):
            above = row[j]
            row[j] = min(row[j] + 1, row[j - 1] + 1, diagonal + (key[i - 1] != given[j - 1]))
            diagonal = above
    return row[-1] <= 2


def apply_override(root, assignment, file):
    """Applies one "a.b.c=value" override to the parsed tree `root`; the
    value is read as TOML, and taken as a string when it is not valid TOML
    (so `--set coupling.L=kdr` works)."""
    path, eq, text = assignment.partition("=")
    if not eq or not path:
        raise SceneError(f"{file}: --set {assignment}: expected key.path=value")
    *tables, key = path.split(".")
    table = root
    for t in tables:
        table = table.setdefault(t, {})
        if not isinstance(table, dict):
            raise SceneError(f"{file}: --set {path}: {t} is not a table")
    try:
        table[key] = tomllib.loads("value = " + text)["value"]
    except tomllib.TOMLDecodeError:
        table[key] = text
