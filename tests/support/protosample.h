/* protosample.h — sample protocol messages of every type for the protocol
 * tests and the fuzzer, and a deep comparison of two messages. Test support
 * only: the samples live in static storage of this file. */
#ifndef PROTOSAMPLE_H
#define PROTOSAMPLE_H
#include "proto.h"

/* Fills m with a message of `type`. variant 0: every optional field present,
 * strings of PROTO_MAX_STRING bytes (multi-byte UTF-8 included), extreme
 * numbers; variant 1: optional fields absent, empty strings, small values. */
void protosample_fill(int type, int variant, proto_msg *m);

/* NULL when a and b carry the same values (strings and blobs by content),
 * else the name of the first field that differs. */
const char *protosample_diff(const proto_msg *a, const proto_msg *b);

#endif
