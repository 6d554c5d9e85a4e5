"""Writing files so that nothing the user has is ever half-written.

Every file MITOS writes (saved rule bases and term sets, converted and exported files, plots,
traces, study results) goes through :func:`atomic_file`: the data goes to a temporary file in
the same directory, is flushed to disk, and only then replaces the target in one rename. A
crash leaves either the old file or the new one. New files get the usual permissions (0666
less the umask), not a temporary file's 0600.
"""

from __future__ import annotations

import contextlib
import os
import secrets
from pathlib import Path
from typing import IO, Iterator

from .errors import MitosError


@contextlib.contextmanager
def atomic_file(path: str | Path, binary: bool = False,
                error: type[MitosError] = MitosError) -> Iterator[IO]:
    """Open a temporary file that replaces ``path`` when the block ends without an error; a
    failure (a missing directory included) raises ``error`` naming the file."""
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    tmp = directory / f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp"
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    except OSError as exc:
        raise error(f"cannot write `{path}`: {exc.strerror or exc}",
                    hint="check that the directory exists and is writable") from None
    try:
        with (os.fdopen(fd, "wb") if binary else
              os.fdopen(fd, "w", encoding="utf-8", newline="")) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        raise error(f"cannot write `{path}`: {exc.strerror or exc}") from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def atomic_write(path: str | Path, data: str | bytes,
                 error: type[MitosError] = MitosError) -> None:
    """Replace ``path`` with ``data`` (text as UTF-8) in one step."""
    with atomic_file(path, binary=isinstance(data, bytes), error=error) as fh:
        fh.write(data)
