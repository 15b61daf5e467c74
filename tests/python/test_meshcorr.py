"""test_meshcorr.py — the Python package meshcorr against a real meshcorrd,
one case per run: `test_meshcorr.py CASE`. Driven by tests/unit/test_python.c,
which starts the daemon, writes the icosphere pair and sets the
MESHCORR_TEST_* variables; exit status 0 = the case passed. The working
directory is the repository's root, except for the fresh-venv case."""
import ctypes
import os
import pickle
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import typing

import numpy as np

import meshcorr

E = os.environ
UNIX, TCP, DIR = E["MESHCORR_TEST_UNIX"], E["MESHCORR_TEST_TCP"], E["MESHCORR_TEST_DIR"]
SRC, TGT = E["MESHCORR_TEST_SRC"], E["MESHCORR_TEST_TGT"]
ALICE, BOB = E["MESHCORR_TEST_ALICE"], E["MESHCORR_TEST_BOB"]
LANDMARKS = np.array([[i, i] for i in range(6)])
JOB = dict(iterations=4, beta_ramp=4, inner_iterations=10, rhm_iterations=3)
CLI_JOB = "--iterations 4 --beta-ramp 4 --inner-iterations 10 --rhm-iterations 3"
TERMS = ("membrane", "bending", "mismatch", "reverse", "energy")


def read_off(path):
    """(V, F) of an OFF file as mesh_write writes it."""
    words = open(path).read().split()
    assert words[0] == "OFF"
    nv, nf = int(words[1]), int(words[2])
    V = np.array(words[4:4 + 3 * nv], dtype=np.float64).reshape(nv, 3)
    F = np.array(words[4 + 3 * nv:4 + 3 * nv + 4 * nf], dtype=np.int64).reshape(nf, 4)
    assert (F[:, 0] == 3).all()
    return V, F[:, 1:]


def expect_error(code, name, fn, *args, has=None, **kw):
    try:
        fn(*args, **kw)
    except meshcorr.MeshcorrError as e:
        assert (e.code, e.name) == (code, name), "%d %s, expected %d %s: %s" % (e.code, e.name, code, name, e)
        assert has is None or has in e.message, "message %r lacks %r" % (e.message, has)
        return e
    raise AssertionError("no MeshcorrError %d from %s" % (code, fn.__name__))


REPO = E.get("MESHCORR_TEST_REPO", ".")


def cli(*args):
    r = subprocess.run([os.path.join(REPO, "build/meshcorr")] + list(args), capture_output=True, text=True)
    assert r.returncode == 0, "meshcorr %s: %s" % (" ".join(args), r.stderr)
    return r.stdout


def case_files_watch_result_same_as_cli():
    c = meshcorr.Client(UNIX)
    job = c.submit(SRC, TGT, landmarks=LANDMARKS, label="py", **JOB)
    records = list(job.watch())
    assert job.state == "COMPLETED", (job.state, job.reason)
    assert records, "no progress"
    for r in records:
        for k in TERMS + ("beta", "gamma", "elapsed", "outer", "total", "stage"):
            assert k in r, k
        for side in ("source", "target"):
            assert set(r[side]) == set(TERMS + ("inner",)), r[side]
        assert abs(r["energy"] - r["source"]["energy"] - r["target"]["energy"]) <= 1e-12 * abs(r["energy"]) + 1e-300
    stages = [r["stage"] for r in records]
    assert "ectm" in stages and stages[-1] == "repair", stages     # the repair of ECTM's maps ends it
    ectm = [r for r in records if r["stage"] == "ectm"]
    assert [r["outer"] for r in ectm] == [1, 2, 3, 4] and ectm[-1]["total"] == 4, ectm
    st = c.job(job.id).status()
    assert st["state"] == "COMPLETED"
    res = job.result(deformed=True)
    # the map's quality in the job's status and list row: the worker's metrics
    q = st["quality"]
    assert q is not None and q["verdict"] in ("ok", "folded", "reversed"), st
    assert q["flipped"] == res.metrics["flipped_fraction"], (q, res.metrics)
    assert q["collapsed"] == res.metrics["collapsed_fraction"], (q, res.metrics)
    V, F = read_off(SRC)
    VT, FT = read_off(TGT)
    assert res.p.faces.dtype == np.int32 and res.p.weights.dtype == np.float64
    assert len(res.p) == len(V) and len(res.q) == len(VT) and res.p.n_target == len(VT)
    assert np.allclose(res.p.weights.sum(1), 1)
    assert res.deformed[0].shape == V.shape and np.array_equal(res.deformed[1], F)
    pts = res.p.points(VT, FT)
    assert pts.shape == V.shape and np.isfinite(pts).all()

    # the CLI's job with the same options: the same maps, the same file
    cid = int(cli("submit", SRC, TGT, "--landmarks", E["MESHCORR_TEST_LMK"], *CLI_JOB.split(),
                  "--label", "cli", "--server", UNIX))
    cli("watch", str(cid), "--server", UNIX)
    pm, qm = os.path.join(DIR, "cli-p.map"), os.path.join(DIR, "cli-q.map")
    cli("result", str(cid), "--out", pm, "--out-reverse", qm, "--server", UNIX)
    assert meshcorr.read_map(pm) == res.p and meshcorr.read_map(qm) == res.q
    mine = os.path.join(DIR, "py-p.map")
    res.p.write(mine, comment="meshcorrd job %d" % cid)
    assert open(mine).read() == open(pm).read()
    assert meshcorr.read_map(mine) == res.p

    listed = {j["id"]: j for j in c.list()}
    assert listed[job.id]["label"] == "py" and listed[cid]["state"] == "COMPLETED"
    assert listed[job.id]["quality"] == q, listed[job.id]
    s = c.stats()
    assert s["completed"] >= 2 and s["workers"] >= 1, s
    job.delete()
    expect_error(-15, "NOT_FOUND", job.status)


