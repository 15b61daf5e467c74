/* test_grafana.c — deploy/grafana/meshcorr.json against the real daemon:
 * the file is one JSON value, every panel has a query, and every metric
 * name a query uses is a family the real meshcorrd's GET /metrics declares
 * (a histogram's _bucket, _sum and _count through its family), so the
 * dashboard cannot drift from what the daemon exports. */
#include "support/harness.h"
#include "support/testdaemon.h"
#include "support/testhttp.h"
#include "support/testfile.h"
#include "support/testjson.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

/* GET /metrics from 127.0.0.1:port: the body, in a static buffer. */
static const char *get_metrics(int port)
{
    static char resp[1 << 18];
    int status = testhttp_request(port, "GET", "/metrics", "", NULL, resp, sizeof resp, 5000);
    if (status != 200)
        FAILF("GET /metrics: status %d: %.100s", status, resp);
    return testhttp_body(resp);
}

/* 1 when the text declares family name (# TYPE name ...), or name is a
 * histogram family's _bucket, _sum or _count. */
static int exported(const char *metrics, const char *name)
{
    char want[160];
    snprintf(want, sizeof want, "# TYPE %s ", name);
    if (strstr(metrics, want))
        return 1;
    static const char *const parts[] = {"_bucket", "_sum", "_count"};
    size_t n = strlen(name);
    for (int i = 0; i < 3; i++) {
        size_t pl = strlen(parts[i]);
        if (n > pl && !strcmp(name + n - pl, parts[i])) {
            snprintf(want, sizeof want, "# TYPE %.*s histogram", (int)(n - pl), name);
            if (strstr(metrics, want))
                return 1;
        }
    }
    return 0;
}

TEST_T(every_grafana_query_names_a_metric_the_daemon_exports, 60)
{
    size_t len;
    char *dash = (char *)testfile_read("deploy/grafana/meshcorr.json", &len);
    dash[len] = '\0';            /* testfile_read leaves room for it */
    CHECK(testjson_valid(dash));
    int port = testhttp_free_port();
    char http[16];
    snprintf(http, sizeof http, "%d", port);
    const char *args[] = {"--http", http, NULL};
    testdaemon d;
    testdaemon_start(&d, "grafana", args);
    const char *metrics = get_metrics(port);

    int exprs = 0, names = 0, panels = 0;
    for (const char *p = dash; (p = strstr(p, "\"gridPos\"")); p++)
        panels++;
    for (const char *p = dash; (p = strstr(p, "\"expr\": \"")); ) {
        p += 9;
        const char *end = strchr(p, '"');
        CHECK(end != NULL);
        exprs++;
        int here = 0;
        for (const char *q = p; q < end; q++) {
            if (strncmp(q, "meshcorr_", 9) || (q > p && (q[-1] == '_' || (q[-1] >= 'a' && q[-1] <= 'z'))))
                continue;
            size_t n = strspn(q, "abcdefghijklmnopqrstuvwxyz0123456789_");
            char name[128];
            CHECK(n < sizeof name);
            memcpy(name, q, n);
            name[n] = '\0';
            if (!exported(metrics, name))
                FAILF("the dashboard's query \"%.*s\" names %s, which meshcorrd's /metrics does not export",
                      (int)(end - p), p, name);
            here++;
            names++;
            q += n - 1;
        }
        if (!here)
            FAILF("the query \"%.*s\" names no meshcorr metric", (int)(end - p), p);
        p = end + 1;
    }
    printf("  %d panels, %d queries naming %d metrics, each exported\n", panels, exprs, names);
    CHECK(exprs >= panels && panels >= 10);
    free(dash);
    testdaemon_stop(&d, SIGTERM);
}
