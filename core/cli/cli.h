/* cli.h — the murk command line, part of the murk executable only (not of libmurk). */
#ifndef MURK_CLI_H
#define MURK_CLI_H

/* Runs `murk render | plugins | compare | bench | grid | --version | --help`; returns the exit status. */
int murk_cli_main(int argc, char **argv);

/* Shared by the subcommands' files. */
const char *murk_cli_q(const char *s); /* untrusted text made printable (eight rotating buffers) */
void murk_cli_error(const char *msg);  /* "murk: MESSAGE" on stderr */
int murk_cli_usage(const char *msg);   /* the message and the usage text on stderr; returns 2 */

int murk_cli_compare(int argc, char **argv); /* compare.c */
int murk_cli_bench(int argc, char **argv);   /* bench.c */

/* The cost counters (murk/counters.h) of a render as JSON for the EXR's murk:counters, and as the
 * end-of-render summary's lines (bench.c). */
#include <stdio.h>
#include "murk/murk.h"
void murk_cli_counters_json(const murk_scene *s, const murk_render_result *r, char *buf, size_t n);
void murk_cli_counters_print(FILE *f, const murk_scene *s, const murk_render_result *r);

/* `murk merge OUT.exr PART...` (merge.c): the parts of a --part I/N render into the whole image. */
int murk_cli_merge(int argc, char **argv);

#endif
