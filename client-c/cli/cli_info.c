/* cli_info.c — `meshcorr info MESH`: counts, topology, area, bounding box
 * and every problem of one mesh (mesh_check.h), and for a mesh the
 * optimizer cannot use as given what the input repair would do to it
 * (repair.h). Exit 0 only for a mesh the optimizer can use as given; 1 for
 * an unusable or unreadable one. */
#include "cli/cli.h"
#include "mesh/mesh.h"
#include "mesh/mesh_check.h"
#include "repair/repair.h"

#include <stdio.h>
#include <string.h>

/* What the input repair (on by default in a job) would do to m. */
static void print_repair(const mesh *m, const char *path)
{
    repair_mesh rm;
    char err[1024], text[2048], prefix[1100];
    if (repair_mesh_run(m, path, NULL, &rm, err, sizeof err)) {
        fprintf(stderr, "meshcorr info: %s\n", err);
        return;
    }
    snprintf(prefix, sizeof prefix, "  repair");
    repair_counts_text(&rm.n, prefix, text, sizeof text);
    printf("a job repairs it (job parameter repair, docs/repair.md) into %d vertices and %d faces; "
           "`meshcorr fix` writes that mesh:\n%s", rm.m->nv, rm.m->nf, text);
    repair_mesh_close(&rm);
}

int cli_info(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--help") == 0) {
        fputs("usage: meshcorr info MESH\n", stdout);
        return 0;
    }
    if (argc == 2 && argv[1][0] == '-' && argv[1][1])
        return cli_usage_error("info", "unknown option %s", argv[1]);
    if (argc != 2)
        return cli_usage_error("info", "need one mesh file (%d given)", argc - 1);
    const char *path = argv[1];
    char err[1024];
    mesh *m = NULL;
    if (mesh_read(path, &m, err, sizeof err)) {
        fprintf(stderr, "meshcorr info: %s\n", err);
        return 1;
    }
    mesh_check_report r;
    if (mesh_check_run(m, &r, err, sizeof err)) {
        fprintf(stderr, "meshcorr info: %s: %s\n", path, err);
        mesh_free(m);
        return 1;
    }
    printf("%s\n", path);
    printf("  vertices        %d\n", r.nv);
    if (m->polygons)
        printf("  faces           %d triangles (the file's %d polygon%s split into triangles)\n",
               r.nf, m->polygons, m->polygons == 1 ? "" : "s");
    else
        printf("  faces           %d\n", r.nf);
    printf("  edges           %d\n", r.ne);
    printf("  components      %d\n  boundary loops  %d\n  euler           %ld\n",
           r.components, r.boundary_loops, r.euler);
    if (r.genus >= 0)
        printf("  genus           %d\n", r.genus);
    else
        printf("  genus           n/a (not a single manifold piece)\n");
    printf("  total area      %.9g\n", r.area);
    printf("  bounding box    [%.6g %.6g %.6g] .. [%.6g %.6g %.6g]\n",
           r.bbox_min[0], r.bbox_min[1], r.bbox_min[2], r.bbox_max[0], r.bbox_max[1], r.bbox_max[2]);
    char problems[4096];
    int n = mesh_check_problems(&r, path, problems, sizeof problems);
    if (n > 0) {
        fputs(problems, stderr);
        fprintf(stderr, "meshcorr info: %s: %d problem%s; the optimizer cannot use this mesh as "
                "given\n", path, n, n == 1 ? "" : "s");
    }
    int usable = mesh_check_usable(&r);
    if (!usable)
        print_repair(m, path);
    mesh_free(m);
    return usable ? 0 : 1;
}
