"""map.py — a barycentric map (per source vertex a face of the other mesh
and three weights), its points on that mesh, fields carried across it
(transfer), its nearest vertices (to_vertex_map), and the `meshcorr-map 1`
text format `meshcorr result` and `meshcorr match` write
(workers/map/bmap.c): the header line, `#` comments, "<source vertices>
<target vertices>", then "<face> <w0> <w1> <w2>" per source vertex, weights
as %.17g. Also vertex-to-vertex maps (one target vertex per source vertex,
the layout BCICP and BIM write) as Maps, with the base rule of `meshcorr
match --init-base` (workers/map/vmap.h)."""
from __future__ import annotations

import os
from typing import Any, Optional, Union

import numpy as np

HEADER = "# meshcorr-map 1"


class Map:
    """faces: (n,) int32 faces of the target; weights: (n, 3) float64, row i
    the barycentric coordinates of source vertex i's point on the target
    triangle faces[i]; n_target: the target's vertex count (the format's
    header needs it). The target's faces F2 (m, 3) and positions V2
    (n_target, 3) are the arrays read_mesh() returns for the target."""

    def __init__(self, faces: Any, weights: Any, n_target: int) -> None:
        self.faces = np.ascontiguousarray(faces, dtype=np.int32)
        self.weights = np.ascontiguousarray(weights, dtype=np.float64)
        if self.faces.ndim != 1 or self.weights.shape != (len(self.faces), 3):
            raise ValueError("a map is n faces and n by 3 weights, got faces of shape %s and weights of shape %s"
                             % (self.faces.shape, self.weights.shape))
        self.n_target = int(n_target)

    def __len__(self) -> int:
        return len(self.faces)

    def _target_faces(self, F2: Any) -> np.ndarray:
        """F2 checked against the map: an (m, 3) array of vertex ids below
        n_target holding every face the map uses."""
        F2 = np.asarray(F2)
        if F2.ndim != 2 or F2.shape[1] != 3 or F2.dtype.kind not in "iu":
            raise ValueError("F2: expected the target's faces, an (m, 3) integer array, got shape %s of %s"
                             % (F2.shape, F2.dtype))
        if len(self) and int(self.faces.max()) >= len(F2):
            raise ValueError("F2 has %d faces, the map uses face %d: not the map's target"
                             % (len(F2), int(self.faces.max())))
        bad = F2[(F2 < 0) | (F2 >= self.n_target)]
        if bad.size:
            raise ValueError("F2: vertex id %d outside [0, %d), the target's vertices" % (int(bad[0]), self.n_target))
        return F2

    def transfer(self, values: Any, F2: Any) -> np.ndarray:
        """A per-vertex field of the target carried to the source: values of
        shape (n_target,) or (n_target, k) (a scalar, texture coordinates,
        colours, positions...) give (n,) or (n, k), row i the field
        interpolated linearly at source vertex i's point, sum_k
        weights[i, k] * values[F2[faces[i], k]] (exact at the barycentric
        point). F2: the target's faces."""
        F2 = self._target_faces(F2)
        vals = np.asarray(values)
        if vals.ndim not in (1, 2) or vals.shape[0] != self.n_target:
            raise ValueError("values: expected shape (%d,) or (%d, k), one row per target vertex, got %s"
                             % (self.n_target, self.n_target, vals.shape))
        if vals.dtype.kind not in "iufc":
            raise ValueError("values: expected numbers, got %s" % vals.dtype)
        at = vals[F2[self.faces]]                    # (n, 3) or (n, 3, k): the corners' values
        return np.einsum("ik,ik->i" if vals.ndim == 1 else "ik,ikd->id", self.weights, at)

    def points(self, V2: Any, F2: Any) -> np.ndarray:
        """The mapped points on the target (V2: its (n_target, 3) positions,
        F2: its faces): (n, 3), row i = sum_k weights[i, k] V2[F2[faces[i], k]]."""
        V2 = np.asarray(V2, dtype=np.float64)
        if V2.shape != (self.n_target, 3):
            raise ValueError("V2: expected the target's positions, shape (%d, 3), got %s" % (self.n_target, V2.shape))
        return self.transfer(V2, F2)

    def to_vertex_map(self, V2: Any, F2: Any) -> np.ndarray:
        """The map as vertex-to-vertex: an (n,) int64 array, entry i the
        target vertex nearest (in space) to source vertex i's point among
        the three corners of its face (the first of equals); vertex_map()
        turns it back into a Map."""
        F2 = self._target_faces(F2)
        V2 = np.asarray(V2, dtype=np.float64)
        if V2.shape != (self.n_target, 3):
            raise ValueError("V2: expected the target's positions, shape (%d, 3), got %s" % (self.n_target, V2.shape))
        corners = F2[self.faces].astype(np.int64)   # (n, 3)
        at = self.transfer(V2, F2)
        d2 = ((V2[corners] - at[:, None, :]) ** 2).sum(axis=2)
        return corners[np.arange(len(self)), np.argmin(d2, axis=1)]

    def write(self, path: Union[str, "os.PathLike[str]"], comment: Optional[str] = None) -> None:
        """Writes the map as `meshcorr-map 1`; comment lines follow the header."""
        with open(path, "w") as fp:
            fp.write(HEADER + "\n")
            for line in (comment.split("\n") if comment else []):
                fp.write("# %s\n" % line)
            fp.write("%d %d\n" % (len(self), self.n_target))
            for f, w in zip(self.faces.tolist(), self.weights.tolist()):
                fp.write("%d %s %s %s\n" % (f, _g17(w[0]), _g17(w[1]), _g17(w[2])))

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Map) and self.n_target == other.n_target and
                np.array_equal(self.faces, other.faces) and np.array_equal(self.weights, other.weights))

    def __repr__(self) -> str:
        return "Map(%d rows onto %d faces of a %d-vertex target)" % (len(self), len(np.unique(self.faces)),
                                                                     self.n_target)


