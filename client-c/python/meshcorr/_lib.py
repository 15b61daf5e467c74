"""_lib.py — libmeshcorr.so.1 through ctypes: finding and loading it, the C
structs of meshcorr.h, the mc_job_spec laid out from the library's own
parameter list (mc_param_*), checked against mc_job_spec_size(), and the
in-process engine libmeshcorr-engine.so.1, loaded on first use.

libmeshcorr is, in this order, the first of these that loads:
  $MESHCORR_LIB (a path; when set, nothing else is tried),
  the path `make install-python` wrote into _libpath.py,
  build/libmeshcorr.so.1 of the source tree this package sits in,
  libmeshcorr.so.1 through the system loader (LD_LIBRARY_PATH, or the
  ldconfig cache after `make install` and ldconfig).
libmeshcorr-engine.so.1 is taken from the folder libmeshcorr was loaded
from, else through the system loader."""
from __future__ import annotations

import ctypes
import os
import threading

import numpy as np

from . import errors

LIBNAME, ENGINE_LIBNAME = "libmeshcorr.so.1", "libmeshcorr-engine.so.1"


def _candidates():
    env = os.environ.get("MESHCORR_LIB")
    if env:
        return [env]
    found = []
    try:
        from ._libpath import LIBMESHCORR
        found.append(LIBMESHCORR)
    except ImportError:
        pass
    here = os.path.dirname(os.path.abspath(__file__))
    tree = os.path.normpath(os.path.join(here, "..", "..", "..", "build", LIBNAME))
    if os.path.exists(tree):
        found.append(tree)
    return found + [LIBNAME]


def _load():
    tried = []
    for path in _candidates():
        if os.sep in path:                   # a path: kept absolute, for the engine's folder
            path = os.path.abspath(path)
        try:
            return ctypes.CDLL(path)
        except OSError as e:
            tried.append("%s (%s)" % (path, e))
    raise ImportError("meshcorr: cannot load libmeshcorr: tried %s. Set MESHCORR_LIB to the path of "
                      "build/libmeshcorr.so.1, or run `make install` (and ldconfig)" % "; ".join(tried))


lib = _load()
_libc = ctypes.CDLL(None)
_libc.free.argtypes = [ctypes.c_void_p]
free = _libc.free

c_u8p = ctypes.POINTER(ctypes.c_ubyte)


class MapRow(ctypes.Structure):
    _fields_ = [("face", ctypes.c_uint32), ("w", ctypes.c_double * 3)]


# mc_map_row as a numpy record, to read and write arrays of rows in place.
MAP_ROW_DTYPE = np.dtype([("face", np.uint32), ("w", np.float64, 3)], align=True)
assert MAP_ROW_DTYPE.itemsize == ctypes.sizeof(MapRow)


class Progress(ctypes.Structure):
    _fields_ = [("job_id", ctypes.c_uint64), ("stage", ctypes.c_int),
                ("outer", ctypes.c_uint32), ("total", ctypes.c_uint32),
                ("inner", ctypes.c_uint32 * 2),
                ("membrane", ctypes.c_double * 2), ("bending", ctypes.c_double * 2),
                ("mismatch", ctypes.c_double * 2), ("reverse", ctypes.c_double * 2),
                ("energy", ctypes.c_double * 2),
                ("beta", ctypes.c_double), ("gamma", ctypes.c_double),
                ("elapsed_s", ctypes.c_double), ("fraction", ctypes.c_double),
                ("eta_s", ctypes.c_double), ("ahead", ctypes.c_uint32)]


class Quality(ctypes.Structure):
    _fields_ = [("verdict", ctypes.c_int), ("flipped", ctypes.c_double), ("collapsed", ctypes.c_double)]


class JobStatus(ctypes.Structure):
    _fields_ = [("job_id", ctypes.c_uint64), ("state", ctypes.c_int),
                ("priority", ctypes.c_int32), ("user", ctypes.c_char * 256),
                ("label", ctypes.c_char * 1025), ("reason", ctypes.c_char * 1025),
                ("submit_ms", ctypes.c_int64), ("start_ms", ctypes.c_int64),
                ("end_ms", ctypes.c_int64), ("has_progress", ctypes.c_int),
                ("progress", Progress), ("quality", Quality)]


