/* web_route.c — the HTTP endpoint's requests, other than /metrics, to the
 * one that answers them: /api/v1/ to the API (web_api.c), /static/ to the
 * embedded assets, /login and /logout, and the pages (web.c), each page
 * only behind a login. Holds the web's lock for the whole request. */
#include "web.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

static enum MHD_Result handle(web *w, web_req *r)
{
    int get = !strcmp(r->method, MHD_HTTP_METHOD_GET), post = !strcmp(r->method, MHD_HTTP_METHOD_POST);
    const char *u = r->url;
    if (!strncmp(u, "/api/v1/", 8) || !strcmp(u, "/api/v1"))
        return web_api(w, r, u + 7);
    if (!strncmp(u, "/static/", 8)) {
        if (!get)
            return web_reply_text(r, MHD_HTTP_METHOD_NOT_ALLOWED, "GET only\n");
        return web_page(r, MHD_HTTP_OK, u + 8);
    }
    if (!strcmp(u, "/login")) {
        if (post)
            return web_login(w, r);
        if (!get)
            return web_reply_text(r, MHD_HTTP_METHOD_NOT_ALLOWED, "GET or POST only\n");
        return web_login_page(r, MHD_HTTP_OK, "");
    }
    if (!strcmp(u, "/logout")) {
        if (!post)
            return web_reply_text(r, MHD_HTTP_METHOD_NOT_ALLOWED, "POST only\n");
        return web_logout(w, r);
    }
    const char *name = !strcmp(u, "/") ? "index.html" : !strcmp(u, "/workers") ? "workers.html"
                     : !strncmp(u, "/jobs/", 6) ? "job.html" : NULL;
    if (!name)
        return web_reply_text(r, MHD_HTTP_NOT_FOUND, "not found: the pages are /, /jobs/ID and /workers; "
                              "the metrics /metrics; the API /api/v1/\n");
    if (!get)
        return web_reply_text(r, MHD_HTTP_METHOD_NOT_ALLOWED, "GET only\n");
    enum MHD_Result res;
    if (web_auth(w, r, &res))
        return res;
    if (!strcmp(name, "job.html")) {
        char *end;
        errno = 0;
        unsigned long long id = strtoull(u + 6, &end, 10);
        store_job j;
        if (errno || *end || end == u + 6 || web_job(w, r, id, &j, NULL, 0))
            return web_reply_text(r, MHD_HTTP_NOT_FOUND, "no such job\n");
    }
    return web_page(r, MHD_HTTP_OK, name);
}

enum MHD_Result web_handle(web *w, web_req *r)
{
    web_lock(w);
    web_snapshot(w);
    enum MHD_Result rc = handle(w, r);
    web_unlock(w);
    explicit_bzero(r->csrf, sizeof r->csrf);
    return rc;
}
