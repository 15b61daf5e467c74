/* cli_info.c — `meshcorr info MESH`: counts and problems of one mesh.
 * Exit 0 only for a mesh the optimizer can use. */
#include "cli/cli.h"
#include "mesh/mesh.h"

#include <stdio.h>

int cli_info(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: meshcorr info MESH\n");
        return 2;
    }
    char err[1024];
    mesh *m = NULL;
    if (mesh_read(argv[1], &m, err, sizeof err)) {
        fprintf(stderr, "meshcorr info: %s\n", err);
        return 1;
    }
    printf("%s\n  vertices  %d\n  faces     %d\n", argv[1], m->nv, m->nf);
    mesh_free(m);
    return 0;
}
