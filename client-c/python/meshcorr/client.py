"""client.py — Client (one connection to meshcorrd) and Job (one job on
it): submit from mesh files or numpy arrays, status, watch, wait, result,
cancel, delete, list, stats. Every failure raises MeshcorrError with the
protocol's (or libmeshcorr's) code and the server's message."""
import ctypes
import os
import queue
import threading

import numpy as np

from . import _lib
from ._lib import lib, check, errbuf
from .errors import MeshcorrError
from .map import Map, is_map_file, read_map, read_vertex_map, vertex_map

STAGES = ("start", "rhm", "ectm", "init", "ddm", "repair", "queued")
_WANT_P, _WANT_Q, _WANT_DEFORMED, _WANT_METRICS = 1, 2, 4, 8
_PARAM_NAMES = {p.name: p for p in _lib.PARAMS}


def _default_server():
    env = os.environ.get("MESHCORR_SERVER")
    if env:
        return env
    return "unix:%s/meshcorr.sock" % (os.environ.get("XDG_RUNTIME_DIR") or "/tmp")


def _text(value):
    """A keyword's value as the text `meshcorr submit --option` takes."""
    if isinstance(value, (bool, np.bool_)):
        return "1" if value else "0"
    if isinstance(value, float):
        return "%.17g" % value
    return str(value)


def _encode(mesh, qbits):
    """(Draco bytes as a ctypes buffer, length) of a path or a (V, F) pair."""
    out, n, err = _lib.c_u8p(), ctypes.c_size_t(), errbuf()
    if isinstance(mesh, (str, bytes, os.PathLike)):
        rc = lib.mc_encode_mesh_file_quantized(os.fsencode(mesh), qbits, ctypes.byref(out), ctypes.byref(n),
                                               err, len(err))
    else:
        V, F = mesh
        V = np.ascontiguousarray(V, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.intc)
        if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
            raise ValueError("a mesh is a path or (V, F): V n by 3 floats, F m by 3 vertex indices")
        rc = lib.mc_encode_mesh_quantized(V.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), len(V),
                                          F.ctypes.data_as(ctypes.POINTER(ctypes.c_int)), len(F), qbits,
                                          ctypes.byref(out), ctypes.byref(n), err, len(err))
    check(rc, err.value)
    try:
        return ctypes.create_string_buffer(ctypes.string_at(out, n.value), n.value), n.value
    finally:
        _lib.free(out)


def _vertex_count(blob, n):
    v, nv = ctypes.POINTER(ctypes.c_double)(), ctypes.c_int()
    f, nf, err = ctypes.POINTER(ctypes.c_int)(), ctypes.c_int(), errbuf()
    rc = lib.mc_decode_mesh(ctypes.cast(blob, _lib.c_u8p), n, ctypes.byref(v), ctypes.byref(nv),
                            ctypes.byref(f), ctypes.byref(nf), err, len(err))
    _lib.free(v)
    _lib.free(f)
    check(rc, err.value)
    return nv.value


def _mesh_of(blob, n):
    """(vertex count, faces as an (m, 3) array) of Draco bytes."""
    v, nv = ctypes.POINTER(ctypes.c_double)(), ctypes.c_int()
    f, nf, err = ctypes.POINTER(ctypes.c_int)(), ctypes.c_int(), errbuf()
    rc = lib.mc_decode_mesh(ctypes.cast(blob, _lib.c_u8p), n, ctypes.byref(v), ctypes.byref(nv),
                            ctypes.byref(f), ctypes.byref(nf), err, len(err))
    F = np.ctypeslib.as_array(f, (nf.value * 3,)).reshape(-1, 3).copy() if rc == 0 else None
    _lib.free(v)
    _lib.free(f)
    check(rc, err.value)
    return nv.value, F


def _rows(m, to=None, n_from=None, base=None):
    """A Map, a map file's path (meshcorr-map 1, or a vertex map onto the
    mesh to = (Draco bytes, length) with n_from rows, base as init_base),
    or 0-based vertex ids as an array of mc_map_row."""
    if not isinstance(m, Map):
        if isinstance(m, (str, bytes, os.PathLike)) and is_map_file(m):
            m = read_map(m)
        else:
            nt, F = _mesh_of(*to)
            if isinstance(m, (str, bytes, os.PathLike)):
                m = read_vertex_map(m, F, nt, n_from, base)
            else:
                m = vertex_map(m, F, nt)
    rows = (_lib.MapRow * len(m))()
    for i, (f, w) in enumerate(zip(m.faces.tolist(), m.weights.tolist())):
        rows[i].face = f
        rows[i].w[:] = w
    return rows


