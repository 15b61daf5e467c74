"""result.py — what a job gives back, the same for a server's job
(Job.result(), Job.watch()) and an in-process one (match()): Result (maps,
deformed source, metrics) and progress records as dicts."""
from __future__ import annotations

import ctypes
from typing import Any, Dict, Optional, Tuple

import numpy as np

from . import _lib
from ._spec import decode
from .map import Map


def _stage_names() -> Tuple[str, ...]:
    """The protocol's stage names in their order, from libmeshcorr's one list."""
    names = []
    while True:
        name = _lib.lib.mc_stage_name(len(names))
        if not name:
            return tuple(names)
        names.append(name.decode())


STAGES = _stage_names()
TERMS = ("membrane", "bending", "mismatch", "reverse", "energy")
WANT_P, WANT_Q, WANT_DEFORMED, WANT_METRICS = 1, 2, 4, 8


class Result:
    """A finished job's answer. p: Map source -> target, one row per source
    vertex; q: Map target -> source (bijective model), else None;
    deformed: (V, F) of the deformed source when asked for, else None;
    metrics: {name: value} as the worker measured the map (flipped_fraction,
    collapsed_fraction, mean_abs_log_area, median_conformal, final_energy,
    iterations, elapsed_s, quality_verdict, and reverse_* for q);
    repair: what the input repair did, {"source": {count: n}, "target":
    {...}} from the metrics repair_source_* and repair_target_*, or None
    when neither mesh needed it (docs/repair.md); stages: a stage's maps
    from before the final ones when asked for (Job.result(stages=True),
    match(stages=True)):
    {"rhm": Map, "rhm-reverse": Map} on a chain RHM then ECTM, their
    quality in metrics as rhm_*; else {}."""

    def __init__(self, p: Map, q: Optional[Map], deformed: Optional[Tuple[np.ndarray, np.ndarray]],
                 metrics: Dict[str, float]) -> None:
        self.p, self.q, self.deformed, self.metrics = p, q, deformed, metrics
        self.repair = repair_of(metrics)
        self.stages: Dict[str, Map] = {}

    def __repr__(self) -> str:
        parts = ["p=%r" % self.p, "q=%r" % self.q]
        if self.deformed is not None:
            parts.append("deformed=(%d vertices, %d faces)" % (len(self.deformed[0]), len(self.deformed[1])))
        if "final_energy" in self.metrics:
            parts.append("final_energy=%.6g" % self.metrics["final_energy"])
        return "Result(%s)" % ", ".join(parts)


def repair_of(metrics: Dict[str, float]) -> Optional[Dict[str, Dict[str, int]]]:
    """The repair record of a result's metrics (keys repair_source_NAME and
    repair_target_NAME), or None when there is none."""
    rec: Dict[str, Dict[str, int]] = {"source": {}, "target": {}}
    for key, value in metrics.items():
        for side in rec:
            if key.startswith("repair_%s_" % side):
                rec[side][key[len("repair_%s_" % side):]] = int(value)
    return rec if rec["source"] or rec["target"] else None


def map_of(rows: Any, n: int, n_target: int) -> Map:
    """A Map of n mc_map_rows (copied)."""
    if not n:
        return Map(np.zeros(0, np.int32), np.zeros((0, 3)), n_target)
    a = np.ctypeslib.as_array(ctypes.cast(rows, ctypes.POINTER(ctypes.c_byte)),
                              (n * ctypes.sizeof(_lib.MapRow),))
    rec = a.view(_lib.MAP_ROW_DTYPE)
    return Map(rec["face"].astype(np.int32), rec["w"].copy(), n_target)


def add_stages(res: Result, s: Any) -> None:
    """RHM's maps of the mc_stage_maps s into res.stages ("rhm", and
    "rhm-reverse" for the bijective model), where the job has them."""
    if s.np:
        res.stages["rhm"] = map_of(s.p, s.np, res.p.n_target)
    if s.nq:
        res.stages["rhm-reverse"] = map_of(s.q, s.nq, s.np)


def result_of(r: _lib.JobResult, n_target: Optional[int], what: str) -> Result:
    """The Result of a filled mc_job_result; n_target: the target's vertex
    count when r has no q to tell it (an injective job); what: the job, for
    the message when neither does."""
    nt = r.nq or n_target
    if not nt:
        raise ValueError("%s is injective: give n_target (the target's vertex count)" % what)
    p = map_of(r.p, r.np, nt)
    q = map_of(r.q, r.nq, r.np) if r.nq else None
    y = decode(r.deformed, r.deformed_len) if r.deformed_len else None
    m = {r.metric_keys[i].decode(): r.metric_values[i] for i in range(r.nmetrics)}
    return Result(p, q, y, m)


def number(v: float) -> Optional[float]:
    """A C double as JSON has it: None for NaN."""
    return None if v != v else v


def progress_dict(p: _lib.Progress) -> Dict[str, Any]:
    """A progress record as Job.watch() yields it, with the names `meshcorr
    watch --progress json` prints: job, stage, outer, total, fraction (the
    whole job's share done), eta (seconds left; None while not known),
    elapsed, ahead (a queued record: jobs that start before it), beta,
    gamma, the terms of both directions summed, and source, target: each
    direction's terms and inner iterations."""
    d: Dict[str, Any] = {"job": p.job_id, "stage": STAGES[p.stage] if p.stage < len(STAGES) else str(p.stage),
                         "outer": p.outer, "total": p.total, "fraction": number(p.fraction),
                         "eta": number(p.eta_s), "elapsed": p.elapsed_s, "ahead": p.ahead,
                         "beta": number(p.beta), "gamma": number(p.gamma)}
    for side, name in enumerate(("source", "target")):
        d[name] = {t: getattr(p, t)[side] for t in TERMS}
        d[name]["inner"] = p.inner[side]
    for t in TERMS:
        d[t] = d["source"][t] + d["target"][t]      # both directions, as `meshcorr watch` prints
    return d
