"""Opening input and output files safely (docs/robustness.md, "Files").

spacar's output files (MATASC files, saved results) are overwritten as SPACAR does with its own
files, but never through a symbolic link: a link planted where an output file goes would make
the run overwrite whatever it points to. Only regular files are written (a FIFO or a device in
the place of an output file is refused rather than blocking or writing into it). Every failure
is a :class:`spacar.InputError` naming the file. Files written by other libraries (NumPy's
.npz, matplotlib's animations) are written to a temporary file next to the output and renamed
onto it (:func:`write_replacing`). Input files other than the SPACAR input (URDF) are read with
the reader's rules (:func:`read_input`): regular files only, at most a given size.
"""
from __future__ import annotations

import os
import shutil
import stat
import tempfile

from ..errors import InputError

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)


def reason(err: OSError) -> str:
    """The short reason of an OS error, e.g. "No space left on device"."""
    return err.strerror or str(err)


def check_output_path(path: str) -> None:
    """Refuse an output path that is a symbolic link or a non-regular file (before any work is
    done for it; open_output checks again as it opens)."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    except ValueError as err:  # a NUL in the name
        raise InputError(f"{path!r}: cannot open the output file ({err})") from None
    if stat.S_ISLNK(mode):
        raise InputError(f"{path}: refusing to write through a symbolic link (remove it or choose another output name)")
    if not stat.S_ISREG(mode):
        raise InputError(f"{path}: not a regular file; spacar writes its output to regular files only")


def open_output(path: str, *, append: bool = False) -> int:
    """A file descriptor for writing ``path``: emptied (or appended to with ``append``), created
    if missing; refused if ``path`` is a symbolic link or not a regular file."""
    flags = os.O_WRONLY | os.O_CREAT | _NOFOLLOW | _NONBLOCK | getattr(os, "O_CLOEXEC", 0)
    flags |= os.O_APPEND if append else 0
    try:
        # Said plainly first (O_NOFOLLOW would report ELOOP, a FIFO without a reader ENXIO); the
        # flags and fstat below hold even if the path is replaced in between.
        check_output_path(path)
        fd = os.open(path, flags, 0o666)
    except OSError as err:
        raise InputError(f"{path}: cannot open the output file ({reason(err)})") from None
    except InputError:  # said above (an InputError is also a ValueError)
        raise
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


def write_replacing(path: str, write, what: str) -> None:
    """Write ``path`` through ``write(temporary_path)``: a temporary file next to it (of the same
    suffix, which some writers read the format from) renamed onto it once complete, so that a
    failed write leaves the old file. A symbolic link or a non-regular file in its place is
    refused (open_output); the file keeps its mode, and a file with hard links is rewritten in
    place, so that the links keep sharing it. ``what``: the failure's words ("save the
    results")."""
    from ..errors import SpacarError

    existed = os.path.lexists(path)
    existing = open_output(path, append=True)  # refuses a link or a non-regular file (appending: not emptied)
    info = os.fstat(existing)
    os.close(existing)
    directory, name = os.path.split(os.path.abspath(path))
    fd, temporary = tempfile.mkstemp(prefix=f".{name}.", suffix=".tmp" + os.path.splitext(name)[1], dir=directory)
    try:
        os.fchmod(fd, stat.S_IMODE(info.st_mode))  # the file's mode, not mkstemp's 0600 (issue 38)
        os.close(fd)
        write(temporary)
        if info.st_nlink > 1:  # hard links keep sharing the file: its bytes are replaced in place
            with open(temporary, "rb") as src:
                with os.fdopen(open_output(path), "wb") as dst:
                    shutil.copyfileobj(src, dst)
            os.unlink(temporary)
        else:
            os.replace(temporary, path)
    except BaseException as err:
        if os.path.exists(temporary):
            os.unlink(temporary)
        if not existed and os.path.isfile(path) and os.path.getsize(path) == 0:
            os.unlink(path)  # the empty file made to check the path: nothing was there before
        if isinstance(err, OSError):
            raise SpacarError(f"{path}: cannot {what} ({reason(err)})") from None
        raise


def read_input(path: str, limit: int, what: str) -> bytes:
    """The bytes of the input file ``path``: a regular file (a FIFO or a device is refused at
    once, never waited on) of at most ``limit`` bytes. ``what``: the file's kind ("URDF")."""
    try:
        # O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused below.
        fd = os.open(path, os.O_RDONLY | _NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as err:
        raise InputError(f"{path}: cannot read the {what} file ({reason(err)})") from None
    except ValueError as err:  # a NUL in the name
        raise InputError(f"{path!r}: cannot read the {what} file ({err})") from None
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        raise InputError(f"{path}: not a regular file (a {what} file must be a regular file, not a FIFO, "
                         "device or directory)")
    with os.fdopen(fd, "rb") as fh:
        if info.st_size > limit:
            raise InputError(f"{path}: the {what} file has {info.st_size} bytes, more than the limit of {limit} bytes")
        if _NONBLOCK:
            os.set_blocking(fd, True)
        data = fh.read(limit + 1)
    if len(data) > limit:  # it grew while read
        raise InputError(f"{path}: the {what} file has more than the limit of {limit} bytes")
    return data
