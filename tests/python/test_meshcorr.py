"""test_meshcorr.py — the Python package meshcorr against a real meshcorrd,
one case per run: `test_meshcorr.py CASE`. Driven by tests/unit/test_python.c,
which starts the daemon, writes the icosphere pair and sets the
MESHCORR_TEST_* variables; exit status 0 = the case passed."""
import os
import subprocess
import sys

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


def cli(*args):
    r = subprocess.run(["build/meshcorr"] + list(args), capture_output=True, text=True)
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
    job = c.submit(SRC, TGT, landmarks=LANDMARKS, iterations=100000, beta_ramp=4, inner_iterations=10,
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
    expect_error(-19, "BAD_MESH", c.submit, (Vb, Fb), SRC, landmarks=LANDMARKS, **JOB, has="non-manifold")
    expect_error(-20, "BAD_LANDMARKS", c.submit, SRC, TGT, landmarks=[[0, 0], [1, 1], [2, 500]], **JOB, has="500")
    expect_error(-21, "BAD_PARAMS", c.submit, SRC, TGT, landmarks=LANDMARKS, inner_iterations=500000,
                 has="inner_iterations")
    expect_error(-21, "BAD_PARAMS", c.submit, SRC, TGT, landmarks=LANDMARKS, iterations=0,
                 has="params.iterations = 0 < 1")
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
    MeshcorrError, the code and name the C layers use."""
    c = meshcorr.Client(UNIX)
    job = c.submit(SRC, TGT, landmarks=LANDMARKS, **dict(JOB, beta0=1e308, beta1=1e308))
    assert job.wait() == "FAILED", (job.state, job.reason)
    assert isinstance(job.error, meshcorr.MeshcorrError), job.error
    assert (job.error.code, job.error.name) == (-30, "NUMERIC"), job.error
    assert job.error.message == job.reason and job.reason.startswith("NUMERIC: "), job.reason
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


if __name__ == "__main__":
    globals()["case_" + sys.argv[1]]()
    print("ok", sys.argv[1])
