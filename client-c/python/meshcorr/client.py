"""client.py — Client (one connection to meshcorrd) and Job (one job on
it): submit from mesh files or numpy arrays, status, watch, wait, result,
cancel, delete, list, stats. Every failure raises a MeshcorrError subclass
(errors.py) with the protocol's (or libmeshcorr's) code and the server's
message; a closed Client raises ClientClosedError (a ValueError)."""
from __future__ import annotations

import ctypes
import os
import queue
import threading
import time
from typing import Any, Dict, Iterator, List, Optional, Sequence

from . import _lib
from ._lib import check, errbuf, lib
from ._spec import MeshLike, Spec
from .errors import (MC_EADDRESS, MC_EARG, MC_ETIMEOUT, ClientClosedError, InvalidInputError, MeshcorrError,
                     MeshcorrTimeoutError)
from .result import WANT_DEFORMED, WANT_METRICS, WANT_P, WANT_Q, Result, add_stages, number, progress_dict, result_of


def _default_server() -> str:
    env = os.environ.get("MESHCORR_SERVER")
    if env:
        return env
    return "unix:/run/meshcorr/meshcorrd.sock"      # MC_DEFAULT_SERVER: the shipped config's socket


def _quality(q: Any) -> Optional[Dict[str, Any]]:
    if q.verdict < 0:
        return None
    return {"verdict": lib.mc_quality_name(q.verdict).decode(), "flipped": q.flipped, "collapsed": q.collapsed}


def _state_name(state: int) -> str:
    name = lib.mc_state_name(state)
    return name.decode() if name else str(state)


