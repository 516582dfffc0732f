"""A restricted evaluator for xacro's ``${...}`` and ``$(eval ...)`` expressions, on Python's ``ast``.

xacro evaluates expressions with Python's ``eval``; its guards (no ``__`` names, no builtins) are
easy to walk around (``python.vars(python.type)[...]`` reaches ``os.system``). Linting a stranger's
pull request must not run its code, so safe mode evaluates the expression tree itself and knows
every value it may touch:

- numbers, strings, ``True``/``False``/``None``, list/tuple/dict literals, indexing and slicing;
- arithmetic, comparisons, ``and``/``or``/``not``, ``a if c else b``;
- names: properties and arguments (through the ``lookup`` the caller gives), the functions and
  constants xacro documents (:data:`MATH`, :data:`BUILTINS`) and namespaces the caller builds
  (:class:`Namespace`: ``math.pi``, ``xacro.load_yaml``);
- a dotted name only on a namespace or a mapping (a property namespace of ``xacro:include ns=``,
  a YAML dictionary: ``props.arm.mass`` is a key lookup), never Python's ``getattr``.

Everything else (attributes of other values, names starting with ``__``, the ``python``
namespace, comprehensions, lambdas, f-strings, ``%``-formatting, starred arguments) raises
:class:`Refused`. Work is bounded: integers over :data:`MAX_INT_BITS` bits, strings and lists over
:data:`MAX_ITEMS` items are refused before they are built (``9**9**9``, ``'a' * 10**9``).
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable, Mapping
from typing import Any

MAX_INT_BITS = 4096
"""Largest integer an expression may build (about 1,230 decimal digits); no robot needs more than 64."""
MAX_ITEMS = 1_000_000
"""Longest string, list or range an expression may build."""
MAX_EXPRESSION_CHARS = 20_000
"""Longest expression text evaluated (the longest in the real files seen is under 200 characters)."""

SAFE_MODE_HINT = "pass --xacro trusted only for files you trust"


class Refused(Exception):
    """The expression uses something safe mode does not evaluate; the text says what."""

    def __init__(self, what: str) -> None:
        super().__init__(f"safe xacro refuses {what} ({SAFE_MODE_HINT})")


class Function:
    """A function an expression may call: a name for messages and a plain Python callable whose
    arguments and result are checked by the evaluator."""

    __slots__ = ("name", "call")

    def __init__(self, name: str, call: Callable[..., Any]) -> None:
        self.name = name
        self.call = call

    def __repr__(self) -> str:
        return f"<function {self.name}>"


class Namespace:
    """A read-only group of names reachable with a dot (``math.pi``, ``xacro.arg``)."""

    __slots__ = ("name", "members")

    def __init__(self, name: str, members: Mapping[str, Any]) -> None:
        self.name = name
        self.members = dict(members)

    def __repr__(self) -> str:
        return f"<namespace {self.name}>"


def _int_result(value: int) -> int:
    if value.bit_length() > MAX_INT_BITS:
        raise Refused(f"an integer of {value.bit_length()} bits (the limit is {MAX_INT_BITS})")
    return value


def _check(value: Any) -> Any:
    """``value`` if it is a kind safe mode works with and within the size limits."""
    if isinstance(value, bool) or value is None or isinstance(value, float):
        return value
    if isinstance(value, int):
        return _int_result(value)
    if isinstance(value, (str, range)):
        if len(value) > MAX_ITEMS:
            raise Refused(f"a {type(value).__name__} of {len(value)} items (the limit is {MAX_ITEMS})")
        return value
    if isinstance(value, (list, tuple, dict)):
        if _weight(value) > MAX_ITEMS:  # nested repetitions share items: count what str() would write
            raise Refused(f"a {type(value).__name__} of more than {MAX_ITEMS} items, nested ones counted")
        return value
    if isinstance(value, (Function, Namespace)):
        return value
    if _is_table(value):
        return value
    raise Refused(f"a value of type {type(value).__name__}")


def _weight(value: Any) -> int:
    """Items and characters in ``value`` counting every nested occurrence (stops past :data:`MAX_ITEMS`)."""
    total, stack = 0, [value]
    while stack and total <= MAX_ITEMS:
        item = stack.pop()
        if isinstance(item, dict):
            total += len(item)
            stack.extend(item.keys())
            stack.extend(item.values())
        elif isinstance(item, (list, tuple)):
            total += len(item)
            stack.extend(item)
        elif isinstance(item, str):
            total += len(item)
    return total


def _is_table(value: Any) -> bool:
    """xacro's property tables (a ``xacro:include ns=`` namespace) without importing xacro."""
    return type(value).__name__ in ("NameSpace", "Table") and type(value).__module__ == "xacro"