def case_arrays_same_map_as_files():
    c = meshcorr.Client(UNIX)
    S, T = read_off(SRC), read_off(TGT)
    a = c.submit(S, T, landmarks=LANDMARKS, **JOB)
    f = c.submit(SRC, TGT, landmarks=LANDMARKS, **JOB)
    assert a.wait() == "COMPLETED" and f.wait() == "COMPLETED"
    ra, rf = a.result(), f.result()
    assert ra.p == rf.p and ra.q == rf.q
    # injective from arrays, init from the bijective map: P only, sized by the target
    i = c.submit(S, T, init=rf.p, model="injective", iterations=2, beta_ramp=2, inner_iterations=5)
    assert i.wait() == "COMPLETED", i.reason
    ri = i.result()
    assert ri.q is None and len(ri.p) == len(S[0]) and ri.p.n_target == len(T[0])


def case_cancel():
    c = meshcorr.Client(UNIX)
    job = c.submit(SRC, TGT, landmarks=LANDMARKS, iterations=100000, stop_change=0, beta_ramp=4, inner_iterations=10,
                   rhm_iterations=3)
    for r in job.watch():
        if r["stage"] == "ectm":
            job.cancel()
            break
    assert job.wait() == "CANCELLED", job.state
    assert job.status()["state"] == "CANCELLED"
    expect_error(-16, "BAD_STATE", job.result)           # BAD_STATE: no maps of a cancelled job


def case_tokens_over_tcp():
    alice, bob = meshcorr.Client(TCP, ALICE), meshcorr.Client(TCP, BOB)
    assert alice.user == "alice" and bob.user == "bob"
    job = alice.submit(SRC, TGT, landmarks=LANDMARKS, **JOB)
    assert job.id in [j["id"] for j in alice.list()]
    assert job.id not in [j["id"] for j in bob.list()]
    expect_error(-15, "NOT_FOUND", bob.job(job.id).status)
    expect_error(-15, "NOT_FOUND", bob.job(job.id).cancel)
    assert job.wait() == "COMPLETED"
    expect_error(-13, "UNAUTHORIZED", meshcorr.Client, TCP, "not-a-token")
    os.environ["MESHCORR_SERVER"], os.environ["MESHCORR_TOKEN"] = TCP, BOB
    assert meshcorr.Client().user == "bob"     # the CLI's defaults


def case_bad_input_refused():
    c = meshcorr.Client(UNIX)
    V, F = read_off(SRC)
    nv = len(V)
    # one more face on an existing edge: three faces meet there
    Vb = np.vstack([V, [[2.0, 0, 0]]])
    Fb = np.vstack([F, [[F[0, 0], F[0, 1], nv]]])
    expect_error(-19, "BAD_MESH", c.submit, (Vb, Fb), SRC, landmarks=LANDMARKS, **JOB, repair="no",
                 has="non-manifold")
    expect_error(-20, "BAD_LANDMARKS", c.submit, SRC, TGT, landmarks=[[0, 0], [1, 1], [2, 500]], **JOB, has="500")
    expect_error(-21, "BAD_PARAMS", c.submit, SRC, TGT, landmarks=LANDMARKS, inner_iterations=500000,
                 has="inner_iterations")
    expect_error(-21, "BAD_PARAMS", c.submit, SRC, TGT, landmarks=LANDMARKS, iterations=0,
                 has="iterations = 0: out of range [1, 1000000]")
    expect_error(-100, "MC_EARG", c.submit, SRC, TGT, landmarks=LANDMARKS, model="sideways", has="sideways")
    expect_error(-100, "MC_EARG", c.submit, SRC, TGT, landmarks=LANDMARKS, no_such_option=1, has="no_such_option")
    expect_error(-100, "MC_EARG", c.submit, (V, np.array([[0, 1, nv + 5]])), TGT, landmarks=LANDMARKS)
    assert c.list() == []


