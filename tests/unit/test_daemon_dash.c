/* test_daemon_dash.c — meshcorrd's dashboards, black-box: a real daemon
 * started with --modbus and --metrics on free 127.0.0.1 ports, running the
 * real 381 -> 390 job from the demo's initial maps, read by Debian's mbpoll
 * (an independent Modbus client), by raw Modbus frames and by a raw HTTP
 * GET, and compared with STATS/STATUS from libmeshcorr; /metrics, idle and
 * with a job running, passes Prometheus' own parser and naming conventions
 * (tests/support/promcheck.py with Debian's python3-prometheus-client,
 * which also refuses texts that break them). Also the register
 * packing (floats and 32-bit values, high word first) against known bits and
 * a decoder written here from the IEEE-754 layout. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testhttp.h"
#include "support/testfile.h"
#include "support/testrun.h"
#include "map/bmap.h"
#include "mcd.h"
#include "mesh/mesh.h"
#include "meshcorr.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* ---- helpers --------------------------------------------------------------- */

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

static int tcp_connect(int port)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {0};
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || connect(fd, (struct sockaddr *)&a, sizeof a))
        FAILF("connect 127.0.0.1:%d: %s", port, strerror(errno));
    return fd;
}

/* Bytes within timeout_ms: >0 read, 0 closed by the peer, -1 nothing yet. */
static int read_wait(int fd, uint8_t *buf, size_t sz, int timeout_ms)
{
    struct pollfd p = {fd, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) <= 0)
        return -1;
    ssize_t n = recv(fd, buf, sz, 0);
    return n < 0 ? 0 : (int)n;   /* a reset counts as closed */
}

/* One raw Modbus TCP request (unit 1); the reply's PDU into pdu (its length). */
static int mb_request(int fd, const uint8_t *pdu, size_t n, uint8_t *rpdu, size_t rsz)
{
    static uint16_t tid = 1;
    uint8_t req[300];
    tid++;
    req[0] = (uint8_t)(tid >> 8), req[1] = (uint8_t)tid, req[2] = req[3] = 0;
    req[4] = (uint8_t)((n + 1) >> 8), req[5] = (uint8_t)(n + 1), req[6] = 1;
    memcpy(req + 7, pdu, n);
    if (send(fd, req, 7 + n, MSG_NOSIGNAL) != (ssize_t)(7 + n))
        FAILF("send: %s", strerror(errno));
    uint8_t rsp[300];
    size_t got = 0;
    while (got < 7 || got < 6 + (size_t)(rsp[4] << 8 | rsp[5])) {
        int r = read_wait(fd, rsp + got, sizeof rsp - got, 3000);
        if (r <= 0)
            FAILF("no Modbus reply to function 0x%02x (%s)", pdu[0], r ? "timeout" : "closed");
        got += (size_t)r;
    }
    CHECK(rsp[0] == req[0] && rsp[1] == req[1] && rsp[2] == 0 && rsp[3] == 0);
    size_t pl = got - 7;
    memcpy(rpdu, rsp + 7, pl < rsz ? pl : rsz);
    return (int)pl;
}

/* Function fc with a 4-byte body (address, count/value); the exception code, or 0 for a normal reply. */
static int mb_exception(int fd, uint8_t fc, uint16_t a, uint16_t b)
{
    uint8_t pdu[16] = {fc, (uint8_t)(a >> 8), (uint8_t)a, (uint8_t)(b >> 8), (uint8_t)b}, r[300];
    size_t n = 5;
    if (fc == 0x0F || fc == 0x10) {            /* write multiple: byte count + data */
        pdu[5] = fc == 0x10 ? (uint8_t)(2 * b) : 1;
        pdu[6] = pdu[7] = 0;
        n = 6 + pdu[5];
    }
    int rl = mb_request(fd, pdu, n, r, sizeof r);
    if (r[0] == (fc | 0x80)) {
        CHECK_INT(rl, 2);
        return r[1];
    }
    CHECK_INT(r[0], fc);
    return 0;
}

/* mbpoll's output lines "[ADDR]: \tVALUE": n values of width registers
 * each from address first (values[i] at first + i * width); how many were read. */
static int mbpoll(int port, const char *type, int width, int first, int n, double *values, char *out, size_t osz)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "mbpoll -m tcp -p %d -t %s -B -0 -r %d -c %d -1 -o 2 127.0.0.1 2>&1", port, type,
             first, n);
    FILE *fp = popen(cmd, "r");
    if (!fp)
        FAILF("popen mbpoll: %s", strerror(errno));
    size_t len = 0;
    out[0] = '\0';
    char line[512];
    int found = 0;
    while (fgets(line, sizeof line, fp)) {
        if (len + strlen(line) < osz)
            len += (size_t)snprintf(out + len, osz - len, "%s", line);
        int addr;
        double v;
        if (sscanf(line, "[%d]: %lf", &addr, &v) == 2 && addr >= first && addr < first + n * width) {
            values[(addr - first) / width] = v;
            found++;
        }
    }
    int st = pclose(fp);
    return WIFEXITED(st) && WEXITSTATUS(st) == 0 ? found : -1;
}