def _map_of(rows, n, n_target):
    a = np.ctypeslib.as_array(ctypes.cast(rows, ctypes.POINTER(ctypes.c_byte)),
                              (n * ctypes.sizeof(_lib.MapRow),))
    rec = a.view(np.dtype([("face", np.uint32), ("w", np.float64, 3)], align=True))
    return Map(rec["face"].astype(np.int32), rec["w"].copy(), n_target)


def _number(v):
    """A C double as JSON has it: None for NaN."""
    return None if v != v else v


def _progress(p):
    """A progress record with the names `meshcorr watch --progress json` prints."""
    d = {"job": p.job_id, "stage": STAGES[p.stage] if p.stage < len(STAGES) else str(p.stage),
         "outer": p.outer, "total": p.total, "fraction": _number(p.fraction), "eta": _number(p.eta_s),
         "elapsed": p.elapsed_s, "ahead": p.ahead, "beta": _number(p.beta), "gamma": _number(p.gamma)}
    for side, name in enumerate(("source", "target")):
        d[name] = {t: getattr(p, t)[side] for t in ("membrane", "bending", "mismatch", "reverse", "energy")}
        d[name]["inner"] = p.inner[side]
    for t in ("membrane", "bending", "mismatch", "reverse", "energy"):
        d[t] = d["source"][t] + d["target"][t]      # both directions, as `meshcorr watch` prints
    return d


class Result:
    """p, q: Map (q None for an injective job); deformed: (V, F) of the
    deformed source when asked, else None; metrics: {name: value}."""

    def __init__(self, p, q, deformed, metrics):
        self.p, self.q, self.deformed, self.metrics = p, q, deformed, metrics


