"""meshcorr — Python client of meshcorrd over libmeshcorr (ctypes): submit
mesh pairs from files or numpy arrays, follow their progress, and get the
barycentric maps back as numpy arrays.

    import meshcorr
    c = meshcorr.Client()                     # $MESHCORR_SERVER, $MESHCORR_TOKEN
    job = c.submit("cow.off", "camel.off", landmarks=pairs, iterations=5)
    for p in job.watch():
        print(p["stage"], p["outer"], p["energy"])
    res = job.result()
    res.p.write("cow-camel.map")              # meshcorr-map 1
    points = res.p.points(V2, F2)

PARAMS lists the job parameters (the library's one list)."""
from ._lib import PARAMS
from .client import Client, Job, Result
from .errors import MeshcorrError
from .map import Map, read_map, read_vertex_map, vertex_map, write_map

__all__ = ["Client", "Job", "Result", "Map", "MeshcorrError", "read_map", "read_vertex_map", "vertex_map",
           "write_map", "PARAMS"]