static void need_mbpoll(void)
{
    if (system("mbpoll -V >/dev/null 2>&1") != 0)
        SKIP("mbpoll is not installed (deploy/install-deps.sh installs it)");
}

static uint32_t u32(const double *r, int a)
{
    return (uint32_t)r[a] << 16 | (uint32_t)r[a + 1];
}

/* IEEE-754 single from its two registers (high word first), decoded from
 * the bit layout with ldexp: no type punning, independent of mbus_put_f32. */
static double decode_f32(uint16_t hi, uint16_t lo)
{
    uint32_t b = (uint32_t)hi << 16 | lo;
    int sign = b >> 31, exp = (int)(b >> 23 & 0xFF);
    uint32_t frac = b & 0x7FFFFF;
    double v = exp ? ldexp(1.0 + frac / 8388608.0, exp - 127) : ldexp(frac / 8388608.0, -126);
    return sign ? -v : v;
}

/* ---- packing ---------------------------------------------------------------- */

TEST(registers_pack_floats_and_u32_high_word_first)
{
    uint16_t r[2];
    mbus_put_f32(r, 1.0f);
    CHECK_INT(r[0], 0x3F80);
    CHECK_INT(r[1], 0x0000);
    mbus_put_f32(r, -2.5f);
    CHECK_INT(r[0], 0xC020);
    CHECK_INT(r[1], 0x0000);
    mbus_put_f32(r, 0.1f);                    /* 0x3DCCCCCD */
    CHECK_INT(r[0], 0x3DCC);
    CHECK_INT(r[1], 0xCCCD);
    mbus_put_u32(r, 0x12345678u);
    CHECK_INT(r[0], 0x1234);
    CHECK_INT(r[1], 0x5678);
    const float vals[] = {116.14405f, 65.711364f, 500.0f, 1e5f, -3.25e-3f, 1e-40f, 6938.0f};
    for (size_t i = 0; i < sizeof vals / sizeof vals[0]; i++) {
        mbus_put_f32(r, vals[i]);
        if (decode_f32(r[0], r[1]) != (double)vals[i])
            FAILF("%.9g packed as %04x %04x decodes to %.9g", vals[i], r[0], r[1], decode_f32(r[0], r[1]));
    }
}

TEST(register_map_puts_each_figure_at_its_documented_address)
{
    snap_slot slots[2] = {{0}};
    mcd_snapshot snap = {0}, *s = &snap;
    s->slots = slots;
    s->nslots = 2;
    s->seq = 70001;                           /* the heartbeat is its low 16 bits */
    s->uptime_s = 0x00012345;
    s->queued = 7;
    s->running = 1;
    s->workers = 2;
    s->completed = 0x100000003ull;            /* low 32 bits */
    s->failed = 4;
    s->cancelled = 5;
    s->slots[1] = (snap_slot){0x200000009ull, PROTO_SLOT_BUSY, 1, PROTO_STAGE_ECTM, 5, 20, -2.5, 1.0, 42,
                              0.8765, 77000.4};
    size_t n = mbus_nregs(2);
    CHECK_INT(n, 56);
    uint16_t *r = calloc(n, sizeof *r);
    mbus_fill(s, r);
    CHECK_INT(r[0], 70001 & 0xFFFF);
    CHECK_INT(r[1], PROTO_VERSION);
    CHECK_INT(r[2], 0x0001);
    CHECK_INT(r[3], 0x2345);
    CHECK_INT(r[5], 7);
    CHECK_INT(r[6], 1);
    CHECK_INT(r[7], 2);
    CHECK_INT(r[8] << 16 | r[9], 3);
    CHECK_INT(r[11], 4);
    CHECK_INT(r[13], 5);
    CHECK_INT(r[14], 16);
    CHECK_INT(r[15], 20);
    CHECK_INT(r[16 + 3], 0xFFFF);             /* idle slot 0: no progress */
    CHECK_INT(r[16 + 14], 0);
    CHECK_INT(r[16 + 16] << 16 | r[16 + 17], 0xFFFF << 16 | 0xFFFF);   /* no time left known */
    const uint16_t *b = r + 36;
    CHECK_INT(b[0] << 16 | b[1], 9);
    CHECK_INT(b[2], PROTO_SLOT_BUSY);
    CHECK_INT(b[3], PROTO_STAGE_ECTM);
    CHECK_INT(b[5], 5);
    CHECK_INT(b[7], 20);
    CHECK_INT(b[8], 0xC020);
    CHECK_INT(b[9], 0);
    CHECK_INT(b[10], 0x3F80);
    CHECK_INT(b[13], 42);
    CHECK_INT(b[14], 87);                     /* the whole job's share, not the stage's 5 of 20 */
    CHECK_INT(b[15], 1);
    CHECK_INT(b[16] << 16 | b[17], 77000);    /* seconds left */
    CHECK_INT(b[18], 25);                     /* the stage's own: 5 of 20 */
    CHECK_INT(b[19], 8765);
    free(r);
}

/* ---- the live daemon ------------------------------------------------------- */

typedef struct dash {
    testdaemon d;
    int modbus, metrics;
    mc_client *c;                             /* admin */
    uint64_t job;
} dash;