def case_vertex_map_refined_by_ddm_then_ectm():
    """A vertex-map file (1-based, vertex i -> i) as init with stages
    ddm,ectm: progress shows the ddm stage, then ECTM's iterations; the same
    map given as 0-based ids gives the same result; a bad line is named."""
    c = meshcorr.Client(UNIX)
    V, F = read_off(SRC)
    path = os.path.join(DIR, "identity.vmap")
    with open(path, "w") as fp:
        fp.write("".join("%d\n" % (i + 1) for i in range(len(V))))
    job = c.submit(SRC, TGT, init=path, stages="ddm,ectm", ddm_k=30, label="vmap", **JOB)
    records = list(job.watch())
    assert job.state == "COMPLETED", (job.state, job.reason)
    stages = [r["stage"] for r in records]
    assert stages[:2] == ["ddm", "ddm"] and stages[2:] == ["ectm"] * 4, stages
    a = job.result().p
    job = c.submit(SRC, TGT, init=np.arange(len(V)), stages="ddm,ectm", ddm_k=30, **JOB)
    list(job.watch())
    assert job.state == "COMPLETED", (job.state, job.reason)
    assert job.result().p == a
    with open(path, "w") as fp:
        fp.write("".join("%d\n" % (i + 1) for i in range(len(V) - 1)) + "9999\n")
    try:
        c.submit(SRC, TGT, init=path, init_base=1, stages="ddm", **JOB)
    except ValueError as e:
        assert "identity.vmap:%d: target vertex 9999 out of range" % len(V) in str(e), e
    else:
        raise AssertionError("a vertex 9999 was not refused")
    expect_error(-100, "MC_EARG", c.submit, SRC, TGT, init=np.arange(len(V)), stages="ectm,ddm", has="ectm,ddm")


def case_failed_job_error_is_its_kind():
    """A job whose stage fails numerically (ECTM's energy overflows with a
    mismatch weight of 1e308) ends FAILED with Job.error the NUMERIC
    error (NumericError: a MeshcorrError and an ArithmeticError), the code
    and name the C layers use, its message the reason's after the name."""
    c = meshcorr.Client(UNIX)
    job = c.submit(SRC, TGT, landmarks=LANDMARKS, **dict(JOB, beta0=1e308, beta1=1e308))
    assert job.wait() == "FAILED", (job.state, job.reason)
    assert type(job.error) is meshcorr.NumericError, type(job.error)
    assert isinstance(job.error, meshcorr.MeshcorrError) and isinstance(job.error, ArithmeticError), job.error
    assert (job.error.code, job.error.name) == (-30, "NUMERIC"), job.error
    assert job.reason.startswith("NUMERIC: ") and job.error.message == job.reason[len("NUMERIC: "):], job.reason
    assert str(job.error) == "NUMERIC (-30): " + job.error.message, str(job.error)   # the name once
    ok = c.submit(SRC, TGT, landmarks=LANDMARKS, **JOB)
    assert ok.wait() == "COMPLETED" and ok.error is None, (ok.state, ok.reason)


def case_progress_keys_are_the_clis():
    """The progress dicts have the keys of `meshcorr watch --progress json`
    (and of meshcorr match's), and the whole job's fraction rises to 1."""
    c = meshcorr.Client(UNIX)
    job = c.submit(SRC, TGT, landmarks=LANDMARKS, **JOB)
    records = list(job.watch())
    assert job.state == "COMPLETED", (job.state, job.reason)
    import json
    lines = [json.loads(l) for l in cli("watch", str(job.id), "--progress", "json", "--server", UNIX).splitlines()
             if l.startswith("{")]
    assert len(lines) == len(records), (len(lines), len(records))
    for d, j in zip(records, lines):
        assert set(j) <= set(d), set(j) - set(d)
        for k in j:
            if k in ("source", "target"):
                assert set(j[k]) == set(d[k]), (j[k], d[k])
            elif isinstance(j[k], float) and k not in ("eta", "elapsed"):
                assert abs(j[k] - d[k]) <= 1e-12 * abs(j[k]), (k, j[k], d[k])
            elif k not in ("eta", "elapsed"):
                assert j[k] == d[k], (k, j[k], d[k])
    fr = [d["fraction"] for d in records]
    assert fr == sorted(fr) and fr[0] > 0 and fr[-1] == 1, fr
    assert records[0]["stage"] == "start", records[0]
    listed = {j["id"]: j for j in c.list()}
    assert listed[job.id]["fraction"] == 1 and listed[job.id]["ahead"] == 0, listed[job.id]
    assert job.status()["progress"]["fraction"] == 1


def expect(cls, fn, *args, has=None, **kw):
    """The exception fn raises, which must be a cls; has: a part of its text."""
    try:
        fn(*args, **kw)
    except cls as e:
        assert has is None or has in str(e), "%r lacks %r" % (str(e), has)
        return e
    raise AssertionError("no %s from %s" % (cls.__name__, getattr(fn, "__name__", fn)))


def case_closed_client_raises_value_error():
    """1: a closed client, and a Job used after its `with` block, raise
    ClientClosedError (a ValueError and a MeshcorrError) from every method;
    libmeshcorr itself refuses a NULL client instead of crashing."""
    c = meshcorr.Client(UNIX)
    c.close()
    c.close()                                            # again: nothing
    assert c.closed and "closed" in repr(c)
    calls = [c.list, c.stats, lambda: c.job(1), lambda: c.submit(SRC, TGT, landmarks=LANDMARKS)]
    with meshcorr.Client(UNIX) as w:
        job = w.submit(SRC, TGT, landmarks=LANDMARKS, **JOB)
    calls += [job.status, job.result, job.cancel, job.delete, job.wait, lambda: next(job.watch())]
    for fn in calls:
        e = expect(meshcorr.ClientClosedError, fn, has="I/O operation on closed client")
        assert isinstance(e, ValueError) and isinstance(e, meshcorr.MeshcorrError), type(e).__mro__
    # the C library under the binding: NULL is MC_EARG, never a crash
    lib = meshcorr._lib.lib
    n, jobs = ctypes.c_uint32(), ctypes.POINTER(meshcorr._lib.JobInfo)()
    assert lib.mc_list(None, None, 0, ctypes.byref(jobs), ctypes.byref(n)) == -100
    assert lib.mc_status(None, 1, ctypes.byref(meshcorr._lib.JobStatus())) == -100
    assert lib.mc_ping is not None and lib.mc_cancel(None, 1) == -100
    assert lib.mc_errmsg(None) == b"no client (NULL)" and lib.mc_user(None) == b""
    # the job is still on the server, and a new client sees it through
    with meshcorr.Client(UNIX) as again:
        assert again.job(job.id).wait() == "COMPLETED"


