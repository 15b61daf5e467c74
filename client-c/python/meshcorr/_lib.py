"""_lib.py — libmeshcorr.so.1 through ctypes: finding and loading it, the C
structs of meshcorr.h, and the mc_job_spec laid out from the library's own
parameter list (mc_param_*), checked against mc_job_spec_size().

The library is $MESHCORR_LIB when set, else the path `make install` wrote
into _libpath.py, else build/libmeshcorr.so.1 of the source tree this
package sits in, else the system loader's libmeshcorr.so.1."""
import ctypes
import os

from .errors import MeshcorrError


def _find():
    env = os.environ.get("MESHCORR_LIB")
    if env:
        return env
    try:
        from ._libpath import LIBMESHCORR
        return LIBMESHCORR
    except ImportError:
        pass
    here = os.path.dirname(os.path.abspath(__file__))
    tree = os.path.join(here, "..", "..", "..", "build", "libmeshcorr.so.1")
    return tree if os.path.exists(tree) else "libmeshcorr.so.1"


lib = ctypes.CDLL(_find())
_libc = ctypes.CDLL(None)
_libc.free.argtypes = [ctypes.c_void_p]
free = _libc.free

c_u8p = ctypes.POINTER(ctypes.c_ubyte)


class MapRow(ctypes.Structure):
    _fields_ = [("face", ctypes.c_uint32), ("w", ctypes.c_double * 3)]


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
_declare("mc_quality_name", ctypes.c_char_p, ctypes.c_int)
_declare("mc_state_parse", ctypes.c_int, ctypes.c_char_p)
_declare("mc_job_spec_init", None, ctypes.POINTER(JobSpec))
_declare("mc_job_spec_set", ctypes.c_int, ctypes.POINTER(JobSpec), ctypes.c_char_p, ctypes.c_char_p,
         c_err, ctypes.c_size_t)
_declare("mc_connect", ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(c_client_p),
         c_err, ctypes.c_size_t)
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


def check(rc, detail):
    """Raises MeshcorrError(rc, detail) when rc is not 0; detail is bytes or str."""
    if rc:
        if isinstance(detail, (bytes, bytearray)):
            detail = detail.decode(errors="replace")
        raise MeshcorrError(rc, lib.mc_err_name(rc).decode(), lib.mc_strerror(rc).decode(), detail)
