/* cmd.h — what the murk command's subcommands share, wherever they live: the usage text, quoting untrusted
 * text, the one-line error and usage messages, the stop signals of render and bench, and whether to show
 * progress (common.c). A static library, which each binary holding subcommands links (exporting none of it);
 * the names keep the murk_cli_ prefix of the command line they serve. */
#ifndef MURK_CMD_H
#define MURK_CMD_H

#include <signal.h>

extern const char murk_cli_usage_text[]; /* every subcommand's synopsis: `murk --help` */
const char *murk_cli_q(const char *s); /* untrusted text made printable (eight rotating buffers) */
void murk_cli_error(const char *msg);  /* "murk: MESSAGE" on stderr */
int murk_cli_usage(const char *msg);   /* the message and the usage text on stderr; returns 2 */

/* SIGINT, SIGTERM and SIGHUP set the returned flag (murk_render_opts.stop) instead of ending murk: `render`
 * and `bench` stop cleanly (one ignored when murk started stays ignored: nohup). Then the exit status,
 * 128 + the signal, and its name ("SIGINT", "SIGTERM", "SIGHUP"). */
volatile sig_atomic_t *murk_cli_catch_stop_signals(void);
int murk_cli_stop_status(void);
const char *murk_cli_stop_name(void);
/* 1 if progress goes to stderr: a terminal, or MURK_PROGRESS=1 (mpirun's pipe, a test's file). */
int murk_cli_progress(void);

#endif
