"""Scalar values of a scene: a number, or a muparser expression of x, y, z, t.

The C++ solver hands the text to muparser (cpp/scene/expression.cpp); this module
parses the same subset (docs/user-guide.md, "Expressions") and evaluates it on numpy
arrays, with muparser's rules:

    precedence, low to high:  c ? a : b  (right-assoc.)
                              ||   &&   < > <= >= == !=   + -   * / and unary -   ^ (right-assoc.)
    -2^2 = -4, 2^3^2 = 512, comparisons and && || give 1.0 or 0.0, log is ln.

The parser builds a small tree of tuples; nothing is passed to Python's eval.
"""
import math
import re

import numpy as np

VARIABLES = ("x", "y", "z", "t")
CONSTANTS = {"pi": math.pi, "_pi": 3.141592653589, "_e": math.e}  # muparser's _pi is cut short


def _rint(v):
    return np.floor(v + 0.5)


FUNCTIONS = {  # name -> (numpy function, number of arguments; None = one or more)
    "sin": (np.sin, 1), "cos": (np.cos, 1), "tan": (np.tan, 1),
    "asin": (np.arcsin, 1), "acos": (np.arccos, 1), "atan": (np.arctan, 1),
    "sinh": (np.sinh, 1), "cosh": (np.cosh, 1), "tanh": (np.tanh, 1),
    "asinh": (np.arcsinh, 1), "acosh": (np.arccosh, 1), "atanh": (np.arctanh, 1),
    "exp": (np.exp, 1), "log": (np.log, 1), "ln": (np.log, 1), "log2": (np.log2, 1),
    "log10": (np.log10, 1), "sqrt": (np.sqrt, 1), "abs": (np.abs, 1), "sign": (np.sign, 1),
    "rint": (_rint, 1),
    "min": (lambda *a: np.minimum.reduce(np.broadcast_arrays(*a)), None),
    "max": (lambda *a: np.maximum.reduce(np.broadcast_arrays(*a)), None),
    "sum": (lambda *a: np.add.reduce(np.broadcast_arrays(*a)), None),
    "avg": (lambda *a: np.add.reduce(np.broadcast_arrays(*a)) / len(a), None),
}

BINARY = {
    "||": lambda a, b: ((a != 0) | (b != 0)) * 1.0, "&&": lambda a, b: ((a != 0) & (b != 0)) * 1.0,
    "<": lambda a, b: (a < b) * 1.0, ">": lambda a, b: (a > b) * 1.0,
    "<=": lambda a, b: (a <= b) * 1.0, ">=": lambda a, b: (a >= b) * 1.0,
    "==": lambda a, b: (a == b) * 1.0, "!=": lambda a, b: (a != b) * 1.0,
    "+": np.add, "-": np.subtract, "*": np.multiply, "/": np.divide, "^": np.power,
}
# Binary operators by precedence level, lowest first (all left-associative;
# ^ is handled apart, it is right-associative and binds tighter than unary -).
LEVELS = [("||",), ("&&",), ("<", ">", "<=", ">=", "==", "!="), ("+", "-"), ("*", "/")]

TOKEN = re.compile(r"\s*(?:(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"
                   r"|(?P<name>[A-Za-z_]\w*)"
                   r"|(?P<op><=|>=|==|!=|&&|\|\||[-+*/^<>?:(),]))")


class ExpressionError(ValueError):
    pass


def _tokens(text):
    tokens, pos = [], 0
    while pos < len(text):
        if text[pos:].strip() == "":
            break
        m = TOKEN.match(text, pos)
        if not m:
            start = len(text) - len(text[pos:].lstrip())
            raise ExpressionError(f'Unexpected token "{text[start:].split()[0]}" found at position {start}.')
        kind = m.lastgroup
        tokens.append((kind, m.group(kind), m.start(kind)))
        pos = m.end()
    tokens.append(("end", "", len(text)))
    return tokens


