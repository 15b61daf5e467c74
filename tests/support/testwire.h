/* testwire.h — raw protocol connections to a testdaemon, for tests that
 * make the daemon meet what libmeshcorr would never send on purpose (a
 * header that declares a frame and stops, many WATCHes on one connection,
 * RESULTs nobody reads). Frames are encoded with the real codec
 * (proto_msg_encode, proto_frame_put_header). Test code only; every
 * failure fails the test. */
#ifndef TESTWIRE_H
#define TESTWIRE_H
#include <stddef.h>
#include <stdint.h>
#include "proto.h"
#include "support/testdaemon.h"

/* A connected socket: token NULL = d's Unix socket, else d's TCP address
 * (nothing sent yet). */
int testwire_connect(const testdaemon *d, const char *token);
/* testwire_connect, then HELLO (with token, or peer credentials) and its
 * HELLO_OK read. */
int testwire_session(const testdaemon *d, const char *token);
void testwire_send(int fd, const void *p, size_t n);
void testwire_send_msg(int fd, const proto_msg *m);
/* Only the 20-byte header of a frame of this type declaring payload_len
 * bytes: the rest never comes. */
void testwire_send_header(int fd, int type, uint32_t request_id, uint32_t payload_len);
/* The next frame within timeout_s (fails the test otherwise); its payload
 * stays in *buf, which the caller frees after proto_msg_free(m). Frames
 * up to max_frame bytes. */
void testwire_read_msg(int fd, proto_msg *m, uint8_t **buf, size_t max_frame, double timeout_s);
/* The next frame is ERROR code whose message has what (request id rid). */
void testwire_expect_error(int fd, uint32_t rid, int code, const char *what, double timeout_s);
/* Monotonic seconds. */
double testwire_now(void);

#endif
