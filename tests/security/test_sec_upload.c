/* test_sec_upload.c — one user's stalled uploads cannot block everyone's:
 * alice's four 20-byte SUBMIT headers declaring 256 MiB each (what fills
 * the default --max-request-memory of 1 GiB) get her at most her share
 * (--max-request-memory-per-user, a quarter by default): the second is
 * refused BUSY naming that limit and logged, and meanwhile bob's, the
 * admin's (TCP) and a Unix-socket user's SUBMITs are stored. With
 * small limits, an admin still gets in once the others' declarations fill
 * all the ordinary room: the reserve. Real daemon; raw frames for the
 * stalled headers, libmeshcorr for the others. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testsec.h"
#include "support/testwire.h"
#include "meshcorr.h"

#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define HUGE_FRAME (256u << 20)     /* the default --max-frame: a frame of it is allowed */

/* alice declares a HUGE_FRAME SUBMIT on a session of her own; the number
 * of ERROR BUSY answers she got (0 or 1) is returned, the socket kept open
 * in *fd. */
static int declare_huge(const testdaemon *d, int *fd, uint32_t rid)
{
    *fd = testwire_session(d, TESTDAEMON_ALICE);
    testwire_send_header(*fd, PROTO_MSG_SUBMIT, rid, HUGE_FRAME - PROTO_HDR_SIZE);
    /* a refusal comes at once; an admitted header gets no answer */
    struct timespec ts = {0, 300 * 1000000L};
    nanosleep(&ts, NULL);
    char b;
    ssize_t n = recv(*fd, &b, 1, MSG_PEEK | MSG_DONTWAIT);
    if (n <= 0)
        return 0;
    testwire_expect_error(*fd, rid, PROTO_EBUSY, "max-request-memory-per-user", 5);
    return 1;
}

TEST_T(one_users_huge_upload_headers_do_not_block_other_users_or_the_admin, 180)
{
    testdaemon_need_worker();
    testdaemon d;
    testdaemon_start(&d, "upload", NULL);
    int fds[4], busy = 0;
    for (int i = 0; i < 4; i++)
        busy += declare_huge(&d, &fds[i], 100 + (uint32_t)i);
    /* everyone else goes on: bob, the admin on TCP, root on the Unix
     * socket, each with a SUBMIT of a megabyte and a half (one that arrives
     * in several reads, so it is admitted before it is whole) */
    const char *tokens[] = {TESTDAEMON_BOB, TESTDAEMON_ADMIN, NULL};
    for (int i = 0; i < 3; i++) {
        mc_client *c = testdaemon_client(&d, tokens[i]);
        int rc;
        uint64_t id = testsec_submit_sphere(c, 5, MC_STAGES_RHM, 1, &rc);
        if (rc)
            FAILF("%s's SUBMIT while alice holds her uploads: %s (%s)", i == 0 ? "bob" : i == 1 ? "the admin" : "root",
                  mc_strerror(rc), mc_errmsg(c));
        CHECK_INT(mc_cancel(c, id), 0);
        mc_close(c);
    }
    /* her first fits her share (256 MiB of the 1 GiB), the others did not */
    CHECK_INT(busy, 3);
    CHECK(testdaemon_log_has(&d, "BUSY: user alice is sending 268435456 bytes of requests already; this"
                                 " 268435456-byte SUBMIT does not fit under max-request-memory-per-user 268435456"));
    for (int i = 0; i < 4; i++)
        close(fds[i]);
    testdaemon_stop(&d, SIGTERM);
}

TEST_T(the_admins_reserve_holds_when_ordinary_users_fill_the_rest, 120)
{
    testdaemon_need_worker();
    /* 4 MiB in all, 1.5 MiB a user: ordinary users together may declare
     * 2.5 MiB; the last 1.5 MiB is the reserve of admins and the Unix socket */
    static const char *const args[] = {"--max-request-memory", "4194304", "--max-request-memory-per-user",
                                       "1572864", NULL};
    testdaemon d;
    testdaemon_start(&d, "reserve", args);
    int a1 = testwire_session(&d, TESTDAEMON_ALICE), b1 = testwire_session(&d, TESTDAEMON_BOB);
    int b2 = testwire_session(&d, TESTDAEMON_BOB), a2 = testwire_session(&d, TESTDAEMON_ALICE);
    testwire_send_header(b1, PROTO_MSG_SUBMIT, 7, 1310720 - PROTO_HDR_SIZE);
    /* bob's next half MiB would pass his share */
    testwire_send_header(b2, PROTO_MSG_SUBMIT, 8, 524288 - PROTO_HDR_SIZE);
    testwire_expect_error(b2, 8, PROTO_EBUSY, "max-request-memory-per-user 1572864", 10);
    testwire_send_header(a1, PROTO_MSG_SUBMIT, 7, 1310720 - PROTO_HDR_SIZE);
    /* alice has room in her share, but the ordinary room is full */
    testwire_send_header(a2, PROTO_MSG_SUBMIT, 9, 262144 - PROTO_HDR_SIZE);
    testwire_expect_error(a2, 9, PROTO_EBUSY, "less the admins' reserve", 10);
    CHECK(testdaemon_log_has(&d, "this 262144-byte SUBMIT does not fit under max-request-memory 4194304 less the"
                                 " admins' reserve"));
    /* the admin (TCP) and the Unix socket still get in, with frames of
     * several reads */
    const char *tokens[] = {TESTDAEMON_ADMIN, NULL};
    for (int i = 0; i < 2; i++) {
        mc_client *c = testdaemon_client(&d, tokens[i]);
        int rc;
        uint64_t id = testsec_submit_sphere(c, 4, MC_STAGES_RHM, 1, &rc);
        if (rc)
            FAILF("%s's SUBMIT with the ordinary room full: %s (%s)", i ? "root" : "the admin", mc_strerror(rc),
                  mc_errmsg(c));
        CHECK_INT(mc_cancel(c, id), 0);
        mc_close(c);
    }
    close(a1);
    close(a2);
    close(b1);
    close(b2);
    testdaemon_stop(&d, SIGTERM);
}
