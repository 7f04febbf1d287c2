"""Hashes of what the PeriDEM translator makes of every deck and of broken copies of them.

A refactor of granulate.peridem must not change a translation, a note or an error message.
This translates each deck of tests/data/peridem (and of ../shared/peridem/decks when it is
there), with and without --peridem-compat, and each deck again with every key deleted in turn
and every value replaced in turn by a string, -1, 0, a list, a block, null, 2.5 and true; it
hashes the case file `granulate convert` would write with its notes, or the error message.

    python benchmarks/translation_hashes.py --save before.json     # on the old install
    python benchmarks/translation_hashes.py --compare before.json  # new: exit 1 if any differ

About 12,000 translations: some 20 minutes on one core.
"""

from __future__ import annotations

import argparse
import copy
import hashlib
import json
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml

from granulate import peridem
from granulate.errors import InputError

ROOT = Path(__file__).resolve().parent.parent
DELETE = object()
BAD_VALUES: list[Any] = [DELETE, "x", -1, 0, [1, 2], {"a": 1}, None, 2.5, True]


def decks() -> list[Path]:
    """The decks, each folder's contents once (the shared decks and the tests' are copies)."""
    found, seen = [], set()
    for root in (ROOT / "tests/data/peridem", ROOT.parent / "shared/peridem/decks"):
        for deck in sorted(root.glob("*/input*.yaml")):
            files = sorted(f for f in deck.parent.iterdir() if f.is_file())
            key = hashlib.sha256(b"".join(f.read_bytes() for f in files)).hexdigest()
            if key not in seen:
                seen.add(key)
                found.append(deck)
    return found


def translation(path: Path, compat: bool, folder: Path) -> str:
    """The hash of the converted case and notes, or of the error (paths made neutral)."""
    try:
        result = peridem.translate(path, compat=compat)
        text = peridem.to_yaml(result, compat) + "\n".join(result.notes)
    except InputError as error:
        text = "error: " + str(error)
    text = text.replace(str(path), "DECK").replace(str(folder), "FOLDER")
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def key_paths(node: Any, prefix: tuple = ()) -> Iterator[tuple]:
    """Every key of the deck's blocks, and the first three items of every list."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield (*prefix, key)
            yield from key_paths(value, (*prefix, key))
    elif isinstance(node, list):
        for index in range(min(3, len(node))):
            yield (*prefix, index)


def broken(data: dict, path: tuple, value: Any) -> dict:
    copied = copy.deepcopy(data)
    node = copied
    for key in path[:-1]:
        node = node[key]
    if value is DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return copied


def all_hashes() -> dict[str, str]:
    hashes: dict[str, str] = {}
    for deck in decks():
        name = f"{deck.parent.parent.name}/{deck.parent.name}"
        for compat in (False, True):
            hashes[f"{name}/compat={compat}"] = translation(deck, compat, deck.parent)
        data = yaml.safe_load(deck.read_text())
        with tempfile.TemporaryDirectory() as work:
            folder = Path(work)
            for file in deck.parent.iterdir():
                if file.is_file():
                    shutil.copy(file, folder / file.name)
            target = folder / deck.name
            for path in key_paths(data):
                for value in BAD_VALUES:
                    target.write_text(yaml.safe_dump(broken(data, path, value)))
                    shown = "deleted" if value is DELETE else repr(value)
                    key = f"{name}/{'.'.join(map(str, path))}={shown}"
                    hashes[key] = translation(target, False, folder)
        print(f"{name}: {len(hashes)} translations so far", flush=True)
    return hashes


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--save", type=Path, help="write the hashes to this JSON file")
    parser.add_argument("--compare", type=Path, help="compare with hashes saved earlier")
    args = parser.parse_args(argv)
    hashes = all_hashes()
    if args.save:
        args.save.write_text(json.dumps(hashes, indent=0, sort_keys=True))
    changed = []
    if args.compare:
        before = json.loads(args.compare.read_text())
        changed = sorted(k for k in set(before) | set(hashes) if before.get(k) != hashes.get(k))
        for key in changed:
            print(f"changed: {key}")
    verdict = "DIFFERENCES" if changed else "identical" if args.compare else "hashed"
    print(f"{len(hashes)} translations: {verdict}")
    return 1 if changed else 0


if __name__ == "__main__":
    raise SystemExit(main())
