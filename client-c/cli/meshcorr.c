/* meshcorr.c — main() of the `meshcorr` CLI: dispatch to a subcommand. */
#include "cli/cli.h"
#include "util/ompenv.h"
#include "meshcorr.h"

#include <stdio.h>
#include <string.h>

static const struct {
    const char *name;
    int (*run)(int, char **);
    const char *help;
} commands[] = {
    { "info",    cli_info,    "MESH             print counts, topology, area, problems" },
    { "convert", cli_convert, "IN OUT           convert between .off .obj .ply .drc" },
    { "fix",     cli_fix,     "IN OUT           write IN repaired as a job repairs it (docs/repair.md)" },
    { "match",   cli_match,   "SOURCE TARGET .. elastic correspondence (see meshcorr match --help)" },
    { "eval",    cli_eval,    "SOURCE TARGET P.map .. quality of a map (see meshcorr eval --help)" },
    { "devices", cli_devices, "                 list OpenCL devices for --backend opencl|auto" },
    { "params",  cli_params,  "[--markdown|--mdoc] the job parameters: options, defaults, ranges" },
    { "submit",  cli_submit,  "SOURCE TARGET .. send a job to meshcorrd; prints its id (--watch: then follow it)" },
    { "status",  cli_status,  "ID               a job's state, times and latest progress" },
    { "watch",   cli_watch,   "ID [--from K]    follow a job's energies; exit 0 if it COMPLETED" },
    { "result",  cli_result,  "ID --out P.map   fetch a finished job's maps (and deformed mesh)" },
    { "cancel",  cli_cancel,  "ID               cancel a pending or running job" },
    { "delete",  cli_delete,  "ID               remove a finished job and its result" },
    { "list",    cli_list,    "[--state S]      your jobs (an admin's: everyone's; --json: a JSON array)" },
    { "stats",   cli_stats,   "[--json]         queue, workers, counters" },
};

static void usage(FILE *fp)
{
    fprintf(fp, "usage: meshcorr COMMAND [ARGS]   (meshcorr COMMAND --help: its options)\n"
                "       meshcorr --version\n\ncommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(fp, "  %-8s %s\n", commands[i].name, commands[i].help);
    fprintf(fp, "\nserver commands take --server ADDR (unix:PATH, a bare path, or tcp:HOST:PORT;\n"
                "default $MESHCORR_SERVER, else " MC_DEFAULT_SERVER ") and --token T or\n"
                "--token-file F (default $MESHCORR_TOKEN; not needed on the Unix socket)\n");
}

int main(int argc, char **argv)
{
    ompenv_ensure_passive(argv);
    if (argc < 2)
        return cli_usage_error("", "no command given");
    if (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("meshcorr %s\n", MC_VERSION);
        return 0;
    }
    const char *names[sizeof commands / sizeof commands[0]];
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++) {
        if (strcmp(argv[1], commands[i].name) == 0)
            return commands[i].run(argc - 1, argv + 1);
        names[i] = commands[i].name;
    }
    char buf[256];
    const char *s = argv[1][0] == '-' ? NULL
                  : cli_suggest(argv[1], names, (int)(sizeof names / sizeof names[0]), "", buf, sizeof buf);
    if (argv[1][0] == '-')
        return cli_usage_error("", "unknown option %s (options go after the command)", argv[1]);
    return cli_usage_error("", "unknown command '%s'%s%s%s", argv[1], s ? "; did you mean " : "", s ? s : "",
                           s ? "?" : "");
}