class JobInfo(ctypes.Structure):
    _fields_ = [("job_id", ctypes.c_uint64), ("state", ctypes.c_int),
                ("priority", ctypes.c_int32), ("submit_ms", ctypes.c_int64),
                ("user", ctypes.c_char * 256), ("label", ctypes.c_char * 1025),
                ("outer", ctypes.c_uint32), ("total", ctypes.c_uint32),
                ("quality", Quality), ("fraction", ctypes.c_double), ("eta_s", ctypes.c_double),
                ("ahead", ctypes.c_uint32)]


class JobResult(ctypes.Structure):
    _fields_ = [("p", ctypes.POINTER(MapRow)), ("np", ctypes.c_uint32),
                ("q", ctypes.POINTER(MapRow)), ("nq", ctypes.c_uint32),
                ("deformed", c_u8p), ("deformed_len", ctypes.c_size_t),
                ("metric_keys", ctypes.POINTER(ctypes.c_char_p)),
                ("metric_values", ctypes.POINTER(ctypes.c_double)),
                ("nmetrics", ctypes.c_uint32)]


class StageMaps(ctypes.Structure):
    _fields_ = [("p", ctypes.POINTER(MapRow)), ("np", ctypes.c_uint32),
                ("q", ctypes.POINTER(MapRow)), ("nq", ctypes.c_uint32)]


class ServerStats(ctypes.Structure):
    _fields_ = [("queued", ctypes.c_uint32), ("running", ctypes.c_uint32),
                ("workers", ctypes.c_uint32), ("completed", ctypes.c_uint64),
                ("failed", ctypes.c_uint64), ("cancelled", ctypes.c_uint64),
                ("nslots", ctypes.c_uint32), ("slot_job", ctypes.POINTER(ctypes.c_uint64)),
                ("slot_state", ctypes.POINTER(ctypes.c_int)),
                ("devices", (ctypes.c_char * 128) * 8), ("ndevices", ctypes.c_uint32),
                ("backend", ctypes.c_char * 16), ("backend_ok", ctypes.c_int),
                ("backend_status", ctypes.c_char * 1024)]


def _declare(name, res, *args):
    f = getattr(lib, name)
    f.restype = res
    f.argtypes = list(args)


_declare("mc_param_count", ctypes.c_int)
for _n in ("mc_param_name", "mc_param_cli", "mc_param_values", "mc_param_help"):
    _declare(_n, ctypes.c_char_p, ctypes.c_int)
_declare("mc_param_type", ctypes.c_int, ctypes.c_int)
_declare("mc_job_spec_size", ctypes.c_size_t)

# enum mc_param_type: ENUM, BOOL, U32, F64, STR, and their C members.
PARAM_TYPES = ("enum", "bool", "u32", "f64", "str")
_CTYPES = (ctypes.c_int, ctypes.c_int, ctypes.c_uint32, ctypes.c_double, ctypes.c_char_p)


class Param:
    """One row of the parameter list: name, cli option, type, value names, help."""
    def __init__(self, i):
        self.name = lib.mc_param_name(i).decode()
        self.cli = lib.mc_param_cli(i).decode()
        self.type = PARAM_TYPES[lib.mc_param_type(i)]
        self.values = [v for v in lib.mc_param_values(i).decode().split("|") if v]
        self.help = lib.mc_param_help(i).decode()

    def __repr__(self):
        return "Param(%s, %s)" % (self.name, self.type)


PARAMS = [Param(i) for i in range(lib.mc_param_count())]


class JobSpec(ctypes.Structure):
    _fields_ = ([("source", c_u8p), ("source_len", ctypes.c_size_t),
                 ("target", c_u8p), ("target_len", ctypes.c_size_t),
                 ("landmarks", ctypes.POINTER(ctypes.c_uint32)), ("nlandmarks", ctypes.c_uint32),
                 ("p", ctypes.POINTER(MapRow)), ("np", ctypes.c_uint32),
                 ("q", ctypes.POINTER(MapRow)), ("nq", ctypes.c_uint32)]
                + [(p.name, _CTYPES[PARAM_TYPES.index(p.type)]) for p in PARAMS]
                + [("priority", ctypes.c_int32), ("label", ctypes.c_char_p)])


if ctypes.sizeof(JobSpec) != lib.mc_job_spec_size():
    raise ImportError("meshcorr: mc_job_spec of %s is %d bytes, the parameter list gives %d"
                      % (lib._name, lib.mc_job_spec_size(), ctypes.sizeof(JobSpec)))

