/* cli_convert.c — `meshcorr convert IN OUT`: format by extension, vertex
 * order kept. */
#include "cli/cli.h"
#include "mesh/mesh.h"

#include <stdio.h>

int cli_convert(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: meshcorr convert IN OUT\n");
        return 2;
    }
    char err[1024];
    mesh *m = NULL;
    if (mesh_read(argv[1], &m, err, sizeof err)) {
        fprintf(stderr, "meshcorr convert: %s\n", err);
        return 1;
    }
    int rc = mesh_write(argv[2], m, err, sizeof err);
    if (rc)
        fprintf(stderr, "meshcorr convert: %s\n", err);
    mesh_free(m);
    return rc ? 1 : 0;
}