def case_version_is_the_project_version():
    """3: __version__ is the VERSION file, through mc_version()."""
    want = open(os.path.join(REPO, "VERSION")).read().strip()
    assert re.fullmatch(r"\d+\.\d+\.\d+", want), want
    assert meshcorr.__version__ == want == meshcorr._lib.lib.mc_version().decode(), meshcorr.__version__


def case_errors_are_builtin_subclasses():
    """4: each refusal is the built-in exception it means and a
    MeshcorrError, with the code, its name once in the text, and the field
    the message names. The daemon runs with --max-jobs-per-user 1."""
    c = meshcorr.Client(UNIX)
    e = expect(FileNotFoundError, c.submit, os.path.join(DIR, "none.off"), TGT, landmarks=LANDMARKS)
    assert isinstance(e, meshcorr.MeshFileNotFoundError) and e.field == "source" and e.filename.endswith("none.off")
    expect(FileNotFoundError, meshcorr.read_mesh, os.path.join(DIR, "none.ply"))
    e = expect(ConnectionError, meshcorr.Client, "unix:" + os.path.join(DIR, "no.sock"))
    assert isinstance(e, meshcorr.ServerConnectionError) and e.code == -102, e
    expect(ValueError, meshcorr.Client, "http://localhost")
    e = expect(PermissionError, meshcorr.Client, TCP, "not-a-token")
    assert (e.code, e.name) == (-13, "UNAUTHORIZED"), e
    e = expect(ValueError, c.submit, SRC, TGT, landmarks=LANDMARKS, iterations=0)
    assert isinstance(e, meshcorr.BadParamsError) and (e.code, e.field) == (-21, "iterations"), e
    assert str(e) == "BAD_PARAMS (-21): iterations = 0: out of range [1, 1000000]", str(e)   # the name once
    e = expect(ValueError, c.submit, SRC, TGT, landmarks=LANDMARKS, model="sideways")
    assert isinstance(e, meshcorr.BadParamsError) and e.field == "model", e
    e = expect(ValueError, c.submit, SRC, TGT, landmarks=[[0, 0], [1, 1], [2, 500]])
    assert isinstance(e, meshcorr.BadLandmarksError) and (e.code, e.field) == (-20, "landmarks"), e
    V, F = read_off(SRC)
    bad = (np.vstack([V, [[2.0, 0, 0]]]), np.vstack([F, [[F[0, 0], F[0, 1], len(V)]]]))
    e = expect(ValueError, c.submit, SRC, bad, landmarks=LANDMARKS, repair="no")
    assert isinstance(e, meshcorr.BadMeshError) and (e.code, e.field) == (-19, "target"), e
    garbage = os.path.join(DIR, "garbage.off")
    open(garbage, "w").write("OFF\n3 1 0\n0 0 0\n1 0\n")
    e = expect(meshcorr.BadMeshError, meshcorr.read_mesh, garbage, has="garbage.off")
    assert isinstance(e, ValueError)
    quads = (V, np.hstack([F, F[:, :1]]))
    expect(meshcorr.BadMeshError, c.submit, SRC, quads, landmarks=LANDMARKS, has="pass the file's path")
    e = expect(LookupError, c.job(999).status)
    assert isinstance(e, meshcorr.JobNotFoundError) and e.name == "NOT_FOUND", e
    long_job = c.submit(SRC, TGT, landmarks=LANDMARKS, iterations=100000, stop_change=0, beta_ramp=4, inner_iterations=10)
    e = expect(meshcorr.ServerBusyError, c.submit, SRC, TGT, landmarks=LANDMARKS, **JOB)
    assert e.name == "USER_LIMIT" and isinstance(e, meshcorr.MeshcorrError), e
    long_job.cancel()
    assert long_job.wait() == "CANCELLED"
    e = expect(RuntimeError, long_job.result)
    assert isinstance(e, meshcorr.JobStateError) and e.name == "BAD_STATE", e
    # pickled (multiprocessing) they keep their class and fields
    p = pickle.loads(pickle.dumps(meshcorr.BadParamsError(-21, "BAD_PARAMS", "d", "params.eta = -1", "eta")))
    assert type(p) is meshcorr.BadParamsError and (p.code, p.field, str(p)) == (-21, "eta",
                                                                               "BAD_PARAMS (-21): params.eta = -1")
    assert expect_error(-21, "BAD_PARAMS", c.submit, SRC, TGT, landmarks=LANDMARKS, iterations=0)   # still works


