/* testraw.h — the wire protocol over plain sockets, for tests that do what
 * libmeshcorr never would: connect from a chosen loopback address
 * (127.0.0.2, ...), stay silent, send half a frame or a forged header, or
 * read exactly what the server answers. Every helper fails the test on a
 * local error (a socket call that should not fail). Test code only. */
#ifndef TESTRAW_H
#define TESTRAW_H
#include <stddef.h>
#include <stdint.h>
#include "proto.h"

/* Monotonic seconds. */
double testraw_now(void);
/* A TCP connection to addr ("tcp:HOST:PORT") from source address src
 * (NULL: any); nothing sent. */
int testraw_tcp(const char *addr, const char *src);
/* A connection to the Unix socket addr ("unix:PATH"); nothing sent. */
int testraw_unix(const char *addr);
void testraw_send(int fd, const void *p, size_t n);
void testraw_send_msg(int fd, const proto_msg *m);
/* n bytes within the deadline (testraw_now() time): 0, 1 at EOF or a
 * reset, -1 at the deadline. */
int testraw_recv(int fd, uint8_t *p, size_t n, double deadline);
/* The next frame within timeout_s: 0 with m decoded (its payload in *buf:
 * free() it after the message), 1 at EOF, -1 when nothing came in time.
 * Fails the test on a frame that does not decode. */
int testraw_read_msg(int fd, proto_msg *m, uint8_t **buf, double timeout_s);
/* HELLO with token (NULL: none, for the Unix socket) and client name;
 * returns the reply's type (PROTO_MSG_HELLO_OK or PROTO_MSG_ERROR), its
 * ERROR code in *code and message in msg (may be NULL), or -1 at EOF or
 * after timeout_s. */
int testraw_hello(int fd, const char *token, const char *client, int *code, char *msg, size_t msgsz,
                  double timeout_s);
/* A request with an empty payload (STATS, PING, LIST with defaults...)
 * answered: the reply's type, or -1 (EOF or no answer in timeout_s). */
int testraw_ask(int fd, int type, uint32_t request_id, double timeout_s);
/* 1 when the server closed fd (EOF or reset) within timeout_s, reading and
 * dropping what comes before; 0 when it is still open then. */
int testraw_closed_within(int fd, double timeout_s);
/* Descriptors the process pid has open (/proc/PID/fd), or -1. */
int testraw_fd_count(int pid);

#endif