def _g17(x: float) -> str:
    return "%.17g" % x


def read_map(path: Union[str, "os.PathLike[str]"]) -> Map:
    """Reads a `meshcorr-map 1` file into a Map (ValueError when it is not one)."""
    with open(path) as fp:
        lines = fp.read().split("\n")
    if not lines or lines[0].rstrip() != HEADER:
        raise ValueError('%s:1: first line must be "%s"' % (path, HEADER))
    i = 1
    while i < len(lines) and lines[i].startswith("#"):
        i += 1
    try:
        n, nt = (int(x) for x in lines[i].split())
    except (IndexError, ValueError):
        raise ValueError('%s:%d: expected "<source vertices> <target vertices>"' % (path, i + 1))
    rows = [ln.split() for ln in lines[i + 1:] if ln.strip()]
    if len(rows) != n or any(len(r) != 4 for r in rows):
        raise ValueError("%s: expected %d rows of <face> <w0> <w1> <w2>" % (path, n))
    faces = np.array([int(r[0]) for r in rows], dtype=np.int32)
    weights = np.array([[float(x) for x in r[1:]] for r in rows], dtype=np.float64).reshape(n, 3)
    return Map(faces, weights, nt)


def write_map(path: Union[str, "os.PathLike[str]"], m: Map, comment: Optional[str] = None) -> None:
    """m.write(path, comment)."""
    m.write(path, comment)


def vertex_map(ids: Any, F2: Any, n_target: int) -> Map:
    """A Map from 0-based target vertex ids, one per source vertex: weight 1
    at the vertex, in the lowest face of F2 (the target's faces) listing it."""
    ids = np.asarray(ids, dtype=np.int64)
    F2 = np.asarray(F2, dtype=np.int64)
    if ids.ndim != 1 or (ids < 0).any() or (ids >= n_target).any():
        raise ValueError("a vertex map is one target vertex id in [0, %d) per source vertex" % n_target)
    flat = F2.reshape(-1)
    none = len(flat)
    first = np.full(n_target, none, dtype=np.int64)
    np.minimum.at(first, flat, np.arange(len(flat)))   # the lowest position listing each vertex
    q = first[ids]
    if (q == none).any():
        raise ValueError("target vertex %d lies on no face" % int(ids[np.argmax(q == none)]))
    weights = np.zeros((len(ids), 3))
    weights[np.arange(len(ids)), q % 3] = 1
    return Map((q // 3).astype(np.int32), weights, n_target)


def read_vertex_map(path: Union[str, "os.PathLike[str]"], F2: Any, n_target: int, n_source: Optional[int] = None,
                    base: Optional[int] = None) -> Map:
    """Reads a vertex-map file (one target vertex index a line; '#' and
    blank lines skipped) into a Map on the target with faces F2. base 0 or
    1, or None: a 0 among the indices means 0-based, n_target among them
    1-based, neither is refused as ambiguous (ValueError naming the file)."""
    ids, lines = [], []
    with open(path) as fp:
        for k, ln in enumerate(fp, 1):
            t = ln.strip()
            if not t or t.startswith("#"):
                continue
            try:
                v = float(t)
                if v != int(v):
                    raise ValueError
            except ValueError:
                raise ValueError("%s:%d: %r is not a target vertex index (one integer a line)" % (path, k, t))
            ids.append(int(v))
            lines.append(k)
    if n_source is not None and len(ids) != n_source:
        raise ValueError("%s: %d entries, expected %d (one target vertex per source vertex)"
                         % (path, len(ids), n_source))
    if base is None:
        if 0 in ids:
            base = 0
        elif n_target in ids:
            base = 1
        else:
            raise ValueError("%s: neither 0 nor %d among the indices: 0- or 1-based cannot be told; "
                             "give the base (init_base=0 or 1)" % (path, n_target))
    for v, k in zip(ids, lines):
        if not base <= v < n_target + base:
            raise ValueError("%s:%d: target vertex %d out of range [%d, %d] (%d-based)"
                             % (path, k, v, base, n_target - 1 + base, base))
    return vertex_map(np.array(ids, dtype=np.int64) - base, F2, n_target)


def is_map_file(path: Union[str, bytes, "os.PathLike[str]"]) -> bool:
    """True when the file starts with the meshcorr-map 1 header."""
    with open(path) as fp:
        return fp.readline().rstrip() == HEADER