class Client:
    """One connection to meshcorrd. server: "unix:PATH", "tls:HOST:PORT" or
    "tcp:HOST:PORT" (default $MESHCORR_SERVER, else
    unix:/run/meshcorr/meshcorrd.sock; a bare path is a Unix socket); token: the user's token for TCP
    (default $MESHCORR_TOKEN; a Unix socket needs none); ca: for tls:, the
    PEM file of the CA the server's certificate must chain to (default
    $MESHCORR_CA, else the system's trust store); timeout: seconds
    connecting and each request may take (MeshcorrTimeoutError past it;
    None: libmeshcorr's 30 s per request; 0: no limit). Use it from one
    thread at a time; close() it, or use it in a `with` block. Every call
    after close() raises ClientClosedError."""

    server: str
    user: str
    is_admin: bool

    def __init__(self, server: Optional[str] = None, token: Optional[str] = None,
                 timeout: Optional[float] = None, ca: Optional[str] = None) -> None:
        self._c: Optional[int] = None
        self.server = server or _default_server()
        bare_path = self.server.startswith(("/", ".")) or ":" not in self.server
        if not self.server.startswith(("unix:", "tcp:", "tls:")) and not bare_path:
            raise _lib.error(MC_EADDRESS, "server %r: expected unix:PATH (or a path), tls:HOST:PORT or tcp:HOST:PORT" % self.server,
                             InvalidInputError, "server")
        self.token = token if token is not None else os.environ.get("MESHCORR_TOKEN")
        self.timeout = timeout
        self.user, self.is_admin = "", False
        self.ca = ca
        self._c = self._connect()
        self.user = lib.mc_user(self._c).decode()
        self.is_admin = bool(lib.mc_is_admin(self._c))

    def _connect_now(self) -> int:
        c, err = _lib.c_client_p(), errbuf()
        rc = lib.mc_connect_ca(self.server.encode(), self.token.encode() if self.token else None,
                               os.fsencode(self.ca) if self.ca else None, ctypes.byref(c), err, len(err))
        check(rc, err.value)
        if self.timeout is not None:
            lib.mc_set_timeout(c, int(self.timeout * 1000))
        return c.value

    def _connect(self) -> int:
        """A new connection with HELLO done, within self.timeout: the
        connection attempt runs on a thread of its own, which closes what it
        got when the caller gave up waiting."""
        if not self.timeout:
            return self._connect_now()
        box: Dict[str, Any] = {}
        lock = threading.Lock()

        def attempt() -> None:
            try:
                c, e = self._connect_now(), None
            except Exception as ex:              # handed to the caller below
                c, e = None, ex
            with lock:
                if box.get("abandoned"):
                    lib.mc_close(c)
                else:
                    box["result"] = (c, e)

        t = threading.Thread(target=attempt, name="meshcorr-connect", daemon=True)
        t.start()
        t.join(self.timeout)
        with lock:
            if "result" not in box:
                box["abandoned"] = True
                raise _lib.error(MC_ETIMEOUT, "%s: not connected within %g s" % (self.server, self.timeout))
        c, e = box["result"]
        if e is not None:
            raise e
        return c

    def _handle(self) -> int:
        """The connection, or ClientClosedError after close()."""
        if self._c is None:
            raise _lib.error(MC_EARG, "I/O operation on closed client (%s)" % self.server, ClientClosedError)
        return self._c

    def _check(self, rc: int) -> None:
        check(rc, lib.mc_errmsg(self._c) if rc else b"")

    @property
    def closed(self) -> bool:
        return self._c is None

    def close(self) -> None:
        """Closes the connection (again: nothing). Jobs keep running on the server."""
        c, self._c = self._c, None
        lib.mc_close(c)

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:                        # interpreter shutdown: the library may be gone
            pass

    def __enter__(self) -> "Client":
        self._handle()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        return "Client(server=%r, user=%r%s)" % (self.server, self.user, ", closed" if self.closed else "")

    def submit(self, source: MeshLike, target: MeshLike, landmarks: Optional[Any] = None,
               init: Optional[Any] = None, init_reverse: Optional[Any] = None, priority: int = 0,
               label: Optional[str] = None, quantization: int = 0, device: Optional[str] = None,
               init_base: Optional[int] = None, **params: Any) -> "Job":
        """Submits a job; returns its Job. source, target: a mesh file's path
        (.off .obj .ply, or .drc sent as it is) or (V, F) numpy arrays;
        landmarks: (k, 2) (source, target) vertex ids (integers: a numpy
        integer array or pairs; anything else is refused naming the
        element), or a landmark file's path (str or os.PathLike: pairs,
        `source_vertex target_vertex` a line, read by libmeshcorr with the
        reader of `meshcorr submit --landmarks`), or a tuple of two paths
        (a source and a target list: --source-landmarks and
        --target-landmarks); init, init_reverse: initial maps P and Q (a
        Map; a map file, meshcorr-map 1 or a vertex map, one target vertex
        a line, 0- or 1-based by the rule of `meshcorr match --init-base`
        unless init_base says; or an array of 0-based target vertex ids);
        quantization: bits per coordinate (0 lossless); device: an OpenCL
        device name part (backend "opencl:DEVICE"); params: the job
        parameters of PARAMS by name (model="injective", iterations=5,
        beta0=1e3, partial=True, backend="cpu", stages="ddm,ectm", ...). A
        bad value is refused with the server's message (BadParamsError,
        BadLandmarksError, BadMeshError: ValueErrors, with .field naming the
        argument)."""
        c = self._handle()
        s = Spec(source, target, landmarks, init, init_reverse, priority, label, quantization, device, init_base,
                 params)
        job_id = ctypes.c_uint64()
        self._check(lib.mc_submit(c, ctypes.byref(s.spec), ctypes.byref(job_id)))
        job = Job(self, job_id.value, s.target_vertices() if s.injective else None)
        job.state = "PENDING"
        return job

    def job(self, job_id: int) -> "Job":
        """The Job of an id (one submitted earlier, or by someone else for an admin)."""
        self._handle()
        return Job(self, int(job_id), None)

    def list(self, user: Optional[str] = None, states: Optional[Sequence[str]] = None) -> List[Dict[str, Any]]:
        """Jobs as dicts (id, state, user, priority, submit_ms, outer, total,
        label, quality: see Job.status; fraction, eta: the latest progress
        record's share of the whole job done and seconds left, None when not
        known; ahead: a pending job's place in the queue): own ones, or
        user's (admin); states: names to keep."""
        c = self._handle()
        mask = 0
        for s in states or ():
            v = lib.mc_state_parse(s.encode())
            if v < 0:
                raise _lib.error(MC_EARG, "unknown job state %r" % s, InvalidInputError, "states")
            mask |= 1 << v
        jobs, n = ctypes.POINTER(_lib.JobInfo)(), ctypes.c_uint32()
        self._check(lib.mc_list(c, user.encode() if user else None, mask, ctypes.byref(jobs), ctypes.byref(n)))
        try:
            return [{"id": j.job_id, "state": _state_name(j.state), "user": j.user.decode(),
                     "priority": j.priority, "submit_ms": j.submit_ms, "outer": j.outer, "total": j.total,
                     "label": j.label.decode(), "quality": _quality(j.quality), "fraction": number(j.fraction),
                     "eta": number(j.eta_s), "ahead": j.ahead} for j in jobs[:n.value]]
        finally:
            _lib.free(jobs)

    def stats(self) -> Dict[str, Any]:
        """The server's statistics as a dict (queued, running, workers,
        completed, failed, cancelled, slots, devices, backend, backend_ok,
        backend_status)."""
        c = self._handle()
        s = _lib.ServerStats()
        self._check(lib.mc_stats(c, ctypes.byref(s)))
        try:
            names = {0: "idle", 1: "starting", 2: "busy", 3: "draining"}
            return {"queued": s.queued, "running": s.running, "workers": s.workers,
                    "completed": s.completed, "failed": s.failed, "cancelled": s.cancelled,
                    "slots": [{"job": s.slot_job[i], "state": names.get(s.slot_state[i], "?")}
                              for i in range(s.nslots)],
                    "devices": [s.devices[i].value.decode() for i in range(s.ndevices)],
                    "backend": s.backend.decode(), "backend_ok": bool(s.backend_ok),
                    "backend_status": s.backend_status.decode()}
        finally:
            lib.mc_stats_free(ctypes.byref(s))


