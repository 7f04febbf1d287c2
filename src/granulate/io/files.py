"""Input files: one check that a path is a readable file, and one way to read a text file,
each with a message that says what the path is instead (missing, a folder, a link that leads
nowhere, not UTF-8 text)."""

from __future__ import annotations

from pathlib import Path

from granulate.errors import InputError


def existing_file(path: str | Path, what: str) -> Path:
    """`path` when it is a readable file; else InputError naming `what` and what the path is
    instead (missing, a folder, a symbolic link that leads nowhere or in a loop)."""
    file = Path(path)
    try:
        if file.is_file():
            return file
        if file.is_dir():
            raise InputError(f"{what} {file} is a folder, not a file")
        if file.is_symlink():
            raise InputError(f"{what} {file} is a symbolic link that leads nowhere (or in a loop)")
    except OSError as error:  # a loop of links, a name too long
        raise InputError(f"{what} {file} cannot be opened: {error.strerror or error}") from None
    raise InputError(f"{what} {file} does not exist")


def read_text(path: str | Path, what: str) -> str:
    """The text of an existing UTF-8 file, or InputError naming `what` and the problem."""
    file = existing_file(path, what)
    try:
        return file.read_text()
    except UnicodeDecodeError:
        raise InputError(
            f"{what} {file} is not UTF-8 text (a binary file, or UTF-16? save it as UTF-8)"
        ) from None
    except OSError as error:
        raise InputError(f"cannot read {what} {file}: {error.strerror or error}") from None