static mc_map_row *rows(const bmap *P)
{
    mc_map_row *r = calloc((size_t)P->n, sizeof *r);
    for (int i = 0; i < P->n; i++) {
        r[i].face = (uint32_t)P->face[i];
        memcpy(r[i].w, P->w + 3 * i, sizeof r[i].w);
    }
    return r;
}

/* The demo job 381 -> 390 from its initial maps: iterations outer
 * iterations of inner L-BFGS steps each. */
static uint64_t submit_demo(mc_client *c, int iterations, int inner)
{
    char s_off[1024], t_off[1024], p_map[1024], q_map[1024], err[512];
    snprintf(s_off, sizeof s_off, "%s", harness_data_path("shrec07_bim/Meshes/381.off"));
    snprintf(t_off, sizeof t_off, "%s", harness_data_path("shrec07_bim/Meshes/390.off"));
    snprintf(p_map, sizeof p_map, "%s", harness_data_path("ectm_demo_381_390/init_381_to_390.map"));
    snprintf(q_map, sizeof q_map, "%s", harness_data_path("ectm_demo_381_390/init_390_to_381.map"));
    mesh *S = NULL, *T = NULL;
    bmap *P = NULL, *Q = NULL;
    if (mesh_read(s_off, &S, err, sizeof err) || mesh_read(t_off, &T, err, sizeof err) ||
        bmap_read(p_map, S, T, &P, err, sizeof err) || bmap_read(q_map, T, S, &Q, err, sizeof err))
        FAILF("demo input: %s", err);
    unsigned char *sb, *tb;
    size_t sl, tl;
    if (mc_encode_mesh_file(s_off, &sb, &sl, err, sizeof err) || mc_encode_mesh_file(t_off, &tb, &tl, err, sizeof err))
        FAILF("encode: %s", err);
    mc_job_spec spec;
    mc_job_spec_init(&spec);
    spec.source = sb, spec.source_len = sl, spec.target = tb, spec.target_len = tl;
    mc_map_row *pr = rows(P), *qr = rows(Q);
    spec.p = pr, spec.np = (uint32_t)P->n, spec.q = qr, spec.nq = (uint32_t)Q->n;
    spec.iterations = (uint32_t)iterations;
    spec.inner_iterations = (uint32_t)inner;
    spec.stop_change = 0;
    spec.label = "demo 381 -> 390";
    uint64_t id = 0;
    int rc = mc_submit(c, &spec, &id);
    if (rc)
        FAILF("SUBMIT: %s (%s)", mc_strerror(rc), mc_errmsg(c));
    free(pr), free(qr), free(sb), free(tb);
    bmap_free(P), bmap_free(Q), mesh_free(S), mesh_free(T);
    return id;
}

static void dash_start(dash *x, const char *name)
{
    char mb[32], me[32];
    x->modbus = testhttp_free_port();
    do
        x->metrics = testhttp_free_port();
    while (x->metrics == x->modbus);
    snprintf(mb, sizeof mb, "127.0.0.1:%d", x->modbus);
    snprintf(me, sizeof me, "%d", x->metrics);     /* port only: 127.0.0.1 */
    const char *args[] = {"--modbus", mb, "--metrics", me, NULL};
    testdaemon_start(&x->d, name, args);
    x->c = testdaemon_client(&x->d, TESTDAEMON_ADMIN);
}

/* Waits until the job runs and has reported an ECTM iteration. */
static void wait_iterating(dash *x)
{
    mc_job_status st;
    for (double t0 = now_s(); now_s() - t0 < 60; testdaemon_sleep_ms(50)) {
        CHECK_INT(mc_status(x->c, x->job, &st), 0);
        if (st.state >= MC_COMPLETED)
            FAILF("job ended %s: %s", mc_state_name(st.state), st.reason);
        if (st.has_progress && st.progress.stage == PROTO_STAGE_ECTM && st.progress.outer >= 1)
            return;
    }
    FAILF("job %llu reported no ECTM iteration within 60 s", (unsigned long long)x->job);
}

/* Block 0 and slot 0: 36 registers read by mbpoll. */
static void poll_regs(dash *x, double r[36])
{
    char out[8192];
    int n = mbpoll(x->modbus, "3", 1, 0, 36, r, out, sizeof out);
    if (n != 36)
        FAILF("mbpoll read %d of 36 registers:\n%s", n, out);
}

