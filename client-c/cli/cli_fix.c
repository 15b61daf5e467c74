/* cli_fix.c — `meshcorr fix IN OUT`: the input repair a job applies
 * (repair.h) written out as a mesh, with what was repaired on stderr and,
 * with --vertex-map, which input vertex each output vertex is. A mesh that
 * needs nothing is written as it is. */
#include "cli/cli.h"
#include "mesh/mesh.h"
#include "repair/repair.h"

#include <stdio.h>
#include <string.h>

static void usage(FILE *fp)
{
    fputs("usage: meshcorr fix IN OUT [--vertex-map FILE]\n"
          "Writes IN repaired as a job repairs it (docs/repair.md): vertices at the same\n"
          "position welded, degenerate and duplicate faces removed, faces turned to agree,\n"
          "non-manifold edges and vertices split, the largest piece kept. --vertex-map FILE:\n"
          "line i is the 0-based vertex of IN that vertex i of OUT is.\n", fp);
}

static int write_vertex_map(const char *path, const repair_mesh *r)
{
    FILE *fp = fopen(path, "w");
    if (!fp) {
        fprintf(stderr, "meshcorr fix: %s: cannot open for writing\n", path);
        return -1;
    }
    for (int i = 0; i < r->m->nv; i++)
        fprintf(fp, "%d\n", r->vert[i]);
    if (fclose(fp)) {
        fprintf(stderr, "meshcorr fix: %s: write failed\n", path);
        return -1;
    }
    return 0;
}

int cli_fix(int argc, char **argv)
{
    const char *pos[2] = { NULL, NULL }, *vmap = NULL;
    int npos = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
        if (strcmp(argv[i], "--vertex-map") == 0) {
            if (i + 1 == argc)
                return cli_usage_error("fix", "--vertex-map needs a file");
            vmap = argv[++i];
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return cli_usage_error("fix", "unknown option %s", argv[i]);
        } else if (npos < 2) {
            pos[npos++] = argv[i];
        } else {
            return cli_usage_error("fix", "need IN and OUT mesh files (%d given)", npos + 1);
        }
    }
    if (npos != 2)
        return cli_usage_error("fix", "need IN and OUT mesh files (%d given)", npos);
    if (cli_output_check("fix", "OUT", pos[1]) || (vmap && cli_output_check("fix", "--vertex-map", vmap)))
        return CLI_EXIT_USAGE;
    char err[1024];
    mesh *m = NULL;
    if (mesh_read(pos[0], &m, err, sizeof err)) {
        fprintf(stderr, "meshcorr fix: %s\n", err);
        return 1;
    }
    repair_mesh r;
    int status = 1;
    if (repair_mesh_run(m, pos[0], NULL, &r, err, sizeof err)) {
        fprintf(stderr, "meshcorr fix: %s\n", err);
        mesh_free(m);
        return 1;
    }
    char text[2048], prefix[1100];
    snprintf(prefix, sizeof prefix, "meshcorr fix: %s: repaired", pos[0]);
    if (repair_counts_text(&r.n, prefix, text, sizeof text))
        fputs(text, stderr);
    else if (m->polygons)
        fprintf(stderr, "meshcorr fix: %s: nothing to repair; its %d polygon%s written as triangles\n",
                pos[0], m->polygons, m->polygons == 1 ? "" : "s");
    else
        fprintf(stderr, "meshcorr fix: %s: nothing to repair\n", pos[0]);
    if (mesh_write(pos[1], r.m, err, sizeof err))
        fprintf(stderr, "meshcorr fix: %s\n", err);
    else if (!vmap || !write_vertex_map(vmap, &r))
        status = 0;
    repair_mesh_close(&r);
    mesh_free(m);
    return status;
}
