"""map.py — a barycentric map (per source vertex a face of the other mesh
and three weights), its points on that mesh, and the `meshcorr-map 1` text
format `meshcorr result` and `meshcorr match` write (workers/map/bmap.c):
the header line, `#` comments, "<source vertices> <target vertices>", then
"<face> <w0> <w1> <w2>" per source vertex, weights as %.17g. Also
vertex-to-vertex maps (one target vertex per source vertex, the layout
BCICP and BIM write) as Maps, with the base rule of `meshcorr match
--init-base` (workers/map/vmap.h)."""
import numpy as np

HEADER = "# meshcorr-map 1"


class Map:
    """faces: (n,) int32 faces of the target; weights: (n, 3) float64;
    n_target: the target's vertex count (the format's header needs it)."""

    def __init__(self, faces, weights, n_target):
        self.faces = np.ascontiguousarray(faces, dtype=np.int32)
        self.weights = np.ascontiguousarray(weights, dtype=np.float64)
        if self.faces.ndim != 1 or self.weights.shape != (len(self.faces), 3):
            raise ValueError("a map is n faces and n by 3 weights")
        self.n_target = int(n_target)

    def __len__(self):
        return len(self.faces)

    def points(self, V2, F2):
        """The mapped points on the target (V2: m by 3 positions, F2: its
        faces): n by 3, row i = sum_k weights[i, k] V2[F2[faces[i], k]]."""
        V2 = np.asarray(V2, dtype=np.float64)
        F2 = np.asarray(F2)
        return np.einsum("ik,ikd->id", self.weights, V2[F2[self.faces]])

    def write(self, path, comment=None):
        """Writes the map as `meshcorr-map 1`; comment lines follow the header."""
        with open(path, "w") as fp:
            fp.write(HEADER + "\n")
            for line in (comment.split("\n") if comment else []):
                fp.write("# %s\n" % line)
            fp.write("%d %d\n" % (len(self), self.n_target))
            for f, w in zip(self.faces.tolist(), self.weights.tolist()):
                fp.write("%d %s %s %s\n" % (f, _g17(w[0]), _g17(w[1]), _g17(w[2])))

    def __eq__(self, other):
        return (isinstance(other, Map) and self.n_target == other.n_target and
                np.array_equal(self.faces, other.faces) and np.array_equal(self.weights, other.weights))

    def __repr__(self):
        return "Map(%d -> %d vertices)" % (len(self), self.n_target)


def _g17(x):
    return "%.17g" % x


def read_map(path):
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


def write_map(path, m, comment=None):
    """m.write(path, comment)."""
    m.write(path, comment)


def vertex_map(ids, F2, n_target):
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


def read_vertex_map(path, F2, n_target, n_source=None, base=None):
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


def is_map_file(path):
    """True when the file starts with the meshcorr-map 1 header."""
    with open(path) as fp:
        return fp.readline().rstrip() == HEADER
