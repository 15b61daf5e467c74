/* testjob.c — see testjob.h. Builds and writes job.frame; runs nothing. */
#include "support/testjob.h"
#include "corr/corr.h"
#include "map/bmap.h"
#include "mesh/mesh.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

void testjob_close(testjob *j)
{
    if (!j)
        return;
    free(j->src_drc);
    free(j->tgt_drc);
    free(j->landmarks);
    free(j->p_rows);
    free(j->q_rows);
    memset(j, 0, sizeof *j);
}

static int encode(const mesh *m, unsigned char **buf, proto_blob *b, char *err, size_t errsz)
{
    size_t len = 0;
    if (mesh_encode_drc(m, buf, &len, err, errsz))
        return -1;
    b->data = *buf;
    b->len = (uint32_t)len;
    return 0;
}

static int load_map(const char *path, const mesh *from, const mesh *to, proto_map_row **rows,
                    proto_map *out, char *err, size_t errsz)
{
    if (!path)
        return 0;
    bmap *P = NULL;
    if (bmap_read(path, from, to, &P, err, errsz))
        return -1;
    if (!(*rows = malloc(sizeof **rows * ((size_t)P->n + 1)))) {
        bmap_free(P);
        snprintf(err, errsz, "%s: out of memory", path);
        return -1;
    }
    for (int i = 0; i < P->n; i++) {
        (*rows)[i].face = (uint32_t)P->face[i];
        memcpy((*rows)[i].w, P->w + 3 * (size_t)i, sizeof(*rows)[i].w);
    }
    out->rows = *rows;
    out->n = (uint32_t)P->n;
    bmap_free(P);
    return 0;
}

int testjob_build(testjob *j, const char *src_path, const char *tgt_path,
                  const proto_landmark *landmarks, unsigned nlandmarks, const char *p0_path,
                  const char *q0_path, const ectm_params *params, char *err, size_t errsz)
{
    memset(j, 0, sizeof *j);
    mesh *S = NULL, *T = NULL;
    int rc = -1;
    proto_submit *s = &j->msg.u.submit;
    j->msg.type = PROTO_MSG_SUBMIT;
    if (mesh_read(src_path, &S, err, errsz) || mesh_read(tgt_path, &T, err, errsz) ||
        encode(S, &j->src_drc, &s->source, err, errsz) ||
        encode(T, &j->tgt_drc, &s->target, err, errsz) ||
        load_map(p0_path, S, T, &j->p_rows, &s->p, err, errsz) ||
        load_map(q0_path, T, S, &j->q_rows, &s->q, err, errsz))
        goto done;
    if (nlandmarks) {
        if (!(j->landmarks = malloc(sizeof *landmarks * nlandmarks))) {
            snprintf(err, errsz, "landmarks: out of memory");
            goto done;
        }
        memcpy(j->landmarks, landmarks, sizeof *landmarks * nlandmarks);
        s->landmarks = j->landmarks;
        s->nlandmarks = nlandmarks;
    }
    ectm_params def;
    ectm_params_init(&def);
    proto_params_init(&s->params);
    corr_params_to_job(params ? params : &def, NULL, &s->params, NULL, 0);
    s->label = "testjob";
    rc = 0;
done:
    mesh_free(S);
    mesh_free(T);
    if (rc)
        testjob_close(j);
    return rc;
}

int testjob_save(const testjob *j, const char *dir, char *err, size_t errsz)
{
    if (mkdir(dir, 0755) != 0 && errno != EEXIST) {
        snprintf(err, errsz, "%s: cannot create: %s", dir, strerror(errno));
        return -1;
    }
    proto_buf b;
    proto_buf_init(&b);
    char path[4096];
    snprintf(path, sizeof path, "%s/job.frame", dir);
    int rc = proto_msg_encode(&b, &j->msg, err, errsz) ? -1 : 0;
    FILE *fp = rc ? NULL : fopen(path, "wb");
    if (!rc && !fp) {
        snprintf(err, errsz, "%s: cannot create: %s", path, strerror(errno));
        rc = -1;
    }
    if (fp) {
        size_t put = fwrite(b.data, 1, b.len, fp);
        if (fclose(fp) != 0 || put != b.len) {
            snprintf(err, errsz, "%s: write failed", path);
            rc = -1;
        }
    }
    proto_buf_free(&b);
    return rc;
}

int testjob_write(const char *dir, const char *src_path, const char *tgt_path,
                  const proto_landmark *landmarks, unsigned nlandmarks, const char *p0_path,
                  const char *q0_path, const ectm_params *params, char *err, size_t errsz)
{
    testjob j;
    if (testjob_build(&j, src_path, tgt_path, landmarks, nlandmarks, p0_path, q0_path, params,
                      err, errsz))
        return -1;
    int rc = testjob_save(&j, dir, err, errsz);
    testjob_close(&j);
    return rc;
}
