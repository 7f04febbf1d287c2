"""Mistakes in input, told the same way wherever they come from: pydantic validation errors of
case-file data or of API objects (one line per problem, the key path, what was expected and
found, a suggestion for a misspelt key or kind), and the arguments of API calls (unknown,
missing or of the wrong kind)."""

from __future__ import annotations

import difflib
import functools
import inspect
import numbers
from collections.abc import Sequence
from typing import Any, TypeVar

from pydantic import BaseModel, BeforeValidator, ValidationError

from granulate.errors import InputError


def _location(loc: tuple[Any, ...]) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or "(top level)"


def _fields_for(parent: Any, models: Sequence[type[BaseModel]]) -> list[str]:
    """Field names of the spec models that best match a mapping (for typo suggestions)."""
    if not isinstance(parent, dict):
        return []
    kind = parent.get("type", parent.get("distribution"))
    scores: list[tuple[int, list[str]]] = []
    for model in models:
        names = list(model.model_fields)
        score = sum(1 for key in parent if key in names)
        tag = model.model_fields.get("type") or model.model_fields.get("distribution")
        if kind is not None and tag is not None and kind in getattr(tag.annotation, "__args__", ()):
            score += 10
        scores.append((score, names))
    best = max(score for score, _ in scores)
    return sorted({name for score, names in scores if score == best for name in names})


#: Names other codes (PeriDEM) use for our shapes.
_SYNONYMS = {
    "circle": "disc",
    "hexagon": "regular_polygon",
    "triangle": "regular_polygon",
    "square": "regular_polygon",
    "cube": "box",
    "cuboid": "box",
    "rect": "rectangle",
    "stl": "surface",
}


def _clean(loc: tuple[Any, ...], data: Any) -> tuple[tuple[Any, ...], Any]:
    """The key path as the user wrote it (without pydantic's union tags), and the mapping that
    holds its last key."""
    path: list[Any] = []
    current, parent = data, None
    for part in loc:
        if isinstance(current, list) and isinstance(part, int) and part < len(current):
            path.append(part)
            parent, current = current, current[part]
        elif isinstance(current, dict) and part in current:
            path.append(part)
            parent, current = current, current[part]
        elif isinstance(current, dict) and part in (
            current.get("type"),
            current.get("distribution"),
        ):
            continue  # the tag of a discriminated union
        elif isinstance(part, str) and ("[" in part or part in ("str", "int", "float", "list")):
            continue  # a union member's name
        else:
            path.append(part)
            parent, current = current, None
    return tuple(path), parent


def describe(error: ValidationError, data: Any, models: Sequence[type[BaseModel]]) -> str:
    """One line per problem: key path, what was expected, what was found; a suggestion for
    misspelt keys (from the fields of `models` that best match the mapping) and kinds."""
    problems = [(p, *_clean(p["loc"], data)) for p in error.errors()]
    lines: list[str] = []
    for problem, loc, parent in problems:
        kind = problem["type"]
        # A shape given inline that fails also fails as a shape name: keep the real reason.
        if kind == "string_type" and isinstance(problem.get("input"), dict):
            if any(other[1][: len(loc)] == loc and other[0] is not problem for other in problems):
                continue
        where = _location(loc)
        if kind == "extra_forbidden":
            bad = str(loc[-1])
            suggestion = difflib.get_close_matches(bad, _fields_for(parent, models), n=1)
            hint = f"; did you mean {suggestion[0]!r}?" if suggestion else ""
            message = f"{where}: unknown key {bad!r}{hint}"
        elif kind == "missing":
            message = f"{where}: required key is missing"
        elif kind in ("union_tag_invalid", "union_tag_not_found"):
            ctx = problem.get("ctx", {})
            expected = str(ctx.get("expected_tags", ""))
            found = str(ctx.get("tag", problem.get("input")))
            options = [t.strip().strip("'") for t in expected.split(",")]
            message = f"{where}: unknown kind {found!r}; expected one of {expected}"
            match = difflib.get_close_matches(found, options, n=1)
            if _SYNONYMS.get(found) in options:
                message += f"; a {found} is {_SYNONYMS[found]!r} here"
            elif match:
                message += f"; did you mean {match[0]!r}?"
        else:
            found = problem.get("input")
            shown = "a mapping" if isinstance(found, dict) else repr(found)
            if len(shown) > 60:
                shown = shown[:57] + "..."
            text = problem["msg"].removeprefix("Value error, ")
            if isinstance(found, dict) and problem["type"] == "value_error":
                # A check of a whole mapping (which names, which combination): no value to show.
                message = text if not loc else f"{where}: {text}"
            else:
                message = f"{where}: {text} (found {shown})"
        if message not in lines:
            lines.append(message)
    if len(lines) == 1:
        return lines[0]
    return f"{len(lines)} problems:\n  " + "\n  ".join(lines)


