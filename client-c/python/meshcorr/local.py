"""local.py — match(): a job run in this process by the engine
(libmeshcorr-engine.so.1's mc_match_stages), with no daemon. It takes the inputs
and parameters of Client.submit() and returns what Job.result() returns:
the same checks, the same engine run, the same maps as meshcorrd gives
for the same job."""
from __future__ import annotations

import ctypes
import signal
import threading
from typing import Any, Callable, Dict, List, Optional

from . import _lib
from ._lib import errbuf
from ._spec import MeshLike, Spec
from .result import WANT_DEFORMED, WANT_METRICS, WANT_P, WANT_Q, Result, add_stages, progress_dict, result_of

ProgressCallback = Callable[[Dict[str, Any]], Optional[bool]]


def match(source: MeshLike, target: MeshLike, landmarks: Optional[Any] = None, init: Optional[Any] = None,
          init_reverse: Optional[Any] = None, init_base: Optional[int] = None, quantization: int = 0,
          device: Optional[str] = None, progress: Optional[ProgressCallback] = None, threads: int = 0,
          deformed: bool = False, metrics: bool = True, stages: bool = False, **params: Any) -> Result:
    """Runs the job in this process and returns its Result. The arguments
    are Client.submit()'s (source, target: paths or (V, F) arrays;
    landmarks: (k, 2) vertex ids, or a landmark file's path as `meshcorr
    match --landmarks` reads it; init, init_reverse, init_base;
    quantization; device; the job parameters of PARAMS by name), and
    deformed, metrics, stages as
    Job.result()'s (stages: RHM's maps that ECTM started from in
    Result.stages). The meshes travel as they would to a server (Draco,
    lossless unless quantization says), so the maps are the ones meshcorrd
    returns for the same job. progress: called with each progress record
    (the dicts Job.watch() yields) in this thread; returning True stops the
    job (JobCancelledError), and an exception it raises stops the job and
    is raised from match(). threads: OpenMP threads, 0 = by the pair's size
    (as the server's workers do). Blocks until the job ends; other Python
    threads run meanwhile. Refusals raise what submit() raises
    (BadParamsError, BadLandmarksError, BadMeshError, ...)."""
    engine = _lib.engine()
    s = Spec(source, target, landmarks, init, init_reverse, 0, None, quantization, device, init_base, params)
    raised: List[BaseException] = []
    interrupted: List[int] = []

    def on_progress(ctx: Any, p: Any) -> int:
        if interrupted:
            return 1
        try:
            return 1 if progress is not None and progress(progress_dict(p.contents)) is True else 0
        except BaseException as e:
            raised.append(e)
            return 1

    cb = _lib.PROGRESS_FN(on_progress)
    want = WANT_P | WANT_Q | (WANT_DEFORMED if deformed else 0) | (WANT_METRICS if metrics else 0)
    r, sm, err = _lib.JobResult(), _lib.StageMaps(), errbuf()
    # Ctrl-C while the engine runs: Python's handler would raise
    # KeyboardInterrupt inside the C callback, where ctypes drops it, so a
    # handler of ours notes it, the callback (run once per record) stops the
    # job, and it is raised once the engine has returned.
    old = None
    if (threading.current_thread() is threading.main_thread() and
            signal.getsignal(signal.SIGINT) is signal.default_int_handler):
        old = signal.signal(signal.SIGINT, lambda signum, frame: interrupted.append(signum))
    try:
        rc = engine.mc_match_stages(ctypes.byref(s.spec), int(threads), want, cb, None, ctypes.byref(r),
                                    ctypes.byref(sm) if stages else None, err, len(err))
    finally:
        if old is not None:
            signal.signal(signal.SIGINT, old)
    try:
        if interrupted:
            raise KeyboardInterrupt
        if raised:
            raise raised[0]
        _lib.check(rc, err.value)
        res = result_of(r, s.target_vertices() if s.injective else None, "the job")
        add_stages(res, sm)
        return res
    finally:
        _lib.lib.mc_result_free(ctypes.byref(r))
        _lib.lib.mc_stage_maps_free(ctypes.byref(sm))
