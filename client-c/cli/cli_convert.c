/* cli_convert.c — `meshcorr convert IN OUT`: format by extension, vertex
 * order kept. Refuses to write a mesh with NaN/Inf coordinates or bad face
 * indices (other problems are reported by `meshcorr info`, not here). */
#include "cli/cli.h"
#include "mesh/mesh.h"
#include "mesh/mesh_check.h"

#include <stdio.h>
#include <string.h>

int cli_convert(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--help") == 0) {
        fputs("usage: meshcorr convert IN OUT\n", stdout);
        return 0;
    }
    for (int i = 1; i < argc; i++)
        if (argv[i][0] == '-' && argv[i][1])
            return cli_usage_error("convert", "unknown option %s", argv[i]);
    if (argc != 3)
        return cli_usage_error("convert", "need IN and OUT mesh files (%d given)", argc - 1);
    if (cli_output_check("convert", "OUT", argv[2]))
        return CLI_EXIT_USAGE;
    char err[1024];
    mesh *m = NULL;
    if (mesh_read(argv[1], &m, err, sizeof err)) {
        fprintf(stderr, "meshcorr convert: %s\n", err);
        return 1;
    }
    mesh_check_report r;
    int rc = mesh_check_run(m, &r, err, sizeof err);
    if (rc) {
        fprintf(stderr, "meshcorr convert: %s: %s\n", argv[1], err);
    } else if (r.nonfinite_vertices || r.bad_index_faces) {
        char problems[2048];
        mesh_check_problems(&r, argv[1], problems, sizeof problems);
        fprintf(stderr, "%smeshcorr convert: %s: not written\n", problems, argv[2]);
        rc = 1;
    } else {
        rc = mesh_write(argv[2], m, err, sizeof err);
        if (rc)
            fprintf(stderr, "meshcorr convert: %s\n", err);
    }
    mesh_free(m);
    return rc ? 1 : 0;
}