class _Parser:
    """Recursive descent over the token list; returns tuples ("num", v),
    ("var", name), ("call", f, args), ("neg", a), ("bin", op, a, b),
    ("if", c, a, b) or ("seq", trees)."""

    def __init__(self, text):
        self.tokens = _tokens(text)
        self.i = 0

    def peek(self):
        return self.tokens[self.i]

    def take(self):
        token = self.tokens[self.i]
        self.i += 1
        return token

    def expect(self, op):
        kind, value, pos = self.take()
        if value != op or kind != "op":
            if kind == "end":
                raise ExpressionError(f'Missing "{op}" at the end of the expression (position {pos}).')
            raise ExpressionError(f'Unexpected token "{value}" found at position {pos} (expected "{op}").')

    def parse(self):
        trees = [self.ternary()]
        while self.peek()[1] == ",":  # "a, b": muparser evaluates both, returns b
            self.take()
            trees.append(self.ternary())
        kind, value, pos = self.peek()
        if kind != "end":
            raise ExpressionError(f'Unexpected token "{value}" found at position {pos}.')
        return trees[0] if len(trees) == 1 else ("seq", trees)

    def ternary(self):
        condition = self.binary(0)
        if self.peek()[1] == "?" and self.peek()[0] == "op":
            self.take()
            a = self.ternary()
            self.expect(":")
            b = self.ternary()
            return ("if", condition, a, b)
        return condition

    def binary(self, level):
        if level == len(LEVELS):
            return self.unary()
        tree = self.binary(level + 1)
        while self.peek()[0] == "op" and self.peek()[1] in LEVELS[level]:
            op = self.take()[1]
            tree = ("bin", op, tree, self.binary(level + 1))
        return tree

    def unary(self):
        if self.peek()[0] == "op" and self.peek()[1] in "+-":
            sign = self.take()[1]
            kind, value, pos = self.peek()
            if kind == "op" and value in "+-":  # muparser refuses "--x"
                raise ExpressionError(f'Unexpected operator "{value}" found at position {pos}')
            operand = self.power()
            return ("neg", operand) if sign == "-" else operand
        return self.power()

    def power(self):
        base = self.primary()
        if self.peek()[0] == "op" and self.peek()[1] == "^":
            self.take()
            return ("bin", "^", base, self.unary())  # right-associative: 2^3^2 = 2^9
        return base

    def primary(self):
        kind, value, pos = self.take()
        if kind == "number":
            return ("num", float(value))
        if kind == "name":
            if value in VARIABLES:
                return ("var", value)
            if value in CONSTANTS:
                return ("num", CONSTANTS[value])
            if value in FUNCTIONS and self.peek()[1] == "(" and self.peek()[2] == pos + len(value):
                self.take()
                args = [self.ternary()]
                while self.peek()[1] == ",":
                    self.take()
                    args.append(self.ternary())
                self.expect(")")
                arity = FUNCTIONS[value][1]
                if arity is not None and len(args) != arity:
                    raise ExpressionError(f'Too many parameters for function "{value}" at position {pos}.')
                return ("call", value, args)
            raise ExpressionError(f'Unexpected token "{value}" found at position {pos}.')
        if kind == "op" and value == "(":
            tree = self.ternary()
            self.expect(")")
            return tree
        if kind == "end":
            raise ExpressionError(f"Unexpected end of expression at position {pos}")
        raise ExpressionError(f'Unexpected operator "{value}" found at position {pos}')


def _evaluate(tree, env):
    kind = tree[0]
    if kind == "num":
        return tree[1]
    if kind == "var":
        return env[tree[1]]
    if kind == "neg":
        return -_evaluate(tree[1], env)
    if kind == "bin":
        return BINARY[tree[1]](_evaluate(tree[2], env), _evaluate(tree[3], env))
    if kind == "call":
        return FUNCTIONS[tree[1]][0](*(_evaluate(a, env) for a in tree[2]))
    if kind == "seq":
        return [_evaluate(a, env) for a in tree[1]][-1]
    if kind == "if":
        return np.where(_evaluate(tree[1], env) != 0, _evaluate(tree[2], env), _evaluate(tree[3], env))
    raise AssertionError(kind)


def _variables(tree):
    if tree[0] == "var":
        return {tree[1]}
    if tree[0] == "num":
        return set()
    children = {"call": tree[-1], "seq": tree[1], "neg": tree[1:], "if": tree[1:], "bin": tree[2:]}[tree[0]]
    return set().union(*(_variables(c) for c in children))


class Expression:
    """A number, or a parsed expression; `text` is what the scene said
    (`shown`: the scene's text when `value` is it with its names
    substituted, section.py's substitute_names)."""

    def __init__(self, value, shown=None):
        self._function = None
        if isinstance(value, str):
            self.text = value if shown is None else shown
            try:
                self._tree = _Parser(value).parse()
            except ExpressionError as e:
                raise ExpressionError(f'cannot parse expression "{self.text}": {e}') from None
            used = _variables(self._tree)
            self.depends_on_time = "t" in used
            self.depends_on_space = bool(used - {"t"})
            if not used:
                self._value, self._tree = float(self(0.0, 0.0, 0.0, 0.0)), None
        else:
            self._value, self._tree = float(value), None
            self.text = f"{self._value:.17g}"
            self.depends_on_time = self.depends_on_space = False

    @classmethod
    def function(cls, f, text):
        """A value computed by the program itself, f(x, y, z, t) on arrays
        (e.g. a closed form imposed on a boundary); `text` describes it."""
        e = cls(0.0)
        e.text, e._function, e.depends_on_time, e.depends_on_space = text, f, True, True
        return e

    @property
    def is_constant(self):
        return self._tree is None and self._function is None

    def __call__(self, x, y, z, t):
        """Value at points (numbers or arrays of one shape) and time t."""
        if self._function is not None:
            return self._function(x, y, z, t)
        if self._tree is None:
            return np.full(np.shape(x), self._value) if np.ndim(x) else self._value
        env = {"x": np.asarray(x, dtype=float), "y": np.asarray(y, dtype=float),
               "z": np.asarray(z, dtype=float), "t": float(t)}
        with np.errstate(all="ignore"):  # muparser returns nan/inf silently
            value = _evaluate(self._tree, env)
        return np.broadcast_to(np.asarray(value, dtype=float), np.shape(x)).copy() if np.ndim(x) \
            else float(value)

    def at(self, points, t):
        """Values at the columns of a 3 x n array of points (dolfinx interpolation)."""
        return self(points[0], points[1], points[2], t)