TEST_T(modbus_registers_follow_a_running_job_and_agree_with_stats, 90)
{
    testdaemon_need_worker();
    need_mbpoll();
    dash x;
    dash_start(&x, "modbus");
    x.job = submit_demo(x.c, 20, 20);
    wait_iterating(&x);

    /* STATUS, registers, STATUS: when the three agree on the iteration, the
     * floats must be the same numbers rounded to float32 */
    double r[36], first_outer, first_beat;
    mc_job_status a, b;
    int matched = 0;
    for (int tries = 0; tries < 100 && !matched; tries++) {
        CHECK_INT(mc_status(x.c, x.job, &a), 0);
        poll_regs(&x, r);
        CHECK_INT(mc_status(x.c, x.job, &b), 0);
        if (a.state != MC_RUNNING || b.state != MC_RUNNING)
            FAILF("job left RUNNING while being polled");
        if (a.progress.outer != b.progress.outer || u32(r, 20) != a.progress.outer)
            continue;
        matched = 1;
        CHECK_INT(u32(r, 16), (uint32_t)x.job);          /* job id, low 32 bits */
        CHECK_INT(r[18], PROTO_SLOT_BUSY);
        CHECK_INT(r[19], PROTO_STAGE_ECTM);
        CHECK_INT(u32(r, 22), 20);
        /* an ECTM-only job: the whole job's share is ECTM's, and the
         * registers say the record's share and time left */
        CHECK_INT(r[30], (int)(a.progress.fraction * 100 + 1e-9));
        CHECK_INT(r[30], a.progress.outer * 100 / 20);
        CHECK_INT(r[31], 1);
        CHECK_INT(u32(r, 32), (uint32_t)a.progress.eta_s);
        CHECK_INT(r[34], a.progress.outer * 100 / 20);
        CHECK_INT(r[35], (int)(a.progress.fraction * 10000 + 1e-9));
        float e = (float)(a.progress.energy[0] + a.progress.energy[1]), be = (float)a.progress.beta;
        double got_e = decode_f32((uint16_t)r[24], (uint16_t)r[25]), got_b = decode_f32((uint16_t)r[26], (uint16_t)r[27]);
        if (got_e != (double)e || got_b != (double)be)
            FAILF("registers: energy %.9g beta %.9g; STATUS: %.9g %.9g", got_e, got_b, (double)e, (double)be);
        /* mbpoll's own float decoding (-B: high word first) reads the same
         * registers as the same numbers (to its 6 printed digits) */
        int same = 0;
        for (int k = 0; k < 20 && !same; k++) {
            double p1[4], p2[4], f[2];
            char out[8192];
            CHECK_INT(mbpoll(x.modbus, "3", 1, 24, 4, p1, out, sizeof out), 4);
            CHECK_INT(mbpoll(x.modbus, "3:float", 2, 24, 2, f, out, sizeof out), 2);
            CHECK_INT(mbpoll(x.modbus, "3", 1, 24, 4, p2, out, sizeof out), 4);
            if (memcmp(p1, p2, sizeof p1) != 0)
                continue;
            same = 1;
            double de = decode_f32((uint16_t)p1[0], (uint16_t)p1[1]), db = decode_f32((uint16_t)p1[2], (uint16_t)p1[3]);
            CHECK_NEAR(f[0], de, fabs(de) * 1e-5);
            CHECK_NEAR(f[1], db, fabs(db) * 1e-5);
        }
        CHECK(same);
        double elapsed = (double)(store_now_ms() - a.start_ms) / 1000;
        CHECK(u32(r, 28) <= elapsed + 1 && u32(r, 28) + 2 >= elapsed);
    }
    if (!matched)
        FAILF("registers never caught up with STATUS");

    /* block 0 agrees with STATS */
    mc_server_stats st;
    CHECK_INT(mc_stats(x.c, &st), 0);
    CHECK_INT(r[1], PROTO_VERSION);
    CHECK_INT(u32(r, 4), st.queued);
    CHECK_INT(r[6], st.running);
    CHECK_INT(r[7], st.workers);
    CHECK_INT(u32(r, 8), st.completed);
    CHECK_INT(u32(r, 10), st.failed);
    CHECK_INT(u32(r, 12), st.cancelled);
    CHECK_INT(st.slot_job[0], x.job);
    CHECK_INT(r[18], st.slot_state[0]);
    CHECK(u32(r, 2) < 120);                          /* uptime: started within this test */
    mc_stats_free(&st);

    /* while the job runs the iteration and the heartbeat move */
    first_outer = u32(r, 20);
    first_beat = r[0];
    CHECK(first_outer >= 1);
    double t0 = now_s();
    while (u32(r, 20) <= first_outer && now_s() - t0 < 60) {
        testdaemon_sleep_ms(200);
        poll_regs(&x, r);
    }
    if (u32(r, 20) <= first_outer)
        FAILF("outer iteration stuck at %.0f", first_outer);
    CHECK(r[0] != first_beat);
    printf("  outer iteration %.0f -> %u in %.1f s; heartbeat %.0f -> %.0f\n", first_outer, u32(r, 20),
           now_s() - t0, first_beat, r[0]);

    /* cancelled: the counter moves in STATS and in the registers alike */
    CHECK_INT(mc_cancel(x.c, x.job), 0);
    testdaemon_wait_state(x.c, x.job, MC_CANCELLED, 30);
    testdaemon_sleep_ms(2 * SNAP_PERIOD_MS);
    poll_regs(&x, r);
    CHECK_INT(mc_stats(x.c, &st), 0);
    CHECK_INT(u32(r, 12), st.cancelled);
    CHECK(st.cancelled >= 1);
    CHECK_INT(r[6], 0);
    CHECK_INT(u32(r, 16), 0);
    mc_stats_free(&st);
    mc_close(x.c);
    double t1 = now_s();
    testdaemon_stop(&x.d, SIGTERM);
    printf("  daemon with both dashboards stopped %.0f ms after SIGTERM\n", (now_s() - t1) * 1000);
}

