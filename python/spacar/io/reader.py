"""Reader of the SPACAR95 input format (manual §5; formulation.md §9.1).

Lexical rules: one keyword per line, parameters separated by white space; ``*`` in column 1
starts a comment line; keywords are case-insensitive and only their first 8 characters count;
numbers are Fortran-style (``1.``, ``.5``, ``1e-3``, ``1.0D-3``). Input comes in blocks, each
ended by ``END``; ``EOF`` or the physical end of the file ends the input.

Lines end at LF, CR or CR LF only (as editors and Fortran count them, so line numbers match);
every other white-space character, including tab, VT, FF, NEL (U+0085) and U+2028/U+2029 (which
Python's ``str.splitlines`` would take as line ends), separates tokens like a blank, in
:func:`read` and :func:`read_string` alike.

:func:`read` takes regular files only (a FIFO or a device is refused at once), at most
``max_bytes`` (default :data:`MAX_INPUT_BYTES`) and lines of at most :data:`MAX_LINE_CHARS`
characters, read line by line. Messages quote at most a few dozen characters of any token.

The reader only tokenises and checks each line against the keyword table; applying a line is a
call of the builder method of the same name on :class:`spacar.Model`. Every error names the
file, the line number and the keyword.
"""
from __future__ import annotations

import io
import os
import re
import stat
import warnings
from dataclasses import dataclass, field

from .._util import show
from ..errors import InputError, SpacarError
from ..keywords import INT, LOOKUP, Keyword, did_you_mean
from ..model import Model, check_args

_INT_RE = re.compile(r"^[+-]?\d+$", re.ASCII)
_REAL_RE = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eEdD][+-]?\d+)?$", re.ASCII)
# Only these end a line: str.splitlines() would also split at form feeds and other separators
# and so report wrong line numbers.
_NEWLINE_RE = re.compile(r"\r\n|\r|\n")
# read(): the largest input file (bytes) and line (characters) accepted. A line holds at most
# 10**6 values (keywords.py); 16 MiB fits that many values of 16 characters.
MAX_INPUT_BYTES = 256 * 2**20
MAX_LINE_CHARS = 16 * 2**20


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


def _keyword_echo(token: str) -> str:
    """A token in the keyword position of a message, cut to a few dozen characters."""
    return token.upper() if len(token) <= 24 else token[:21].upper() + "..."


def parse(text: str, file: str = "<string>") -> list[Block]:
    """Split an input text into blocks of commands; checks syntax, counts and types."""
    _check_text(text, file)
    return _parse_lines(_NEWLINE_RE.split(text), file)


def _parse_lines(lines, file: str) -> list[Block]:
    """The blocks of an iterable of lines (without their line ends)."""
    blocks = [Block()]
    ended_by_eof = False
    for lineno, raw in enumerate(lines, start=1):
        if raw.startswith("*"):
            continue
        tokens = raw.split()
        if not tokens:
            continue
        if ended_by_eof:
            raise _error(file, lineno, tokens[0].upper()[:8], "text after EOF")
        head = tokens[0]
        if not head[0].isalpha():
            raise _error(file, lineno, _keyword_echo(head),
                         f"a line must start with a keyword (a letter first), not {show(head)}")
        kw = LOOKUP.get(head.upper()[:8])
        if kw is None:
            raise _error(file, lineno, _keyword_echo(head), f"unknown keyword {show(head)}{did_you_mean(head)}")
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
    return _model(parse(text, file), file)


def _model(blocks: list, file: str) -> Model:
    model = Model()
    model.source = file
    for b in blocks:
        if not b.ended:
            first, last = b.commands[0], b.commands[-1]
            message = f"{file}, lines {first.line}..{last.line}: input without a closing END is ignored"
            model.warnings.append(message)
            # Said at once too: a text with no END at all gives a model without elements (issue 38).
            warnings.warn(message, stacklevel=3)
    model.blocks = [b for b in blocks if b.ended]
    if model.blocks:
        apply_block(model, model.blocks[0])
    return model


def read(path, *, max_bytes: int | None = None) -> Model:
    """Read a SPACAR95 input file (see :func:`read_string`): a regular file of at most
    ``max_bytes`` bytes (default :data:`MAX_INPUT_BYTES`, 256 MiB), read line by line."""
    try:
        path = os.fspath(path)
    except TypeError:
        raise InputError(f"read: a file name or path, got {show(path)}") from None
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    limit = MAX_INPUT_BYTES if max_bytes is None else max_bytes
    if isinstance(limit, bool) or not isinstance(limit, int) or limit < 1:
        raise InputError(f"read: max_bytes must be a positive integer or None, got {show(max_bytes)}")
    try:
        # O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused below.
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except (OSError, ValueError) as err:  # ValueError: a NUL in the name
        raise InputError(f"{path}: cannot read the input file ({getattr(err, 'strerror', None) or err})") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise InputError(f"{path}: not a regular file (an input file must be a regular file, not a "
                             f"{_file_kind(info.st_mode)})")
        if info.st_size > limit:
            raise InputError(f"{path}: the input file has {info.st_size} bytes, more than the limit of {limit} "
                             "(read(path, max_bytes=...))")
        os.set_blocking(fd, True)
        fh = io.open(fd, encoding="utf-8", errors="replace", newline="", closefd=False)
    except BaseException:
        os.close(fd)
        raise
    try:
        with fh:
            blocks = _parse_lines(_lines(fh, path, limit), path)
    except OSError as err:
        raise InputError(f"{path}: cannot read the input file ({err.strerror or err})") from None
    finally:
        os.close(fd)
    return _model(blocks, path)


def _file_kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "directory"), (stat.S_ISFIFO, "FIFO"), (stat.S_ISCHR, "character device"),
                       (stat.S_ISBLK, "block device"), (stat.S_ISSOCK, "socket")):
        if test(mode):
            return name
    return "special file"


def _lines(fh, path: str, limit: int):
    """The lines of an open text file without their ends; at most MAX_LINE_CHARS characters a
    line and ``limit`` characters in all (a file may grow while it is read)."""
    total = 0
    lineno = 0
    while True:
        line = fh.readline(MAX_LINE_CHARS + 2)
        if not line:
            return
        lineno += 1
        total += len(line)
        if total > limit:
            raise InputError(f"{path}: the input file has more than the limit of {limit} bytes "
                             "(read(path, max_bytes=...))")
        if line.endswith("\r\n"):
            line = line[:-2]
        elif line.endswith(("\n", "\r")):
            line = line[:-1]
        if len(line) > MAX_LINE_CHARS:
            raise _error(path, lineno, None, f"the line is longer than {MAX_LINE_CHARS} characters")
        yield line