def unknown_name(name: str, options: Sequence[str]) -> str:
    """A hint for a misspelt name: did you mean the closest of `options`, or the list."""
    match = difflib.get_close_matches(name, list(options), n=1)
    if match:
        return f"; did you mean {match[0]!r}?"
    return f"; expected one of {', '.join(map(repr, options)) or 'none'}"


def call_problem(where: str, signature: inspect.Signature, args: tuple, kwargs: dict) -> str:
    """What is wrong with a call of `where` that `signature` cannot bind: an unknown keyword
    (with a suggestion), a missing argument or too many positional ones."""
    names = [n for n in signature.parameters if n != "self"]
    for key in kwargs:
        if key not in signature.parameters:
            return f"{where}: unknown argument {key!r}{unknown_name(key, names)}"
    try:
        signature.bind(*args, **kwargs)
    except TypeError as error:
        text = str(error)
        if "missing" in text:
            missing = text.split("'")[1] if "'" in text else text
            return f"{where}: the argument {missing!r} is missing"
        return f"{where}: {text}; the arguments are {', '.join(names)}"
    return f"{where}: arguments not understood"


C = TypeVar("C", bound=type)


def checked_arguments(cls: C) -> C:
    """Make a class's constructor raise InputError (naming the argument, with a suggestion)
    for unknown, missing or surplus arguments, and for a string, a boolean or None given for a
    parameter annotated as a plain number."""
    init = cls.__init__
    signature = inspect.signature(init)
    numeric = _numeric_parameters(signature)

    @functools.wraps(init)
    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        try:
            bound = signature.bind(self, *args, **kwargs)
        except TypeError:
            problem = call_problem(cls.__name__, signature, (self, *args), kwargs)
            raise InputError(problem) from None
        for name, (integer, optional) in numeric.items():
            value = bound.arguments.get(name)
            if name in bound.arguments and not (optional and value is None):
                check_number(f"{cls.__name__}: {name}", value, integer=integer)
        init(self, *args, **kwargs)

    cls.__init__ = __init__  # type: ignore[misc]
    return cls


def check_number(what: str, value: Any, integer: bool = False) -> None:
    """InputError unless `value` is a real number (an integer with `integer`); booleans and
    strings are refused ("2.5e-4" as a string is a common slip)."""
    kind = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, kind):
        expected = "an integer" if integer else "a number"
        hint = " (without quotes)" if isinstance(value, str) else ""
        raise InputError(f"{what} must be {expected}{hint}, got {value!r}")


def _numeric_parameters(signature: inspect.Signature) -> dict[str, tuple[bool, bool]]:
    """Parameters annotated as a plain float or int: (is it an int, may it be None)."""
    out = {}
    for name, parameter in signature.parameters.items():
        annotation = str(parameter.annotation).replace(" ", "")
        if annotation in ("float", "int", "float|None", "int|None"):
            out[name] = (annotation.startswith("int"), annotation.endswith("|None"))
    return out


def api_error(
    where: str, error: ValidationError, data: dict[str, Any], model: type[BaseModel]
) -> InputError:
    """The InputError of an API object's validation error, told as a case file's is."""
    text = describe(error, data, [model]).replace(": unknown key ", ": unknown argument ")
    return InputError(f"{where}: {text}")


def _refuse_bool(value: Any) -> Any:
    if isinstance(value, bool):
        raise ValueError("a number is expected, not a yes/no (true/false) value")
    return value


#: Marks a number field of a pydantic model: YAML's yes/no/true/false (Python's bools) are
#: refused instead of read as 1 and 0.
NOT_BOOL = BeforeValidator(_refuse_bool)