/* A read of block 0 over a raw socket answers within timeout_ms (*ms: how fast). */
static int served_within(int port, int timeout_ms, double *ms_out)
{
    int fd = tcp_connect(port);
    double t0 = now_s();
    uint8_t pdu[5] = {0x04, 0, 0, 0, 16}, r[300];
    int n = mb_request(fd, pdu, 5, r, sizeof r);
    double ms = (now_s() - t0) * 1000;
    close(fd);
    if (ms_out)
        *ms_out = ms;
    return n == 2 + 32 && r[0] == 0x04 && r[1] == 32 && ms < timeout_ms;
}

TEST_T(modbus_refuses_writes_and_junk_and_keeps_serving, 60)
{
    need_mbpoll();
    dash x;
    dash_start(&x, "hostile");
    /* mbpoll as a writer: ILLEGAL FUNCTION, nothing written */
    char out[8192];
    double v[2];
    char cmd[256];
    snprintf(cmd, sizeof cmd, "mbpoll -m tcp -p %d -t 4 -0 -r 0 -1 -o 2 127.0.0.1 5 2>&1", x.modbus);
    FILE *fp = popen(cmd, "r");
    size_t len = fread(out, 1, sizeof out - 1, fp);
    out[len] = '\0';
    CHECK(pclose(fp) != 0);
    CHECK_STR_HAS(out, "Illegal function");
    CHECK(mbpoll(x.modbus, "3", 1, 1, 1, v, out, sizeof out) == 1 && v[0] == PROTO_VERSION);

    /* raw frames: every function but 0x04 is ILLEGAL FUNCTION (1); bad
     * counts ILLEGAL DATA VALUE (3); addresses off the map ILLEGAL DATA ADDRESS (2) */
    int fd = tcp_connect(x.modbus);
    static const uint8_t refused[] = {0x01, 0x02, 0x03, 0x05, 0x06, 0x07, 0x0F, 0x10, 0x11, 0x16, 0x17, 0x2B, 0x42};
    for (size_t i = 0; i < sizeof refused; i++)
        if (mb_exception(fd, refused[i], 0, 1) != 1)
            FAILF("function 0x%02x: not ILLEGAL FUNCTION", refused[i]);
    CHECK_INT(mb_exception(fd, 0x04, 0, 0), 3);
    CHECK_INT(mb_exception(fd, 0x04, 0, 126), 3);
    uint32_t nregs = (uint32_t)mbus_nregs(1);                 /* one worker slot */
    CHECK_INT(mb_exception(fd, 0x04, (uint16_t)nregs, 1), 2);
    CHECK_INT(mb_exception(fd, 0x04, (uint16_t)(nregs - 4), 5), 2);
    CHECK_INT(mb_exception(fd, 0x04, 65535, 1), 2);
    CHECK_INT(mb_exception(fd, 0x04, (uint16_t)(nregs - 16), 16), 0);
    close(fd);

    /* garbage bytes: the connection is closed */
    fd = tcp_connect(x.modbus);
    uint8_t junk[64], buf[64];
    srand(7);
    for (size_t i = 0; i < sizeof junk; i++)
        junk[i] = (uint8_t)(rand() | 1);
    CHECK(send(fd, junk, sizeof junk, MSG_NOSIGNAL) == (ssize_t)sizeof junk);
    CHECK_INT(read_wait(fd, buf, sizeof buf, 2000), 0);
    close(fd);

    /* half an MBAP header held open: others are served meanwhile, then it is closed */
    int half = tcp_connect(x.modbus);
    CHECK(send(half, "\x00\x01\x00", 3, MSG_NOSIGNAL) == 3);
    testdaemon_sleep_ms(100);
    double t0 = now_s(), served_ms;
    CHECK(served_within(x.modbus, 200, &served_ms));
    CHECK(mbpoll(x.modbus, "3", 1, 1, 1, v, out, sizeof out) == 1);
    mc_server_stats st;
    CHECK_INT(mc_stats(x.c, &st), 0);
    CHECK_INT(st.workers, 1);
    mc_stats_free(&st);
    int r = read_wait(half, buf, sizeof buf, 3000);
    CHECK_INT(r, 0);
    printf("  a second client served in %.2f ms while a half frame was held; the half frame closed after %.0f ms\n",
           served_ms, (now_s() - t0) * 1000 + 100);
    close(half);

    /* MBUS_MAX_CLIENTS idle connections: one more is closed at once, the daemon still answers STATS */
    int held[MBUS_MAX_CLIENTS];
    for (int i = 0; i < MBUS_MAX_CLIENTS; i++)
        held[i] = tcp_connect(x.modbus);
    testdaemon_sleep_ms(300);
    fd = tcp_connect(x.modbus);
    CHECK_INT(read_wait(fd, buf, sizeof buf, 2000), 0);
    close(fd);
    CHECK_INT(mc_ping(x.c), 0);
    for (int i = 0; i < MBUS_MAX_CLIENTS; i++)
        close(held[i]);
    testdaemon_sleep_ms(300);
    CHECK(served_within(x.modbus, 1000, NULL));
    mc_close(x.c);
    testdaemon_stop(&x.d, SIGTERM);
}

/* ---- /metrics --------------------------------------------------------------- */

