/* cli.h — the `meshcorr` command-line tool's subcommands. Each cli_<verb>.c
 * holds one subcommand; meshcorr.c only dispatches. Exit status: 0 ok,
 * 1 the input is unusable or the job failed, 2 bad usage (CLI_EXIT_USAGE). */
#ifndef CLI_H
#define CLI_H
#include <getopt.h>
#include <stddef.h>

#define CLI_EXIT_USAGE 2

/* cli_usage.c: a usage error is one line naming it, then "see `meshcorr
 * CMD --help`" (cmd "" or NULL: the top level); both return CLI_EXIT_USAGE. */
int cli_usage_error(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
int cli_usage_see(const char *cmd);
/* getopt_long over opts (short options: -h only) with messages of our own
 * and no abbreviated names: the option's code, -1 after the last, or '?'
 * after printing the error line (an unknown or abbreviated option with the
 * names it may have meant, a missing value, a value given to a flag); the
 * caller then ends with cli_usage_see. */
int cli_getopt(const char *cmd, int argc, char **argv, const struct option *opts);
/* The names (each after prefix) word may have meant: those it starts, or
 * the nearest by edit distance when it is near enough to be a typo; in buf,
 * or NULL when none is. */
const char *cli_suggest(const char *word, const char *const *names, int n, const char *prefix, char *buf,
                        size_t sz);
/* 0 when path can be written (a file, or a new name in a folder that
 * exists and is writable); else -1 after printing "meshcorr CMD: OPT PATH:
 * why". Commands check every output before they start work. */
int cli_output_check(const char *cmd, const char *opt, const char *path);
/* --out-stage NAME=FILE (match, result): FILE into *rhm (NAME rhm) or
 * *rhm_rev (rhm-reverse); -1 after the usage error for another NAME or no
 * FILE. */
int cli_out_stage(const char *cmd, const char *arg, const char **rhm, const char **rhm_rev);

int cli_info(int argc, char **argv);
int cli_convert(int argc, char **argv);
int cli_fix(int argc, char **argv);
int cli_match(int argc, char **argv);
int cli_eval(int argc, char **argv);
int cli_devices(int argc, char **argv);
int cli_params(int argc, char **argv);
/* cli_remote.c: through meshcorrd (libmeshcorr) */
int cli_submit(int argc, char **argv);
int cli_status(int argc, char **argv);
int cli_watch(int argc, char **argv);
int cli_result(int argc, char **argv);
int cli_cancel(int argc, char **argv);
int cli_delete(int argc, char **argv);
int cli_list(int argc, char **argv);
int cli_stats(int argc, char **argv);

#endif
