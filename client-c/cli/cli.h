/* cli.h — the `meshcorr` command-line tool's subcommands. Each cli_<verb>.c
 * holds one subcommand; meshcorr.c only dispatches. Exit status: 0 ok,
 * 1 the input is unusable or the job failed, 2 bad usage. */
#ifndef CLI_H
#define CLI_H

int cli_info(int argc, char **argv);
int cli_convert(int argc, char **argv);
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
