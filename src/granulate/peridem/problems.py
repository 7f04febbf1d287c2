"""The one problem collector of a deck's translation, and the readers of deck values that
report to it: numbers, lists of numbers, blocks and Copy_*_Data links."""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from granulate.errors import InputError


class Problems:
    """Collects every problem of a deck, so the user sees them all at once."""

    def __init__(self, source: Path) -> None:
        self.source = source
        self.errors: list[str] = []

    def add(self, message: str) -> None:
        self.errors.append(message)

    def unknown(self, where: str, keys: Any, known: set[str]) -> None:
        for key in keys:
            if key not in known:
                match = difflib.get_close_matches(str(key), sorted(known), n=1)
                hint = f"; did you mean {match[0]!r}?" if match else ""
                self.add(f"{where}: unknown key {key!r}{hint}")

    def raise_if_any(self) -> None:
        if self.errors:
            listed = "\n  - ".join(self.errors)
            raise InputError(
                f"{self.source}: {len(self.errors)} problem(s) in the PeriDEM deck:\n  - {listed}"
            )

    def number(self, value: Any, where: str, *, positive: bool = False) -> float:
        """value as a finite (positive) float; NaN, with a problem, if it is none."""
        try:
            x = float(value)
        except (TypeError, ValueError):
            self.add(f"{where}: expected a number, got {value!r}")
            return math.nan
        if not math.isfinite(x) or (positive and x <= 0):
            self.add(f"{where}: expected a {'positive ' if positive else ''}number, got {value!r}")
        return x

    def numbers(self, value: Any, where: str) -> list[float]:
        if not isinstance(value, list):
            self.add(f"{where}: expected a list of numbers, got {value!r}")
            return []
        return [self.number(v, f"{where}[{k}]") for k, v in enumerate(value)]

    def block(self, data: dict[str, Any], key: str, where: str) -> dict[str, Any]:
        """data[key], a block of keys ({} if absent or, with a problem, not a block)."""
        value = data.get(key, {})
        if value is None:
            return {}
        if not isinstance(value, dict):
            self.add(f"{where}.{key}: expected a block of keys, got {value!r}")
            return {}
        return value

    def copied(
        self,
        block: dict[str, Any],
        key: str,
        copy_key: str,
        target: Callable[[Any], str | None],
        section: str,
        missing: str,
    ) -> dict[str, Any]:
        """The block ``section.key``, following ``copy_key`` links (``target(value)``: the key a
        link names, or None when it names nothing); {} with a problem reported for a missing
        block, a bad link or a cycle."""
        seen: list[str] = []
        while True:
            info = block.get(key)
            if not isinstance(info, dict):
                self.add(f"{section}.{key}: missing ({missing})")
                return {}
            if copy_key not in info:
                return info
            seen.append(key)
            other = target(info[copy_key])
            if other is None or other in seen:
                self.add(f"{section}.{key}.{copy_key}: nothing to copy at {info[copy_key]!r}")
                return {}
            key = other
