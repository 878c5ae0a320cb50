/* cli.h — the murk command line, part of the murk executable only (not of libmurk). */
#ifndef MURK_CLI_H
#define MURK_CLI_H

#include <signal.h>
#include <stddef.h>

/* Runs `murk render | info | plugins | compare | bench | merge | check | grid | help | --version | --help`;
 * returns the exit status. */
int murk_cli_main(int argc, char **argv);
/* `murk info SCENE.yaml [--set ...]` (info.c). */
int murk_cli_info(int argc, char **argv);
/* A scene as the murk command loads it (info.c): murk_scene_load plus the command's rule that every
 * medium and material is used (murk_scene_check_unused). NULL after printing the one-line error. */
struct murk_scene *murk_cli_load(const char *path, const char *const *sets, size_t nsets);

/* Shared by the subcommands' files (common.c, which reaches none of them). */
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

int murk_cli_compare(int argc, char **argv); /* compare.c */
int murk_cli_plugins(int argc, char **argv); /* plugins.c */
int murk_cli_bench(int argc, char **argv);   /* bench.c */

#include <stdio.h>
/* What the scene holds in memory (info.c): every grid, mesh, texture and Embree's scene with its bytes when
 * detail, else one line of totals per kind; then the process's peak resident memory. */
void murk_cli_memory_print(FILE *f, const struct murk_scene *s, int detail);

/* `murk merge OUT.exr PART...` (merge.c): the parts of a --part I/N render into the whole image. */
int murk_cli_merge(int argc, char **argv);

#endif