def _length(value: Any) -> int | None:
    return len(value) if isinstance(value, (str, list, tuple)) else None


def _add(left: Any, right: Any) -> Any:
    sizes = (_length(left), _length(right))
    if None not in sizes and sizes[0] + sizes[1] > MAX_ITEMS:
        raise Refused(f"a result of {sizes[0] + sizes[1]} items (the limit is {MAX_ITEMS})")
    return left + right


def _multiply(left: Any, right: Any) -> Any:
    for sequence, count in ((left, right), (right, left)):
        size = _length(sequence)
        if size is not None and isinstance(count, int) and size * max(count, 0) > MAX_ITEMS:
            raise Refused(f"a repetition of {size * count} items (the limit is {MAX_ITEMS})")
    if isinstance(left, int) and isinstance(right, int) and left.bit_length() + right.bit_length() > MAX_INT_BITS + 1:
        raise Refused(f"an integer product over {MAX_INT_BITS} bits")
    return left * right


def _power(base: Any, exponent: Any) -> Any:
    growing = isinstance(base, int) and isinstance(exponent, int) and exponent > 0 and abs(base) > 1
    if growing and (exponent > MAX_INT_BITS or (abs(base).bit_length() - 1) * exponent > MAX_INT_BITS):
        raise Refused(f"a power over {MAX_INT_BITS} bits")
    return base**exponent


def _shift(value: Any, amount: Any) -> Any:
    if isinstance(value, int) and isinstance(amount, int) and value and amount > MAX_INT_BITS:
        raise Refused(f"a shift over {MAX_INT_BITS} bits")
    return value << amount


def _modulo(left: Any, right: Any) -> Any:
    if isinstance(left, str):
        raise Refused("%-formatting of strings")
    return left % right


_BINARY: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: _add, ast.Sub: operator.sub, ast.Mult: _multiply, ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv, ast.Mod: _modulo, ast.Pow: _power, ast.LShift: _shift,
    ast.RShift: operator.rshift, ast.BitAnd: operator.and_, ast.BitOr: operator.or_, ast.BitXor: operator.xor,
}
_UNARY: dict[type, Callable[[Any], Any]] = {
    ast.UAdd: operator.pos, ast.USub: operator.neg, ast.Not: operator.not_, ast.Invert: operator.invert,
}
_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le, ast.Gt: operator.gt,
    ast.GtE: operator.ge, ast.Is: operator.is_, ast.IsNot: operator.is_not,
    ast.In: lambda a, b: a in b, ast.NotIn: lambda a, b: a not in b,
}


def evaluate(text: str, lookup: Callable[[str], Any], member: Callable[[Any, str], Any] | None = None) -> Any:
    """The value of expression ``text``; names are answered by ``lookup`` (which raises NameError
    for an unknown one), ``table.name`` and ``table['name']`` on one of xacro's property tables by
    ``member(table, name)`` (default: the table's own lookup). Raises :class:`Refused` for what safe
    mode does not evaluate, and the exceptions Python would (SyntaxError, ZeroDivisionError, ...) otherwise."""
    if len(text) > MAX_EXPRESSION_CHARS:
        raise Refused(f"an expression of {len(text)} characters (the limit is {MAX_EXPRESSION_CHARS})")
    tree = ast.parse(text.strip(), "<expression>", mode="eval")
    try:
        return _Evaluator(lookup, member or (lambda table, name: table[name])).visit(tree.body)
    except RecursionError:
        raise Refused("an expression nested this deeply") from None