c_client_p = ctypes.c_void_p
c_err = ctypes.c_char_p
PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(Progress))

_declare("mc_strerror", ctypes.c_char_p, ctypes.c_int)
_declare("mc_err_name", ctypes.c_char_p, ctypes.c_int)
_declare("mc_reason_error", ctypes.c_int, ctypes.c_char_p)
_declare("mc_state_name", ctypes.c_char_p, ctypes.c_int)
_declare("mc_stage_name", ctypes.c_char_p, ctypes.c_int)
_declare("mc_quality_name", ctypes.c_char_p, ctypes.c_int)
_declare("mc_state_parse", ctypes.c_int, ctypes.c_char_p)
_declare("mc_job_spec_init", None, ctypes.POINTER(JobSpec))
_declare("mc_job_spec_set", ctypes.c_int, ctypes.POINTER(JobSpec), ctypes.c_char_p, ctypes.c_char_p,
         c_err, ctypes.c_size_t)
_declare("mc_connect", ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(c_client_p),
         c_err, ctypes.c_size_t)
_declare("mc_connect_ca", ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p,
         ctypes.POINTER(c_client_p), c_err, ctypes.c_size_t)
_declare("mc_close", None, c_client_p)
_declare("mc_set_timeout", None, c_client_p, ctypes.c_int)
_declare("mc_errmsg", ctypes.c_char_p, c_client_p)
_declare("mc_user", ctypes.c_char_p, c_client_p)
_declare("mc_is_admin", ctypes.c_int, c_client_p)
_declare("mc_submit", ctypes.c_int, c_client_p, ctypes.POINTER(JobSpec), ctypes.POINTER(ctypes.c_uint64))
_declare("mc_status", ctypes.c_int, c_client_p, ctypes.c_uint64, ctypes.POINTER(JobStatus))
_declare("mc_list", ctypes.c_int, c_client_p, ctypes.c_char_p, ctypes.c_uint32,
         ctypes.POINTER(ctypes.POINTER(JobInfo)), ctypes.POINTER(ctypes.c_uint32))
_declare("mc_watch", ctypes.c_int, c_client_p, ctypes.c_uint64, ctypes.c_uint32, PROGRESS_FN,
         ctypes.c_void_p, ctypes.POINTER(ctypes.c_int), c_err, ctypes.c_size_t)
_declare("mc_result", ctypes.c_int, c_client_p, ctypes.c_uint64, ctypes.c_uint, ctypes.POINTER(JobResult))
_declare("mc_result_free", None, ctypes.POINTER(JobResult))
_declare("mc_result_stage", ctypes.c_int, c_client_p, ctypes.c_uint64, ctypes.c_char_p,
         ctypes.POINTER(StageMaps))
_declare("mc_stage_maps_free", None, ctypes.POINTER(StageMaps))
_declare("mc_cancel", ctypes.c_int, c_client_p, ctypes.c_uint64)
_declare("mc_delete", ctypes.c_int, c_client_p, ctypes.c_uint64)
_declare("mc_stats", ctypes.c_int, c_client_p, ctypes.POINTER(ServerStats))
_declare("mc_stats_free", None, ctypes.POINTER(ServerStats))
_declare("mc_encode_mesh_file_quantized", ctypes.c_int, ctypes.c_char_p, ctypes.c_int,
         ctypes.POINTER(c_u8p), ctypes.POINTER(ctypes.c_size_t), c_err, ctypes.c_size_t)
_declare("mc_encode_mesh_quantized", ctypes.c_int, ctypes.POINTER(ctypes.c_double), ctypes.c_int,
         ctypes.POINTER(ctypes.c_int), ctypes.c_int, ctypes.c_int, ctypes.POINTER(c_u8p),
         ctypes.POINTER(ctypes.c_size_t), c_err, ctypes.c_size_t)
_declare("mc_decode_mesh", ctypes.c_int, c_u8p, ctypes.c_size_t,
         ctypes.POINTER(ctypes.POINTER(ctypes.c_double)), ctypes.POINTER(ctypes.c_int),
         ctypes.POINTER(ctypes.POINTER(ctypes.c_int)), ctypes.POINTER(ctypes.c_int), c_err, ctypes.c_size_t)


def errbuf():
    return ctypes.create_string_buffer(4096)


