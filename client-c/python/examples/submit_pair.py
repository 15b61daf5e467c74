"""submit_pair.py — submits a mesh pair to meshcorrd, prints its progress
and saves the map (meshcorr-map 1), with the package meshcorr.
usage: submit_pair.py SOURCE TARGET PAIRS OUT.map [ITERATIONS]
PAIRS: one "source_vertex target_vertex" line per landmark (# comments).
The server and token: $MESHCORR_SERVER, $MESHCORR_TOKEN (else the Unix socket)."""
import sys

import numpy as np

import meshcorr

source, target, pairs, out = sys.argv[1:5]
params = {"iterations": int(sys.argv[5])} if len(sys.argv) > 5 else {}   # else the default
landmarks = np.loadtxt(pairs, dtype=int, comments="#", ndmin=2)

client = meshcorr.Client()
job = client.submit(source, target, landmarks=landmarks, label="submit_pair.py", **params)
print("job", job.id)
for p in job.watch():
    print("%-5s %3d/%d energy %.4e beta %.2e %.1f s"
          % (p["stage"], p["outer"], p["total"], p["energy"], p["beta"], p["elapsed"]))
if job.state != "COMPLETED":
    sys.exit("job %d %s: %s" % (job.id, job.state, job.reason))
result = job.result()
result.p.write(out, comment="meshcorrd job %d" % job.id)
print("job %d COMPLETED: %d rows written to %s" % (job.id, len(result.p), out))
