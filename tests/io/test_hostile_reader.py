"""Issue 24, findings 5 and 8: what `read` accepts, and what reader messages echo.

- Only regular files: a FIFO is refused at once (before, it blocked forever), `/dev/zero` too
  (before, it grew to 24 GB); a size cap (`max_bytes=`, default MAX_INPUT_BYTES) and a line
  length cap, read line by line.
- Messages quote at most a few dozen characters of a token (a 1 MB keyword gave a 1 MB message).
- Lines end at LF, CR, CR LF only; VT, FF, NEL, U+2028/U+2029 separate tokens like a blank, in
  `read` and `read_string` alike.
"""
import os
import threading
import time

import pytest

import spacar
from spacar.io import reader
from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
def test_a_fifo_is_refused_at_once(tmp_path):
    fifo = tmp_path / "input.dat"
    os.mkfifo(fifo)
    start = time.perf_counter()
    with pytest.raises(spacar.InputError, match=r"input\.dat: not a regular file .*FIFO"):
        spacar.read(fifo)
    assert time.perf_counter() - start < 1


@pytest.mark.parametrize("device, kind", [("/dev/zero", "character device"), ("/dev/null", "character device")])
def test_devices_are_refused(device, kind):
    if not os.path.exists(device):
        pytest.skip(f"no {device}")
    with pytest.raises(spacar.InputError, match=f"{device}: not a regular file .*{kind}"):
        spacar.read(device)


def test_a_directory_is_refused(tmp_path):
    with pytest.raises(spacar.InputError, match="not a regular file .*directory"):
        spacar.read(tmp_path)


def test_the_size_cap(tmp_path):
    path = tmp_path / "big.dat"
    path.write_text(EXAMPLE.read_text() + "* padding\n" * 1000)
    size = path.stat().st_size
    assert spacar.read(path, max_bytes=size).nodes
    with pytest.raises(spacar.InputError, match=f"big.dat: the input file has {size} bytes, more than the limit "
                                                f"of {size - 1}"):
        spacar.read(path, max_bytes=size - 1)
    assert reader.MAX_INPUT_BYTES == 256 * 2**20
    for bad in (0, -1, 1.5, True, "10"):
        with pytest.raises(spacar.InputError, match="max_bytes must be a positive integer"):
            spacar.read(path, max_bytes=bad)


def test_a_file_growing_while_read_is_cut_at_the_cap(tmp_path, monkeypatch):
    """The cap holds while reading, not only by the size the file had when opened."""
    path = tmp_path / "grow.dat"
    path.write_text("* a comment\n" * 10)
    real = reader._lines

    def growing(fh, name, limit):
        with open(path, "a") as out:
            out.write("* more\n" * 10000)
        yield from real(fh, name, limit)

    monkeypatch.setattr(reader, "_lines", growing)
    with pytest.raises(spacar.InputError, match="more than the limit of 1000 bytes"):
        spacar.read(path, max_bytes=1000)


def test_the_line_length_cap(tmp_path, monkeypatch):
    monkeypatch.setattr(reader, "MAX_LINE_CHARS", 100)
    path = tmp_path / "long.dat"
    path.write_text("* ok\nX 1 " + "1.0 " * 30 + "\n")
    with pytest.raises(spacar.InputError, match=r"long\.dat, line 2: the line is longer than 100 characters"):
        spacar.read(path)


def test_read_and_read_string_agree_on_the_example(tmp_path):
    text = EXAMPLE.read_text()
    for ending in ("\n", "\r\n", "\r"):
        path = tmp_path / "e.dat"
        path.write_bytes(text.replace("\n", ending).encode())
        assert spacar.read(path).dump(17) == spacar.read_string(text).dump(17)


HUGE = "A" * 10**6


@pytest.mark.parametrize("line", [
    HUGE,                                # unknown keyword
    "1" + HUGE,                          # not a keyword
    "X 1 " + HUGE,                       # not a number
    "FIX " + "9" * 10**6 + " 1",         # an integer out of range
    "X 1 1.0 " + "2" * 10**6,            # a real of a million digits (finite? refused or too many)
    "X 1 " + "1.0 " * 300000,            # too many values
    "TIMESTEP " + "x" * 10**6,
])
def test_messages_quote_a_bounded_part_of_the_input(line):
    with pytest.raises(spacar.InputError) as info:
        spacar.read_string(line + "\nEND\n", "f.dat")
    message = str(info.value)
    assert message.startswith("f.dat, line 1")
    assert len(message) < 300, message[:400]


SEPARATORS = {"VT": "\x0b", "FF": "\x0c", "NEL": "\x85", "LS": "\u2028", "PS": "\u2029", "FS": "\x1c",
              "NBSP": "\xa0", "TAB": "\t"}


@pytest.mark.parametrize("name", SEPARATORS)
def test_unicode_line_separators_are_blanks_everywhere(tmp_path, name):
    sep = SEPARATORS[name]
    text = EXAMPLE.read_text()
    lines = text.split("\n")
    # between the tokens of every line, and as a line of its own
    spaced = "\n".join(line.replace(" ", sep) if not line.startswith("*") else line for line in lines)
    spaced = spaced.replace("\nEND", f"\n{sep}\nEND", 1)
    reference = spacar.read_string(text).dump(17)
    assert spacar.read_string(spaced).dump(17) == reference
    path = tmp_path / "sep.dat"
    path.write_text(spaced, encoding="utf-8")
    assert spacar.read(path).dump(17) == reference
    # it ends no line: a second keyword after it is a value of the first, and the line numbers
    # count LF only, in both readers
    bad = f"* c\nFIX 1 1{sep}FIX 2 1\nEND\n"
    path.write_text(bad, encoding="utf-8")
    for read in (lambda: spacar.read_string(bad, str(path)), lambda: spacar.read(path)):
        with pytest.raises(spacar.InputError, match=r"sep\.dat, line 2, keyword FIX: 'FIX' is not an integer"):
            read()
