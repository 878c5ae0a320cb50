/* main.c — the murk command: argument parsing and subcommands are in cli.c, the renderer in libmurk. */
#include "cli.h"

int main(int argc, char **argv) { return murk_cli_main(argc, argv); }
