"""One run per output folder: an advisory lock held for the whole run.

The lock is ``fcntl.flock`` on a file in the output folder. The kernel releases it when the
holding process ends in any way (also ``kill -9``), so a lock left by a killed run is never
stale: the next run simply takes it. The file records who holds it (pid, host, start time,
command) for the message a second run prints when it refuses. On file systems without
``flock`` (some network mounts) the lock degrades to a no-op with a warning.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import socket
import sys
from pathlib import Path

from .errors import ParameterError

__all__ = ["RunLock"]


class RunLock:
    """``with RunLock(folder, "sweep"):`` holds ``folder/.recipdyn.lock`` or refuses."""

    def __init__(self, folder: str | Path, what: str = "run"):
        self.path = Path(folder) / ".recipdyn.lock"
        self.what = what
        self._fd: int | None = None

    def __enter__(self) -> RunLock:
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not POSIX
            print("warning: no file locking on this platform; do not run two jobs on one folder",
                  file=sys.stderr)  # fmt: skip
            return self
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            try:
                info = json.loads(os.read(fd, 4096).decode() or "{}")
            except (ValueError, OSError):
                info = {}
            os.close(fd)
            who = (f"pid {info.get('pid', '?')} on {info.get('host', '?')}, started "
                   f"{info.get('started', '?')}: {info.get('what', '?')}")  # fmt: skip
            raise ParameterError(
                f"{self.path.parent} is in use by another recipdyn run ({who}); wait for it to "
                "finish or choose another --out"
            ) from None
        except OSError:  # pragma: no cover - no flock on this file system
            print(f"warning: cannot lock {self.path}; do not run two jobs on this folder",
                  file=sys.stderr)  # fmt: skip
        os.ftruncate(fd, 0)
        info = dict(pid=os.getpid(), host=socket.gethostname(), what=self.what,
                    started=_dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"))  # fmt: skip
        os.pwrite(fd, json.dumps(info).encode(), 0)
        self._fd = fd
        return self

    def __exit__(self, *exc) -> None:
        if self._fd is not None:
            os.close(self._fd)  # releases the flock; the file stays (harmless, reused)
            self._fd = None