/* GET (or method) path over a raw socket: the status code; the body into body. */
static int http_ask(int port, const char *method, const char *path, char *body, size_t bsz)
{
    static char resp[1 << 16];
    int status = testhttp_request(port, method, path, "", NULL, resp, sizeof resp, 3000);
    if (status <= 0)
        FAILF("not an HTTP response: %.100s", resp);
    snprintf(body, bsz, "%s", testhttp_body(resp));
    return status;
}

typedef struct sample { char name[128], labels[256]; double value; } sample;

/* Parses Prometheus text: every sample `name{labels} value` or `name value`
 * with a numeric value, and its family announced by # HELP and # TYPE. */
static int parse_metrics(char *text, sample *out, int max)
{
    char help[64][128], type[64][128];
    int nh = 0, nt = 0, n = 0;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        char name[128], kind[32];
        if (sscanf(line, "# HELP %127s", name) == 1) {
            CHECK(nh < 64 && strlen(line) > strlen(name) + 8);
            snprintf(help[nh++], 128, "%s", name);
            continue;
        }
        if (sscanf(line, "# TYPE %127s %31s", name, kind) == 2) {
            CHECK(!strcmp(kind, "gauge") || !strcmp(kind, "counter") || !strcmp(kind, "histogram"));
            CHECK(nt < 64);
            snprintf(type[nt++], 128, "%s", name);
            continue;
        }
        if (line[0] == '#')
            FAILF("unexpected comment line: %s", line);
        CHECK(n < max);
        sample *s = &out[n++];
        size_t k = strcspn(line, "{ ");
        CHECK(k > 0 && k < sizeof s->name);
        memcpy(s->name, line, k);
        s->name[k] = '\0';
        for (size_t i = 0; i < k; i++)
            CHECK(line[i] == '_' || (line[i] >= 'a' && line[i] <= 'z') || (i && line[i] >= '0' && line[i] <= '9'));
        char *rest = line + k;
        s->labels[0] = '\0';
        if (*rest == '{') {
            char *close = strchr(rest, '}');
            CHECK(close != NULL && (size_t)(close - rest) < sizeof s->labels);
            memcpy(s->labels, rest + 1, (size_t)(close - rest - 1));
            s->labels[close - rest - 1] = '\0';
            rest = close + 1;
        }
        CHECK(*rest == ' ');
        char *end;
        s->value = strtod(rest + 1, &end);
        if (end == rest + 1 || *end != '\0' || !isfinite(s->value))
            FAILF("sample value not numeric: %s", line);
        /* a histogram's samples are its family's name with _bucket, _sum, _count */
        char fam[128];
        snprintf(fam, sizeof fam, "%s", s->name);
        static const char *const parts[] = {"_bucket", "_sum", "_count"};
        for (int p = 0; p < 3; p++) {
            size_t fl = strlen(fam), pl = strlen(parts[p]);
            if (fl > pl && !strcmp(fam + fl - pl, parts[p]) && strstr(fam, "_seconds")) {
                fam[fl - pl] = '\0';
                break;
            }
        }
        int h = 0, t = 0;
        for (int i = 0; i < nh; i++)
            h |= !strcmp(help[i], s->name) || !strcmp(help[i], fam);
        for (int i = 0; i < nt; i++)
            t |= !strcmp(type[i], s->name) || !strcmp(type[i], fam);
        if (!h || !t)
            FAILF("%s has no # HELP or # TYPE before it", s->name);
    }
    return n;
}

static double metric(const sample *s, int n, const char *name, const char *labels)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(s[i].name, name) && !strcmp(s[i].labels, labels))
            return s[i].value;
    FAILF("no sample %s{%s}", name, labels);
    return 0;
}

