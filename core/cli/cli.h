/* cli.h — the murk command line, part of the murk executable only (not of libmurk). */
#ifndef MURK_CLI_H
#define MURK_CLI_H

/* Runs `murk render | plugins | compare | grid | --version | --help`; returns the exit status. */
int murk_cli_main(int argc, char **argv);

/* `murk merge OUT.exr PART...` (merge.c): the parts of a --part I/N render into the whole image. */
int murk_cli_merge(int argc, char **argv);

#endif