def case_timeouts_raise_timeout_error_and_the_job_keeps_running():
    """5: wait() and watch() past their timeout raise TimeoutError while
    the job runs on; the watch's thread and connection end; a server that
    never answers HELLO is a TimeoutError of Client(timeout=)."""
    c = meshcorr.Client(UNIX)
    threads = threading.active_count()
    job = c.submit(SRC, TGT, landmarks=LANDMARKS, iterations=100000, stop_change=0, beta_ramp=4, inner_iterations=10)
    t0 = time.monotonic()
    e = expect(TimeoutError, job.wait, timeout=0.5, has="keeps running")
    assert isinstance(e, meshcorr.MeshcorrTimeoutError) and 0.5 <= time.monotonic() - t0 < 5, time.monotonic() - t0
    seen = []
    t0 = time.monotonic()
    try:
        for r in job.watch(timeout=1.5):
            seen.append(r)
    except TimeoutError:
        pass
    else:
        raise AssertionError("watch(timeout=1.5) of a long job ended")
    assert 1.5 <= time.monotonic() - t0 < 6 and seen, (time.monotonic() - t0, len(seen))
    assert job.status()["state"] == "RUNNING", job.status()
    for _ in range(50):                      # the abandoned watches' threads are gone
        if threading.active_count() == threads:
            break
        time.sleep(0.1)
    assert threading.active_count() == threads, threading.enumerate()
    # Ctrl-C while waiting: KeyboardInterrupt, and the watch's thread ends
    threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
    expect(KeyboardInterrupt, job.wait)
    for _ in range(50):
        if threading.active_count() == threads:
            break
        time.sleep(0.1)
    assert threading.active_count() == threads, threading.enumerate()
    job.cancel()
    assert job.wait(timeout=60) == "CANCELLED"
    # a listener that never accepts: connect queues, HELLO gets no answer
    path = os.path.join(DIR, "silent.sock")
    silent = socket.socket(socket.AF_UNIX)
    silent.bind(path)
    silent.listen(1)
    t0 = time.monotonic()
    expect(TimeoutError, meshcorr.Client, "unix:" + path, timeout=0.5)
    assert time.monotonic() - t0 < 3, time.monotonic() - t0


def case_read_mesh_gives_the_engines_arrays():
    """6: read_mesh of OFF, OBJ, PLY and Draco (written by `meshcorr
    convert`) gives the file's arrays in its order; a polygon comes back
    as its triangles."""
    V, F = read_off(SRC)
    for ext in ("off", "obj", "ply", "drc"):
        path = os.path.join(DIR, "s." + ext)
        cli("convert", SRC, path)
        V2, F2 = meshcorr.read_mesh(path)
        assert V2.dtype == np.float64 and F2.dtype == np.int32 and V2.shape == V.shape, (ext, V2.shape)
        assert np.array_equal(V2, V) and np.array_equal(F2, F), ext
    # a quad of an OBJ file comes back as its two triangles, in its place
    quad = os.path.join(DIR, "quad.obj")
    with open(quad, "w") as fp:
        fp.write("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 5 2\nf 1 2 3 4\n")
    V2, F2 = meshcorr.read_mesh(quad)
    assert F2.tolist() == [[0, 4, 1], [0, 1, 2], [0, 2, 3]], F2.tolist()


def case_maps_give_vertex_ids_and_carry_fields():
    """7: a result's map as nearest target vertices (checked by brute
    force), fields carried across exactly (linear fields, constants, shapes
    named on error), and vertex ids back to a Map."""
    res = meshcorr.match(SRC, TGT, landmarks=LANDMARKS, **JOB)
    V1, _ = meshcorr.read_mesh(SRC)
    V2, F2 = meshcorr.read_mesh(TGT)
    P = res.p
    pts = P.points(V2, F2)
    ids = P.to_vertex_map(V2, F2)
    corners = F2[P.faces]
    for i in range(len(P)):
        d = [np.sum((V2[v] - pts[i]) ** 2) for v in corners[i]]
        assert ids[i] == corners[i][int(np.argmin(d))], i
    assert ids.shape == (len(V1),) and (ids >= 0).all() and (ids < len(V2)).all()
    # a vertex map as a Map gives its ids back
    back = meshcorr.vertex_map(ids, F2, len(V2))
    assert np.array_equal(back.to_vertex_map(V2, F2), ids)
    assert np.array_equal(back.points(V2, F2), V2[ids])
    # transfer: exact for linear fields, a (n2, k) field as well as (n2,)
    c = np.array([0.3, -1.2, 2.5])
    lin = P.transfer(V2 @ c + 4.0, F2)
    assert lin.shape == (len(V1),) and np.allclose(lin, pts @ c + 4.0, rtol=0, atol=1e-12)
    uv = np.c_[V2[:, 0], 2 * V2[:, 1]]
    assert np.allclose(P.transfer(uv, F2), np.c_[pts[:, 0], 2 * pts[:, 1]], rtol=0, atol=1e-12)
    assert np.array_equal(P.transfer(V2, F2), pts)
    assert np.allclose(P.transfer(np.full(len(V2), 7.0), F2), 7.0, rtol=0, atol=1e-12)
    n2 = len(V2)
    expect(ValueError, P.transfer, np.zeros(n2 - 1), F2, has="expected shape (%d,) or (%d, k)" % (n2, n2))
    expect(ValueError, P.transfer, np.zeros((n2, 2, 2)), F2, has="(%d,) or (%d, k)" % (n2, n2))
    expect(ValueError, P.transfer, np.zeros(n2), F2[:10], has="not the map's target")
    expect(ValueError, P.to_vertex_map, V2[:5], F2, has="shape (%d, 3)" % n2)


