"""Reader of the SPACAR95 input format (manual §5; formulation.md §9.1).

Lexical rules: one keyword per line, parameters separated by white space; ``*`` in column 1
starts a comment line; keywords are case-insensitive and only their first 8 characters count;
numbers are Fortran-style (``1.``, ``.5``, ``1e-3``, ``1.0D-3``). Input comes in blocks, each
ended by ``END``; ``EOF`` or the physical end of the file ends the input.

The reader only tokenises and checks each line against the keyword table; applying a line is a
call of the builder method of the same name on :class:`spacar.Model`. Every error names the
file, the line number and the keyword.
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field

from .._util import show
from ..errors import InputError, SpacarError
from ..keywords import INT, LOOKUP, Keyword
from ..model import Model, check_args

_INT_RE = re.compile(r"^[+-]?\d+$", re.ASCII)
_REAL_RE = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eEdD][+-]?\d+)?$", re.ASCII)
# Only these end a line: str.splitlines() would also split at form feeds and other separators
# and so report wrong line numbers.
_NEWLINE_RE = re.compile(r"\r\n|\r|\n")


@dataclass(frozen=True)
class Command:
    """One keyword line: where it came from, the keyword and its parsed numbers."""

    file: str
    line: int
    keyword: str
    args: tuple

    def where(self) -> str:
        return f"{self.file}, line {self.line}, keyword {self.keyword}"


@dataclass
class Block:
    """The commands of one input block; ``ended`` is False for trailing lines without END."""

    commands: list = field(default_factory=list)
    ended: bool = True


def _error(file, line, keyword, reason):
    where = f"{file}, line {line}" + (f", keyword {keyword}" if keyword else "")
    return InputError(f"{where}: {reason}")


def _number(token: str, kind: str):
    if kind == INT:
        if len(token) > 40 and _INT_RE.match(token):
            # Far out of range (and Python refuses to convert very long digit strings).
            raise ValueError(f"{token[:20]}... ({len(token)} digits) is out of range")
        if _INT_RE.match(token):
            return int(token)
        if _REAL_RE.match(token):
            value = float(token.replace("d", "e").replace("D", "e"))
            if value.is_integer():
                return int(value)
        raise ValueError(f"{show(token)} is not an integer")
    if _REAL_RE.match(token) or _INT_RE.match(token):
        return float(token.replace("d", "e").replace("D", "e"))
    if token.lower().lstrip("+-") in ("nan", "inf", "infinity"):
        raise ValueError(f"{show(token)} is not a number (NaN and infinity are not accepted)")
    raise ValueError(f"{show(token)} is not a number")


def _parse_line(kw: Keyword, tokens):
    """Numbers of a line by the keyword's signature (types and counts)."""
    values = []
    pos = 0
    for p, n in zip(kw.params, kw.counts(len(tokens))):
        for tok in tokens[pos:pos + n]:
            values.append(_number(tok, p.kind))
        pos += n
    for tok in tokens[pos:]:
        # Surplus values: a malformed number is reported as such; otherwise they are kept, so
        # that the count check reports "too many values".
        values.append(_number(tok, "real"))
    return values


def _check_text(text, file):
    if not isinstance(text, str):
        raise InputError(f"the input must be a text (str), got {type(text).__name__}"
                         + (": decode bytes first, e.g. data.decode('utf-8')" if isinstance(text, bytes) else ""))
    if not isinstance(file, str):
        raise InputError(f"the file name must be a str, got {type(file).__name__}")


def parse(text: str, file: str = "<string>") -> list[Block]:
    """Split an input text into blocks of commands; checks syntax, counts and types."""
    _check_text(text, file)
    blocks = [Block()]
    ended_by_eof = False
    for lineno, raw in enumerate(_NEWLINE_RE.split(text), start=1):
        if raw.startswith("*"):
            continue
        tokens = raw.split()
        if not tokens:
            continue
        if ended_by_eof:
            raise _error(file, lineno, tokens[0].upper()[:8], "text after EOF")
        head = tokens[0]
        if not head[0].isalpha():
            raise _error(file, lineno, head.upper(),
                         f"a line must start with a keyword (a letter first), not {show(head)}")
        kw = LOOKUP.get(head.upper()[:8])
        if kw is None:
            raise _error(file, lineno, head.upper(), f"unknown keyword {show(head)}")
        try:
            values = _parse_line(kw, tokens[1:])
            check_args(kw, values)
        except (ValueError, InputError) as err:
            raise _error(file, lineno, kw.name, str(err).removeprefix(f"{kw.name}: ")) from None
        if kw.name == "EOF":
            ended_by_eof = True
            continue
        if kw.name == "END":
            blocks[-1].ended = True
            blocks.append(Block())
            continue
        blocks[-1].ended = False
        blocks[-1].commands.append(Command(file, lineno, kw.name, tuple(values)))
    if not blocks[-1].commands:
        blocks.pop()
    return blocks


def apply_block(model: Model, block: Block) -> None:
    """Apply the commands of a block to the model, naming the line of any failing command."""
    for cmd in block.commands:
        try:
            model.apply(cmd.keyword, *cmd.args, origin=cmd.where())
        except SpacarError as err:
            raise type(err)(f"{cmd.where()}: {err}") from None


def read_string(text: str, file: str = "<string>") -> Model:
    """Read an input text: returns the model with its first block applied and all blocks in
    ``model.blocks``."""
    blocks = parse(text, file)
    model = Model()
    model.source = file
    for b in blocks:
        if not b.ended:
            first, last = b.commands[0], b.commands[-1]
            model.warnings.append(
                f"{file}, lines {first.line}..{last.line}: input without a closing END is ignored")
    model.blocks = [b for b in blocks if b.ended]
    if model.blocks:
        apply_block(model, model.blocks[0])
    return model


def read(path) -> Model:
    """Read a SPACAR95 input file (see :func:`read_string`)."""
    try:
        path = os.fspath(path)
    except TypeError:
        raise InputError(f"read: a file name or path, got {show(path)}") from None
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            text = fh.read()
    except (OSError, ValueError) as err:  # ValueError: a NUL in the name
        raise InputError(f"{path}: cannot read the input file ({getattr(err, 'strerror', None) or err})") from None
    return read_string(text, path)
