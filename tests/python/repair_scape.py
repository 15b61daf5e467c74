"""repair_scape.py — SOURCE TARGET LANDMARKS OUT: the Python package's
in-process match() of a mesh pair with a landmark list (ids, the same on
both meshes), default parameters, the map written to OUT as a
meshcorr-map 1 file; prints the result's repair record. Driven by
tests/unit/test_daemon_repair.c, which scores the map."""
import sys

import numpy as np

import meshcorr

src, tgt, lmk, out = sys.argv[1:5]
ids = np.array([int(line.split()[0]) for line in open(lmk) if line.strip()])
r = meshcorr.match(src, tgt, landmarks=np.stack([ids, ids], axis=1))
print("repair:", r.repair)
assert r.repair is not None and r.repair["source"]["split_vertices"] == 1, r.repair
assert len(r.p) == 12500, len(r.p)
r.p.write(out)
