/* main.c — the murk command: argument parsing and subcommands are in cli.c, the renderer in libmurk. */
#include "cli/cli.h"
#include "plugin/plugin_loader.h"

int main(int argc, char **argv)
{
    murk_crash_handler_install();
    return murk_cli_main(argc, argv);
}
