"""errors.py — the package's exceptions. Every failure is a MeshcorrError
carrying the code (the protocol's -1 to -99 for the server's refusals,
libmeshcorr's -100 and below), its name and the message, and is also the
built-in exception it means, so callers catch it either way:

    MeshcorrError
    ├── InvalidInputError (ValueError)     bad arguments, OVER_LIMIT, TOO_LARGE
    │   ├── BadMeshError                   BAD_MESH, a mesh file that does not parse
    │   ├── BadLandmarksError              BAD_LANDMARKS, malformed landmarks
    │   ├── BadParamsError                 BAD_PARAMS, unknown or bad parameters
    │   └── BadMapError                    BAD_MAP, an initial map that does not fit its meshes
    ├── ClientClosedError (ValueError)     a call on a closed Client
    ├── MeshFileNotFoundError (FileNotFoundError)
    ├── AccessDeniedError (PermissionError)  UNAUTHORIZED, FORBIDDEN, an unreadable file
    ├── JobNotFoundError (LookupError)     NOT_FOUND
    ├── JobStateError (RuntimeError)       BAD_STATE (no maps of a failed job)
    ├── JobCancelledError                  CANCELLED (match() stopped by its progress callback)
    ├── ServerBusyError                    QUEUE_FULL, USER_LIMIT, BUSY, OVER_QUOTA: retry later
    │                                      (OVER_QUOTA: once jobs of yours are deleted)
    ├── ServerConnectionError (ConnectionError)  cannot connect, connection lost,
    │                                      SHUTTING_DOWN, TIMED_OUT (cut by the server)
    ├── MeshcorrTimeoutError (TimeoutError)  no answer in time, wait()/watch() timeout
    ├── MeshcorrMemoryError (MemoryError)  out of memory here
    ├── NumericError (ArithmeticError)     NUMERIC: a stage of the job failed numerically
    ├── ProtocolError                      a reply that breaks the protocol
    └── ServerError                        the server's own failure (INTERNAL, STORAGE, NOMEM)
"""
from __future__ import annotations

import re
from typing import Optional

# libmeshcorr's own codes (meshcorr.h, MC_ERRORS)
MC_EARG, MC_EADDRESS, MC_ECONNECT, MC_EIO, MC_ETIMEOUT, MC_EPROTO, MC_ENOMEM, MC_EFILE, MC_ETLS = range(-100, -109, -1)


class MeshcorrError(Exception):
    """code: the negative error code (-15 ...); name: its name
    ("NOT_FOUND", "BAD_PARAMS", "MC_EARG"); description: the code's meaning
    ("no such job"); message: the server's message or the local detail;
    field: the submit()/match() argument the message names ("iterations",
    "landmarks", "source", "target", "init", "init_reverse"), else None."""

    def __init__(self, code: int, name: str, description: str, message: Optional[str],
                 field: Optional[str] = None) -> None:
        self.code = code
        self.name = name
        self.description = description
        self.message = message or description
        self.field = field
        self._text = "%s (%d): %s" % (name, code, self.message)
        super().__init__(self._text)

    def __str__(self) -> str:
        return self._text        # also for the OSError subclasses, whatever errno says

    def __reduce__(self):
        return (_rebuild, (type(self), self.code, self.name, self.description, self.message, self.field))


def _rebuild(cls, code, name, description, message, field):
    return cls(code, name, description, message, field)


class InvalidInputError(MeshcorrError, ValueError):
    """An argument the server or the library refuses (also OVER_LIMIT,
    TOO_LARGE: an input over a limit)."""


class BadMeshError(InvalidInputError):
    """BAD_MESH: a mesh that does not decode or that the engine cannot use
    (the message names "source" or "target"); also a file that does not
    parse."""


class BadLandmarksError(InvalidInputError):
    """BAD_LANDMARKS, or landmarks that are not (k, 2) vertex ids."""


class BadParamsError(InvalidInputError):
    """BAD_PARAMS, or a parameter name or value that does not parse."""


