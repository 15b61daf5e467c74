"""_spec.py — a job's inputs as the mc_job_spec both Client.submit() and
match() hand to libmeshcorr: meshes (a file's path or (V, F) arrays) as
Draco bytes, landmarks checked element by element or read from landmark
files by libmeshcorr (the CLI's reader), initial maps as rows, parameters
by name from the one list. The spec points into buffers this object keeps
alive."""
from __future__ import annotations

import ctypes
import numbers
import os
from collections.abc import Mapping
from typing import Any, Optional, Tuple, Union

import numpy as np

from . import _lib
from ._lib import check, errbuf, lib
from .errors import (MC_EARG, MC_EFILE, AccessDeniedError, BadLandmarksError, BadMeshError, BadParamsError,
                     InvalidInputError, MeshFileNotFoundError)
from .map import Map, is_map_file, read_map, read_vertex_map, vertex_map

PathLike = Union[str, bytes, "os.PathLike[str]"]
MeshLike = Union[PathLike, Tuple[Any, Any]]
MAX_VERTEX_ID = 0xFFFFFFFF


def _is_path(x: Any) -> bool:
    return isinstance(x, (str, bytes, os.PathLike))


def open_check(path: PathLike, field: str) -> None:
    """Raises the package's exception when path cannot be opened for
    reading: MeshFileNotFoundError, AccessDeniedError, or
    InvalidInputError (a folder ...), errno and filename set."""
    try:
        with open(path, "rb"):
            pass
    except OSError as e:
        cls = (MeshFileNotFoundError if isinstance(e, FileNotFoundError) else
               AccessDeniedError if isinstance(e, PermissionError) else InvalidInputError)
        err = _lib.error(MC_EFILE, "%s: %s" % (os.fsdecode(path), e.strerror), cls, field)
        err.errno, err.strerror, err.filename = e.errno, e.strerror, os.fsdecode(path)
        raise err from None


def encode(mesh: MeshLike, qbits: int, field: str) -> Tuple[ctypes.Array, int]:
    """(Draco bytes as a ctypes buffer, length) of a path or a (V, F) pair."""
    out, n, err = _lib.c_u8p(), ctypes.c_size_t(), errbuf()
    if _is_path(mesh):
        open_check(mesh, field)
        rc = lib.mc_encode_mesh_file_quantized(os.fsencode(mesh), qbits, ctypes.byref(out), ctypes.byref(n),
                                               err, len(err))
        check(rc, err.value, BadMeshError if rc == MC_EFILE else None, field)
    else:
        try:
            V, F = mesh
        except (TypeError, ValueError):
            raise _lib.error(MC_EARG, "%s: a mesh is a file's path or (V, F) arrays, got %s"
                             % (field, type(mesh).__name__), BadMeshError, field) from None
        V = np.ascontiguousarray(V, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.intc)
        if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
            hint = ("; F of polygons: pass the file's path instead (its reader splits them into triangles)"
                    if F.ndim == 2 and F.shape[1] > 3 else "")
            raise _lib.error(MC_EARG, "%s: V must be (n, 3) positions and F (m, 3) vertex indices, got V %s "
                             "and F %s%s" % (field, V.shape, F.shape, hint), BadMeshError, field)
        rc = lib.mc_encode_mesh_quantized(V.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), len(V),
                                          F.ctypes.data_as(ctypes.POINTER(ctypes.c_int)), len(F), qbits,
                                          ctypes.byref(out), ctypes.byref(n), err, len(err))
        check(rc, b"%s: %s" % (field.encode(), err.value), BadMeshError if rc == MC_EARG else None, field)
    try:
        return ctypes.create_string_buffer(ctypes.string_at(out, n.value), n.value), n.value
    finally:
        _lib.free(out)


def decode(blob: Any, n: int) -> Tuple[np.ndarray, np.ndarray]:
    """(V, F) of Draco bytes: float64 (nv, 3) and int32 (nf, 3) arrays."""
    v, nv = ctypes.POINTER(ctypes.c_double)(), ctypes.c_int()
    f, nf, err = ctypes.POINTER(ctypes.c_int)(), ctypes.c_int(), errbuf()
    rc = lib.mc_decode_mesh(ctypes.cast(blob, _lib.c_u8p), n, ctypes.byref(v), ctypes.byref(nv),
                            ctypes.byref(f), ctypes.byref(nf), err, len(err))
    try:
        check(rc, err.value)
        return (np.ctypeslib.as_array(v, (nv.value, 3)).copy() if nv.value else np.zeros((0, 3)),
                np.ctypeslib.as_array(f, (nf.value, 3)).astype(np.int32) if nf.value else
                np.zeros((0, 3), np.int32))
    finally:
        _lib.free(v)
        _lib.free(f)


