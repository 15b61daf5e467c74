"""meshcorr — dense correspondences between triangle meshes, from Python:
jobs on a shared meshcorrd (Client) or in this process (match), meshes and
maps as numpy arrays. Over libmeshcorr (ctypes); docs/python.md is the guide.

    import meshcorr
    V1, F1 = meshcorr.read_mesh("cow.off")
    with meshcorr.Client() as c:              # $MESHCORR_SERVER, $MESHCORR_TOKEN
        job = c.submit("cow.off", "camel.off", landmarks=pairs, iterations=50)
        for p in job.watch(timeout=3600):
            print(p["stage"], p["outer"], p["energy"])
        res = job.result()
    res.p.write("cow-camel.map")              # meshcorr-map 1
    points = res.p.points(V2, F2)             # the cow's vertices on the camel
    uv = res.p.transfer(UV2, F2)              # a per-vertex field carried over
    ids = res.p.to_vertex_map(V2, F2)         # the nearest camel vertex per cow vertex

    res = meshcorr.match("cow.off", "camel.off", landmarks=pairs, iterations=50)   # no daemon

PARAMS lists the job parameters (the library's one list); __version__ is
the library's version (mc_version). Every failure is a MeshcorrError that
is also the built-in exception it means (errors.py)."""
from ._lib import PARAMS, VERSION as __version__
from .client import Client, Job
from .errors import (AccessDeniedError, BadLandmarksError, BadMapError, BadMeshError, BadParamsError,
                     ClientClosedError, InvalidInputError, JobCancelledError, JobNotFoundError, JobStateError,
                     MeshcorrError, MeshcorrMemoryError, MeshcorrTimeoutError, MeshFileNotFoundError, NumericError,
                     ProtocolError, ServerBusyError, ServerConnectionError, ServerError)
from .local import match
from .map import Map, read_map, read_vertex_map, vertex_map, write_map
from .mesh import read_mesh
from ._spec import read_landmarks
from .result import Result

__all__ = ["Client", "Job", "Result", "Map", "match", "read_mesh", "read_landmarks", "read_map", "read_vertex_map", "vertex_map",
           "write_map", "PARAMS", "__version__",
           "MeshcorrError", "InvalidInputError", "BadMeshError", "BadLandmarksError", "BadParamsError",
           "BadMapError", "ClientClosedError", "MeshFileNotFoundError", "AccessDeniedError", "JobNotFoundError", "JobStateError",
           "JobCancelledError", "ServerBusyError", "ServerConnectionError", "MeshcorrTimeoutError",
           "MeshcorrMemoryError", "NumericError", "ProtocolError", "ServerError"]