class BadMapError(InvalidInputError):
    """BAD_MAP: an initial map (init, init_reverse) with the wrong rows, a
    bad face or weights, or a reverse map without a forward one."""


class ClientClosedError(MeshcorrError, ValueError):
    """A call on a Client after close() (or after its `with` block), as a
    closed file's read() raises ValueError."""


class MeshFileNotFoundError(MeshcorrError, FileNotFoundError):
    """A mesh or map file that does not exist (filename: its path)."""


class AccessDeniedError(MeshcorrError, PermissionError):
    """UNAUTHORIZED (a refused token), FORBIDDEN, or a file that cannot be read."""


class JobNotFoundError(MeshcorrError, LookupError):
    """NOT_FOUND: no such job, or another user's."""


class JobStateError(MeshcorrError, RuntimeError):
    """BAD_STATE: the job's state does not allow this (no maps of a
    cancelled or failed job)."""


class JobCancelledError(MeshcorrError):
    """CANCELLED: the in-process job was stopped by its progress callback."""


class ServerBusyError(MeshcorrError):
    """QUEUE_FULL, USER_LIMIT, BUSY: the server is at a limit; retry later."""


class ServerConnectionError(MeshcorrError, ConnectionError):
    """The server cannot be reached, or the connection was lost or cut
    (SHUTTING_DOWN, TIMED_OUT)."""


class MeshcorrTimeoutError(MeshcorrError, TimeoutError):
    """No answer within the timeout; for Job.wait() and Job.watch(), the job
    did not end in time (it keeps running on the server)."""


class MeshcorrMemoryError(MeshcorrError, MemoryError):
    """Out of memory in this process."""


class NumericError(MeshcorrError, ArithmeticError):
    """NUMERIC: a stage of the job failed numerically (a factorisation, the
    eigen-solver, a non-finite energy); Job.error of a job that ended so."""


class ProtocolError(MeshcorrError):
    """A frame or reply that does not follow the protocol."""


class ServerError(MeshcorrError):
    """The server failed on its side (INTERNAL, STORAGE, NOMEM)."""


_CLASSES = {
    -5: InvalidInputError, -8: InvalidInputError, -10: InvalidInputError,
    -11: ServerError, -13: AccessDeniedError, -14: AccessDeniedError, -15: JobNotFoundError,
    -16: JobStateError, -17: ServerBusyError, -18: ServerBusyError, -19: BadMeshError,
    -20: BadLandmarksError, -21: BadParamsError, -22: ServerError, -23: ServerError,
    -24: ServerConnectionError, -25: JobCancelledError, -26: ServerBusyError, -27: ServerConnectionError,
    -28: ServerBusyError, -29: BadMapError, -30: NumericError,
    MC_EARG: InvalidInputError, MC_EADDRESS: ServerConnectionError, MC_ECONNECT: ServerConnectionError,
    MC_EIO: ServerConnectionError, MC_ETIMEOUT: MeshcorrTimeoutError, MC_EPROTO: ProtocolError,
    MC_ENOMEM: MeshcorrMemoryError, MC_EFILE: BadMeshError, MC_ETLS: ServerConnectionError,
}

# The argument a server message names by its first words (PROTOCOL.md's
# field names), as submit()'s keyword.
_FIELDS = ((re.compile(r"params\.(\w+)"), None), (re.compile(r"(\w+) = "), None),
           (re.compile(r"landmarks\b"), "landmarks"),
           (re.compile(r"(source|target) mesh\b"), None), (re.compile(r"initial map p\b"), "init"),
           (re.compile(r"initial map q\b"), "init_reverse"), (re.compile(r"threads\b"), "threads"))


def field_of(message: str) -> Optional[str]:
    """The argument named at the start of a message, or None."""
    for rx, name in _FIELDS:
        m = rx.match(message)
        if m:
            return name or m.group(1)
    return None


def error_class(code: int) -> type:
    """The exception class of a code (MeshcorrError for others)."""
    return _CLASSES.get(code, ProtocolError if -9 <= code <= -1 or code == -12 else MeshcorrError)
