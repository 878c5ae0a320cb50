/* main.c — the murk command: everything lives in libmurk (cli.c). */
#include "murk/murk.h"

int main(int argc, char **argv) { return murk_cli_main(argc, argv); }