class _Evaluator:
    """Walks one expression tree; each node kind has a method, anything else is refused."""

    def __init__(self, lookup: Callable[[str], Any], member: Callable[[Any, str], Any]) -> None:
        self.lookup = lookup
        self.member = member

    def visit(self, node: ast.AST) -> Any:
        method = getattr(self, f"visit_{type(node).__name__}", None)
        if method is None:
            raise Refused(_describe(node))
        return method(node)

    def visit_Constant(self, node: ast.Constant) -> Any:
        if isinstance(node.value, (bytes, complex)) or node.value is Ellipsis:
            raise Refused(f"a {type(node.value).__name__} literal")
        return _check(node.value)

    def visit_Name(self, node: ast.Name) -> Any:
        name = node.id
        if name.startswith("__"):
            raise Refused(f"the name {name!r}")
        if name == "python":
            raise Refused("the python namespace")
        return _check(self.lookup(name))

    def visit_Attribute(self, node: ast.Attribute) -> Any:
        owner = self.visit(node.value)
        name = node.attr
        if name.startswith("_"):
            raise Refused(f"the attribute {name!r}")
        if isinstance(owner, Namespace):
            if name not in owner.members:
                raise Refused(f"{owner.name}.{name}")
            return owner.members[name]
        if _is_table(owner):  # xacro's NameSpace forwards the dot to its table
            try:
                return _check(self.member(owner, name))
            except KeyError:
                raise NameError(f"name '{name}' is not defined") from None
        if isinstance(owner, dict) and type(owner) is not dict:  # xacro's YAML dictionary: keys by dot
            if name not in owner:
                raise AttributeError(f"The yaml dictionary has no key '{name}'")
            return _check(owner[name])
        raise Refused(f"attribute access (.{name} on a {type(owner).__name__})")

    def visit_Subscript(self, node: ast.Subscript) -> Any:
        owner = self.visit(node.value)
        key = self.visit(node.slice)
        if _is_table(owner):
            return _check(self.member(owner, key))
        if not isinstance(owner, (str, list, tuple, dict, range)):
            raise Refused(f"indexing a {type(owner).__name__}")
        return _check(owner[key])

    def visit_Slice(self, node: ast.Slice) -> slice:
        parts = [None if part is None else self.visit(part) for part in (node.lower, node.upper, node.step)]
        return slice(*parts)

    def visit_List(self, node: ast.List) -> list:
        return _check([self.visit(item) for item in self._items(node.elts)])

    def visit_Tuple(self, node: ast.Tuple) -> tuple:
        return _check(tuple(self.visit(item) for item in self._items(node.elts)))

    def visit_Dict(self, node: ast.Dict) -> dict:
        if any(key is None for key in node.keys):
            raise Refused("** in a dict literal")
        return _check({self.visit(key): self.visit(value) for key, value in zip(node.keys, node.values)})

    @staticmethod
    def _items(items: list[ast.expr]) -> list[ast.expr]:
        if any(isinstance(item, ast.Starred) for item in items):
            raise Refused("* unpacking")
        return items

    def visit_BinOp(self, node: ast.BinOp) -> Any:
        function = _BINARY.get(type(node.op))
        if function is None:
            raise Refused(f"the operator {type(node.op).__name__}")
        return _check(function(self.visit(node.left), self.visit(node.right)))

    def visit_UnaryOp(self, node: ast.UnaryOp) -> Any:
        return _check(_UNARY[type(node.op)](self.visit(node.operand)))

    def visit_BoolOp(self, node: ast.BoolOp) -> Any:
        is_and = isinstance(node.op, ast.And)
        value = None
        for item in node.values:
            value = self.visit(item)
            if bool(value) != is_and:
                return value
        return value

    def visit_Compare(self, node: ast.Compare) -> bool:
        left = self.visit(node.left)
        for op, item in zip(node.ops, node.comparators):
            right = self.visit(item)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    def visit_IfExp(self, node: ast.IfExp) -> Any:
        return self.visit(node.body) if self.visit(node.test) else self.visit(node.orelse)

    def visit_Call(self, node: ast.Call) -> Any:
        function = self.visit(node.func)
        if not isinstance(function, Function):
            raise Refused(f"calling a {type(function).__name__}")
        args = [self.visit(item) for item in self._items(node.args)]
        if any(keyword.arg is None for keyword in node.keywords):
            raise Refused("** arguments")
        kwargs = {keyword.arg: self.visit(keyword.value) for keyword in node.keywords}
        return _check(function.call(*args, **kwargs))