TEST_T(metrics_endpoint_is_prometheus_text_matching_stats, 90)
{
    testdaemon_need_worker();
    dash x;
    dash_start(&x, "metrics");
    x.job = submit_demo(x.c, 20, 20);
    uint64_t queued = submit_demo(x.c, 2, 1);        /* waits behind the first: one worker */
    wait_iterating(&x);
    testdaemon_sleep_ms(2 * SNAP_PERIOD_MS);
    static char body[1 << 16];
    static sample s[256];
    CHECK_INT(http_ask(x.metrics, "GET", "/metrics", body, sizeof body), 200);
    mc_server_stats st;
    CHECK_INT(mc_stats(x.c, &st), 0);
    int n = parse_metrics(body, s, 256);
    CHECK(n >= 10);
    CHECK_INT(metric(s, n, "meshcorr_queue_depth", ""), st.queued);
    CHECK_INT(st.queued, 1);
    CHECK_INT(metric(s, n, "meshcorr_running_jobs", ""), st.running);
    CHECK_INT(metric(s, n, "meshcorr_workers", ""), st.workers);
    CHECK_INT(metric(s, n, "meshcorr_jobs_total", "state=\"completed\""), st.completed);
    CHECK_INT(metric(s, n, "meshcorr_jobs_total", "state=\"failed\""), st.failed);
    CHECK_INT(metric(s, n, "meshcorr_jobs_total", "state=\"cancelled\""), st.cancelled);
    CHECK(metric(s, n, "meshcorr_uptime_seconds", "") >= 0);
    char lab[64];
    snprintf(lab, sizeof lab, "slot=\"0\",job_id=\"%llu\"", (unsigned long long)x.job);
    CHECK_INT(metric(s, n, "meshcorr_slot_state", lab), st.slot_state[0]);
    CHECK_INT(st.slot_job[0], x.job);
    CHECK_INT(metric(s, n, "meshcorr_slot_stage", lab), PROTO_STAGE_ECTM);
    CHECK_INT(metric(s, n, "meshcorr_slot_total_iterations", lab), 20);
    CHECK(metric(s, n, "meshcorr_slot_outer_iteration", lab) >= 1);
    /* the ratio is the whole job's share done; an ECTM-only job's is ECTM's */
    double ratio = metric(s, n, "meshcorr_slot_progress_ratio", lab);
    CHECK(ratio > 0 && ratio <= 1);
    CHECK_NEAR(ratio, metric(s, n, "meshcorr_slot_outer_iteration", lab) / 20, 1e-9);
    CHECK(metric(s, n, "meshcorr_slot_eta_seconds", lab) >= 0);
    CHECK(metric(s, n, "meshcorr_slot_energy", lab) > 0);
    CHECK(metric(s, n, "meshcorr_slot_beta", lab) > 0);
    mc_stats_free(&st);

    /* the counters after a cancel agree with STATS */
    CHECK_INT(mc_cancel(x.c, queued), 0);
    CHECK_INT(mc_cancel(x.c, x.job), 0);
    testdaemon_wait_state(x.c, x.job, MC_CANCELLED, 30);
    testdaemon_sleep_ms(2 * SNAP_PERIOD_MS);
    CHECK_INT(http_ask(x.metrics, "GET", "/metrics", body, sizeof body), 200);
    CHECK_INT(mc_stats(x.c, &st), 0);
    n = parse_metrics(body, s, 256);
    CHECK_INT(st.cancelled, 2);
    CHECK_INT(metric(s, n, "meshcorr_jobs_total", "state=\"cancelled\""), 2);
    CHECK_INT(metric(s, n, "meshcorr_queue_depth", ""), 0);
    CHECK_INT(metric(s, n, "meshcorr_running_jobs", ""), 0);
    CHECK_INT(metric(s, n, "meshcorr_slot_state", "slot=\"0\",job_id=\"0\""), 0);
    mc_stats_free(&st);

    /* other paths and methods: / is the web UI, which sends a browser
     * without a session to its login page */
    CHECK_INT(http_ask(x.metrics, "GET", "/", body, sizeof body), 303);
    CHECK_INT(http_ask(x.metrics, "GET", "/metricsx", body, sizeof body), 404);
    CHECK_INT(http_ask(x.metrics, "POST", "/metrics", body, sizeof body), 405);
    CHECK_INT(http_ask(x.metrics, "DELETE", "/metrics", body, sizeof body), 405);
    mc_close(x.c);
    testdaemon_stop(&x.d, SIGTERM);
}

/* Runs promcheck.py with Debian's python3 (the one with Debian's packages)
 * on args; its exit status, its report in out. */
static int promcheck(const char *args, char *out, size_t outsz)
{
    return testrunf(out, outsz, "/usr/bin/python3 tests/support/promcheck.py %s 2>&1", args);
}

TEST_T(metrics_pass_prometheus_own_parser_idle_and_running, 120)
{
    testdaemon_need_worker();
    static char body[1 << 16], report[1 << 14], files[2][600];
    dash x;
    dash_start(&x, "promparse");
    testdaemon_sleep_ms(2 * SNAP_PERIOD_MS);
    CHECK_INT(http_ask(x.metrics, "GET", "/metrics", body, sizeof body), 200);
    snprintf(files[0], sizeof files[0], "%s", testfile_text("idle.prom", body));

    x.job = testdaemon_submit_ok(x.c, 1000, 1, 0);      /* runs until cancelled */
    mc_job_status st;
    for (int i = 0; i < 3000; i++) {                      /* up to 60 s */
        CHECK_INT(mc_status(x.c, x.job, &st), 0);
        if (st.state >= MC_COMPLETED)
            FAILF("job ended %s: %s", mc_state_name(st.state), st.reason);
        if (st.has_progress && st.progress.stage == PROTO_STAGE_ECTM)
            break;
        testdaemon_sleep_ms(20);
    }
    CHECK(st.has_progress && st.progress.stage == PROTO_STAGE_ECTM);
    testdaemon_sleep_ms(2 * SNAP_PERIOD_MS);
    CHECK_INT(http_ask(x.metrics, "GET", "/metrics", body, sizeof body), 200);
    snprintf(files[1], sizeof files[1], "%s", testfile_text("running.prom", body));
    CHECK_STR_HAS(body, "meshcorr_slot_energy{");
    CHECK_INT(mc_cancel(x.c, x.job), 0);
    testdaemon_wait_state(x.c, x.job, MC_CANCELLED, 30);

    char args[2048];
    snprintf(args, sizeof args,
             "%s %s --expect meshcorr_queue_depth --expect meshcorr_running_jobs --expect meshcorr_jobs_total"
             " --expect meshcorr_workers --expect meshcorr_uptime_seconds --expect meshcorr_snapshots_total"
             " --expect meshcorr_slot_state --expect meshcorr_slot_elapsed_seconds --expect meshcorr_slot_stage"
             " --expect meshcorr_slot_outer_iteration --expect meshcorr_slot_total_iterations"
             " --expect meshcorr_slot_progress_ratio --expect meshcorr_slot_eta_seconds"
             " --expect meshcorr_slot_energy --expect meshcorr_slot_beta --expect meshcorr_build_info"
             " --expect meshcorr_user_queue_depth --expect meshcorr_user_running_jobs"
             " --expect meshcorr_job_duration_seconds --expect meshcorr_job_queue_wait_seconds",
             files[0], files[1]);
    int rc = promcheck(args, report, sizeof report);
    if (rc != 0)
        FAILF("promcheck.py (exit %d; python3-prometheus-client: deploy/install-deps.sh):\n%s", rc, report);
    mc_close(x.c);
    testdaemon_stop(&x.d, SIGTERM);
}

