/* cli_params.c — `meshcorr params [--markdown]`: the job parameters of the
 * one list (protocol/proto_params.h) with their options, defaults and
 * ranges; --markdown prints PROTOCOL.md's parameter table (`make
 * doc-params` puts it there). */
#include "cli/cli.h"
#include "cli/cli_job.h"
#include "proto.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int cli_params(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--markdown") == 0) {
        size_t n = proto_params_table(NULL, 0);
        char *t = malloc(n + 1);
        if (!t) {
            fprintf(stderr, "meshcorr params: out of memory\n");
            return 1;
        }
        proto_params_table(t, n + 1);
        fputs(t, stdout);
        free(t);
        return 0;
    }
    if (argc != 1) {
        fprintf(argc == 2 && !strcmp(argv[1], "--help") ? stdout : stderr,
                "usage: meshcorr params [--markdown]\n"
                "the job options of meshcorr match and submit; --markdown: as PROTOCOL.md's table\n");
        return argc == 2 && !strcmp(argv[1], "--help") ? 0 : 2;
    }
    cli_job_usage(stdout);
    return 0;
}
