"""Unit tests of the prototype's scene expressions
(python_prototype/scene/expression.py), the twins of
tests/unit/test_expression.cpp: numbers and constant texts are constants,
the x/y/z/t dependence flags, values at points and times (and on arrays of
points), muparser's syntax (docs/user-guide.md, "Expressions"), bad text
refused with a muparser-like message, and the program's own functions."""
import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import support  # noqa: E402,F401  (the repository on sys.path)
from python_prototype.scene.expression import Expression, ExpressionError  # noqa: E402


class ExpressionTest(unittest.TestCase):
    def test_numbers_and_constant_texts_are_constants(self):
        number = Expression(2.5)
        self.assertTrue(number.is_constant)
        self.assertFalse(number.depends_on_time)
        self.assertFalse(number.depends_on_space)
        self.assertEqual(number(1, 2, 3, 4), 2.5)
        self.assertEqual(number.text, "2.5")
        text = Expression("2*3 + 1")
        self.assertTrue(text.is_constant)
        self.assertEqual(text(0, 0, 0, 0), 7.0)
        self.assertEqual(text(5, -1, 2, 9), 7.0)
        self.assertEqual(text.text, "2*3 + 1", "the scene's text is kept")
        self.assertEqual(Expression("pi")(0, 0, 0, 0), math.pi)
        self.assertTrue(Expression("sin(pi/2)").is_constant)

    def test_dependence_flags(self):
        for text, space, time in (("x", True, False), ("y + 1", True, False), ("2*z", True, False),
                                  ("t", False, True), ("x*t", True, True), ("sin(t) + y^2", True, True),
                                  ("pi * 2", False, False)):
            e = Expression(text)
            self.assertEqual(e.depends_on_space, space, text)
            self.assertEqual(e.depends_on_time, time, text)
            self.assertEqual(e.is_constant, not space and not time, text)

    def test_evaluates_at_points_and_times(self):
        e = Expression("x + 2*y - z*t")
        self.assertEqual(e(1, 2, 3, 4), -7.0)
        self.assertEqual(e(0, 0, 0, 0), 0.0)
        self.assertEqual(e.at(np.array([[-1.0], [0.5], [2.0]]), 0.25)[0], -0.5)
        # Each evaluation sets every variable: no value is left from the last.
        self.assertEqual(e(1, 2, 3, 4), -7.0)
        # The prototype evaluates arrays of points at once.
        np.testing.assert_array_equal(e(np.array([1.0, 0.0]), np.array([2.0, 0.0]), np.array([3.0, 0.0]), 4),
                                      [-7.0, 0.0])

    def test_muparser_syntax(self):
        for text, value in (("-2^2", -4), ("2^3^2", 512), ("2 * 3 + 4 / 2", 8), ("1e-3 * 1.5e3", 1.5),
                            ("1 < 2 ? 3 : 4", 3), ("1 > 2 ? 3 : 4", 4), ("(1 < 2) && (2 < 1)", 0),
                            ("(1 < 2) || (2 < 1)", 1), ("2 == 2", 1), ("2 != 2", 0),
                            ("log(_e)", 1), ("log10(1000)", 3), ("sqrt(abs(-16))", 4),
                            ("min(3, 1, 2)", 1), ("max(3, 1, 2)", 3), ("sum(1, 2, 3)", 6),
                            ("avg(1, 2, 3)", 2), ("rint(2.6)", 3), ("exp(0) + cos(0)", 2)):
            self.assertAlmostEqual(Expression(text)(0, 0, 0, 0), value, delta=4 * math.ulp(value),
                                   msg=text)
        step = Expression("x > 0.5 ? 1 : 0")
        self.assertEqual(step(1, 0, 0, 0), 1.0)
        self.assertEqual(step(0, 0, 0, 0), 0.0)

    def test_bad_text_is_refused_with_a_message(self):
        for text in ("1 +", "foo(x)", "x y", "(x + 1", "sin(x", "2 * * 3", "", "w"):
            with self.assertRaises(ExpressionError, msg=f'accepted "{text}"') as caught:
                Expression(text)
            message, head = str(caught.exception), f'cannot parse expression "{text}": '
            self.assertTrue(message.startswith(head), message)
            self.assertGreater(len(message), len(head), f"muparser's reason follows: {message}")
            self.assertNotIn("\n", message, "one line")
        # An unknown name is named.
        with self.assertRaises(ExpressionError) as caught:
            Expression("2 * foo")
        self.assertIn('"foo"', str(caught.exception))

    def test_program_functions(self):
        # A value the program computes (a closed form on a boundary): neither a
        # constant nor a parsed text, taken as time-dependent.
        e = Expression.function(lambda x, y, z, t: x * t + 1, "closed form")
        self.assertFalse(e.is_constant)
        self.assertTrue(e.depends_on_time)
        self.assertEqual(e(2, 0, 0, 3), 7.0)
        self.assertEqual(e.text, "closed form")


if __name__ == "__main__":
    unittest.main()