TEST(promcheck_refuses_texts_that_break_the_conventions)
{
    static char report[1 << 14];
    static const struct { const char *text, *finding; } bad[] = {
        {"# HELP meshcorr_jobs Jobs.\n# TYPE meshcorr_jobs counter\nmeshcorr_jobs 3\n", "does not end in _total"},
        {"# TYPE meshcorr_queue_depth gauge\nmeshcorr_queue_depth 1\n", "has no HELP"},
        {"# HELP meshcorr_queue_depth Jobs.\nmeshcorr_queue_depth 1\n", "has no TYPE"},
        {"# HELP meshcorr_queue_total Jobs.\n# TYPE meshcorr_queue_total gauge\nmeshcorr_queue_total 1\n",
         "the counters' suffix"},
        {"# HELP meshcorr_uptime Up.\n# TYPE meshcorr_uptime gauge\nmeshcorr_uptime 1\n", "_seconds"},
        {"# HELP meshcorr_slot_state S.\n# TYPE meshcorr_slot_state gauge\nmeshcorr_slot_state{job=\"1\"} 1\n",
         "label 'job'"},
        {"# HELP meshcorr_workers W.\n# TYPE meshcorr_workers gauge\nmeshcorr_workers one\n", "parser refuses"},
        {"# HELP meshcorr_wait_seconds W.\n# TYPE meshcorr_wait_seconds histogram\n"
         "meshcorr_wait_seconds_bucket{le=\"1\"} 3\nmeshcorr_wait_seconds_bucket{le=\"+Inf\"} 2\n"
         "meshcorr_wait_seconds_sum 1\nmeshcorr_wait_seconds_count 2\n", "not cumulative"},
        {"# HELP meshcorr_workers W.\n# TYPE meshcorr_workers gauge\nmeshcorr_workers{le=\"1\"} 1\n", "label 'le'"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        int rc = promcheck(testfile_text("bad.prom", bad[i].text), report, sizeof report);
        if (rc != 1 || !strstr(report, bad[i].finding))
            FAILF("promcheck.py on\n%s: exit %d, wanted 1 and \"%s\":\n%s", bad[i].text, rc, bad[i].finding, report);
    }
    const char *good = "# HELP meshcorr_jobs_total Jobs.\n# TYPE meshcorr_jobs_total counter\n"
                       "meshcorr_jobs_total{state=\"failed\"} 0\n"
                       "# HELP meshcorr_wait_seconds W.\n# TYPE meshcorr_wait_seconds histogram\n"
                       "meshcorr_wait_seconds_bucket{le=\"1\"} 1\nmeshcorr_wait_seconds_bucket{le=\"+Inf\"} 2\n"
                       "meshcorr_wait_seconds_sum 3.5\nmeshcorr_wait_seconds_count 2\n";
    int rc = promcheck(testfile_text("good.prom", good), report, sizeof report);
    if (rc != 0)
        FAILF("promcheck.py refused a good text (exit %d):\n%s", rc, report);
}

TEST(dashboard_options_parse_host_and_port)
{
    mcd_conf c;
    char err[256];
    conf_init(&c);
    CHECK_INT(c.modbus.port, -1);
    CHECK_INT(c.http.port, -1);
    CHECK_INT(conf_set(&c, "modbus", "1502", err, sizeof err), 0);
    CHECK_STR_HAS(c.modbus.host, "127.0.0.1");
    CHECK_INT(c.modbus.port, 1502);
    CHECK_INT(conf_set(&c, "metrics", "0.0.0.0:9101", err, sizeof err), 0);
    CHECK(!strcmp(c.http.host, "0.0.0.0") && c.http.port == 9101);
    CHECK_INT(conf_set(&c, "metrics", "[::1]:9102", err, sizeof err), 0);
    CHECK(!strcmp(c.http.host, "::1") && c.http.port == 9102);
    CHECK_INT(conf_set(&c, "http", "9103", err, sizeof err), 0);     /* --metrics is its alias */
    CHECK(!strcmp(c.http.host, "127.0.0.1") && c.http.port == 9103);
    CHECK(conf_set(&c, "modbus", "host:", err, sizeof err) != 0);
    CHECK(conf_set(&c, "modbus", ":1502", err, sizeof err) != 0);
    CHECK(conf_set(&c, "modbus", "70000", err, sizeof err) != 0);
    CHECK_STR_HAS(err, "--modbus");
}