class _End:
    """The watch thread's last word: mc_watch's code and the job's end."""

    def __init__(self, rc: int, err: bytes, state: int, reason: str) -> None:
        self.rc, self.err, self.state, self.reason = rc, err, state, reason


class Job:
    """A job on the server. id: its number; state: its state's name as last
    seen here ("PENDING" after submit; status(), watch() and wait() update
    it; None for Client.job() until then); reason: why it ended, after
    watch() or wait(); error: after watch() or wait(), the exception of the
    kind the job failed with (errors.py's class of its code: NumericError,
    BadMeshError, ...; code and name NUMERIC, BAD_MESH, ...), None when it
    did not fail in its worker."""

    id: int
    state: Optional[str]
    reason: str
    error: Optional[MeshcorrError]

    def __init__(self, client: Client, job_id: int, n_target: Optional[int]) -> None:
        self.client, self.id, self._n_target = client, job_id, n_target
        self.state, self.reason, self.error = None, "", None

    def __repr__(self) -> str:
        return "Job(id=%d, state=%r)" % (self.id, self.state)

    def status(self) -> Dict[str, Any]:
        """A dict: id, state, priority, user, label, reason, submit_ms,
        start_ms, end_ms, progress (the latest, as watch() yields, or None),
        quality (once COMPLETED, how good the map is as the worker measured
        it: a dict verdict "ok", "folded" or "reversed", flipped and
        collapsed fractions; None before)."""
        c = self.client._handle()
        s = _lib.JobStatus()
        self.client._check(lib.mc_status(c, self.id, ctypes.byref(s)))
        self.state = _state_name(s.state)
        return {"id": s.job_id, "state": self.state, "priority": s.priority,
                "user": s.user.decode(), "label": s.label.decode(), "reason": s.reason.decode(),
                "submit_ms": s.submit_ms, "start_ms": s.start_ms, "end_ms": s.end_ms,
                "progress": progress_dict(s.progress) if s.has_progress else None,
                "quality": _quality(s.quality)}

    def watch(self, from_outer: int = 0, timeout: Optional[float] = None) -> Iterator[Dict[str, Any]]:
        """Yields a progress dict per record (replayed from outer iteration
        from_outer, then live) until the job ends; then self.state and
        self.reason tell how it ended. A dict: job, stage (queued, start,
        rhm, ddm, repair, ectm), outer, total, fraction (the whole job's
        share done), eta (seconds left; None not known), elapsed (s), ahead
        (queued: jobs before it), beta, gamma, membrane, bending,
        mismatch, reverse, energy (both directions summed), and source,
        target: each direction's terms and inner iterations. timeout:
        seconds the whole watch may take; past it MeshcorrTimeoutError (a
        TimeoutError), and the job keeps running on the server. It follows
        the job on a connection of its own, closed when the watch ends or
        is abandoned."""
        self.client._handle()                # ClientClosedError after close()
        conn = self.client._connect()
        deadline = None if timeout is None else time.monotonic() + timeout
        records: "queue.Queue[Any]" = queue.Queue()
        lock = threading.Lock()
        open_ = [True]

        def on_progress(ctx: Any, p: Any) -> int:
            records.put(progress_dict(p.contents))
            return 0

        cb = _lib.PROGRESS_FN(on_progress)

        def run() -> None:
            state, reason = ctypes.c_int(-1), ctypes.create_string_buffer(1100)
            rc = lib.mc_watch(conn, self.id, from_outer, cb, None, ctypes.byref(state), reason, len(reason))
            err = lib.mc_errmsg(conn) if rc else b""
            with lock:                       # never closed while the caller interrupts it
                open_[0] = False
                lib.mc_close(conn)
            records.put(_End(rc, err, state.value, reason.value.decode(errors="replace")))

        threading.Thread(target=run, name="meshcorr-watch-%d" % self.id, daemon=True).start()
        end = None
        try:
            while end is None:
                left = None if deadline is None else deadline - time.monotonic()
                try:
                    if left is not None and left <= 0:
                        raise queue.Empty
                    r = records.get(timeout=left)
                except queue.Empty:
                    raise self._timed_out(timeout) from None
                if isinstance(r, _End):
                    end = r
                else:
                    yield r
        finally:
            if end is None:                  # abandoned: a timeout, break, an exception, Ctrl-C
                with lock:
                    if open_[0]:
                        lib.mc_interrupt(conn)
        check(end.rc, end.err)
        self.state = _state_name(end.state)
        self.reason = end.reason
        code = lib.mc_reason_error(end.reason.encode())     # the kind the job failed with, if any
        self.error = _lib.error(code, end.reason) if code else None

    def _timed_out(self, timeout: float) -> Exception:
        try:
            now = "still %s" % self.status()["state"]
        except Exception:                    # the message only; the timeout is what matters
            now = "not ended"
        return _lib.error(MC_ETIMEOUT, "job %d %s after %g s; it keeps running on the server (cancel() stops it)"
                          % (self.id, now, timeout), MeshcorrTimeoutError)

    def wait(self, timeout: Optional[float] = None) -> str:
        """Follows the job to its end; returns its final state's name
        ("COMPLETED", "FAILED", ...; the reason is in self.reason). timeout:
        seconds to wait at most; past it MeshcorrTimeoutError (a
        TimeoutError), and the job keeps running on the server."""
        for _ in self.watch(timeout=timeout):
            pass
        return self.state

    def result(self, deformed: bool = False, metrics: bool = True, n_target: Optional[int] = None,
               stages: bool = False) -> Result:
        """The maps of a COMPLETED job as a Result: p (and q for the
        bijective model) as Maps, the deformed source (V, F) when deformed;
        with stages, RHM's maps that ECTM started from in Result.stages
        ("rhm", and "rhm-reverse" for the bijective model) on a chain RHM
        then ECTM. n_target: the target's vertex count for an injective
        job's P (known when this client submitted it). JobStateError when
        the job has no maps (not COMPLETED)."""
        c = self.client._handle()
        want = WANT_P | WANT_Q | (WANT_DEFORMED if deformed else 0) | (WANT_METRICS if metrics else 0)
        r = _lib.JobResult()
        self.client._check(lib.mc_result(c, self.id, want, ctypes.byref(r)))
        try:
            res = result_of(r, n_target or self._n_target, "job %d" % self.id)
        finally:
            lib.mc_result_free(ctypes.byref(r))
        if stages:
            s = _lib.StageMaps()
            self.client._check(lib.mc_result_stage(c, self.id, b"rhm", ctypes.byref(s)))
            try:
                add_stages(res, s)
            finally:
                lib.mc_stage_maps_free(ctypes.byref(s))
        return res

    def cancel(self) -> None:
        """Asks the server to cancel the job (it ends CANCELLED)."""
        self.client._check(lib.mc_cancel(self.client._handle(), self.id))

    def delete(self) -> None:
        """Deletes the job and its results from the server."""
        self.client._check(lib.mc_delete(self.client._handle(), self.id))