class Client:
    """One connection to meshcorrd. server: "unix:PATH" or "tcp:HOST:PORT"
    (default $MESHCORR_SERVER, else unix:$XDG_RUNTIME_DIR/meshcorr.sock);
    token: the user's token for TCP (default $MESHCORR_TOKEN; a Unix socket
    needs none); timeout: seconds a request waits (None: libmeshcorr's 30 s;
    0: forever). Use it from one thread at a time; close() or `with`."""

    def __init__(self, server=None, token=None, timeout=None):
        self.server = server or _default_server()
        self.token = token if token is not None else os.environ.get("MESHCORR_TOKEN")
        self.timeout = timeout
        self._c = self._connect()
        self.user = lib.mc_user(self._c).decode()
        self.is_admin = bool(lib.mc_is_admin(self._c))

    def _connect(self):
        c, err = _lib.c_client_p(), errbuf()
        rc = lib.mc_connect(self.server.encode(), self.token.encode() if self.token else None,
                            ctypes.byref(c), err, len(err))
        check(rc, err.value)
        if self.timeout is not None:
            lib.mc_set_timeout(c, int(self.timeout * 1000))
        return c

    def _check(self, rc):
        check(rc, lib.mc_errmsg(self._c) if rc else b"")

    def close(self):
        lib.mc_close(self._c)
        self._c = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def submit(self, source, target, landmarks=None, init=None, init_reverse=None, priority=0, label=None,
               quantization=0, device=None, init_base=None, **params):
        """Submits a job; returns its Job. source, target: a mesh file's path
        or (V, F) numpy arrays; landmarks: (k, 2) (source, target) vertex
        ids; init, init_reverse: initial maps P and Q (a Map; a map file,
        meshcorr-map 1 or a vertex map, one target vertex a line, 0- or
        1-based by the rule of `meshcorr match --init-base` unless
        init_base says; or an array of 0-based target vertex ids);
        quantization: bits per coordinate (0 lossless); device: an OpenCL
        device name part (backend "opencl:DEVICE"); params: the job
        parameters of `meshcorr params` by name (model="injective",
        iterations=5, beta0=1e3, partial=True, backend="cpu",
        stages="ddm,ectm", ...). A bad
        value is refused with the server's message."""
        qbits = int(quantization)
        sb, sn = _encode(source, qbits)
        tb, tn = _encode(target, qbits)
        spec = _lib.JobSpec()
        lib.mc_job_spec_init(ctypes.byref(spec))
        spec.source, spec.source_len = ctypes.cast(sb, _lib.c_u8p), sn
        spec.target, spec.target_len = ctypes.cast(tb, _lib.c_u8p), tn
        keep = [sb, tb]
        if landmarks is not None:
            lm = np.ascontiguousarray(landmarks, dtype=np.int64)
            if lm.ndim != 2 or lm.shape[1] != 2 or (lm < 0).any() or (lm > 0xffffffff).any():
                raise ValueError("landmarks: a (k, 2) array of (source, target) vertex ids")
            lm = lm.astype(np.uint32)
            keep.append(lm)
            spec.landmarks = lm.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32))
            spec.nlandmarks = len(lm)
        if init is not None:
            rows = _rows(init, (tb, tn), _mesh_of(sb, sn)[0], init_base)
            keep.append(rows)
            spec.p, spec.np = rows, len(rows)
        if init_reverse is not None:
            rows = _rows(init_reverse, (sb, sn), _mesh_of(tb, tn)[0], init_base)
            keep.append(rows)
            spec.q, spec.nq = rows, len(rows)
        if device is not None:
            params["backend"] = "%s:%s" % (params.get("backend") or "cpu", device)
        for name, value in params.items():
            text = _text(value).encode()
            keep.append(text)
            err = errbuf()
            check(lib.mc_job_spec_set(ctypes.byref(spec), name.encode(), text, err, len(err)), err.value)
        spec.priority = int(priority)
        if label is not None:
            spec.label = label.encode()
        job_id = ctypes.c_uint64()
        self._check(lib.mc_submit(self._c, ctypes.byref(spec), ctypes.byref(job_id)))
        injective = spec.model == 1
        return Job(self, job_id.value, _vertex_count(tb, tn) if injective else None)

    def job(self, job_id):
        """The Job of an id (one submitted earlier, or by someone else for an admin)."""
        return Job(self, int(job_id), None)

    def list(self, user=None, states=None):
        """Jobs as dicts (id, state, user, priority, submit_ms, outer, total,
        label, quality: see Job.status; fraction, eta: the latest progress
        record's share of the whole job done and seconds left, None when not
        known; ahead: a pending job's place in the queue): own ones, or
        user's (admin); states: names to keep."""
        mask = 0
        for s in states or ():
            v = lib.mc_state_parse(s.encode())
            if v < 0:
                raise ValueError("unknown job state %r" % s)
            mask |= 1 << v
        jobs, n = ctypes.POINTER(_lib.JobInfo)(), ctypes.c_uint32()
        self._check(lib.mc_list(self._c, user.encode() if user else None, mask, ctypes.byref(jobs),
                                ctypes.byref(n)))
        try:
            return [{"id": j.job_id, "state": lib.mc_state_name(j.state).decode(), "user": j.user.decode(),
                     "priority": j.priority, "submit_ms": j.submit_ms, "outer": j.outer, "total": j.total,
                     "label": j.label.decode(), "quality": _quality(j.quality), "fraction": _number(j.fraction),
                     "eta": _number(j.eta_s), "ahead": j.ahead} for j in jobs[:n.value]]
        finally:
            _lib.free(jobs)

    def stats(self):
        """The server's statistics as a dict (queued, running, workers,
        completed, failed, cancelled, slots, devices, backend, backend_ok,
        backend_status)."""
        s = _lib.ServerStats()
        self._check(lib.mc_stats(self._c, ctypes.byref(s)))
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


def _quality(q):
    if q.verdict < 0:
        return None
    return {"verdict": lib.mc_quality_name(q.verdict).decode(), "flipped": q.flipped, "collapsed": q.collapsed}


