/* mc__wire.h — libmeshcorr's mapping between its public structs
 * (meshcorr.h) and the protocol's messages, shared by the client
 * (mc_client.c: SUBMIT out, PROGRESS and RESULT_OK in) and the in-process
 * job (local/mc_match.c), so that both hand the engine the same job and
 * return its answer the same way. Internal: hidden in libmeshcorr.so. */
#ifndef MC__WIRE_H
#define MC__WIRE_H
#include "meshcorr.h"
#include "proto.h"

#define MC__HIDDEN __attribute__((visibility("hidden")))

/* The SUBMIT of spec: m borrows every blob, array and string from spec.
 * MC_EARG (detail in err) when a mesh is missing or over the wire's
 * 32-bit length. */
MC__HIDDEN int mc__submit_of(const mc_job_spec *spec, proto_submit *m, char *err, size_t errsz);
MC__HIDDEN void mc__progress_of(mc_progress *out, const proto_progress *p);
/* The parts of r that `what` (MC_WANT_*) names, copied into out (zeroed
 * first; mc_result_free releases it). MC_ENOMEM leaves out freed. */
MC__HIDDEN int mc__result_of(const proto_result_ok *r, unsigned what, mc_job_result *out);
/* RHM's maps of r (rhm_p, rhm_q) copied into out (zeroed first).
 * MC_ENOMEM leaves out freed. */
MC__HIDDEN int mc__stage_of(const proto_result_ok *r, mc_stage_maps *out);

#endif
