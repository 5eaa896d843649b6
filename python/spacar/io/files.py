"""Opening output files safely (docs/robustness.md, "Files").

spacar's output files (MATASC files, saved results) are overwritten as SPACAR does with its own
files, but never through a symbolic link: a link planted where an output file goes would make
the run overwrite whatever it points to. Only regular files are written (a FIFO or a device in
the place of an output file is refused rather than blocking or writing into it). Every failure
is a :class:`spacar.InputError` naming the file.
"""
from __future__ import annotations

import os
import stat

from ..errors import InputError

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)


def reason(err: OSError) -> str:
    """The short reason of an OS error, e.g. "No space left on device"."""
    return err.strerror or str(err)


def open_output(path: str, *, append: bool = False) -> int:
    """A file descriptor for writing ``path``: emptied (or appended to with ``append``), created
    if missing; refused if ``path`` is a symbolic link or not a regular file."""
    flags = os.O_WRONLY | os.O_CREAT | _NOFOLLOW | _NONBLOCK | getattr(os, "O_CLOEXEC", 0)
    flags |= os.O_APPEND if append else 0
    try:
        # Said plainly first (O_NOFOLLOW would report ELOOP, a FIFO without a reader ENXIO); the
        # flags and fstat below hold even if the path is replaced in between.
        try:
            mode = os.lstat(path).st_mode
        except FileNotFoundError:
            mode = None
        if mode is not None and stat.S_ISLNK(mode):
            raise InputError(f"{path}: refusing to write through a symbolic link (remove it or choose "
                             "another output name)")
        if mode is not None and not stat.S_ISREG(mode):
            raise InputError(f"{path}: not a regular file; spacar writes its output to regular files only")
        fd = os.open(path, flags, 0o666)
    except OSError as err:
        raise InputError(f"{path}: cannot open the output file ({reason(err)})") from None
    except ValueError as err:  # a NUL in the name
        raise InputError(f"{path!r}: cannot open the output file ({err})") from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise InputError(f"{path}: not a regular file; spacar writes its output to regular files only")
        if not append:
            os.ftruncate(fd, 0)  # after the checks: a FIFO or device is never truncated
        if _NONBLOCK:
            os.set_blocking(fd, True)
    except OSError as err:
        os.close(fd)
        raise InputError(f"{path}: cannot open the output file ({reason(err)})") from None
    except InputError:
        os.close(fd)
        raise
    return fd


def write_all(fd: int, data: bytes) -> None:
    """Write all of ``data`` (os.write may write less than asked)."""
    view = memoryview(data)
    while view:
        n = os.write(fd, view)
        view = view[n:]
