"""Files written whole or not at all: every file of the store, the reports and the record.

A file is written to a new temporary file in its own folder (``.<name>.<random>.tmp``: hidden, and matched
by no reader's pattern such as ``*.parquet``), then renamed over its name (``os.replace``, atomic on local
POSIX file systems and on NFS).  A reader (a browser on a report, another command) sees the previous file
or the new one, never part of one; a writer that fails, or is killed, leaves the previous file as it was
(a killed writer leaves its temporary, matched by :data:`TEMPORARIES`).  A full disk (or quota) while
writing is :class:`DiskFull`: one line naming the folder.

    save(path, lambda tmp: frame.to_csv(tmp, index=False))   # any writer that takes a path
    save_figure(fig, path, dpi=110)                          # its format from the name, not the temporary's
    write_text(path, html)
"""

import errno
import os
import secrets
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

FULL = (errno.ENOSPC, errno.EDQUOT)
TEMPORARIES = ".*.tmp"  # the glob of a folder's temporaries (a writer killed mid-write leaves one)


class DiskFull(OSError):
    """No space left on the disk of a folder being written: one line naming the folder."""


@contextmanager
def replacing(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` to write; renamed over ``path`` when the block ends, deleted if it
    raises (the previous ``path`` untouched).  A full disk raises :class:`DiskFull`."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(8)}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        yield tmp
        os.replace(tmp, path)
    except BaseException as error:
        tmp.unlink(missing_ok=True)
        if _full(error):
            raise DiskFull(f"{path.parent}: no space left on its disk (writing {path.name}); no file there "
                           "is left part-written (each is replaced whole or not at all): free some space and "
                           "rerun the same command") from None
        raise


def save(path: str | Path, write: Callable[[Path], object]) -> Path:
    """``write(tmp)`` (a writer that takes a path), then ``tmp`` renamed to ``path``; ``path``."""
    with replacing(path) as tmp:
        write(tmp)
    return Path(path)


def save_figure(figure, path: str | Path, **options) -> Path:
    """A matplotlib figure as ``path``, in the format its suffix names (``.png``, ``.svg``); ``options``:
    ``savefig``'s."""
    return save(path, lambda tmp: figure.savefig(tmp, format=Path(path).suffix[1:], **options))


def write_text(path: str | Path, text: str, durable: bool = False) -> Path:
    """``text`` as ``path``; ``durable``: on the disk (fsync) before the rename, so that a power cut leaves
    the old file or the new, not an empty one.  The file gets the mode ``open()`` gives (0o666 less the
    umask), so that a store or a report folder can be shared."""
    with replacing(path) as tmp, open(tmp, "x") as handle:  # "x": created here, never an existing file
        handle.write(text)
        if durable:
            handle.flush()
            os.fsync(handle.fileno())
    return Path(path)


def _full(error: BaseException | None) -> bool:
    """Whether ``error``, or an error it was raised from, is a full disk (a library may wrap the OSError)."""
    seen = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, OSError) and error.errno in FULL:
            return True
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return False