def _vertex_id(x: Any, where: str) -> int:
    """x as a vertex id, or BadLandmarksError naming where: an integer (or
    a float equal to one) in [0, 2^32 - 1]; never a bool."""
    if isinstance(x, (bool, np.bool_)):
        bad = "a bool, not a vertex id"
    elif isinstance(x, numbers.Integral):
        bad = None if 0 <= int(x) <= MAX_VERTEX_ID else "not a vertex id (0 to %d)" % MAX_VERTEX_ID
    elif isinstance(x, numbers.Real):
        f = float(x)
        bad = ("not a whole number: a vertex id is an integer" if not np.isfinite(f) or f != int(f) else
               None if 0 <= f <= MAX_VERTEX_ID else "not a vertex id (0 to %d)" % MAX_VERTEX_ID)
    else:
        bad = "a %s, not a vertex id" % type(x).__name__
    if bad:
        raise _lib.error(MC_EARG, "%s = %r: %s" % (where, x, bad), BadLandmarksError, "landmarks")
    return int(x)


# Values that are never landmark pairs nor rows of them: refused by type,
# never iterated (a str would be taken apart character by character).
_NOT_PAIRS = (str, bytes, bytearray, os.PathLike, Mapping)
_WANT = "landmarks: expected a (k, 2) array of (source, target) vertex ids or a landmark file's path, got %s"


def _landmark_files(landmarks: Any) -> Optional[Tuple[Any, Any]]:
    """(pairs file, None) of a str or os.PathLike, (source list, target
    list) of a tuple of two of them; None for anything else (a list of two
    strs is refused as rows that are not pairs)."""
    if isinstance(landmarks, (str, os.PathLike)):
        return landmarks, None
    if (isinstance(landmarks, tuple) and len(landmarks) == 2 and
            all(isinstance(x, (str, os.PathLike)) for x in landmarks)):
        return landmarks[0], landmarks[1]
    return None


def _positions(mesh: MeshLike) -> np.ndarray:
    """A mesh's (n, 3) float64 positions: a file's as the engine reads it
    (read_mesh, the CLI's reader), or V of (V, F)."""
    if _is_path(mesh):
        from .mesh import read_mesh     # mesh.py imports this module
        return read_mesh(mesh)[0]
    return np.ascontiguousarray(mesh[0], dtype=np.float64)


def read_landmarks(path: Any, source: MeshLike, target: MeshLike, target_path: Any = None,
                   one_based: bool = False) -> np.ndarray:
    """A landmark file as a (k, 2) uint32 array of 0-based (source,
    target) vertex ids, read by libmeshcorr's mc_read_landmarks, the reader
    and checks of `meshcorr match`: path a pairs file (--landmarks), or with
    target_path a source and a target list (--source-landmarks,
    --target-landmarks); one_based as --one-based (BCICP and FAUST .vts
    lists). source and target are the meshes the ids are checked against
    (a file's path or (V, F)). A file that cannot be read or that the
    reader refuses raises BadLandmarksError with the reader's message (the
    file, and the line)."""
    sv, tv = _positions(source), _positions(target)
    out, n, err = ctypes.POINTER(ctypes.c_uint32)(), ctypes.c_uint32(), errbuf()
    dp = ctypes.POINTER(ctypes.c_double)
    tp = None if target_path is None else os.fsencode(target_path)
    rc = lib.mc_read_landmarks(os.fsencode(path), tp, 1 if one_based else 0,
                               sv.ctypes.data_as(dp), len(sv), tv.ctypes.data_as(dp), len(tv), ctypes.byref(out),
                               ctypes.byref(n), err, len(err))
    try:
        msg = err.value.decode(errors="replace")
        if rc and not one_based and "looks 1-based" in msg:
            msg += " (meshcorr.read_landmarks(..., one_based=True) reads a 1-based file)"
        check(rc, msg, BadLandmarksError if rc == MC_EFILE else None, "landmarks")
        return np.ctypeslib.as_array(out, (n.value, 2)).copy()
    finally:
        _lib.free(out)


def landmark_pairs(landmarks: Any, source: MeshLike, target: MeshLike) -> np.ndarray:
    """submit()'s and match()'s landmarks as a (k, 2) uint32 array: a
    landmark file's path, or a pair of paths (source list, target list),
    read against the meshes by read_landmarks; else landmark_array."""
    files = _landmark_files(landmarks)
    if files:
        return read_landmarks(files[0], source, target, files[1])
    return landmark_array(landmarks)


