/* testhttp.h — the HTTP endpoint of a test daemon over a raw socket: a
 * free loopback port to give --http (or --modbus), and one request with its
 * whole answer, so the tests see exactly the bytes meshcorrd sends. */
#ifndef TESTHTTP_H
#define TESTHTTP_H
#include <stddef.h>

/* A loopback TCP port nobody listens on now, below the range bind(0)
 * hands out (fails the test if none). */
int testhttp_free_port(void);

/* method path to 127.0.0.1:port, HTTP/1.0, with the extra header lines
 * headers ("" or lines each ending in \r\n) and body (NULL: none; a
 * Content-Length is sent either way). The whole answer, headers included,
 * into resp (cut at rsz - 1 bytes), read until the server closes or no byte
 * comes for timeout_ms. The status code; 0 when the answer is not HTTP;
 * -1 when the connection or the send fails. Never fails the test itself,
 * so threads may call it. */
int testhttp_request(int port, const char *method, const char *path, const char *headers, const char *body,
                     char *resp, size_t rsz, int timeout_ms);

/* The body of a whole answer (after its blank line); "" when there is none. */
const char *testhttp_body(const char *resp);

#endif