def case_landmarks_must_be_integer_vertex_ids():
    """8: floats that are not whole, negatives, bools and other types are
    refused naming the element, before anything reaches the server; numpy
    integer arrays of any width are accepted and give the same job."""
    c = meshcorr.Client(UNIX)
    base = [[i, i] for i in range(6)]
    for bad, where in (([[0, 0], [1, 1.5]] + base[2:], "landmarks[1][1] = 1.5"),
                       ([[0, 0], [1, -1]] + base[2:], "landmarks[1][1] = -1"),
                       ([[True, 0]] + base[1:], "landmarks[0][0] = True"),
                       (np.array(base, dtype=bool), "landmarks[0][0] = False"),
                       (np.array(base, dtype=np.float64) + [[0, 0.25]] * 6, "landmarks[0][1] = 0.25"),
                       (np.array(base, dtype=np.int64) - 1, "landmarks[0][0] = -1"),
                       ([[0, 0], [1, "2"]] + base[2:], "landmarks[1][1] = '2'"),
                       ([[0, 0, 0]] + base[1:], "landmarks[0] has 3 elements"),
                       (np.zeros((6, 3), dtype=int), "got an array of shape (6, 3)")):
        for fn in (c.submit, meshcorr.match):
            e = expect(ValueError, fn, SRC, TGT, landmarks=bad, has=where, **JOB)
            assert isinstance(e, meshcorr.BadLandmarksError) and e.field == "landmarks", e
    assert c.list() == []                        # nothing was sent
    maps = []
    for lm in (np.array(base, dtype=np.int16), np.array(base, dtype=np.uint32), base,
               np.array(base, dtype=np.float64)):   # whole floats are ids too (np.loadtxt's default)
        job = c.submit(SRC, TGT, landmarks=lm, **JOB)
        assert job.wait() == "COMPLETED", job.reason
        maps.append(job.result().p)
    assert all(m == maps[0] for m in maps[1:])


def case_landmark_files_read_by_the_clis_reader():
    """A landmark file's path (str or os.PathLike) and a tuple of two lists
    give the job of the equivalent array, in match() and submit(); a missing
    file, a malformed one and one out of range raise BadLandmarksError with
    the reader's file and line; a value that is neither an array nor a path
    is refused saying what landmarks may be, a str never taken apart."""
    import pathlib
    c = meshcorr.Client(UNIX)

    def write(name, text):
        path = os.path.join(DIR, name)
        open(path, "w").write(text)
        return path

    pairs = write("pairs.txt", "# source target\n" + open(E["MESHCORR_TEST_LMK"]).read())
    src_list = write("src.txt", "".join("%d\n" % i for i in range(6)))
    tgt_list = write("tgt.txt", "".join("%d\n" % i for i in range(6)))
    missing = os.path.join(DIR, "none.txt")
    for fn in (c.submit, meshcorr.match):
        e = expect(ValueError, fn, SRC, TGT, landmarks=missing, has=missing, **JOB)
        assert isinstance(e, meshcorr.BadLandmarksError) and e.field == "landmarks", e
        for text, where in (("0 0\n1 x\n2 2\n", "bad.txt:2: "), ("0 0\n1 1\n2 500\n", "bad.txt:3: "),
                            ("0\n1\n2\n", "bad.txt:1: ")):
            e = expect(ValueError, fn, SRC, TGT, landmarks=write("bad.txt", text), has=where, **JOB)
            assert isinstance(e, meshcorr.BadLandmarksError) and e.field == "landmarks", e
        want = "expected a (k, 2) array of (source, target) vertex ids or a landmark file's path, got "
        for bad, has in (({0: 0, 1: 1, 2: 2}, want + "dict"), (pairs.encode(), want + "bytes"), (7, want + "int"),
                         (["0 0", "1 1", "2 2"], "landmarks[0] = '0 0': a str, not a (source, target) pair")):
            e = expect(ValueError, fn, SRC, TGT, landmarks=bad, has=has, **JOB)
            assert isinstance(e, meshcorr.BadLandmarksError) and e.field == "landmarks", e
    assert c.list() == []                        # nothing was sent
    arrays = meshcorr.match(SRC, TGT, landmarks=LANDMARKS, **JOB)
    for lm in (pairs, pathlib.Path(pairs), (src_list, pathlib.Path(tgt_list))):
        local = meshcorr.match(SRC, TGT, landmarks=lm, **JOB)
        assert local.p == arrays.p and local.q == arrays.q, lm
    job = c.submit(SRC, TGT, landmarks=pairs, **JOB)
    assert job.wait(timeout=120) == "COMPLETED", job.reason
    assert job.result().p == arrays.p
    # 1-based lists (BCICP, FAUST): refused as a path with the way to read
    # them, read by read_landmarks(..., one_based=True)
    ns, nt = len(meshcorr.read_mesh(SRC)[0]), len(meshcorr.read_mesh(TGT)[0])
    src1 = write("src1.txt", "".join("%d\n" % i for i in (1, 2, 3, 4, 5, ns)))
    tgt1 = write("tgt1.txt", "".join("%d\n" % i for i in (1, 2, 3, 4, 5, nt)))
    e = expect(ValueError, meshcorr.match, SRC, TGT, landmarks=(src1, tgt1), has="one_based=True", **JOB)
    assert isinstance(e, meshcorr.BadLandmarksError) and "looks 1-based" in str(e), e
    lm = meshcorr.read_landmarks(src1, SRC, TGT, tgt1, one_based=True)
    assert lm.tolist() == [[0, 0], [1, 1], [2, 2], [3, 3], [4, 4], [ns - 1, nt - 1]], lm
    assert np.array_equal(meshcorr.read_landmarks(pairs, SRC, TGT), np.asarray(LANDMARKS, dtype=np.uint32))