def error(rc, detail, cls=None, field=None):
    """The exception of code rc with detail (bytes or str): the class of the
    code unless cls says, field as given or as the message names it. The
    client's messages of server refusals start with the code's name
    ("BAD_PARAMS: ..."), which the exception's text already shows: dropped."""
    if isinstance(detail, (bytes, bytearray)):
        detail = detail.decode(errors="replace")
    name = lib.mc_err_name(rc).decode()
    if detail.startswith(name + ": "):
        detail = detail[len(name) + 2:]
    return (cls or errors.error_class(rc))(rc, name, lib.mc_strerror(rc).decode(), detail,
                                           field if field is not None else errors.field_of(detail))


def check(rc, detail, cls=None, field=None):
    """Raises error(rc, detail, cls, field) when rc is not 0."""
    if rc:
        raise error(rc, detail, cls, field)


if not hasattr(lib, "mc_version"):
    raise ImportError("meshcorr: %s is older than this package (it has no mc_version): rebuild it with make, "
                      "or point MESHCORR_LIB at a current one" % lib._name)
_declare("mc_version", ctypes.c_char_p)
_declare("mc_interrupt", None, c_client_p)
_declare("mc_read_mesh", ctypes.c_int, ctypes.c_char_p, ctypes.POINTER(ctypes.POINTER(ctypes.c_double)),
         ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.POINTER(ctypes.c_int)), ctypes.POINTER(ctypes.c_int),
         c_err, ctypes.c_size_t)
_declare("mc_read_landmarks", ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_int,
         ctypes.POINTER(ctypes.c_double), ctypes.c_int, ctypes.POINTER(ctypes.c_double), ctypes.c_int,
         ctypes.POINTER(ctypes.POINTER(ctypes.c_uint32)), ctypes.POINTER(ctypes.c_uint32), c_err, ctypes.c_size_t)
VERSION = lib.mc_version().decode()


class _DlInfo(ctypes.Structure):
    _fields_ = [("dli_fname", ctypes.c_char_p), ("dli_fbase", ctypes.c_void_p),
                ("dli_sname", ctypes.c_char_p), ("dli_saddr", ctypes.c_void_p)]


def _loaded_from():
    """The file libmeshcorr was loaded from (the system loader's choice
    too, which lib._name does not tell), by dladdr of one of its functions."""
    info = _DlInfo()
    _libc.dladdr.argtypes = [ctypes.c_void_p, ctypes.POINTER(_DlInfo)]
    if _libc.dladdr(ctypes.cast(lib.mc_version, ctypes.c_void_p), ctypes.byref(info)) and info.dli_fname:
        return os.path.abspath(os.fsdecode(info.dli_fname))
    return lib._name


LIBPATH = _loaded_from()
_engine = None
_engine_lock = threading.Lock()


def engine():
    """libmeshcorr-engine.so.1 with mc_match and mc_match_stages declared, loaded on the first
    call. OpenMP threads then wait passively (OMP_WAIT_POLICY=passive, as
    meshcorr's programs run) unless the environment says otherwise."""
    global _engine
    with _engine_lock:
        if _engine is None:
            path = os.path.join(os.path.dirname(LIBPATH), ENGINE_LIBNAME)
            if not os.path.exists(path):
                path = ENGINE_LIBNAME            # the system loader's, as a last resort
            os.environ.setdefault("OMP_WAIT_POLICY", "passive")
            try:
                e = ctypes.CDLL(path)
            except OSError as ex:
                raise ImportError("meshcorr.match: cannot load %s (%s): build it with `make` or install it with "
                                  "`make install-lib`" % (path, ex)) from None
            e.mc_match.restype = ctypes.c_int
            e.mc_match.argtypes = [ctypes.POINTER(JobSpec), ctypes.c_int, ctypes.c_uint, PROGRESS_FN,
                                   ctypes.c_void_p, ctypes.POINTER(JobResult), c_err, ctypes.c_size_t]
            e.mc_match_stages.restype = ctypes.c_int
            e.mc_match_stages.argtypes = [ctypes.POINTER(JobSpec), ctypes.c_int, ctypes.c_uint, PROGRESS_FN,
                                          ctypes.c_void_p, ctypes.POINTER(JobResult), ctypes.POINTER(StageMaps),
                                          c_err, ctypes.c_size_t]
            _engine = e
        return _engine
