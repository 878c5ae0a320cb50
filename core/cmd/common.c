/* common.c — what the murk command's subcommands share (cmd.h): the usage text, quoting untrusted text,
 * the one-line error and usage messages, the stop signals of render and bench, and whether to show
 * progress. Reaches no subcommand; a static library, so that each binary holding subcommands links its copy. */
#include "cmd/cmd.h"
#include "util/util.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

const char murk_cli_usage_text[] =
    "usage:\n"
    "  murk render SCENE.yaml [-o OUT.exr] [--spp N] [--threads N] [--set KEY.PATH=VALUE ...] [--time S] [--quiet]\n"
    "              [--checkpoint FILE [--every S]] [--resume FILE] [--part I/N]\n"
    "  mpirun -n N murk render ...          (one image over N processes)\n"
    "  murk merge OUT.exr PART.exr...       (the parts of a --part I/N render into one image)\n"
    "  murk info SCENE.yaml [--set KEY.PATH=VALUE ...]\n"
    "  murk info IMAGE.png|IMAGE.exr        (its text keys: murk:commit, murk:version)\n"
    "  murk plugins [--markdown] [--all | NAME]\n"
    "  murk compare TEST.exr REFERENCE.exr [--crop X,Y,W,H] [--json] [--diff DIFF.png [--scale S]] [--html PAGE.html]\n"
    "  murk bench SCENE.yaml [--vary KEY=V1,V2,...]... [--spp N1,N2,... | --time S1,...] [--repeat K] [-o DIR] ...\n"
    "  murk check [--seed S] [--quick] [--set KEY=VALUE]... PLUGIN...\n"
    "  murk grid OUT.vol [--min X,Y,Z] [--max X,Y,Z] [--res N] [--seed S] [--frequency F] [--octaves O] [--coverage C]\n"
    "  murk help [COMMAND]      (or murk COMMAND --help)\n"
    "  murk --version\n";

/* Untrusted text (arguments, names read from files) made printable for a message (murk_printable);
 * eight rotating buffers, so one message may quote several. */
const char *murk_cli_q(const char *s)
{
    static char buf[8][1024];
    static int k;
    k = (k + 1) % 8;
    return murk_printable(buf[k], sizeof buf[k], s);
}

/* "murk: MESSAGE" for a message built from input (the scene's and loaders' errors are printable
 * already; plugin and image errors may quote a raw argument). */
void murk_cli_error(const char *msg) { fprintf(stderr, "murk: %s\n", murk_cli_q(msg)); }

int murk_cli_usage(const char *msg)
{
    if (msg)
        fprintf(stderr, "murk: %s\n", msg);
    fputs(murk_cli_usage_text, stderr);
    return 2;
}

/* SIGINT/SIGTERM/SIGHUP during `render` and `bench` (murk_cli_catch_stop_signals, cmd.h): the flag is set
 * and murk goes on. render abandons the running pass, writes the image of the whole passes done
 * (murk:interrupted says so) and exits with 128 + the signal's number; bench (bench.c) stops after the
 * running render, keeps only whole renders' rows and exits the same way. A signal that was ignored when
 * murk started stays ignored: `nohup murk render ...` goes on rendering when its terminal hangs up, as
 * nohup promises, and a job a non-interactive shell started in the background keeps ignoring SIGINT. */
static volatile sig_atomic_t render_stop, render_signal;

static void on_stop_signal(int sig)
{
    render_signal = sig;
    render_stop = 1;
}

volatile sig_atomic_t *murk_cli_catch_stop_signals(void)
{
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
        struct sigaction sa, old;
        if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
            continue;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_stop_signal;
        sigemptyset(&sa.sa_mask);
        sigaction(sigs[i], &sa, NULL);
    }
    return &render_stop;
}

int murk_cli_stop_status(void) { return 128 + (render_signal ? (int)render_signal : SIGINT); }

const char *murk_cli_stop_name(void)
{
    return render_signal == SIGTERM ? "SIGTERM" : render_signal == SIGHUP ? "SIGHUP" : "SIGINT";
}

/* Under mpirun stderr is a pipe to the launcher whatever the terminal: MURK_PROGRESS=1 asks for the bar. */
int murk_cli_progress(void)
{
    const char *e = getenv("MURK_PROGRESS");
    return isatty(STDERR_FILENO) || (e && !strcmp(e, "1"));
}
