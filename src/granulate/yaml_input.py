"""Reading YAML that users write: PyYAML's safe loader, with the mistakes it lets through
refused with one InputError each (a key given twice, whose last value silently won; aliases
that expand a small file into millions of values; nesting deep enough to overflow the stack),
and syntax errors told with their line and column."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from granulate.errors import InputError

#: Values a document may expand to through its aliases (each use counted in full).
MOST_VALUES = 1_000_000
#: Nesting a document may reach (lists in mappings in lists ...).
DEEPEST = 100


class _StrictLoader(yaml.SafeLoader):
    """The safe loader, refusing a mapping that repeats a key."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: dict[Any, yaml.Node] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            if key in seen:
                first = seen[key].start_mark.line + 1
                raise InputError(
                    f"line {key_node.start_mark.line + 1}: the key {key!r} is given twice in one "
                    f"mapping (first at line {first}); keep one"
                )
            seen[key] = key_node
        return super().construct_mapping(node, deep=deep)


def _expanded_size(root: yaml.Node) -> int:
    """How many values the document holds with every alias expanded, counted without expanding
    (an alias is the same node object, so each node's size is computed once), and InputError
    past DEEPEST levels of nesting."""
    sizes: dict[int, int] = {}
    stack: list[tuple[yaml.Node, int, bool]] = [(root, 1, False)]
    while stack:
        node, depth, children_done = stack.pop()
        if id(node) in sizes:
            continue
        if depth > DEEPEST:
            raise InputError(f"the YAML is nested more than {DEEPEST} levels deep")
        children = _children(node)
        if children_done or not children:
            sizes[id(node)] = 1 + sum(sizes[id(child)] for child in children)
            continue
        stack.append((node, depth, True))
        stack.extend((child, depth + 1, False) for child in children if id(child) not in sizes)
    return sizes[id(root)]


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    return []


def load_yaml(text: str, source: Path) -> Any:
    """The data of a YAML document, or InputError naming the file and the problem."""
    try:
        loader = _StrictLoader(text)
        try:
            root = loader.get_single_node()
            if root is None:
                return None
            if _expanded_size(root) > MOST_VALUES:
                raise InputError(
                    f"{source}: the YAML expands to more than {MOST_VALUES:,} values through its "
                    "aliases (&name / *name); write the values out"
                )
            return loader.construct_document(root)
        finally:
            loader.dispose()
    except InputError as error:
        message = str(error)
        raise InputError(
            message if message.startswith(str(source)) else f"{source}: {message}"
        ) from None
    except RecursionError:
        raise InputError(f"{source}: the YAML is nested too deeply to read") from None
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(error, "problem", None) or str(error).splitlines()[0]
        raise InputError(f"{source}: not valid YAML{where}: {problem}") from None