def case_match_in_process_equals_the_daemons_job():
    """9: the same job through meshcorrd and through match(): the same
    maps, metrics and progress records, and the same refusals; a progress
    callback stops the job or raises through it."""
    c = meshcorr.Client(UNIX)
    for kw in (dict(landmarks=LANDMARKS, **JOB),
               dict(landmarks=LANDMARKS, model="injective", iterations=3, beta_ramp=3, inner_iterations=10)):
        job = c.submit(SRC, TGT, **kw)
        remote_records = list(job.watch())
        assert job.state == "COMPLETED", job.reason
        remote = job.result(deformed=True)
        local_records = []
        local = meshcorr.match(SRC, TGT, progress=local_records.append, deformed=True, **kw)
        assert local.p == remote.p and (local.q == remote.q if remote.q else local.q is None), kw
        assert np.array_equal(local.deformed[0], remote.deformed[0])
        assert {k: v for k, v in local.metrics.items() if k != "elapsed_s"} == \
            {k: v for k, v in remote.metrics.items() if k != "elapsed_s"}
        clock = ("job", "elapsed", "eta")             # the daemon's id, and each run's own clock
        strip = [{k: v for k, v in r.items() if k not in clock} for r in remote_records]
        assert [{k: v for k, v in r.items() if k not in clock} for r in local_records] == strip
    # from arrays, as submit() takes them
    files = meshcorr.match(SRC, TGT, landmarks=LANDMARKS, **JOB)
    arrays = meshcorr.match(read_off(SRC), read_off(TGT), landmarks=LANDMARKS, **JOB)
    assert arrays.p == files.p and arrays.q == files.q
    # the same refusals, word for word
    for kw in (dict(iterations=0), dict(inner_iterations=500000), dict(landmarks=[[0, 0], [1, 1], [2, 500]])):
        args = dict(dict(landmarks=LANDMARKS), **kw)
        a = expect(ValueError, c.submit, SRC, TGT, **args)
        b = expect(ValueError, meshcorr.match, SRC, TGT, **args)
        assert (type(a), a.code, a.message, a.field) == (type(b), b.code, b.message, b.field), (a, b)
    # the callback stops the job, or raises through it
    e = expect(meshcorr.JobCancelledError, meshcorr.match, SRC, TGT, landmarks=LANDMARKS, iterations=1000, stop_change=0,
               beta_ramp=4, inner_iterations=10, progress=lambda r: r["stage"] == "ectm" and r["outer"] == 2,
               has="cancelled by the progress callback after 2 of 1000")
    assert e.code == -25 and e.name == "CANCELLED", e

    class Stop(Exception):
        pass

    def boom(r):
        raise Stop("from the callback")

    expect(Stop, meshcorr.match, SRC, TGT, landmarks=LANDMARKS, iterations=1000, stop_change=0, progress=boom)
    # Ctrl-C stops the engine and comes out as KeyboardInterrupt
    threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGINT)).start()
    t0 = time.monotonic()
    expect(KeyboardInterrupt, meshcorr.match, SRC, TGT, landmarks=LANDMARKS, iterations=100000, stop_change=0, beta_ramp=4,
           inner_iterations=10)
    assert time.monotonic() - t0 < 6, time.monotonic() - t0
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def case_repair_record_and_keyword():
    """The input repair: a mesh with a face written twice and a stray
    triangle beside it is repaired alike by the daemon and by match():
    result.repair says what was done, p has a row per vertex given; a job
    whose meshes need nothing has no record; repair="no" refuses the mesh."""
    c = meshcorr.Client(UNIX)
    V, F = read_off(SRC)
    nv = len(V)
    Vb = np.vstack([V, [[3.0, 0, 0], [3.0, 1, 0], [3.0, 0, 1]]])
    Fb = np.vstack([F, F[:1], [[nv, nv + 1, nv + 2]]])
    job = c.submit((Vb, Fb), TGT, landmarks=LANDMARKS, **JOB)
    assert job.wait() == "COMPLETED", job.reason
    remote = job.result()
    local = meshcorr.match((Vb, Fb), TGT, landmarks=LANDMARKS, **JOB)
    rec = remote.repair
    assert rec["source"]["duplicate_faces"] == 1 and rec["source"]["pieces"] == 1, rec
    assert rec["source"]["piece_vertices"] == 3 and not any(rec["target"].values()), rec
    assert local.repair == rec and local.p == remote.p and len(remote.p) == nv + 3
    assert meshcorr.match(SRC, TGT, landmarks=LANDMARKS, **JOB).repair is None
    for fn in (c.submit, meshcorr.match):
        expect_error(-19, "BAD_MESH", fn, (Vb, Fb), TGT, landmarks=LANDMARKS, repair="no", **JOB,
                     has="duplicate faces")


