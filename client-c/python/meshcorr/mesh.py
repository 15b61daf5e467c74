"""mesh.py — read_mesh(): a mesh file as numpy arrays, read by libmeshcorr
with the engine's own readers (the ones submit() and match() use on a
path), so the arrays hold exactly the vertices, in exactly the order, that
landmarks and maps refer to."""
from __future__ import annotations

import ctypes
import os
from typing import Tuple

import numpy as np

from . import _lib
from ._lib import check, errbuf, lib
from ._spec import PathLike, open_check
from .errors import MC_EFILE, BadMeshError


def read_mesh(path: PathLike) -> Tuple[np.ndarray, np.ndarray]:
    """(V, F) of a mesh file (.off .obj .ply .drc, by extension): V a
    float64 (n, 3) array of positions, F an int32 (m, 3) array of 0-based
    vertex indices, in the file's order (a polygon face split into
    triangles where it stands: these are the faces a map's rows name).
    MeshFileNotFoundError (a FileNotFoundError) when it does not exist;
    BadMeshError (a ValueError) naming the file, line and field when it
    does not parse."""
    open_check(path, "path")
    v, nv = ctypes.POINTER(ctypes.c_double)(), ctypes.c_int()
    f, nf, err = ctypes.POINTER(ctypes.c_int)(), ctypes.c_int(), errbuf()
    rc = lib.mc_read_mesh(os.fsencode(path), ctypes.byref(v), ctypes.byref(nv), ctypes.byref(f), ctypes.byref(nf),
                          err, len(err))
    try:
        check(rc, err.value, BadMeshError if rc == MC_EFILE else None, "path")
        V = np.ctypeslib.as_array(v, (nv.value, 3)).copy() if nv.value else np.zeros((0, 3))
        F = np.ctypeslib.as_array(f, (nf.value, 3)).astype(np.int32) if nf.value else np.zeros((0, 3), np.int32)
        return V, F
    finally:
        _lib.free(v)
        _lib.free(f)