def landmark_array(landmarks: Any) -> np.ndarray:
    """Landmarks as a (k, 2) uint32 array of (source, target) vertex ids:
    a numpy integer array of shape (k, 2), or k pairs of integers. A float
    that is not whole (1.5), a negative, a bool or anything else that is not
    a vertex id is refused (BadLandmarksError, a ValueError) naming the
    element, e.g. "landmarks[3][1] = 1.5"; a str, bytes or dict, or a row
    that is one, is refused by its type."""
    shape_msg = "landmarks: expected (k, 2) (source, target) vertex id pairs, got %s"
    if isinstance(landmarks, np.ndarray):
        a = landmarks
        if a.size == 0:
            a = a.reshape(0, 2)
        if a.ndim != 2 or a.shape[1] != 2:
            raise _lib.error(MC_EARG, shape_msg % ("an array of shape %s" % (a.shape,)), BadLandmarksError,
                             "landmarks")
        if a.dtype.kind in "iu":
            bad = (a < 0) | (a > MAX_VERTEX_ID)
            if bad.any():
                i, j = np.argwhere(bad)[0]
                _vertex_id(a[i, j], "landmarks[%d][%d]" % (i, j))
            return np.ascontiguousarray(a, dtype=np.uint32)
        rows = a.tolist() if a.dtype.kind != "O" else list(a)
        if a.dtype.kind == "b":
            rows = [[np.bool_(x) for x in r] for r in rows]
    else:
        if isinstance(landmarks, _NOT_PAIRS):
            raise _lib.error(MC_EARG, _WANT % type(landmarks).__name__, BadLandmarksError, "landmarks")
        try:
            rows = []
            for i, r in enumerate(landmarks):
                if isinstance(r, _NOT_PAIRS):
                    raise _lib.error(MC_EARG, "landmarks[%d] = %r: a %s, not a (source, target) pair"
                                     % (i, r, type(r).__name__), BadLandmarksError, "landmarks")
                rows.append(list(r))
        except TypeError:
            raise _lib.error(MC_EARG, _WANT % type(landmarks).__name__, BadLandmarksError,
                             "landmarks") from None
    out = np.empty((len(rows), 2), dtype=np.uint32)
    for i, r in enumerate(rows):
        if len(r) != 2:
            raise _lib.error(MC_EARG, "landmarks[%d] has %d elements, expected a (source, target) pair"
                             % (i, len(r)), BadLandmarksError, "landmarks")
        out[i] = [_vertex_id(x, "landmarks[%d][%d]" % (i, j)) for j, x in enumerate(r)]
    return out


def _text(value: Any) -> str:
    """A keyword's value as the text `meshcorr submit --option` takes."""
    if isinstance(value, (bool, np.bool_)):
        return "1" if value else "0"
    if isinstance(value, float):
        return "%.17g" % value
    return str(value)


class Spec:
    """The mc_job_spec of submit()'s and match()'s arguments (see
    Client.submit); spec is the struct, the rest is kept alive with it."""

    def __init__(self, source: MeshLike, target: MeshLike, landmarks: Optional[Any] = None,
                 init: Optional[Any] = None, init_reverse: Optional[Any] = None, priority: int = 0,
                 label: Optional[str] = None, quantization: int = 0, device: Optional[str] = None,
                 init_base: Optional[int] = None, params: Optional[dict] = None) -> None:
        params = dict(params or {})
        qbits = int(quantization)
        self.source = encode(source, qbits, "source")
        self.target = encode(target, qbits, "target")
        spec = self.spec = _lib.JobSpec()
        lib.mc_job_spec_init(ctypes.byref(spec))
        spec.source, spec.source_len = ctypes.cast(self.source[0], _lib.c_u8p), self.source[1]
        spec.target, spec.target_len = ctypes.cast(self.target[0], _lib.c_u8p), self.target[1]
        self._keep: list = []
        if landmarks is not None:
            lm = landmark_pairs(landmarks, source, target)
            self._keep.append(lm)
            spec.landmarks = lm.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32))
            spec.nlandmarks = len(lm)
        if init is not None:
            rows = self._rows(init, self.target, self.source, init_base, "init")
            spec.p, spec.np = rows, len(rows)
        if init_reverse is not None:
            rows = self._rows(init_reverse, self.source, self.target, init_base, "init_reverse")
            spec.q, spec.nq = rows, len(rows)
        if device is not None:
            params["backend"] = "%s:%s" % (params.get("backend") or "cpu", device)
        for name, value in params.items():
            text = _text(value).encode()
            self._keep.append(text)
            err = errbuf()
            rc = lib.mc_job_spec_set(ctypes.byref(spec), name.encode(), text, err, len(err))
            check(rc, err.value, BadParamsError, name)
        spec.priority = int(priority)
        if label is not None:
            self._keep.append(label.encode())
            spec.label = self._keep[-1]

    @property
    def injective(self) -> bool:
        return self.spec.model == 1

    def target_vertices(self) -> int:
        return len(decode(*self.target)[0])

    def _rows(self, m: Any, to: Tuple[Any, int], frm: Tuple[Any, int], base: Optional[int],
              field: str) -> ctypes.Array:
        """A Map, a map file's path (meshcorr-map 1, or a vertex map onto the
        mesh `to` with a row per vertex of `frm`, base as init_base), or
        0-based target vertex ids, as an array of mc_map_row."""
        if not isinstance(m, Map):
            if _is_path(m):
                open_check(m, field)
            if _is_path(m) and is_map_file(m):
                m = read_map(m)
            else:
                VT, FT = decode(*to)
                if _is_path(m):
                    m = read_vertex_map(m, FT, len(VT), len(decode(*frm)[0]), base)
                else:
                    m = vertex_map(m, FT, len(VT))
        rows = (_lib.MapRow * len(m))()
        a = np.ctypeslib.as_array(ctypes.cast(rows, ctypes.POINTER(ctypes.c_byte)),
                                  (len(m) * ctypes.sizeof(_lib.MapRow),))
        rec = a.view(_lib.MAP_ROW_DTYPE)
        rec["face"] = m.faces
        rec["w"] = m.weights
        self._keep.append(rows)
        return rows

