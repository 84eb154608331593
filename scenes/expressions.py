"""Expressions of the point x = (x, y) written as text in a declarative scene (docs/scenes.md).

The text is parsed with ``ast`` and evaluated by walking the tree over a fixed vocabulary:
numbers, the names ``x``, ``y``, ``pi``, ``e`` and the scene's named parameters, the arithmetic
operators, comparisons (for ``where``) and the numpy functions in ``FUNCTIONS``. Nothing else
parses, so no text reaches ``eval`` and no attribute, import or call outside the list is
possible. Every number is a float, so ``9**9**9`` overflows to inf instead of hanging.
"""

from __future__ import annotations

import ast
import operator
from collections.abc import Callable

import numpy as np

FUNCTIONS: dict[str, Callable] = {
    "sqrt": np.sqrt, "exp": np.exp, "log": np.log, "abs": np.abs,
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "arcsin": np.arcsin, "arccos": np.arccos,
    "arctan": np.arctan, "arctan2": np.arctan2, "sinh": np.sinh, "cosh": np.cosh,
    "tanh": np.tanh, "minimum": np.minimum, "maximum": np.maximum, "where": np.where,
}
CONSTANTS = {"pi": np.pi, "e": np.e}
VARIABLES = ("x", "y")

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
           ast.Div: operator.truediv, ast.Pow: operator.pow, ast.Mod: operator.mod}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}
_COMPARE = {ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
            ast.GtE: operator.ge}


class ExpressionError(ValueError):
    """A text that is not an expression of the allowed vocabulary."""


MAX_LENGTH = 2000  # characters of one expression: a gap or a load is a formula, not a program
MAX_NESTING = 50  # levels of parentheses
MAX_DEPTH = 200  # nested operations: evaluation recurses once per level


def _depth(tree: ast.AST) -> int:
    """The depth of a syntax tree, found without recursion."""
    deepest, stack = 0, [(tree, 1)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))
    return deepest


def _nesting(text: str) -> int:
    """The deepest nesting of parentheses in ``text``."""
    depth = deepest = 0
    for char in text:
        depth += (char == "(") - (char == ")")
        deepest = max(deepest, depth)
    return deepest


def _shown(text: str) -> str:
    """``text`` as a message shows it: repr, cut to 60 characters."""
    return repr(text) if len(text) <= 60 else repr(text[:57] + "...")


class Expression:
    """A parsed expression; ``Expression(text, names)(points)`` evaluates it at points of shape
    (2, ...) and returns an array of shape (...)."""

    def __init__(self, text: str, parameters: dict[str, float] | None = None,
                 where: str = "expression"):
        self.text, self.where = text, where
        self.parameters = dict(parameters or {})
        if not isinstance(text, str | int | float) or isinstance(text, bool):
            raise ExpressionError(f"{where}={text!r} is not an expression of x and y (a string "
                                  "or a number)")
        text = str(text)
        if len(text) > MAX_LENGTH or _nesting(text) > MAX_NESTING:
            raise ExpressionError(f"{where}={_shown(text)} is too long or too deeply nested "
                                  f"(allowed: at most {MAX_LENGTH} characters and "
                                  f"{MAX_NESTING} levels of parentheses)")
        try:
            self.tree = ast.parse(text, mode="eval").body
            if _depth(self.tree) > MAX_DEPTH:
                raise RecursionError  # evaluating it would recurse this deep
            self._check(self.tree)
        except SyntaxError as error:
            raise ExpressionError(f"{where}={_shown(text)} does not parse: {error.msg}") \
                from None
        except (RecursionError, MemoryError):  # chains of operators nest without parentheses
            raise ExpressionError(f"{where}={_shown(text)} is too deeply nested (allowed: at "
                                  f"most {MAX_DEPTH} nested operations)") from None

    def _refuse(self, node, what: str):
        raise ExpressionError(f"{self.where}={self.text!r}: {what} is not allowed (allowed: "
                              f"numbers, x, y, pi, e, {self._names()}+ - * / ** %, comparisons, "
                              f"and {', '.join(FUNCTIONS)})")

    def _names(self) -> str:
        return "".join(f"{name}, " for name in self.parameters)

    def _check(self, node) -> None:
        if isinstance(node, ast.Constant):
            if not isinstance(node.value, int | float) or isinstance(node.value, bool):
                self._refuse(node, f"the constant {node.value!r}")
        elif isinstance(node, ast.Name):
            if node.id not in (*VARIABLES, *CONSTANTS, *self.parameters):
                self._refuse(node, f"the name {node.id!r}")
        elif isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            self._check(node.left)
            self._check(node.right)
        elif isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
            self._check(node.operand)
        elif isinstance(node, ast.Compare) and all(type(op) in _COMPARE for op in node.ops):
            for child in (node.left, *node.comparators):
                self._check(child)
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
              and node.func.id in FUNCTIONS and not node.keywords):
            for child in node.args:
                self._check(child)
        else:
            self._refuse(node, f"'{ast.unparse(node)}'")

    @property
    def uses_position(self) -> bool:
        """Whether the text names x or y (else it is a constant of the parameters)."""
        return any(isinstance(node, ast.Name) and node.id in VARIABLES
                   for node in ast.walk(self.tree))

    def constant(self) -> float:
        """The value of a text that does not name x or y; ExpressionError if it does."""
        if self.uses_position:
            raise ExpressionError(f"{self.where}={_shown(self.text)} depends on x or y (a "
                                  "constant of numbers and [parameters] is needed)")
        return float(self(np.zeros((2, 1)))[0])

    def __call__(self, points: np.ndarray) -> np.ndarray:
        points = np.asarray(points, dtype=float)
        values = {"x": points[0], "y": points[1], **CONSTANTS,
                  **{k: float(v) for k, v in self.parameters.items()}}
        with np.errstate(all="ignore"):  # a non-finite value is the scene's check's to report
            result = self._value(self.tree, values)
        return np.broadcast_to(np.asarray(result, dtype=float), points.shape[1:]).copy()

    def _value(self, node, values):
        if isinstance(node, ast.Constant):
            return np.float64(node.value)  # overflows to inf, never an OverflowError
        if isinstance(node, ast.Name):
            return values[node.id]
        if isinstance(node, ast.BinOp):
            return _BINARY[type(node.op)](self._value(node.left, values),
                                          self._value(node.right, values))
        if isinstance(node, ast.UnaryOp):
            return _UNARY[type(node.op)](self._value(node.operand, values))
        if isinstance(node, ast.Compare):
            left, result = self._value(node.left, values), True
            for op, right_node in zip(node.ops, node.comparators, strict=True):
                right = self._value(right_node, values)
                result = np.logical_and(result, _COMPARE[type(op)](left, right))
                left = right
            return result
        return FUNCTIONS[node.func.id](*(self._value(a, values) for a in node.args))
