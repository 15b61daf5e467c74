/* cli_params.c — `meshcorr params [--markdown|--mdoc]`: the job parameters
 * of the one list (protocol/proto_params.h) with their options, defaults
 * and ranges; --markdown prints PROTOCOL.md's parameter table and --mdoc
 * the job parameter list of meshcorr(1) (`make doc-params` puts both in
 * place; test_proto_params and test_man fail when either is stale). */
#include "cli/cli.h"
#include "cli/cli_job.h"
#include "proto.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One mdoc list item per parameter: option and argument, help, default
 * and range, as `meshcorr match --help` gives them. */
static void params_mdoc(FILE *fp)
{
    for (int i = 0; i < PROTO_NPARAMS; i++) {
        const proto_param_info *f = &proto_param_infos[i];
        char dflt[64], range[160];
        if (f->type == PROTO_PARAM_ENUM || f->type == PROTO_PARAM_STR)
            fprintf(fp, ".It Fl \\-%s Ar %s\n", f->cli, f->values);
        else if (f->type == PROTO_PARAM_BOOL)
            fprintf(fp, ".It Fl \\-%s\n", f->cli);
        else
            fprintf(fp, ".It Fl \\-%s Ar %s\n", f->cli, f->type == PROTO_PARAM_U32 ? "N" : "X");
        cli_param_default(i, dflt, sizeof dflt);
        /* the help, wrapped at blanks to lines of at most 72 bytes (it
         * holds no backslash and no word starts with a dot) */
        for (const char *h = f->help; *h;) {
            size_t n = strlen(h);
            if (n > 72) {
                n = 72;
                while (n > 0 && h[n] != ' ')
                    n--;
                if (n == 0)
                    n = strcspn(h, " ");
            }
            fprintf(fp, "%.*s%s", (int)n, h, h[n] ? "\n" : "");
            h += n + (h[n] == ' ');
        }
        fprintf(fp, ".\nDefault %s", dflt);
        if (f->type == PROTO_PARAM_U32 || f->type == PROTO_PARAM_F64)
            fprintf(fp, ", in %s", proto_param_range(i, range, sizeof range));
        fprintf(fp, "; wire field\n.Va %s .\n", f->name);
    }
}

int cli_params(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--mdoc") == 0) {
        params_mdoc(stdout);
        return 0;
    }
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
    if (argc == 2 && !strcmp(argv[1], "--help")) {
        printf("usage: meshcorr params [--markdown | --mdoc]\n"
               "the job options of meshcorr match and submit; --markdown: as PROTOCOL.md's table;\n"
               "--mdoc: as meshcorr(1)'s list\n");
        return 0;
    }
    if (argc != 1) {
        static const char *const names[] = {"markdown", "mdoc", "help"};
        char buf[128];
        const char *a = argv[1], *sg = strncmp(a, "--", 2) ? NULL : cli_suggest(a + 2, names, 3, "--", buf, sizeof buf);
        return cli_usage_error("params", "%s '%s'%s%s%s", a[0] == '-' ? "unknown option" : "unexpected argument", a,
                               sg ? "; did you mean " : "", sg ? sg : "", sg ? "?" : "");
    }
    cli_job_usage(stdout);
    return 0;
}