def case_reprs_and_type_hints():
    """10: the reprs say what the object is; every public function's hints
    resolve; the package says it is typed (py.typed)."""
    c = meshcorr.Client(UNIX)
    assert repr(c) == "Client(server=%r, user=%r)" % (UNIX, c.user) and c.user, repr(c)
    job = c.submit(SRC, TGT, landmarks=LANDMARKS, **JOB)
    assert repr(job) == "Job(id=%d, state='PENDING')" % job.id, repr(job)
    job.wait()
    assert repr(job) == "Job(id=%d, state='COMPLETED')" % job.id, repr(job)
    res = job.result()
    assert repr(res.p) == "Map(162 rows onto %d faces of a 162-vertex target)" % len(np.unique(res.p.faces))
    assert repr(res).startswith("Result(p=Map(162 rows onto ") and "final_energy=" in repr(res), repr(res)
    for obj in (meshcorr.Client.__init__, meshcorr.Client.submit, meshcorr.Client.list, meshcorr.Job.watch,
                meshcorr.Job.wait, meshcorr.Job.result, meshcorr.match, meshcorr.read_mesh, meshcorr.Map.transfer,
                meshcorr.Map.to_vertex_map, meshcorr.vertex_map, meshcorr.read_map):
        hints = typing.get_type_hints(obj)
        assert "return" in hints, obj
    assert typing.get_type_hints(meshcorr.match)["return"] is meshcorr.Result
    assert os.path.exists(os.path.join(os.path.dirname(meshcorr.__file__), "py.typed"))


def case_docs_examples_run():
    """docs/python.md: every ```python block, in order, in one namespace, in
    a folder holding the page's source.off, target.off and pairs.txt."""
    text = open(os.path.join(REPO, "docs/python.md")).read()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 8, len(blocks)
    work = os.path.join(DIR, "docs")
    os.makedirs(work)
    for name, path in (("source.off", SRC), ("target.off", TGT)):
        open(os.path.join(work, name), "w").write(open(path).read())
    open(os.path.join(work, "pairs.txt"), "w").write("# source target\n" + open(E["MESHCORR_TEST_LMK"]).read())
    os.environ["MESHCORR_SERVER"] = UNIX
    os.chdir(work)
    ns = {}
    for i, b in enumerate(blocks):
        try:
            exec(compile(b, "docs/python.md block %d" % (i + 1), "exec"), ns)
        except Exception:
            print("docs/python.md, python block %d:\n%s" % (i + 1, b))
            raise
    assert ns["job"].state == "COMPLETED" and ns["local"].p == ns["res"].p


def case_venv_match_equals_daemon():
    """2: run with a fresh venv's python after `pip install ./client-c/python`:
    the installed package (its metadata's version the library's), its
    in-process match and a daemon's job give the same maps."""
    assert meshcorr.__file__.startswith(sys.prefix) and sys.prefix != sys.base_prefix, (meshcorr.__file__, sys.prefix)
    import importlib.metadata
    assert importlib.metadata.version("meshcorr") == meshcorr.__version__
    local = meshcorr.match(SRC, TGT, landmarks=LANDMARKS, **JOB)
    with meshcorr.Client(UNIX) as c:
        job = c.submit(SRC, TGT, landmarks=LANDMARKS, **JOB)
        assert job.wait(timeout=120) == "COMPLETED", job.reason
        remote = job.result()
    assert local.p == remote.p and local.q == remote.q
    assert len(local.p) == 162 and np.allclose(local.p.weights.sum(axis=1), 1)


def case_rhm_stage_maps_same_as_cli():
    c = meshcorr.Client(UNIX)
    job = c.submit(SRC, TGT, landmarks=LANDMARKS, label="py", **JOB)
    list(job.watch())
    assert job.state == "COMPLETED", (job.state, job.reason)
    res = job.result(stages=True)
    r, rq = res.stages["rhm"], res.stages["rhm-reverse"]
    assert len(r) == len(res.p) and len(rq) == len(res.q) and r != res.p
    assert 0 <= res.metrics["rhm_flipped_fraction"] <= 1, res.metrics
    assert job.result().stages == {}                               # not asked
    rm, rqm = os.path.join(DIR, "cli-rhm.map"), os.path.join(DIR, "cli-rhmq.map")
    cli("result", str(job.id), "--out-stage", "rhm=" + rm, "--out-stage", "rhm-reverse=" + rqm,
        "--server", UNIX)
    assert meshcorr.read_map(rm) == r and meshcorr.read_map(rqm) == rq
    # in this process: the same maps, the final and RHM's
    local = meshcorr.match(SRC, TGT, landmarks=LANDMARKS, stages=True, **JOB)
    assert local.p == res.p and local.stages["rhm"] == r and local.stages["rhm-reverse"] == rq
    assert meshcorr.match(SRC, TGT, landmarks=LANDMARKS, **JOB).stages == {}   # not asked


if __name__ == "__main__":
    globals()["case_" + sys.argv[1]]()
    print("ok", sys.argv[1])