def _describe(node: ast.AST) -> str:
    names = {"ListComp": "a comprehension", "SetComp": "a comprehension", "DictComp": "a comprehension",
             "GeneratorExp": "a generator expression", "Lambda": "a lambda", "JoinedStr": "an f-string",
             "NamedExpr": "an assignment expression", "Set": "a set literal", "Await": "await",
             "Yield": "yield", "YieldFrom": "yield", "Starred": "* unpacking"}
    return names.get(type(node).__name__, f"the expression element {type(node).__name__}")


# ---------------------------------------------------------------------------------------------------
# The functions and constants expressions may use (what xacro exposes, minus what reaches objects).


def _bounded_range(*args: int) -> range:
    if not all(isinstance(arg, int) for arg in args):
        raise TypeError("range() arguments must be integers")
    result = range(*args)
    return _check(result)


def _bounded_factorial(value: int) -> int:
    if isinstance(value, int) and value > 1000:
        raise Refused(f"factorial({value})")
    return math.factorial(value)


def _round(value: Any, ndigits: Any = None) -> Any:
    if isinstance(ndigits, int) and abs(ndigits) > 1000:  # round(1, -10**9) builds 10**(10**9)
        raise Refused(f"round() to {ndigits} digits")
    return round(value) if ndigits is None else round(value, ndigits)


def _sum(items: Any, start: Any = 0) -> Any:
    if not isinstance(start, (int, float)):  # sum(lists, []) is quadratic
        raise Refused("sum() of anything but numbers")
    return sum(items, start)


def _callable_argument(function: Any) -> Callable[..., Any]:
    if not isinstance(function, Function):
        raise Refused(f"passing a {type(function).__name__} as a function")
    return lambda *items: _check(function.call(*items))


def _map(function: Any, *iterables: Any) -> list:
    """``map`` as a list (xacro's gives a lazy map object; expressions only ever list it)."""
    return _check(list(map(_callable_argument(function), *iterables)))


def _sorted(items: Any, reverse: bool = False) -> list:
    return sorted(items, reverse=bool(reverse))


_UNBOUNDED_MATH = {"prod", "comb", "perm", "lcm", "factorial"}
MATH: dict[str, Any] = {
    name: (Function(name, value) if callable(value) else value)
    for name, value in vars(math).items() if not name.startswith("_") and name not in _UNBOUNDED_MATH
}
"""Python's ``math`` module as xacro exposes it (``pi``, ``sin``, ``radians``, ``sqrt``, ...), minus the
functions whose result grows without bound; ``factorial`` is kept for arguments up to 1,000."""
MATH["factorial"] = Function("factorial", _bounded_factorial)

BUILTINS: dict[str, Any] = {
    "True": True, "False": False,
    **{name: Function(name, function) for name, function in (
        ("list", list), ("dict", dict), ("len", len), ("str", str), ("float", float), ("int", int), ("bool", bool),
        ("min", min), ("max", max), ("round", _round), ("abs", abs), ("sum", _sum), ("tuple", tuple),
        ("sorted", _sorted), ("range", _bounded_range), ("map", _map), ("zip", lambda *items: list(zip(*items))),
        ("any", any), ("all", all))},
}
"""The built-in functions an expression may call (xacro's ``list, dict, map, len, str, float, int,
bool, min, max, round, sorted, range`` and a few harmless others); each result is size-checked."""