class Job:
    """A job on the server. id: its number. After watch() or wait() ends:
    state (the final state's name), reason, and error: a MeshcorrError of
    the kind the job failed with (code and name: NUMERIC, BAD_MESH, ...),
    None when it did not fail in its worker."""

    def __init__(self, client, job_id, n_target):
        self.client, self.id, self._n_target = client, job_id, n_target
        self.state, self.reason, self.error = None, "", None

    def __repr__(self):
        return "Job(%d)" % self.id

    def status(self):
        """A dict: id, state, priority, user, label, reason, submit_ms,
        start_ms, end_ms, progress (the latest, as watch() yields, or None),
        quality (once COMPLETED, how good the map is as the worker measured
        it: a dict verdict "ok", "folded" or "reversed", flipped and
        collapsed fractions; None before)."""
        s = _lib.JobStatus()
        self.client._check(lib.mc_status(self.client._c, self.id, ctypes.byref(s)))
        return {"id": s.job_id, "state": lib.mc_state_name(s.state).decode(), "priority": s.priority,
                "user": s.user.decode(), "label": s.label.decode(), "reason": s.reason.decode(),
                "submit_ms": s.submit_ms, "start_ms": s.start_ms, "end_ms": s.end_ms,
                "progress": _progress(s.progress) if s.has_progress else None,
                "quality": _quality(s.quality)}

    def watch(self, from_outer=0):
        """Yields a progress dict per record (replayed from outer iteration
        from_outer, then live) until the job ends; then self.state and
        self.reason tell how it ended. A dict: job, stage (queued, start,
        rhm, ddm, repair, ectm), outer, total, fraction (the whole job's
        share done), eta (seconds left; None not known), elapsed (s), ahead
        (queued: jobs before it), beta, gamma, membrane, bending,
        mismatch, reverse, energy (both directions summed), and source,
        target: each direction's terms and inner iterations. It follows the
        job on a connection of its own."""
        records, stop = queue.Queue(), threading.Event()
        conn = self.client._connect()

        def on_progress(ctx, p):
            records.put(_progress(p.contents))
            return 1 if stop.is_set() else 0

        def run():
            state, reason = ctypes.c_int(-1), ctypes.create_string_buffer(1100)
            rc = lib.mc_watch(conn, self.id, from_outer, cb, None, ctypes.byref(state), reason, len(reason))
            err = lib.mc_errmsg(conn) if rc else b""
            lib.mc_close(conn)
            records.put((rc, err, state.value, reason.value.decode(errors="replace")))

        cb = _lib.PROGRESS_FN(on_progress)
        t = threading.Thread(target=run, daemon=True)
        t.start()
        try:
            while True:
                r = records.get()
                if isinstance(r, tuple):
                    break
                yield r
        finally:
            stop.set()
        t.join()
        rc, err, state, reason = r
        check(rc, err)
        self.state = lib.mc_state_name(state).decode() if lib.mc_state_name(state) else str(state)
        self.reason = reason
        code = lib.mc_reason_error(reason.encode())     # the kind the job failed with, if any
        self.error = (MeshcorrError(code, lib.mc_err_name(code).decode(), lib.mc_strerror(code).decode(),
                                    reason) if code else None)

    def wait(self):
        """Follows the job to its end; returns its final state's name
        ("COMPLETED", "FAILED", ...; the reason is in self.reason)."""
        for _ in self.watch():
            pass
        return self.state

    def result(self, deformed=False, metrics=True, n_target=None):
        """The maps of a COMPLETED job as a Result: p (and q for the
        bijective model) as Maps, the deformed source (V, F) when deformed.
        n_target: the target's vertex count for an injective job's P (known
        when this client submitted it)."""
        want = _WANT_P | _WANT_Q | (_WANT_DEFORMED if deformed else 0) | (_WANT_METRICS if metrics else 0)
        r = _lib.JobResult()
        self.client._check(lib.mc_result(self.client._c, self.id, want, ctypes.byref(r)))
        try:
            nt = r.nq or n_target or self._n_target
            if not nt:
                raise ValueError("injective job %d: give n_target (the target's vertex count)" % self.id)
            p = _map_of(r.p, r.np, nt)
            q = _map_of(r.q, r.nq, r.np) if r.nq else None
            y = None
            if deformed and r.deformed_len:
                v, nv = ctypes.POINTER(ctypes.c_double)(), ctypes.c_int()
                f, nf, err = ctypes.POINTER(ctypes.c_int)(), ctypes.c_int(), errbuf()
                rc = lib.mc_decode_mesh(r.deformed, r.deformed_len, ctypes.byref(v), ctypes.byref(nv),
                                        ctypes.byref(f), ctypes.byref(nf), err, len(err))
                try:
                    check(rc, err.value)
                    y = (np.ctypeslib.as_array(v, (nv.value, 3)).copy(),
                         np.ctypeslib.as_array(f, (nf.value, 3)).astype(np.int32))
                finally:
                    _lib.free(v)
                    _lib.free(f)
            m = {r.metric_keys[i].decode(): r.metric_values[i] for i in range(r.nmetrics)}
            return Result(p, q, y, m)
        finally:
            lib.mc_result_free(ctypes.byref(r))

    def cancel(self):
        self.client._check(lib.mc_cancel(self.client._c, self.id))

    def delete(self):
        self.client._check(lib.mc_delete(self.client._c, self.id))
